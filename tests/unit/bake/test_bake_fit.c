/* The least-squares vertex fit (core/bake/fit.c) and the weld (weld.c). */
#include "level/bake_testutil.h"
#include "bake/bake_internal.h"

/* A pair of triangles (a, b, c), (b, a, d) in one plane: the regulariser's
 * jump is zero for any linear signal, 2 for the kink |y| (slope 1 on
 * both sides of the edge y = 0), and its weight is (A1 h1^2 + A2 h2^2)/6. */
static void test_edge_jump(void **state)
{
    (void)state;
    const float a[3] = {0, 0, 0}, b[3] = {2, 0, 0}, c[3] = {0.5f, 1, 0}, d[3] = {1.5f, -3, 0};
    double j[4];
    double om = obs__bake_edge_jump(a, b, c, d, j);
    /* A1 = 1, h1 = 1; A2 = 3, h2 = 3 */
    assert_true(fabs(om - (1.0 * 1.0 + 3.0 * 9.0) / 6.0) < 1e-9);
    const float *p[4] = {a, b, c, d};
    for (int t = 0; t < 8; t++) {
        double g0 = t * 0.3 - 1.0, gx = (t % 3) - 1.0, gy = 0.7 * t - 2.0, jump = 0.0;
        for (int k = 0; k < 4; k++)
            jump += j[k] * (g0 + gx * p[k][0] + gy * p[k][1]);
        assert_true(fabs(jump) < 1e-9);
    }
    double kink = 0.0;
    for (int k = 0; k < 4; k++)
        kink += j[k] * fabs(p[k][1]);
    assert_true(fabs(kink - 2.0) < 1e-9);
    /* folded out of the plane (the pair unfolded), the same holds for a
     * signal linear in the unfolded coordinates: distance along the edge
     * and signed distance from it */
    const float df[3] = {1.5f, 0, 3};
    om = obs__bake_edge_jump(a, b, c, df, j);
    assert_true(om > 0.0);
    double unfolded = j[0] * 0 + j[1] * 0 + j[2] * 1.0 + j[3] * -3.0;
    assert_true(fabs(unfolded) < 1e-9);
    /* a degenerate pair */
    const float e[3] = {1, 0, 0};
    assert_true(obs__bake_edge_jump(a, b, e, d, j) < 0.0);
}

/* One plane, flattened and sampled: the fit's input without the trace. */
typedef struct plane {
    obs_bake_scene sc;
    obs__bake_world w;
    obs__bake_samples s;
    obs__bake_weld wd;
} plane;

static void plane_make(plane *pl, const float o[3], const float u[3], const float v[3], int nu,
                       int nv, double per_face)
{
    obs_bake_mesh m;
    char err[OBS_ERR_LEN] = "";
    bt_grid(&m, "plane", o, u, v, nu, nv);
    bt_scene(&pl->sc, &m, 1);
    assert_int_equal(obs__bake_flatten(&pl->sc, &pl->w, err), OBS_OK);
    assert_int_equal(obs__bake_samples_make(&pl->w, per_face, 16, 5, &pl->s, err), OBS_OK);
    memset(&pl->wd, 0, sizeof pl->wd);
}

static void plane_free(plane *pl)
{
    obs__bake_weld_free(&pl->wd);
    obs__bake_samples_free(&pl->s);
    obs__bake_world_free(&pl->w);
    obs_bake_scene_free(&pl->sc);
}

/* A welded plane whose samples carry a linear signal: with the mass matrix
 * from the samples the fit is the least-squares fit of the samples, which
 * a linear signal meets exactly (and the regulariser is zero there); the
 * analytic mass matrix only approaches it as the samples integrate the
 * hat products exactly. */
