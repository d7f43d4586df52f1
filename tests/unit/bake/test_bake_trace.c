/* The obscurance of eq 1 at the samples and at the fitted vertices
 * (core/bake/trace.c, bake.c) against closed forms. */
#include "level/bake_testutil.h"
#include "bake/bake_internal.h"
#include "core/obscurance_crease.h"

#define PI 3.14159265358979323846

/* crease_ao(h, d): tests/unit/core/obscurance_crease.h */

static void test_closed_form_itself(void **state)
{
    (void)state;
    assert_true(fabs(crease_ao(0.0, 1.0) - 0.5) < 1e-6);
    /* far from the wall the wall no longer obscures */
    assert_true(fabs(crease_ao(40.0, 1.0) - 1.0) < 1e-6);
    assert_true(crease_ao(0.5, 1.0) > crease_ao(0.25, 1.0));
}

static void test_plane_is_one(void **state)
{
    (void)state;
    obs_bake_mesh m;
    const float o[3] = {-5, 0, -5}, u[3] = {0, 0, 10}, v[3] = {10, 0, 0};
    bt_grid(&m, "plane", o, u, v, 8, 8);
    obs_bake_scene sc;
    bt_scene(&sc, &m, 1);
    obs_bake_desc d = {0};
    bt_set(&d.params, "rays", "64");
    obs_bake_result r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    assert_int_equal(r.instance_count, 1);
    for (size_t v2 = 0; v2 < sc.meshes[0].vertex_count; v2++) {
        assert_true(fabsf(r.instances[0].ao[v2] - 1.0f) < 1e-5f);
        assert_true(fabsf(r.instances[0].ao_short[v2] - 1.0f) < 1e-5f);
        assert_true(fabsf(r.instances[0].ao_long[v2] - 1.0f) < 1e-5f);
    }
    assert_int_equal(r.stats.samples_dropped_backface, 0);
    assert_true(r.stats.residual_fit[0] < 1e-5);
    obs_bake_result_free(&r);
    obs_bake_scene_free(&sc);
}

/* Floor x in [0, F], z in [-W, W] (normal +y), wall x = 0, y in [0, H]
 * (normal +x), 0.25 apart along the crease; with d <= 0.5 what the finite
 * planes miss weighs at most 2^-(6/0.5) next to the infinite ones, far
 * below the Monte Carlo error.  Eq 1 at the crease has an infinite slope
 * (AO(h) - 1/2 ~ k log(1/k)), which no piecewise-linear signal on a
 * uniform grid follows at its first vertex: the lines away from the
 * crease are graded quadratically (the first 6/24^2 = 0.01 from it). */
#define F 6.0f
#define H 6.0f
#define W 4.0f
static void crease(obs_bake_scene *sc)
{
    obs_bake_mesh m[2];
    const float o[3] = {0, 0, -W}, fz[3] = {0, 0, 2 * W}, fx[3] = {F, 0, 0}, wy[3] = {0, H, 0};
    bt_grid_graded(&m[0], "floor", o, fz, fx, 32, 24, 1.0, 2.0);
    bt_grid_graded(&m[1], "wall", o, wy, fz, 24, 32, 2.0, 1.0);
    bt_scene(sc, m, 2);
}

static void test_crease_samples(void **state)
{
    (void)state;
    obs_bake_scene sc;
    crease(&sc);
    obs__bake_world w;
    obs__bake_samples s;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__bake_flatten(&sc, &w, err), OBS_OK);
    assert_int_equal(obs__bake_samples_make(&w, 2.0, 16, 7, &s, err), OBS_OK);
    obs__bake_trace_desc td = {{0.25f, 0.5f}, 256, 2, 0.25f, 7, NULL, NULL};
    double bvh;
    assert_int_equal(obs__bake_trace(&w, &s, &td, &bvh, err), OBS_OK);
    assert_int_equal(s.dropped, 0);
    for (int c = 0; c < 2; c++) {
        double sum = 0.0, sq = 0.0;
        size_t n = 0;
        for (size_t i = 0; i < s.count; i++) {
            float p[3];
            obs__bake_sample_pos(&w, &s, i, p);
            /* floor and wall samples near the middle */
            int floor = fabsf(p[1]) < 1e-6f;
            float h = floor ? p[0] : p[1];
            if (fabsf(p[2]) > 2.0f || h > 3.0f)
                continue;
            double e = s.ao[2 * i + c] - crease_ao(h, td.distance[c]);
            sum += e;
            sq += e * e;
            n++;
        }
        /* rho in [0, 1]: one sample's 256 rays have sigma <= 0.5 / 16;
         * the mean error of n samples within 4 sigma / sqrt(n), the RMS
         * within sigma. */
        double sigma = 0.5 / 16.0;
        assert_true(n > 500);
        assert_true(fabs(sum / n) < 4.0 * sigma / sqrt((double)n));
        assert_true(sqrt(sq / n) < sigma);
    }
    obs__bake_samples_free(&s);
    obs__bake_world_free(&w);
    obs_bake_scene_free(&sc);
}

