/* The opaque BVH (core/level/occl.c) of a level holding many exact copies
 * of its triangles: the copies are left out of the BVH, its hits those
 * of the level without them.  A BVH cannot split coincident triangles, so
 * every ray that reached them tested each copy: bake-dynamic's probes on
 * 2000 copies of one quad took 90 s here (1 s for the quad alone). */
#include "level/bake_testutil.h"
#include "level/occl.h"

#define COPIES 500

/* A world of a unit floor quad (z = 0, facing +Z), with `copies` more
 * copies of its two triangles in a second mesh: the first copy soup (its
 * own vertices at the same positions), the rest indexed into it. */
static void floor_world(obs_bake_scene *s, obs__bake_world *w, int copies)
{
    const float o[3] = {0, 0, 0}, u[3] = {1, 0, 0}, v[3] = {0, 1, 0};
    obs_bake_mesh m[2];
    bt_grid(&m[0], "floor", o, u, v, 1, 1);
    if (copies) {
        bt_grid(&m[1], "copies", o, u, v, 1, 1);
        m[1].indices = realloc(m[1].indices, 6 * (size_t)copies * sizeof(uint32_t));
        assert_non_null(m[1].indices);
        for (int k = 1; k < copies; k++)
            memcpy(m[1].indices + 6 * k, m[1].indices, 6 * sizeof(uint32_t));
        m[1].triangle_count = 2 * (size_t)copies;
    }
    bt_scene(s, m, copies ? 2 : 1);
    char err[OBS_ERR_LEN] = "";
    if (obs__bake_flatten(s, w, err) != OBS_OK)
        fail_msg("%s", err);
}

static void test_copies_left_out(void **state)
{
    (void)state;
    obs_bake_scene s1, sn;
    obs__bake_world w1, wn;
    floor_world(&s1, &w1, 0);
    floor_world(&sn, &wn, COPIES);
    assert_int_equal(wn.triangle_count, 2 + 2 * COPIES);
    char err[OBS_ERR_LEN] = "";
    obs__bake_occl *o = NULL;
    assert_int_equal(obs__bake_occl_new(&wn, NULL, 0.0f, &o, err), OBS_OK);
    assert_int_equal(o->opaque_count, 2); /* the floor's own two */
    assert_non_null(o->opaque_tri);
    assert_int_equal(o->opaque_tri[0], 0);
    assert_int_equal(o->opaque_tri[1], 1);
    obs__bake_occl_free(o);
    /* without copies nothing changes: every triangle, no list */
    assert_int_equal(obs__bake_occl_new(&w1, NULL, 0.0f, &o, err), OBS_OK);
    assert_int_equal(o->opaque_count, 2);
    assert_null(o->opaque_tri);
    obs__bake_occl_free(o);

    /* the same hits: rays down onto the floor from above, and up at it
     * from below (its back) */
    obs__bake_bvh *b1 = NULL, *bn = NULL;
    assert_int_equal(obs__bake_bvh_new(&w1, &b1, err), OBS_OK);
    assert_int_equal(obs__bake_bvh_new(&wn, &bn, err), OBS_OK);
    float dirs[3 * 16];
    for (int k = 0; k < 16; k++) {
        float a = 0.3f * (float)k, z = k < 8 ? -1.0f : 1.0f;
        dirs[3 * k] = 0.2f * cosf(a);
        dirs[3 * k + 1] = 0.2f * sinf(a);
        dirs[3 * k + 2] = z;
        float len = sqrtf(0.04f + 1.0f);
        for (int c = 0; c < 3; c++)
            dirs[3 * k + c] /= len;
    }
    const float above[3] = {0.5f, 0.5f, 0.7f}, below[3] = {0.5f, 0.5f, -0.7f};
    for (int side = 0; side < 2; side++) {
        float t1[16], tn[16];
        uint8_t k1[16], kn[16];
        obs__bake_bvh_cast(b1, side ? below : above, dirs + (side ? 24 : 0), 8, 10.0f, t1, k1, NULL);
        obs__bake_bvh_cast(bn, side ? below : above, dirs + (side ? 24 : 0), 8, 10.0f, tn, kn, NULL);
        for (int k = 0; k < 8; k++) {
            assert_true(isfinite(t1[k]));
            assert_int_equal(k1[k], side);
        }
        assert_memory_equal(t1, tn, 8 * sizeof(float));
        assert_memory_equal(k1, kn, 8);
    }
    obs__bake_bvh_free(b1);
    obs__bake_bvh_free(bn);
    obs__bake_world_free(&w1);
    obs__bake_world_free(&wn);
    obs_bake_scene_free(&s1);
    obs_bake_scene_free(&sn);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_copies_left_out),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
