/* Object masks in the AO: receivers leaves the unselected pixels at
 * exactly 1 and the selected ones at the chain's AO (the Arnold sample's
 * deep id channel, and a flat Blender frame); occluders excluding a
 * surface changes the AO only where that surface could occlude, and only
 * upwards, at full and at half resolution; GL and the CPU twins agree
 * with masks on every method at both.  Deep input's occluders and
 * self_only: test_mask_deep.c. */
#include "testutil.h"

#include <math.h>
#include <stdlib.h>

#include "gl_testutil.h"
#include "obscura/deep.h"
#include "obscura/mask.h"

#define ARNOLD TESTDATA "/arnold_sample2.exr"
#define ROOM TESTDATA "/room_small.exr"
/* the room's albedo channel: 0.8 walls and floor, 0.2 one object; taken
 * as object IDs (the room frame has no ID pass) */
#define WALLS "id:ViewLayer.DiffCol.R=0.7-0.9"
#define OBJECT "id:ViewLayer.DiffCol.R=0.15-0.25"

static void set(obs_params *p, const char *name, const char *value)
{
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_param_set(p, name, value, err), OBS_OK);
}

static void test_receivers_deep_arnold(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    obs_deep_image d;
    obs_deep_result all, sel;
    obs_params p = {0};
    set(&p, "radius", "1");
    assert_int_equal(obs_deep_read_exr(ARNOLD, NULL, &d, err), OBS_OK);
    assert_int_equal(obs_deep_run_cpu(&d, &p, &all, err), OBS_OK);
    set(&p, "receivers", "id:id=2");
    assert_int_equal(obs_deep_read_masks(&d, ARNOLD, NULL, 0, &p, NULL, err), OBS_OK);
    assert_non_null(d.receivers);
    assert_int_equal(obs_deep_run_cpu(&d, &p, &sel, err), OBS_OK);
    int ones = 0, kept = 0, darker = 0;
    for (int i = 0; i < d.width * d.height; i++) {
        if (d.receivers[i] == 0.0f) {
            assert_true(sel.ao_blend.data[i] == 1.0f);
            assert_true(sel.ao_front.data[i] == 1.0f);
            ones++;
        } else {
            assert_true(sel.ao_blend.data[i] == all.ao_blend.data[i]);
            kept++;
            darker += all.ao_blend.data[i] < 1.0f;
        }
    }
    assert_true(ones > 1000 && kept > 1000 && darker > 100);
    obs_deep_result_free(&all);
    obs_deep_result_free(&sel);
    /* occluders and self_only on deep input: read at every sample
     * (test_mask_deep.c), the receivers kept */
    obs_params q = p;
    set(&q, "occluders", "id:id=1");
    set(&q, "self_only", "on");
    if (obs_deep_read_masks(&d, ARNOLD, NULL, 0, &q, NULL, err) != OBS_OK)
        fail_msg("%s", err);
    assert_non_null(d.receivers);
    assert_non_null(d.occluders);
    assert_non_null(d.object_id);
    obs_deep_free(&d);
}

static void read_room(obs_gbuffer_file *f, const obs_params *p)
{
    char err[OBS_ERR_LEN];
    load(scenes[0], f);
    assert_int_equal(obs_gbuffer_read_masks(f, ROOM, NULL, 0, p, NULL, err), OBS_OK);
}

static void test_receivers_flat(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    obs_params p = {0};
    obs_gbuffer_file f = {0};
    obs_result all, sel;
    read_room(&f, &p);
    assert_int_equal(obs_run_cpu(&f.gb, &p, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE, &all, err), OBS_OK);
    set(&p, "receivers", OBJECT);
    assert_int_equal(obs_gbuffer_read_masks(&f, ROOM, NULL, 0, &p, NULL, err), OBS_OK);
    set(&p, "multibounce", "on");
    assert_int_equal(obs_run_cpu(&f.gb, &p, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE, &sel, err), OBS_OK);
    assert_non_null(sel.multibounce.data);
    const float *w = f.gb.receivers.data;
    int ones = 0, kept = 0;
    for (int i = 0; i < f.gb.width * f.gb.height; i++) {
        if (w[i] == 0.0f) {
            assert_true(sel.ao.data[i] == 1.0f);
            for (int k = 0; k < 3; k++) /* the multi-bounce AO too */
                assert_true(sel.multibounce.data[3 * i + k] == 1.0f);
            ones++;
        } else {
            assert_true(sel.ao.data[i] == all.ao.data[i]);
            kept++;
        }
    }
    assert_true(ones > 1000 && kept > 500);
    /* the sanity check's mean AO counts the pixels by their receivers
     * weight: no "radius too small" for the pixels left at 1 by request */
    obs_exr_info info = {0};
    assert_int_equal(obs_result_sanity(&sel.ao, &f.gb, NULL, &p, &info), 0);
    obs_result_free(&all);
    obs_result_free(&sel);
    obs_gbuffer_free(&f);
}

/* The AO `sel` with the occluders mask f->gb.occluders against `all`
 * without it: it rises or stays everywhere, and changes only at pixels
 * within the sampling radius D (method hemisphere: point samples within
 * D), plus `margin` pixels, of an excluded surface; the number of pixels
 * that changed. */
