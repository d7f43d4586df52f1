/* Large instanced decorators (section 2.2; core/bake/instanced.c,
 * volume.c): eq 3 recovers a known linear function; the sparse grid
 * gives every point of an instance's box its 8 neighbours; trilinear SH
 * reconstruction of a constant and a linear field is exact; a tree under
 * an overhang gets a darker global term than one in the open, its local
 * AO baked once for both instances. */
#include "level/bake_testutil.h"
#include "dynamic/dyn_internal.h"
#include "bake/instanced.h"
#include "bake/volume.h"

static double urand(unsigned *s)
{
    *s = *s * 1103515245u + 12345u;
    return (double)(*s >> 8 & 0xffffff) / 16777216.0;
}

/* Eq 3: f = G_y(q) L(q) with a known y, any L > 0: the fit gives y back;
 * L = 1 (NULL) too, far from the origin (the centring). */
static void test_eq3_recovers_linear(void **state)
{
    (void)state;
    enum { N = 200 };
    float q[3 * N];
    double f[N], L[N], f1[N], y[4];
    const double want[4] = {0.7, -0.02, 0.035, 0.011};
    unsigned s = 7;
    for (int i = 0; i < N; i++) {
        for (int a = 0; a < 3; a++)
            q[3 * i + a] = (float)(1000.0 + 10.0 * urand(&s));
        L[i] = 0.2 + 0.8 * urand(&s);
        double g = want[0] + want[1] * q[3 * i] + want[2] * q[3 * i + 1] + want[3] * q[3 * i + 2];
        f[i] = g * L[i];
        f1[i] = g;
    }
    assert_int_equal(obs__bake_eq3_fit(q, f, L, N, y), 1);
    for (int k = 0; k < 4; k++)
        assert_true(fabs(y[k] - want[k]) < (k ? 1e-7 : 1e-4));
    assert_int_equal(obs__bake_eq3_fit(q, f1, NULL, N, y), 1);
    for (int k = 0; k < 4; k++)
        assert_true(fabs(y[k] - want[k]) < (k ? 1e-7 : 1e-4));
    /* A flat card (z = 5 for every point): the free direction does not
     * blow up and the data are still reproduced. */
    for (int i = 0; i < N; i++) {
        q[3 * i] = (float)urand(&s), q[3 * i + 1] = (float)urand(&s), q[3 * i + 2] = 5.0f;
        f[i] = (0.5 + 0.1 * q[3 * i] - 0.2 * q[3 * i + 1]) * L[i];
    }
    assert_int_equal(obs__bake_eq3_fit(q, f, L, N, y), 1);
    for (int i = 0; i < N; i++) {
        double g = y[0] + y[1] * q[3 * i] + y[2] * q[3 * i + 1] + y[3] * q[3 * i + 2];
        assert_true(fabs(g * L[i] - f[i]) < 1e-6);
    }
    assert_true(fabs(y[3]) < 1e-3);
    /* nothing to fit: the neutral function */
    assert_int_equal(obs__bake_eq3_fit(q, f, NULL, 0, y), 0);
    assert_true(y[0] == 1.0 && y[1] == 0.0 && y[2] == 0.0 && y[3] == 0.0);
}

/* Every point inside every box (random points, the corners, the faces)
 * finds its cell's 8 corners; the grid holds no more than the boxes
 * need; a point away from the boxes lacks some. */