/* The fitted vertex values against the closed form: with alpha 0 (the
 * data term of eq 2 alone) within the Monte Carlo error of a vertex's
 * samples and the graded grid's interpolation error (0.03); with the
 * paper's alpha 1 the regulariser smooths the infinite slope at the
 * crease, which lifts the crease's vertices by about 0.05 (bench/BAKE.md);
 * the bound there is looser. */
static void crease_fit(const char *alpha, double worst_max, double crease_max)
{
    obs_bake_scene sc;
    crease(&sc);
    obs_bake_desc d = {0};
    bt_set(&d.params, "distance_short", "0.25");
    bt_set(&d.params, "distance_long", "0.5");
    bt_set(&d.params, "samples_per_face", "4");
    bt_set(&d.params, "alpha", alpha);
    obs_bake_result r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    double worst[2] = {0, 0}, at0[2] = {0, 0};
    int n0 = 0;
    for (size_t i = 0; i < r.instance_count; i++) {
        const obs_bake_mesh *m = &sc.meshes[r.instances[i].mesh];
        for (size_t v = 0; v < m->vertex_count; v++) {
            const float *p = m->positions + 3 * v;
            float h = i == 0 ? p[0] : p[1];
            if (fabsf(p[2]) > 2.0f || h > 3.0f)
                continue;
            const float *val[2] = {r.instances[i].ao_short, r.instances[i].ao_long};
            for (int c = 0; c < 2; c++) {
                double e = fabs(val[c][v] - crease_ao(h, c ? 0.5 : 0.25));
                worst[c] = fmax(worst[c], e);
                if (h == 0.0f)
                    at0[c] += val[c][v];
            }
            n0 += h == 0.0f;
        }
    }
    print_message("crease vertices, alpha %s: worst |fit - closed form| short %.4f long %.4f; "
                  "mean at the crease %.4f %.4f (closed form 0.5)\n",
                  alpha, worst[0], worst[1], at0[0] / n0, at0[1] / n0);
    assert_true(n0 > 10);
    for (int c = 0; c < 2; c++) {
        assert_true(worst[c] < worst_max);
        assert_true(fabs(at0[c] / n0 - 0.5) < crease_max);
    }
    obs_bake_result_free(&r);
    obs_bake_scene_free(&sc);
}

static void test_crease_vertices(void **state)
{
    (void)state;
    crease_fit("0", 0.03, 0.01);
    crease_fit("1", 0.07, 0.06);
}

/* The mean _AO_SHORT of the crease's vertices (h = 0), the scene's node
 * mirrored through x = 0 or not. */
static double crease_mean(int mirrored)
{
    obs_bake_scene sc;
    crease(&sc);
    if (mirrored)
        sc.nodes[0].world[0] = sc.nodes[0].local[0] = -1.0f;
    obs_bake_desc d = {0};
    bt_set(&d.params, "distance_short", "0.25");
    bt_set(&d.params, "rays", "64");
    obs_bake_result r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    double sum = 0.0;
    int n = 0;
    for (size_t i = 0; i < r.instance_count; i++) {
        const obs_bake_mesh *m = &sc.meshes[r.instances[i].mesh];
        for (size_t v = 0; v < m->vertex_count; v++) {
            const float *p = m->positions + 3 * v;
            if ((i == 0 ? p[0] : p[1]) == 0.0f && fabsf(p[2]) < 2.0f) {
                sum += r.instances[i].ao_short[v];
                n++;
            }
        }
    }
    obs_bake_result_free(&r);
    obs_bake_scene_free(&sc);
    return sum / n;
}

/* A mirroring node transform turns the winding over: the faces must still
 * face the same way as their (mirrored) normals, so the mirrored crease
 * is as dark as the plain one; traced from the wrong side its floor would
 * see nothing (AO 1). */
static void test_mirrored_crease(void **state)
{
    (void)state;
    double plain = crease_mean(0), mirrored = crease_mean(1);
    print_message("crease vertices: plain %.4f, mirrored %.4f\n", plain, mirrored);
    assert_true(plain < 0.7);
    assert_true(fabs(plain - mirrored) < 0.02);
}

