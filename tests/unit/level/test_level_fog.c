/* Shrubs as fog and trees as semi-transparent occluders (section 2.1 of
 * the paper; core/bake/occl.c, trace.c): a plane under a fog slab and
 * under semi-transparent layers against their closed forms, the overlap
 * pre-pass, and decorator geometry kept out of the opaque BVH. */
#include "level/bake_testutil.h"
#include "level/occl.h"

/* A scene of two nodes: "ground" holding the plane, and a child named
 * name holding the other meshes (its class from its name). */
static void two_nodes(obs_bake_scene *s, obs_bake_mesh *meshes, size_t n, const char *name)
{
    bt_scene(s, meshes, n);
    const char *names[2] = {"ground", name};
    const uint32_t counts[2] = {1, (uint32_t)(n - 1)};
    bt_split(s, names, counts, 2);
}

/* The mean _AO_SHORT and _AO_LONG of the ground's vertices. */
static void ground_mean(const obs_bake_result *r, const obs_bake_scene *s, double out[2])
{
    out[0] = out[1] = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < r->instance_count; i++) {
        if (r->instances[i].node != 0)
            continue;
        size_t nv = s->meshes[r->instances[i].mesh].vertex_count;
        for (size_t v = 0; v < nv; v++) {
            out[0] += r->instances[i].ao_short[v];
            out[1] += r->instances[i].ao_long[v];
        }
        n += nv;
    }
    assert_true(n > 0);
    out[0] /= (double)n;
    out[1] /= (double)n;
}

static void bake(const obs_bake_scene *s, const char *tree_att, double density, double out[2])
{
    obs_bake_desc d = {0};
    char err[OBS_ERR_LEN] = "", buf[32];
    bt_set(&d.params, "rays", "256");
    bt_set(&d.params, "samples-per-face", "1");
    bt_set(&d.params, "max-samples-per-face", "1");
    if (tree_att)
        bt_set(&d.params, "tree-attenuation", tree_att);
    snprintf(buf, sizeof buf, "%.9g", density);
    bt_set(&d.params, "shrub-density", buf);
    /* the trees' own AO by the instanced path (section 2.2) is not what
     * these scenes test: the ground under them is */
    bt_set(&d.params, "instanced", "off");
    obs_bake_result r;
    obs_status st = obs_bake_run(s, &d, &r, err);
    if (st != OBS_OK)
        print_message("%s\n", err);
    assert_int_equal(st, OBS_OK);
    ground_mean(&r, s, out);
    obs_bake_result_free(&r);
}

/* A 20 x 20 ground at z = 0 facing +z (10 x 10 quads), centred. */
static void ground(obs_bake_mesh *m)
{
    const float o[3] = {-10, -10, 0}, u[3] = {20, 0, 0}, v[3] = {0, 20, 0};
    bt_grid(m, "ground", o, u, v, 10, 10);
}

/* 2 integral over mu in (0, 1] of mu exp(-x / mu): the cosine-weighted
 * mean of exp(-x / cos theta) over the hemisphere (= 2 E_3(x)), by the
 * midpoint rule on 200,000 intervals. */
static double slab_visibility(double x)
{
    const int n = 200000;
    double s = 0.0;
    for (int i = 0; i < n; i++) {
        double mu = (i + 0.5) / n;
        s += mu * exp(-x / mu);
    }
    return 2.0 * s / n;
}

static void test_fog_slab(void **state)
{
    (void)state;
    /* The shrub's mesh: one slanted quad whose world box is the slab
     * x, y in [-2000, 2000], z in [0.5, 1.5]: every ray from the ground
     * crosses it over h / cos(theta), h = 1, and meets nothing opaque, so
     * AO = 2 E_3(density h) at both distances (eq 1 with rho = 1 for a
     * miss, times exp(-density length), section 2.1).  The box's sides
     * are 2000 away: a ray leaves through them only for cos(theta) <
     * 5e-4, weight < 3e-7. */
    const double density[3] = {0.3, 1.0, 2.5};
    for (int k = 0; k < 3; k++) {
        obs_bake_mesh m[2];
        ground(&m[0]);
        const float o[3] = {-2000, -2000, 0.5f}, u[3] = {4000, 0, 0}, v[3] = {0, 4000, 1.0f};
        bt_grid(&m[1], "bush", o, u, v, 1, 1);
        obs_bake_scene s;
        two_nodes(&s, m, 2, "bush");
        double got[2], want = slab_visibility(density[k] * 1.0);
        bake(&s, NULL, density[k], got);
        print_message("fog density %g: ground AO short %.5f long %.5f, 2 E_3(density h) %.5f\n",
                      density[k], got[0], got[1], want);
        /* 256 stratified rays at each of 200 samples: the mean's error is
         * far below 0.005 */
        assert_true(fabs(got[0] - want) < 0.005);
        assert_true(fabs(got[1] - want) < 0.005);
        obs_bake_scene_free(&s);
    }
}