static void test_grid_neighbours(void **state)
{
    (void)state;
    const float boxes[] = {
        -3.3f, 0.1f, -7.9f, -1.0f, 4.2f, -6.0f, /* negative coordinates, across bricks */
        10.0f, 10.0f, 10.0f, 10.0f, 10.0f, 10.0f, /* a point */
        0.0f, 0.0f, 0.0f, 1.48f, 0.37f, 0.74f,   /* on grid lines (h = 0.37) */
        -1.5f, 1.0f, -7.0f, 0.5f, 2.0f, -6.5f,   /* overlaps the first */
    };
    const size_t nb = sizeof boxes / sizeof boxes[0] / 6;
    const float h = 0.37f;
    obs__vol v;
    char err[OBS_ERR_LEN];
    assert_int_equal(obs__vol_build(&v, h, boxes, nb, 1u << 20, err), OBS_OK);
    assert_true(v.brick_count > 1);
    /* the points of the union of the boxes' index ranges, each once */
    size_t need = 0;
    for (int i = -40; i <= 40; i++)
        for (int j = -40; j <= 40; j++)
            for (int k = -40; k <= 40; k++) {
                int in = 0;
                for (size_t b = 0; b < nb && !in; b++) {
                    const float *bx = boxes + 6 * b;
                    int idx[3] = {i, j, k}, ok = 1;
                    for (int a = 0; a < 3; a++) {
                        double lo = floor((double)bx[a] / h), hi = floor((double)bx[3 + a] / h) + 1;
                        ok &= idx[a] >= lo && idx[a] <= hi;
                    }
                    in = ok;
                }
                need += in;
                assert_int_equal(obs__vol_find(&v, i, j, k) >= 0, in);
            }
    assert_int_equal(v.count, need);
    unsigned s = 3;
    for (size_t b = 0; b < nb; b++) {
        const float *bx = boxes + 6 * b;
        for (int t = 0; t < 2000; t++) {
            float p[3];
            for (int a = 0; a < 3; a++) {
                int pick = t < 8 ? (t >> a & 1) * 2 : (int)(urand(&s) * 5.0);
                /* 0: lo, 2: hi, else a random point between */
                p[a] = pick == 0 ? bx[a] : pick == 2 ? bx[3 + a]
                                                     : bx[a] + (float)urand(&s) * (bx[3 + a] - bx[a]);
            }
            int64_t idx[8];
            double wt[8], sum = 0.0;
            assert_int_equal(obs__vol_corners(&v, p, idx, wt), 8);
            for (int c = 0; c < 8; c++)
                sum += wt[c];
            assert_true(fabs(sum - 1.0) < 1e-12);
        }
    }
    int64_t idx[8];
    double wt[8];
    const float far[3] = {30.0f, -30.0f, 30.0f};
    assert_true(obs__vol_corners(&v, far, idx, wt) < 8);
    double ao[2];
    assert_int_equal(obs__vol_eval(&v, far, NULL, ao), 0);
    obs__vol_free(&v);
    /* a non-finite box and a grid over the point limit are refused */
    const float bad[6] = {0.0f, 0.0f, 0.0f, INFINITY, 1.0f, 1.0f};
    assert_int_equal(obs__vol_build(&v, h, bad, 1, 1u << 20, err), OBS_INVALID_ARGUMENT);
    const float big[6] = {0.0f, 0.0f, 0.0f, 100.0f, 100.0f, 100.0f};
    assert_int_equal(obs__vol_build(&v, h, big, 1, 1u << 20, err), OBS_TOO_LARGE);
    assert_non_null(strstr(err, "volume_spacing"));
}

/* SH coefficients that are a linear function of position (and a
 * constant) at the grid points: the trilinear reconstruction at any p,
 * evaluated at any normal, is that function exactly; a corner inside
 * geometry is left out and a constant stays exact. */
static void test_trilinear_exact(void **state)
{
    (void)state;
    const float box[6] = {-1.2f, 0.3f, 2.0f, 1.7f, 2.9f, 3.1f};
    const float h = 0.5f;
    obs__vol v;
    char err[OBS_ERR_LEN];
    assert_int_equal(obs__vol_build(&v, h, box, 1, 1u << 20, err), OBS_OK);
    /* short: c_k = a_k + b_k . x for the 4 coefficients of bands 0..1 and
     * 0 above; long: constant 0.6 / Y_00 (AO 0.6 everywhere) */
    const double a[4] = {1.1, 0.2, -0.1, 0.3}, b[4][3] = {{0.05, -0.02, 0.01},
                                                           {0.0, 0.03, 0.0},
                                                           {0.01, 0.0, -0.02},
                                                           {-0.03, 0.01, 0.02}};
    const double y00 = 0.28209479177387814;
    for (size_t i = 0; i < v.count; i++) {
        double x[3] = {v.ijk[3 * i] * (double)h, v.ijk[3 * i + 1] * (double)h,
                       v.ijk[3 * i + 2] * (double)h};
        double *c = v.sh + i * OBS__VOL_CHANNELS;
        for (int k = 0; k < 4; k++)
            c[k] = a[k] + b[k][0] * x[0] + b[k][1] * x[1] + b[k][2] * x[2];
        c[OBS_DYN_SH] = 0.6 / y00;
    }
    unsigned s = 11;
    for (int t = 0; t < 500; t++) {
        float p[3], n[3];
        double len = 0.0;
        for (int k = 0; k < 3; k++) {
            p[k] = box[k] + (float)urand(&s) * (box[3 + k] - box[k]);
            n[k] = (float)(urand(&s) - 0.5);
            len += (double)n[k] * n[k];
        }
        for (int k = 0; k < 3; k++)
            n[k] = (float)(n[k] / sqrt(len));
        double c[OBS_DYN_SH] = {0}, ao[2];
        for (int k = 0; k < 4; k++)
            c[k] = a[k] + b[k][0] * p[0] + b[k][1] * p[1] + b[k][2] * p[2];
        assert_int_equal(obs__vol_eval(&v, p, n, ao), 1);
        assert_true(fabs(ao[0] - obs__sh_eval(c, n, 2)) < 1e-9);
        assert_true(fabs(ao[1] - 0.6) < 1e-12);
        assert_int_equal(obs__vol_eval(&v, p, NULL, ao), 1); /* band 0 */
        assert_true(fabs(ao[0] - c[0] * y00) < 1e-9);
    }
    /* one corner inside geometry holds garbage: left out, the constant
     * long channel stays exact */
    const float p[3] = {0.1f, 1.1f, 2.6f};
    int64_t idx[8];
    double wt[8], ao[2];
    assert_int_equal(obs__vol_corners(&v, p, idx, wt), 8);
    v.inside[idx[3]] = 1;
    v.sh[(size_t)idx[3] * OBS__VOL_CHANNELS + OBS_DYN_SH] = 1e3;
    assert_int_equal(obs__vol_eval(&v, p, NULL, ao), 1);
    assert_true(fabs(ao[1] - 0.6) < 1e-12);
    obs__vol_free(&v);
}