/* The same seed gives the same bake whatever the thread count. */
static void test_threads_deterministic(void **state)
{
    (void)state;
    obs_bake_scene sc;
    crease(&sc);
    obs__bake_world w;
    obs__bake_samples s1, s3;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__bake_flatten(&sc, &w, err), OBS_OK);
    assert_int_equal(obs__bake_samples_make(&w, 1.0, 16, 3, &s1, err), OBS_OK);
    assert_int_equal(obs__bake_samples_make(&w, 1.0, 16, 3, &s3, err), OBS_OK);
    obs__bake_trace_desc td = {{0.5f, 2.0f}, 32, 1, 0.25f, 3, NULL, NULL};
    double bvh;
    assert_int_equal(obs__bake_trace(&w, &s1, &td, &bvh, err), OBS_OK);
    td.threads = 3;
    assert_int_equal(obs__bake_trace(&w, &s3, &td, &bvh, err), OBS_OK);
    assert_int_equal(s1.count, s3.count);
    assert_memory_equal(s1.ao, s3.ao, 2 * s1.count * sizeof(float));
    /* and another seed differs */
    td.seed = 4;
    assert_int_equal(obs__bake_trace(&w, &s3, &td, &bvh, err), OBS_OK);
    assert_true(memcmp(s1.ao, s3.ao, 2 * s1.count * sizeof(float)) != 0);
    obs__bake_samples_free(&s1);
    obs__bake_samples_free(&s3);
    obs__bake_world_free(&w);
    obs_bake_scene_free(&sc);
}

/* A plane inside a closed box whose faces point out: every ray of its
 * samples hits a back face, so the rule drops them all; with the limit at
 * 1 none is dropped.  Its vertices still get a value (never black). */
static void test_backface_rule(void **state)
{
    (void)state;
    obs_bake_mesh m[7];
    const float a = 2.0f;
    /* six faces of the cube [-a, a]^3, normals out */
    const float o0[3] = {-a, -a, -a}, o1[3] = {a, a, a};
    const float X[3] = {2 * a, 0, 0}, Y[3] = {0, 2 * a, 0}, Z[3] = {0, 0, 2 * a};
    const float nX[3] = {-2 * a, 0, 0}, nY[3] = {0, -2 * a, 0}, nZ[3] = {0, 0, -2 * a};
    bt_grid(&m[0], "bottom", o0, X, Z, 2, 2); /* X x Z = -Y */
    bt_grid(&m[1], "back", o0, Y, X, 2, 2);   /* Y x X = -Z */
    bt_grid(&m[2], "left", o0, Z, Y, 2, 2);   /* Z x Y = -X */
    bt_grid(&m[3], "top", o1, nZ, nX, 2, 2);   /* (-Z) x (-X) = +Y */
    bt_grid(&m[4], "front", o1, nX, nY, 2, 2); /* (-X) x (-Y) = +Z */
    bt_grid(&m[5], "right", o1, nY, nZ, 2, 2); /* (-Y) x (-Z) = +X */
    const float po[3] = {-1, -1, -1}, pz[3] = {0, 0, 2}, px[3] = {2, 0, 0};
    bt_grid(&m[6], "inside", po, pz, px, 4, 4); /* +Y */
    obs_bake_scene sc;
    bt_scene(&sc, m, 7);
    obs__bake_world w;
    obs__bake_samples s;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__bake_flatten(&sc, &w, err), OBS_OK);
    assert_int_equal(obs__bake_samples_make(&w, 2.0, 16, 1, &s, err), OBS_OK);
    obs__bake_trace_desc td = {{1.0f, 10.0f}, 32, 1, 0.25f, 1, NULL, NULL};
    double bvh;
    assert_int_equal(obs__bake_trace(&w, &s, &td, &bvh, err), OBS_OK);
    size_t inside = 0, outside_dropped = 0;
    for (size_t i = 0; i < s.count; i++) {
        int in = s.tri[i] >= w.inst[6].first_triangle;
        inside += in;
        if (in)
            assert_int_equal(s.valid[i], 0);
        else
            outside_dropped += !s.valid[i];
    }
    assert_true(inside > 0);
    assert_int_equal(outside_dropped, 0);
    assert_int_equal(s.dropped, inside);
    td.backface_limit = 1.0f;
    assert_int_equal(obs__bake_trace(&w, &s, &td, &bvh, err), OBS_OK);
    assert_int_equal(s.dropped, 0);
    obs__bake_samples_free(&s);
    obs__bake_world_free(&w);

    obs_bake_desc d = {0};
    bt_set(&d.params, "rays", "32");
    obs_bake_result r;
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    assert_true(r.stats.samples_dropped_backface > 0);
    /* the cube's outside sees the sky: its values, not 0, fill the inside */
    for (size_t v = 0; v < sc.meshes[6].vertex_count; v++)
        assert_true(r.instances[6].ao[v] > 0.5f);
    obs_bake_result_free(&r);
    obs_bake_scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_form_itself),
        cmocka_unit_test(test_plane_is_one),
        cmocka_unit_test(test_crease_samples),
        cmocka_unit_test(test_crease_vertices),
        cmocka_unit_test(test_mirrored_crease),
        cmocka_unit_test(test_threads_deterministic),
        cmocka_unit_test(test_backface_rule),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