static void run_linear(const char *mass, const char *ridge, double tol, double *worst_out)
{
    const float o[3] = {-3, 0.5f, -2}, u[3] = {0, 0.8f, 5}, v[3] = {6, 0.3f, 0};
    plane pl;
    plane_make(&pl, o, u, v, 10, 12, 3.0);
    char err[OBS_ERR_LEN] = "";
    for (size_t i = 0; i < pl.s.count; i++) {
        float p[3];
        obs__bake_sample_pos(&pl.w, &pl.s, i, p);
        pl.s.ao[2 * i] = 0.2f + 0.05f * p[0] + 0.03f * p[2];
        pl.s.ao[2 * i + 1] = 0.9f - 0.02f * p[0] + 0.01f * p[1];
        pl.s.valid[i] = 1;
    }
    assert_int_equal(obs__bake_weld_make(&pl.w, 1e-5f, 120.0f, &pl.wd, err), OBS_OK);
    assert_int_equal(pl.wd.count, pl.w.vertex_count); /* indexed already */
    obs_bake_params p = {0};
    bt_set(&p, "mass", mass);
    bt_set(&p, "ridge", ridge);
    obs_bake_params_resolve(&p, &p);
    double *x = malloc(6 * pl.wd.count * sizeof *x);
    obs_bake_stats st = {0};
    assert_int_equal(obs__bake_fit(&pl.w, &pl.wd, &pl.s, &p, x, x + 2 * pl.wd.count, x + 4 * pl.wd.count, &st, err),
                     OBS_OK);
    double worst = 0.0;
    for (size_t v2 = 0; v2 < pl.w.vertex_count; v2++) {
        const float *q = pl.w.pos + 3 * v2;
        double f0 = 0.2 + 0.05 * q[0] + 0.03 * q[2], f1 = 0.9 - 0.02 * q[0] + 0.01 * q[1];
        worst = fmax(worst, fmax(fabs(x[2 * pl.wd.of[v2]] - f0), fabs(x[2 * pl.wd.of[v2] + 1] - f1)));
    }
    print_message("linear signal, mass %s, ridge %s: worst vertex error %.2e, residual %.2e, "
                  "regulariser %.2e\n",
                  mass, ridge, worst, st.residual_fit[0], st.regulariser_energy[0]);
    assert_true(worst < tol);
    if (worst_out)
        *worst_out = worst;
    assert_true(st.interior_edges > 0);
    free(x);
    plane_free(&pl);
}

static void test_linear_signal(void **state)
{
    (void)state;
    double analytic;
    run_linear("samples", "0", 2e-5, NULL);
    run_linear("samples", "1e-4", 2e-5, NULL); /* x0 is near the signal */
    run_linear("analytic", "0", 0.5, &analytic);
    assert_true(analytic > 1e-3); /* not exact: b and M disagree */
}

/* Soup: two triangles of a quad, each with its own three vertices, weld to
 * four; the same quad twice back to back (opposite normals) stays two. */
static void test_weld(void **state)
{
    (void)state;
    obs_bake_mesh m;
    memset(&m, 0, sizeof m);
    m.name = strdup("soup");
    m.material = -1;
    const float P[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
    const int corners[4][3] = {{0, 2, 1}, {0, 3, 2}, {0, 1, 2}, {0, 2, 3}};
    m.vertex_count = 12;
    m.triangle_count = 4;
    m.positions = malloc(12 * 3 * sizeof(float));
    m.normals = malloc(12 * 3 * sizeof(float));
    m.indices = malloc(12 * sizeof(uint32_t));
    for (int t = 0; t < 4; t++)
        for (int k = 0; k < 3; k++) {
            int v = 3 * t + k;
            memcpy(m.positions + 3 * v, P[corners[t][k]], sizeof P[0]);
            /* up for the first pair, down for the second */
            const float n[3] = {0, t < 2 ? 1.0f : -1.0f, 0};
            memcpy(m.normals + 3 * v, n, sizeof n);
            m.indices[v] = (uint32_t)v;
        }
    /* a position a hair off: welds within the tolerance */
    m.positions[3 * 4 + 0] += 1e-7f;
    obs_bake_scene sc;
    bt_scene(&sc, &m, 1);
    obs__bake_world w;
    obs__bake_weld wd;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__bake_flatten(&sc, &w, err), OBS_OK);
    assert_int_equal(obs__bake_weld_make(&w, 1e-5f, 120.0f, &wd, err), OBS_OK);
    assert_int_equal(wd.count, 8);
    assert_int_equal(wd.of[0], wd.of[3]);  /* corner 0 of both up faces */
    assert_true(wd.of[0] != wd.of[6]);     /* up and down stay apart */
    obs__bake_weld_free(&wd);
    /* weld_angle 180 joins the two sides */
    assert_int_equal(obs__bake_weld_make(&w, 1e-5f, 180.0f, &wd, err), OBS_OK);
    assert_int_equal(wd.count, 4);
    obs__bake_weld_free(&wd);
    obs__bake_world_free(&w);
    obs_bake_scene_free(&sc);
}