/* Two crossed vertical quads, 1 x 2, based at the origin: the tree. */
static void tree_mesh(obs_bake_mesh *m)
{
    obs_bake_mesh a, b;
    const float o1[3] = {-0.5f, 0.0f, 0.0f}, u1[3] = {1.0f, 0.0f, 0.0f}, v1[3] = {0.0f, 0.0f, 2.0f};
    const float o2[3] = {0.0f, -0.5f, 0.0f}, u2[3] = {0.0f, 1.0f, 0.0f};
    bt_grid(&a, "tree_a", o1, u1, v1, 2, 4);
    bt_grid(&b, "tree_b", o2, u2, v1, 2, 4);
    memset(m, 0, sizeof *m);
    m->name = strdup("tree");
    m->material = -1;
    m->two_sided = 1;
    m->vertex_count = a.vertex_count + b.vertex_count;
    m->triangle_count = a.triangle_count + b.triangle_count;
    m->positions = malloc(m->vertex_count * 3 * sizeof(float));
    m->normals = malloc(m->vertex_count * 3 * sizeof(float));
    m->indices = malloc(m->triangle_count * 3 * sizeof(uint32_t));
    assert_non_null(m->indices);
    memcpy(m->positions, a.positions, a.vertex_count * 3 * sizeof(float));
    memcpy(m->positions + 3 * a.vertex_count, b.positions, b.vertex_count * 3 * sizeof(float));
    memcpy(m->normals, a.normals, a.vertex_count * 3 * sizeof(float));
    memcpy(m->normals + 3 * a.vertex_count, b.normals, b.vertex_count * 3 * sizeof(float));
    memcpy(m->indices, a.indices, a.triangle_count * 3 * sizeof(uint32_t));
    for (size_t k = 0; k < 3 * b.triangle_count; k++)
        m->indices[3 * a.triangle_count + k] = b.indices[k] + (uint32_t)a.vertex_count;
    for (obs_bake_mesh *g = &a; g; g = g == &a ? &b : NULL) {
        free(g->name);
        free(g->positions);
        free(g->normals);
        free(g->indices);
    }
}

static void node(obs_bake_node *nd, const char *name, int parent, const float t[3],
                 uint32_t mesh, const char *extras)
{
    memset(nd, 0, sizeof *nd);
    nd->name = strdup(name);
    nd->parent = parent;
    for (int i = 0; i < 16; i++)
        nd->local[i] = nd->world[i] = i % 5 == 0 ? 1.0f : 0.0f;
    for (int a = 0; t && a < 3; a++)
        nd->local[4 * a + 3] = nd->world[4 * a + 3] = t[a];
    nd->meshes = malloc(sizeof *nd->meshes);
    assert_non_null(nd->meshes);
    nd->meshes[0] = mesh;
    nd->mesh_count = 1;
    nd->extras = extras ? strdup(extras) : NULL;
}