static void test_tree_layers(void **state)
{
    (void)state;
    /* Tree triangles: horizontal layers 1 and 2 above the ground, 4000
     * wide.  Each crossing keeps 1 - tree_attenuation of the visibility
     * (section 2.1), nothing opaque is met: AO = (1 - a)^layers. */
    const char *att[3] = {"0.5", "0.2", "1"};
    const double a[3] = {0.5, 0.2, 1.0};
    for (int layers = 1; layers <= 2; layers++)
        for (int k = 0; k < 3; k++) {
            obs_bake_mesh m[3];
            ground(&m[0]);
            for (int l = 0; l < layers; l++) {
                const float o[3] = {-2000, -2000, 1.0f + (float)l}, u[3] = {4000, 0, 0},
                            v[3] = {0, 4000, 0};
                bt_grid(&m[1 + l], "crown", o, u, v, 1, 1);
            }
            obs_bake_scene s;
            two_nodes(&s, m, 1 + (size_t)layers, "palm_tree");
            double got[2], want = pow(1.0 - a[k], layers);
            bake(&s, att[k], 1.0, got);
            print_message("%d layer(s), tree_attenuation %s: ground AO %.5f %.5f, closed form "
                          "%.5f\n",
                          layers, att[k], got[0], got[1], want);
            assert_true(fabs(got[0] - want) < 1e-3);
            assert_true(fabs(got[1] - want) < 1e-3);
            obs_bake_scene_free(&s);
        }
}

/* The same layer as opaque geometry (its name says nothing) shadows the
 * ground as eq 1 says: rho(h / mu) = 1 - exp(a h / mu) for every ray, so
 * AO = 1 - 2 E_3(-a h), a = ln(0.5) / d: the decorators' path leaves
 * opaque geometry as it was. */
static void test_opaque_layer(void **state)
{
    (void)state;
    obs_bake_mesh m[2];
    ground(&m[0]);
    /* facing down, towards the ground (from behind the rays would drop
     * every sample by the back-face rule) */
    const float o[3] = {-2000, -2000, 1.0f}, u[3] = {0, 4000, 0}, v[3] = {4000, 0, 0};
    bt_grid(&m[1], "roof", o, u, v, 1, 1);
    obs_bake_scene s;
    two_nodes(&s, m, 2, "roof");
    double got[2];
    bake(&s, NULL, 1.0, got);
    double want[2] = {1.0 - slab_visibility(log(2.0) / 2.0),
                      1.0 - slab_visibility(log(2.0) / 300.0)};
    print_message("opaque roof: ground AO short %.5f long %.5f, closed form %.5f %.5f\n",
                  got[0], got[1], want[0], want[1]);
    assert_true(fabs(got[0] - want[0]) < 0.005 && fabs(got[1] - want[1]) < 0.002);
    obs_bake_scene_free(&s);
}

static void test_overlap(void **state)
{
    (void)state;
    /* boxes 0 and 1 overlap in half of each (0.5 of volume 1): each keeps
     * V / (V + O) = 1 / 1.5 of its density; box 2 lies apart; boxes 3 and
     * 4 coincide (each O = V): half each; box 5 is flat (V = 0) inside
     * box 2 and overlaps nothing of volume: unchanged */
    const float box[6 * 6] = {0, 0, 0, 1, 1, 1,         0.5f, 0, 0, 1.5f, 1, 1,
                              10, 0, 0, 12, 2, 2,       20, 0, 0, 21, 1, 1,
                              20, 0, 0, 21, 1, 1,       11, 1, 0, 11.5f, 1, 1};
    float d[6] = {2, 4, 3, 1, 1, 5};
    obs__bake_fog_overlap(box, 6, d);
    for (int i = 0; i < 6; i++)
        print_message("box %d: density %g\n", i, (double)d[i]);
    assert_true(fabsf(d[0] - 2.0f / 1.5f) < 1e-6f);
    assert_true(fabsf(d[1] - 4.0f / 1.5f) < 1e-6f);
    assert_true(d[2] == 3.0f);
    assert_true(fabsf(d[3] - 0.5f) < 1e-7f && fabsf(d[4] - 0.5f) < 1e-7f);
    assert_true(d[5] == 5.0f);
    /* three coincident boxes: a third each */
    const float b3[18] = {0, 0, 0, 2, 2, 2, 0, 0, 0, 2, 2, 2, 0, 0, 0, 2, 2, 2};
    float d3[3] = {3, 3, 3};
    obs__bake_fog_overlap(b3, 3, d3);
    for (int i = 0; i < 3; i++)
        assert_true(fabsf(d3[i] - 1.0f) < 1e-6f);
}

/* Two overlapping shrubs in one bake: their boxes' densities are lowered
 * (occl.c) and the segment through both attenuates by the sum. */
static void test_overlap_in_bake(void **state)
{
    (void)state;
    obs_bake_scene s;
    obs_bake_mesh m[3];
    ground(&m[0]);
    /* two slabs z in [0.5, 1.5] and [1.0, 2.0] (overlap: half of each):
     * each density d / 1.5; along the vertical the ray crosses 1 + 1 of
     * slab: exp(-(2 d / 1.5) / mu) */
    const float o1[3] = {-2000, -2000, 0.5f}, o2[3] = {-2000, -2000, 1.0f}, u[3] = {4000, 0, 0},
                v[3] = {0, 4000, 1.0f};
    bt_grid(&m[1], "bush_a", o1, u, v, 1, 1);
    bt_grid(&m[2], "bush_b", o2, u, v, 1, 1);
    bt_scene(&s, m, 3);
    const char *names[3] = {"ground", "bush_a", "bush_b"};
    const uint32_t counts[3] = {1, 1, 1};
    bt_split(&s, names, counts, 3);
    double got[2], want = slab_visibility(2.0 * 0.9 / 1.5);
    bake(&s, NULL, 0.9, got);
    print_message("two overlapping slabs: ground AO %.5f %.5f, closed form %.5f\n", got[0],
                  got[1], want);
    assert_true(fabs(got[1] - want) < 0.005);
    obs_bake_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fog_slab),
        cmocka_unit_test(test_tree_layers),
        cmocka_unit_test(test_opaque_layer),
        cmocka_unit_test(test_overlap),
        cmocka_unit_test(test_overlap_in_bake),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
