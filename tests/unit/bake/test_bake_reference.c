/* The bake's samples and the reference's obscurance mode estimate one
 * quantity the same way: at a sample's point and face normal, with the
 * same seed, ray count and stream (pixel i = sample i), the reference
 * (core/ground/obscurance.c) gets the value the bake's trace
 * (core/bake/trace.c) got there, to float rounding.  A change of the
 * kernel, the ray set or the random shifts on one side only fails here.
 * The same with decorators: a shrub (fog box) and a tree (semi-transparent
 * card) in the crease, the reference given the bake's occluders
 * (obs_bake_occluders_new, section 2.1). */
#include "level/bake_testutil.h"
#include "bake/bake_internal.h"
#include "level/decor.h"
#include "obscura/io.h"
#include "obscura/reference.h"
#include "obscura/scene.h"

static void same_as_bake(int decor, double *mean)
{
    obs_bake_mesh m[4];
    const float o[3] = {0, 0, -4}, fz[3] = {0, 0, 8}, fx[3] = {6, 0, 0}, wy[3] = {0, 6, 0};
    bt_grid(&m[0], "floor", o, fz, fx, 8, 6); /* normal +y */
    bt_grid(&m[1], "wall", o, wy, fz, 6, 8);  /* normal +x */
    /* a shrub's mesh spanning the box [0.5, 2.5] x [0, 1.5] x [-2, 2], and
     * a tree card at x = 3, both facing the eye (the reference turns a
     * normal that does not towards it) */
    const float bo[3] = {0.5f, 0, -2}, bu[3] = {0, 0, 4}, bv[3] = {2, 1.5f, 0};
    const float to[3] = {3, 0, -3}, tu[3] = {0, 4, 0}, tv[3] = {0, 0, 6};
    bt_grid(&m[2], "bush", bo, bu, bv, 2, 2);
    bt_grid(&m[3], "tree", to, tu, tv, 2, 2);
    obs_bake_scene sc;
    bt_scene(&sc, m, 4);
    /* three nodes: the room, "bush_1", "tree_1" (classes by name) */
    const char *names[3] = {"room", "bush_1", "tree_1"};
    const uint32_t counts[3] = {2, 1, 1};
    bt_split(&sc, names, counts, 3);
    obs_bake_params bp = {0};
    bt_set(&bp, "decorator-source", decor ? "auto" : "off");
    bt_set(&bp, "shrub-density", "0.8");
    bt_set(&bp, "tree-attenuation", "0.4");
    obs__bake_world w;
    obs__bake_samples s;
    obs__bake_decor dc;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__bake_decor_classify(&sc, &bp, NULL, &dc, err), OBS_OK);
    assert_int_equal(dc.counts[OBS__DECOR_SHRUB], decor ? 1 : 0);
    assert_int_equal(dc.counts[OBS__DECOR_TREE], decor ? 1 : 0);
    assert_int_equal(obs__bake_flatten(&sc, &w, err), OBS_OK);
    assert_int_equal(obs__bake_samples_make(&w, 2.0, 16, 5, &s, err), OBS_OK);
    obs__bake_trace_desc td = {{0.5f, 3.0f}, 40, 1, 1.0f, 5, NULL, NULL};
    td.decor = &dc;
    td.tree_attenuation = 0.4f;
    double bvh;
    assert_int_equal(obs__bake_trace(&w, &s, &td, &bvh, err), OBS_OK);
    obs_bake_occluders *occl = NULL;
    char warning[OBS_ERR_LEN];
    assert_int_equal(obs_bake_occluders_new(&sc, &bp, NULL, &occl, warning, err), OBS_OK);
    assert_true(!occl == !decor);

    /* the same triangles as a reference scene (borrowed arrays) */
    obs_scene rs = {.vertex_count = w.vertex_count, .positions = w.pos,
                    .triangle_count = w.triangle_count, .indices = w.tri};
    assert_int_equal(obs_scene_check(&rs, err), OBS_OK);
    const int n = (int)s.count;
    obs_image pos = {n, 1, 3, malloc(3 * (size_t)n * sizeof(float))};
    obs_image nrm = {n, 1, 3, malloc(3 * (size_t)n * sizeof(float))};
    assert_non_null(pos.data);
    assert_non_null(nrm.data);
    for (int i = 0; i < n; i++) {
        obs__bake_sample_pos(&w, &s, (size_t)i, pos.data + 3 * i);
        memcpy(nrm.data + 3 * i, w.fn + 3 * (size_t)s.tri[i], 3 * sizeof(float));
    }
    /* an eye that both faces see from their front */
    obs_camera cam;
    obs_camera_from_fov(60.0f, 1.0f, 0.1f, 100.0f, &cam);
    cam.world_to_camera[3] = -20.0f;
    cam.world_to_camera[7] = -20.0f;
    cam.has_world_to_camera = 1;
    obs_reference_view v = {.camera = &cam, .position = &pos, .normal = &nrm};
    obs_reference_desc d = {.spp = td.rays, .seed = td.seed, .threads = 2, .obscurance = 1,
                            .blend = 0.5f, .occluders = occl};
    d.obscurance_distance[0] = td.distance[0];
    d.obscurance_distance[1] = td.distance[1];
    obs_image ao = {0};
    assert_int_equal(obs_reference_render(&rs, &v, &d, &ao, NULL, err), OBS_OK);
    double worst = 0.0, dark = 0.0;
    *mean = 0.0;
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 2; c++) {
            worst = fmax(worst, fabs(ao.data[3 * i + 1 + c] - s.ao[2 * i + c]));
            dark = fmax(dark, 1.0 - s.ao[2 * i + c]);
            *mean += s.ao[2 * i + c] / (2.0 * n);
        }
    print_message("%s: %d samples: worst |reference - bake| %.2g (darkest sample %.3f, mean "
                  "%.4f)\n",
                  decor ? "decorators" : "all opaque", n, worst, 1.0 - dark, *mean);
    assert_true(n > 100);
    assert_true(dark > 0.3); /* the crease obscures: not a test of 1 = 1 */
    assert_true(worst < 1e-5);
    obs_image_free(&ao);
    obs_image_free(&pos);
    obs_image_free(&nrm);
    obs_bake_occluders_free(occl);
    obs__bake_decor_free(&dc);
    obs__bake_samples_free(&s);
    obs__bake_world_free(&w);
    obs_bake_scene_free(&sc);
}

static void test_same_as_bake(void **state)
{
    (void)state;
    double opaque, decor;
    same_as_bake(0, &opaque);
    same_as_bake(1, &decor);
    /* the decorators change the values: fog and 60 % cards let light
     * through where the opaque bush and card did not */
    assert_true(fabs(opaque - decor) > 0.01);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_as_bake),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