/* A vertex without a valid sample takes its neighbours' value, never 0. */
static void test_fill_from_neighbours(void **state)
{
    (void)state;
    const float o[3] = {0, 0, 0}, u[3] = {0, 0, 4}, v[3] = {4, 0, 0};
    plane pl;
    plane_make(&pl, o, u, v, 4, 4, 2.0);
    char err[OBS_ERR_LEN] = "";
    /* every sample valid at 0.6, except those of faces touching the
     * corner vertex 0 */
    for (size_t i = 0; i < pl.s.count; i++) {
        const uint32_t *t = pl.w.tri + 3 * pl.s.tri[i];
        pl.s.ao[2 * i] = pl.s.ao[2 * i + 1] = 0.6f;
        pl.s.valid[i] = !(t[0] == 0 || t[1] == 0 || t[2] == 0);
    }
    assert_int_equal(obs__bake_weld_make(&pl.w, 1e-5f, 120.0f, &pl.wd, err), OBS_OK);
    obs_bake_params p;
    obs_bake_params_resolve(NULL, &p);
    double *x = malloc(6 * pl.wd.count * sizeof *x);
    obs_bake_stats st = {0};
    assert_int_equal(obs__bake_fit(&pl.w, &pl.wd, &pl.s, &p, x, x + 2 * pl.wd.count, x + 4 * pl.wd.count, &st, err),
                     OBS_OK);
    assert_true(st.vertices_without_samples >= 1);
    assert_int_equal(st.vertices_isolated, 0);
    assert_true(fabs(x[2 * pl.wd.of[0]] - 0.6) < 1e-3);
    free(x);
    /* ridge 0 with vertices without samples: a clear error, not a
     * singular solve */
    bt_set(&p, "ridge", "0");
    x = malloc(6 * pl.wd.count * sizeof *x);
    assert_int_equal(obs__bake_fit(&pl.w, &pl.wd, &pl.s, &p, x, x + 2 * pl.wd.count, x + 4 * pl.wd.count, &st, err),
                     OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "singular"));
    free(x);
    /* no valid sample at all: the same */
    memset(pl.s.valid, 0, pl.s.count);
    bt_set(&p, "ridge", "1e-4");
    x = malloc(6 * pl.wd.count * sizeof *x);
    assert_int_equal(obs__bake_fit(&pl.w, &pl.wd, &pl.s, &p, x, x + 2 * pl.wd.count, x + 4 * pl.wd.count, &st, err),
                     OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "no valid sample"));
    free(x);
    plane_free(&pl);
}

/* The sample counts: proportional to area, at least 1, capped. */
static void test_sample_counts(void **state)
{
    (void)state;
    obs_bake_mesh m[2];
    const float o[3] = {0, 0, 0}, u[3] = {0, 0, 1}, v[3] = {1, 0, 0};
    const float o2[3] = {10, 0, 0}, u2[3] = {0, 0, 100}, v2[3] = {100, 0, 0};
    bt_grid(&m[0], "fine", o, u, v, 10, 10);    /* 200 faces of 0.005 */
    bt_grid(&m[1], "coarse", o2, u2, v2, 1, 1); /* 2 faces of 5000 */
    obs_bake_scene sc;
    bt_scene(&sc, m, 2);
    obs__bake_world w;
    obs__bake_samples s;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__bake_flatten(&sc, &w, err), OBS_OK);
    assert_int_equal(obs__bake_samples_make(&w, 4.0, 16, 1, &s, err), OBS_OK);
    for (size_t t = 0; t < w.triangle_count; t++) {
        size_t n = s.first[t + 1] - s.first[t];
        assert_true(n >= 1 && n <= 16);
        double wsum = 0.0;
        for (size_t i = s.first[t]; i < s.first[t + 1]; i++)
            wsum += s.weight[i];
        assert_true(fabs(wsum - w.area[t]) < 1e-3 * w.area[t]); /* w = A_t / n_t */
    }
    /* the two coarse faces are capped, the rest of the budget goes to the
     * fine ones */
    assert_int_equal(s.first[202] - s.first[200], 32);
    assert_true(s.count >= 4 * 202 - 2);
    assert_true(s.count <= 4 * 202 + 202);
    obs__bake_samples_free(&s);
    obs__bake_world_free(&w);
    obs_bake_scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edge_jump),
        cmocka_unit_test(test_linear_signal),
        cmocka_unit_test(test_weld),
        cmocka_unit_test(test_fill_from_neighbours),
        cmocka_unit_test(test_sample_counts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