/* Ground (z = -0.05, 40 x 40), a roof (z = 2.6, 8 x 8, facing down)
 * over x = -10, and the tree twice: under the roof and at x = +10 in the
 * open.  Both are class tree by their extras. */
static void overhang_scene(obs_bake_scene *s, const char *roof_extras)
{
    obs_bake_mesh m[3];
    const float go[3] = {-20.0f, -20.0f, -0.05f}, gu[3] = {40.0f, 0.0f, 0.0f},
                gv[3] = {0.0f, 40.0f, 0.0f};
    const float ro[3] = {-14.0f, -4.0f, 2.6f}, ru[3] = {0.0f, 8.0f, 0.0f},
                rv[3] = {8.0f, 0.0f, 0.0f}; /* u x v = -z: faces the tree */
    bt_grid(&m[0], "ground", go, gu, gv, 8, 8);
    bt_grid(&m[1], "roof", ro, ru, rv, 4, 4);
    tree_mesh(&m[2]);
    memset(s, 0, sizeof *s);
    s->meshes = calloc(3, sizeof *s->meshes);
    s->nodes = calloc(4, sizeof *s->nodes);
    assert_non_null(s->nodes);
    memcpy(s->meshes, m, sizeof m);
    s->mesh_count = 3;
    s->node_count = 4;
    const float under[3] = {-10.0f, 0.0f, 0.0f}, open[3] = {10.0f, 0.0f, 0.0f};
    node(&s->nodes[0], "ground", -1, NULL, 0, NULL);
    node(&s->nodes[1], "roof", -1, NULL, 1, roof_extras);
    node(&s->nodes[2], "palm_under", -1, under, 2, "{\"class\": \"tree\"}");
    node(&s->nodes[3], "palm_open", -1, open, 2, "{\"class\": \"tree\"}");
    s->instance_count = 4;
    s->world_triangles = m[0].triangle_count + m[1].triangle_count + 2 * m[2].triangle_count;
}

/* Counts the calls with every sample done; asks to stop at call `at`. */
typedef struct stopper {
    int calls, at;
} stopper;

static int stop_at(void *user, size_t done, size_t total)
{
    stopper *s = user;
    return done == total && ++s->calls == s->at;
}

static double mean(const float *v, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += v[i];
    return s / (double)n;
}

static void test_overhang_darker(void **state)
{
    (void)state;
    obs_bake_scene sc;
    overhang_scene(&sc, NULL);
    obs_bake_desc d = {0};
    bt_set(&d.params, "rays", "64");
    bt_set(&d.params, "volume_rays", "256");
    bt_set(&d.params, "volume_spacing", "0.5");
    bt_set(&d.params, "distance_long", "20");
    bt_set(&d.params, "threads", "2");
    obs_bake_result r;
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    assert_int_equal(r.stats.instanced_instances, 2);
    assert_int_equal(r.stats.instanced_meshes, 1); /* once per distinct mesh */
    assert_true(r.stats.volume_points > 0 && r.stats.volume_rays > 0);
    assert_null(r.instances[0].ao_local);
    assert_null(r.instances[1].ao_local);
    const obs_bake_mesh *tm = &sc.meshes[2];
    size_t nv = tm->vertex_count;
    double g[2];
    for (int k = 0; k < 2; k++) {
        const obs_bake_instance *in = &r.instances[2 + k];
        assert_non_null(in->ao_local);
        double s = 0.0;
        for (size_t v = 0; v < nv; v++) {
            const float *q = tm->positions + 3 * v;
            double gv = in->global[0][0] + in->global[0][1] * q[0] + in->global[0][2] * q[1] +
                        in->global[0][3] * q[2];
            s += gv / (double)nv;
            /* the vertex's AO is local x global (section 2.2) */
            double want = in->ao_local[v] * gv;
            want = want < 0.0 ? 0.0 : want > 1.0 ? 1.0 : want;
            assert_true(fabs(in->ao[v] - want) < 1e-5);
        }
        g[k] = s;
    }
    /* the local AO is the mesh's: the same for both instances */
    for (size_t v = 0; v < nv; v++)
        assert_true(r.instances[2].ao_local[v] == r.instances[3].ao_local[v]);
    print_message("global term: under %.3f, open %.3f\n", g[0], g[1]);
    /* under the roof: a darker global term, and darker vertices */
    assert_true(g[0] < g[1] - 0.05);
    assert_true(mean(r.instances[2].ao, nv) < mean(r.instances[3].ao, nv) - 0.05);
    assert_true(g[1] > 0.5 && g[1] < 1.2);
    /* the trees' faces take no samples nor a share of the budget: about
     * 4 per face of the ground's 128 and the roof's 32 */
    size_t samples_instanced = r.stats.samples;
    assert_true(samples_instanced > 600 && samples_instanced < 680);
    assert_int_equal(r.stats.degenerate_triangles, 0); /* the report's count is the level's */
    obs_bake_result_free(&r);

    /* instanced=off: traced in place, no model */
    bt_set(&d.params, "instanced", "off");
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    assert_int_equal(r.stats.instanced_instances, 0);
    assert_null(r.instances[2].ao_local);
    assert_true(r.stats.samples > samples_instanced + 100); /* the trees' 64 faces too */
    obs_bake_result_free(&r);

    /* instanced_min 3: the shared mesh has only 2 tree nodes */
    bt_set(&d.params, "instanced", "trees");
    bt_set(&d.params, "instanced_min", "3");
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    assert_int_equal(r.stats.instanced_instances, 0);
    obs_bake_result_free(&r);

    /* cancelled through the progress callback: the trace's last call is
     * the first with every sample done, then one before each mesh baked
     * alone, then every few hundred volume points */
    bt_set(&d.params, "instanced_min", "1");
    stopper st2 = {0, 2};
    d.progress = stop_at;
    d.progress_user = &st2;
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_CANCELLED);
    assert_non_null(strstr(err, "local AO"));
    stopper st3 = {0, 3};
    d.progress_user = &st3;
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_CANCELLED);
    assert_non_null(strstr(err, "volume"));
    stopper never = {0, 1000};
    d.progress_user = &never;
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    assert_int_equal(r.stats.instanced_instances, 2);
    assert_true(never.calls >= 3);
    obs_bake_result_free(&r);
    d.progress = NULL;

    /* a volume too fine to trace is refused, naming the parameter */
    bt_set(&d.params, "volume_spacing", "0.005");
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_TOO_LARGE);
    assert_non_null(strstr(err, "volume_spacing"));
    obs_bake_scene_free(&sc);
}

