/* Small decorators (section 2.2.1; core/bake/small.c): one scalar per
 * instance resampled from the AO of the geometry around it, on its
 * vertices, in the node's extras of the .glb; a decorator with nothing
 * around it keeps its own fit and is counted. */
#include <unistd.h>

#include "level/bake_testutil.h"

static void bake(const obs_bake_scene *s, const char *source, obs_bake_result *r)
{
    obs_bake_desc d = {0};
    char err[OBS_ERR_LEN] = "";
    bt_set(&d.params, "rays", "128");
    bt_set(&d.params, "samples-per-face", "2");
    bt_set(&d.params, "small-radius", "0.5");
    bt_set(&d.params, "decorator-source", source);
    obs_status st = obs_bake_run(s, &d, r, err);
    if (st != OBS_OK)
        print_message("%s\n", err);
    assert_int_equal(st, OBS_OK);
}

/* A ground under a roof at height 1 (both opaque: uniform AO on the
 * ground), a grass clump (a small upright quad) at the origin, and one
 * more far above the roof with nothing within its sphere. */
static void scene(obs_bake_scene *s)
{
    obs_bake_mesh m[4];
    const float go[3] = {-10, -10, 0}, gu[3] = {20, 0, 0}, gv[3] = {0, 20, 0};
    bt_grid(&m[0], "ground", go, gu, gv, 10, 10);
    const float ro[3] = {-10, -10, 1}, ru[3] = {0, 20, 0}, rv[3] = {20, 0, 0}; /* faces down */
    bt_grid(&m[1], "roof", ro, ru, rv, 4, 4);
    const float qo[3] = {-0.1f, 0, 0}, qu[3] = {0.2f, 0, 0}, qv[3] = {0, 0, 0.3f};
    bt_grid(&m[2], "clump", qo, qu, qv, 1, 1);
    const float fo[3] = {-0.1f, 0, 50}, fu[3] = {0.2f, 0, 0}, fv[3] = {0, 0, 0.3f};
    bt_grid(&m[3], "clump_far", fo, fu, fv, 1, 1);
    bt_scene(s, m, 4);
    const char *names[3] = {"level", "grass_1", "grass_far"};
    const uint32_t counts[3] = {2, 1, 1};
    bt_split(s, names, counts, 3);
}

static void test_resample(void **state)
{
    (void)state;
    obs_bake_scene s;
    scene(&s);
    obs_bake_result r, off;
    bake(&s, "auto", &r);
    bake(&s, "off", &off);
    assert_int_equal(r.stats.decorator_nodes[3], 2);
    assert_int_equal(r.stats.small_decorators, 2);
    assert_int_equal(r.stats.small_unresolved, 1);
    assert_non_null(r.node_ao);
    assert_int_equal(r.node_count, 3);
    assert_true(isnan(r.node_ao[0]) && isnan(r.node_ao[6]));
    /* the ground's mean values near the origin: the clump's scalar */
    double g[2] = {0, 0};
    size_t ng = 0;
    for (size_t i = 0; i < r.instance_count; i++) {
        const obs_bake_instance *in = &r.instances[i];
        const obs_bake_mesh *mm = &s.meshes[in->mesh];
        if (in->mesh == 0)
            for (size_t v = 0; v < mm->vertex_count; v++) {
                const float *p = mm->positions + 3 * v;
                if (fabsf(p[0]) <= 2.0f && fabsf(p[1]) <= 2.0f) {
                    g[0] += in->ao_short[v];
                    g[1] += in->ao_long[v];
                    ng++;
                }
            }
    }
    assert_true(ng > 0);
    g[0] /= (double)ng;
    g[1] /= (double)ng;
    const float *a = r.node_ao + 3;
    print_message("clump: _AO_SHORT %.4f _AO_LONG %.4f _AO %.4f; ground near it %.4f %.4f\n",
                  (double)a[1], (double)a[2], (double)a[0], g[0], g[1]);
    assert_true(fabs(a[1] - g[0]) < 0.01 && fabs(a[2] - g[1]) < 0.01);
    assert_true(fabsf(a[0] - (0.03f * a[1] + 0.97f * a[2])) < 1e-6f);
    for (size_t i = 0; i < r.instance_count; i++) {
        const obs_bake_instance *in = &r.instances[i], *o = &off.instances[i];
        if (in->node == 1) {
            for (size_t v = 0; v < 4; v++)
                assert_true(in->ao_short[v] == a[1] && in->ao_long[v] == a[2] && in->ao[v] == a[0]);
            /* traced as opaque geometry it has its own, other values */
            assert_true(fabs(o->ao_short[0] - a[1]) > 0.01);
        }
        if (in->node == 2) /* unresolved: its own fit */
            assert_true(in->ao_short[0] == o->ao_short[0] && in->ao_long[0] == o->ao_long[0]);
    }
    assert_null(off.node_ao);

    /* the .glb carries the scalar in the node's extras */
    char path[] = "/tmp/obs_small_XXXXXX.glb", err[OBS_ERR_LEN] = "";
    int fd = mkstemps(path, 4);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(obs_bake_write_glb(path, &s, &r, 0, err), OBS_OK);
    obs_bake_scene back;
    assert_int_equal(obs_bake_load(path, 0, &back, err), OBS_OK);
    int found = 0;
    for (size_t n = 0; n < back.node_count; n++)
        if (!strcmp(back.nodes[n].name, "grass_1")) {
            found = 1;
            assert_non_null(back.nodes[n].extras);
            print_message("grass_1 extras: %s\n", back.nodes[n].extras);
            assert_non_null(strstr(back.nodes[n].extras, "\"_AO_SHORT\""));
        } else if (back.nodes[n].extras) {
            assert_null(strstr(back.nodes[n].extras, "_AO"));
        }
    assert_true(found);
    obs_bake_scene_free(&back);
    remove(path);
    obs_bake_result_free(&off);
    obs_bake_result_free(&r);
    obs_bake_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_resample),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