static int check_local(const obs_gbuffer_file *f, const obs_result *all, const obs_result *sel,
                       int margin)
{
    const float *occl = f->gb.occluders.data;
    const int W = f->gb.width, H = f->gb.height;
    /* the radius in pixels at depth z: D f_px / (z - D), f_px from the
     * projection's [1][1] */
    const float fpx = f->gb.camera.projection[5] * 0.5f * (float)H, D = 0.5f;
    int changed = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + x;
            assert_true(sel->ao.data[i] >= all->ao.data[i] - 1e-6f);
            if (sel->ao.data[i] == all->ao.data[i])
                continue;
            changed++;
            float z = f->gb.depth.data[i];
            int r = (int)ceilf(z > D ? D * fpx / (z - D) : (float)W) + margin, near = 0;
            for (int v = y - r; v <= y + r && !near; v++)
                for (int u = x - r; u <= x + r && !near; u++)
                    near = u >= 0 && v >= 0 && u < W && v < H && occl[(size_t)v * W + u] < 1.0f;
            assert_true(near);
        }
    return changed;
}

/* Only the walls and floor as occluders: the AO rises or stays, and
 * changes only at pixels within the sampling radius of an excluded
 * surface (what was excluded: every surface not of the walls' albedo,
 * the object, the black ones, the edges between).  The same at half
 * resolution (each half pixel the masks of the pixel whose depth it
 * keeps): equal to the unmasked half-resolution AO bit for bit away from
 * the excluded surfaces (a margin of the 2x2 blocks the half pixels and
 * the upsample reach), rising near them. */
static void test_occluders_local(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    for (int half = 0; half < 2; half++) {
        obs_params p = {0};
        obs_gbuffer_file f = {0};
        obs_result all, sel;
        set(&p, "method", "hemisphere");
        set(&p, "blur", "off");
        set(&p, "ao_resolution", half ? "half" : "full");
        read_room(&f, &p);
        assert_int_equal(obs_run_cpu(&f.gb, &p, OBS_OUTPUT_AO, &all, err), OBS_OK);
        set(&p, "occluders", WALLS);
        assert_int_equal(obs_gbuffer_read_masks(&f, ROOM, NULL, 0, &p, NULL, err), OBS_OK);
        if (obs_run_cpu(&f.gb, &p, OBS_OUTPUT_AO, &sel, err) != OBS_OK)
            fail_msg("%s", err);
        int changed = check_local(&f, &all, &sel, half ? 4 : 2);
        print_message("%s resolution: %d of %d pixels rose\n", half ? "half" : "full", changed,
                      f.gb.width * f.gb.height);
        assert_true(changed > 100 && changed < f.gb.width * f.gb.height * 3 / 4);
        obs_result_free(&all);
        obs_result_free(&sel);
        obs_gbuffer_free(&f);
    }
}

/* GL against the CPU twins with masks, every method, at both
 * resolutions: the mean absolute difference stays small (a weight is per
 * pixel, so a sample whose position rounds to the next pixel in one of
 * them reads another weight: not bit for bit), far below what the masks
 * move. */
static void test_gl_twin_masks(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    static const char *const methods[] = {"vaopp", "hemisphere", "angle", "hbao", "gtao"};
    for (int half = 0; half < 2; half++)
        for (int m = 0; m < 5; m++)
            for (int self = 0; self < 2; self++) {
                obs_params p = {0};
                obs_gbuffer_file f = {0};
                obs_result g, c, plain;
                set(&p, "method", methods[m]);
                set(&p, "ao_resolution", half ? "half" : "full");
                read_room(&f, &p);
                assert_int_equal(obs_run_cpu(&f.gb, &p, OBS_OUTPUT_AO, &plain, err), OBS_OK);
                set(&p, "occluders", self ? "id:ViewLayer.DiffCol.R=0-1" : WALLS);
                if (self)
                    set(&p, "self_only", "on");
                assert_int_equal(obs_gbuffer_read_masks(&f, ROOM, NULL, 0, &p, NULL, err), OBS_OK);
                if (obs_run(ctx, &f.gb, &p, OBS_OUTPUT_AO, &g, err) != OBS_OK)
                    fail_msg("GL: %s", err);
                assert_int_equal(obs_run_cpu(&f.gb, &p, OBS_OUTPUT_AO, &c, err), OBS_OK);
                double mae = 0.0, moved = 0.0;
                for (int i = 0; i < f.gb.width * f.gb.height; i++) {
                    mae += fabs(g.ao.data[i] - c.ao.data[i]);
                    moved += fabs(plain.ao.data[i] - c.ao.data[i]);
                }
                mae /= f.gb.width * f.gb.height;
                moved /= f.gb.width * f.gb.height;
                print_message("%s, %s, %s: GL vs CPU mean |diff| %.2e; the masks move the AO by "
                              "%.2e\n",
                              half ? "half" : "full", methods[m], self ? "self_only" : "occluders",
                              mae, moved);
                assert_true(mae < 2e-3);
                assert_true(moved > 5 * mae);
                obs_result_free(&g);
                obs_result_free(&c);
                obs_result_free(&plain);
                obs_gbuffer_free(&f);
            }
    obs_ctx_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_receivers_deep_arnold),
        cmocka_unit_test(test_receivers_flat),
        cmocka_unit_test(test_occluders_local),
        cmocka_unit_test(test_gl_twin_masks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