/* The mean over the tree mesh's vertices of instance i's global term. */
static double mean_global(const obs_bake_result *r, const obs_bake_mesh *tm, size_t i)
{
    double s = 0.0;
    for (size_t v = 0; v < tm->vertex_count; v++) {
        const float *q = tm->positions + 3 * v;
        const float *g = r->instances[i].global[0];
        s += (g[0] + g[1] * q[0] + g[2] * q[1] + g[3] * q[2]) / (double)tm->vertex_count;
    }
    return s;
}

/* The volume sees the level's occluders as its surface samples do
 * (section 2.1): a roof that is itself a tree (semi-transparent, 50 %)
 * darkens the tree under it less than an opaque roof, and more than
 * no roof. */
static void test_volume_sees_decorators(void **state)
{
    (void)state;
    double g[2][2];
    for (int k = 0; k < 2; k++) {
        obs_bake_scene sc;
        overhang_scene(&sc, k ? "{\"class\": \"tree\"}" : NULL);
        obs_bake_desc d = {0};
        bt_set(&d.params, "rays", "64");
        bt_set(&d.params, "volume_rays", "256");
        bt_set(&d.params, "volume_spacing", "0.5");
        bt_set(&d.params, "distance_long", "20");
        bt_set(&d.params, "threads", "2");
        obs_bake_result r;
        char err[OBS_ERR_LEN];
        assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
        assert_int_equal(r.stats.instanced_instances, 2 + k);
        g[k][0] = mean_global(&r, &sc.meshes[2], 2);
        g[k][1] = mean_global(&r, &sc.meshes[2], 3);
        obs_bake_result_free(&r);
        obs_bake_scene_free(&sc);
    }
    print_message("global term under the roof: opaque %.3f, a tree %.3f; open %.3f, %.3f\n",
                  g[0][0], g[1][0], g[0][1], g[1][1]);
    assert_true(g[0][0] < g[1][0] - 0.05);
    assert_true(g[1][0] < g[1][1] - 0.05);
    assert_true(fabs(g[0][1] - g[1][1]) < 0.03); /* in the open the roof is far */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_eq3_recovers_linear),
        cmocka_unit_test(test_grid_neighbours),
        cmocka_unit_test(test_trilinear_exact),
        cmocka_unit_test(test_overhang_darker),
        cmocka_unit_test(test_volume_sees_decorators),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
