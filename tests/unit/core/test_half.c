/* ao_resolution half (quality preview): the downsample keeps whole pixels
 * of both sides of a depth edge, the joint bilateral upsample gives each
 * full pixel the AO of its own surface (no halo across the edge, none in
 * a one-pixel gap), GL = CPU twin on real input, and what half resolution
 * refuses. */
#include <string.h>

#include "gl_testutil.h"

#include "chain/frame.h"
#include "obscura/deep.h"

enum { W = 16, H = 12 };

/* Full planes of a depth edge: planar depth z_of(x) facing the camera. */
static void edge_planes(float (*z_of)(int), float *pos, float *nrm)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + x;
            float z = z_of(x);
            pos[4 * i] = (float)x;
            pos[4 * i + 1] = (float)y;
            pos[4 * i + 2] = -z;
            pos[4 * i + 3] = z;
            nrm[3 * i] = nrm[3 * i + 1] = 0.0f;
            nrm[3 * i + 2] = 1.0f;
        }
}

static float edge_at_5(int x) { return x < 5 ? 2.0f : 10.0f; }      /* splits blocks 2x..2x+1 */
static float gap_at_6(int x) { return x == 6 ? 10.0f : 2.0f; }      /* one background column */
static float sky_right(int x) { return x < 7 ? 3.0f : 0.0f; }       /* background (no surface) */

/* Each full pixel of a 2-vs-10 depth edge gets exactly the AO of its own
 * side, the AO being 1 on the near surface and 0.2 on the far one: no
 * value in between, which a plain bilinear upsample gives at the edge. */
static void check_no_halo(float (*z_of)(int), int has_far, const char *name)
{
    obs__frame f, hf;
    memset(&f, 0, sizeof f);
    f.width = W;
    f.height = H;
    f.viewport[2] = W;
    f.viewport[3] = H;
    f.radius = 1.0f;
    obs__frame_half(&f, &hf);
    assert_int_equal(hf.width, W / 2);
    assert_int_equal(hf.height, H / 2);
    static float pos[4 * W * H], nrm[3 * W * H];
    static float hpos[4 * W * H], hnrm[3 * W * H], hao[W * H];
    edge_planes(z_of, pos, nrm);
    int near = 0, far = 0;
    for (int hy = 0; hy < hf.height; hy++)
        for (int hx = 0; hx < hf.width; hx++) {
            long k = obs__half_source(&f, pos, hx, hy);
            size_t h = (size_t)hy * hf.width + hx;
            if (k < 0) {
                memset(hpos + 4 * h, 0, 4 * sizeof(float));
                hao[h] = 1.0f;
                continue;
            }
            memcpy(hpos + 4 * h, pos + 4 * k, 4 * sizeof(float));
            memcpy(hnrm + 3 * h, nrm + 3 * k, 3 * sizeof(float));
            hao[h] = hpos[4 * h + 3] > 5.0f ? 0.2f : 1.0f; /* the AO of its surface */
            near += hpos[4 * h + 3] < 5.0f;
            far += hpos[4 * h + 3] > 5.0f;
        }
    int wrong = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float z = pos[4 * ((size_t)y * W + x) + 3];
            float want = z <= 0.0f ? 1.0f : z > 5.0f ? 0.2f : 1.0f;
            float got = obs__half_upsample(&f, &hf, pos, nrm, hpos, hnrm, hao, x, y);
            wrong += fabsf(got - want) > 1e-5f; /* rounding of sum / wsum only */
        }
    print_message("%s: %d near and %d far half pixels; %d of %d full pixels off their "
                  "surface's AO\n",
                  name, near, far, wrong, W * H);
    assert_true(near > 0 && (far > 0) == has_far);
    assert_int_equal(wrong, 0);
}

static void test_edges(void **state)
{
    (void)state;
    check_no_halo(edge_at_5, 1, "edge inside a 2x2 block");
    check_no_halo(gap_at_6, 1, "one-pixel background gap");
    check_no_halo(sky_right, 0, "surface against background");
}

/* The checkerboard: a block across the edge takes its nearest pixel at
 * even hx + hy and its farthest at odd. */
static void test_checkerboard(void **state)
{
    (void)state;
    obs__frame f;
    memset(&f, 0, sizeof f);
    f.width = W;
    f.height = H;
    static float pos[4 * W * H], nrm[3 * W * H];
    edge_planes(edge_at_5, pos, nrm);
    for (int hy = 0; hy < 3; hy++) {
        long k = obs__half_source(&f, pos, 2, hy); /* pixels 4 (z 2) and 5 (z 10) */
        assert_true(k >= 0);
        assert_int_equal(k % W, (2 + hy) % 2 == 0 ? 4 : 5);
    }
}

static void run_pair(obs_ctx *ctx, const obs_gbuffer *gb, const char *params, obs_result *gl,
                     obs_result *cpu)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "", buf[256];
    snprintf(buf, sizeof buf, "%s", params);
    for (char *kv = strtok(buf, " "); kv; kv = strtok(NULL, " ")) {
        char *eq = strchr(kv, '=');
        *eq = '\0';
        assert_int_equal(obs_param_set(&p, kv, eq + 1, err), OBS_OK);
    }
    unsigned out = OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE;
    if (obs_run(ctx, gb, &p, out, gl, err) != OBS_OK)
        fail_msg("GL %s: %s", params, err);
    if (obs_run_cpu(gb, &p, out, cpu, err) != OBS_OK)
        fail_msg("CPU %s: %s", params, err);
}

/* GL = CPU twin at half resolution (the bounds of test_gl_twin.c: a
 * sample within rounding of a pixel border may read the neighbour), and
 * the half AO close to the full one. */
static void test_twin(void **state)
{
    (void)state;
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    static const char *const variants[] = {
        "quality=preview",
        "quality=preview blur=off",
        "quality=preview ao_definition=volume culling=off",
        "quality=preview method=hbao",
        "quality=preview luminance=lum",
    };
    for (size_t s = 0; s < sizeof scenes / sizeof scenes[0]; s++) {
        obs_gbuffer_file gf;
        load(scenes[s], &gf);
        obs_result full, full_cpu;
        run_pair(ctx, &gf.gb, "quality=default", &full, &full_cpu);
        for (size_t v = 0; v < sizeof variants / sizeof variants[0]; v++) {
            obs_result gl, cpu;
            run_pair(ctx, &gf.gb, variants[v], &gl, &cpu);
            double mean, frac, cmean, cfrac, hmean, hfrac;
            diff(&gl.ao, &cpu.ao, &mean, &frac);
            diff(&gl.composite, &cpu.composite, &cmean, &cfrac);
            print_message("%s %s: GL vs CPU mean |diff| %.2e, %.3f %% > 1e-3\n", scenes[s],
                          variants[v], mean, 100 * frac);
            assert_true(mean < 1e-3);
            assert_true(frac < 0.02);
            assert_true(cmean < 1e-3);
            if (v == 0) {
                diff(&gl.ao, &full.ao, &hmean, &hfrac);
                print_message("%s: half vs full AO mean |diff| %.4f\n", scenes[s], hmean);
                assert_true(hmean < 0.02);
            }
            obs_result_free(&gl);
            obs_result_free(&cpu);
        }
        obs_result_free(&full);
        obs_result_free(&full_cpu);
        obs_gbuffer_free(&gf);
    }
    obs_ctx_destroy(ctx);
}

/* What half resolution does not give, refused by name. */
static void test_refused(void **state)
{
    (void)state;
    obs_gbuffer_file gf;
    load(scenes[0], &gf);
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    char err[OBS_ERR_LEN] = "";
    obs_params p = {0};
    obs_result r;
    assert_int_equal(obs_param_set(&p, "ao_resolution", "half", err), OBS_OK);
    assert_int_equal(obs_run(ctx, &gf.gb, &p, OBS_OUTPUT_SAMPLE_COUNT, &r, err),
                     OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "sample_count"));
    assert_int_equal(obs_run_cpu(&gf.gb, &p, OBS_OUTPUT_CULL_MASK, &r, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_param_set(&p, "bleeding", "full", err), OBS_OK);
    assert_int_equal(obs_run(ctx, &gf.gb, &p, OBS_OUTPUT_AO, &r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "bleeding"));

    obs_deep_image d;
    if (obs_deep_read_exr(TESTDATA "/deep_small.exr", NULL, &d, err) != OBS_OK)
        fail_msg("%s", err);
    obs_params q = {0};
    assert_int_equal(obs_param_set(&q, "quality", "preview", err), OBS_OK);
    obs_deep_result dr;
    assert_int_equal(obs_deep_run(ctx, &d, &q, &dr, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "deep input"));
    obs_deep_free(&d);
    obs_ctx_destroy(ctx);
    obs_gbuffer_free(&gf);
}

/* Object masks at half resolution: each half pixel carries the occluders
 * weight and the object of the full pixel whose depth it keeps, here a
 * weight and an ID told apart by the surface (0.25 and 7 on the near
 * side, 1 and 3 on the far one), so that a half pixel at a 2-vs-10 edge
 * whose block holds both has the ones of its own depth's surface. */
static void test_masks_follow_depth(void **state)
{
    (void)state;
    obs__frame f, hf;
    memset(&f, 0, sizeof f);
    f.width = W;
    f.height = H;
    static float pos[4 * W * H], nrm[3 * W * H], occl[W * H], ids[W * H];
    static float hw[W * H], hid[W * H];
    edge_planes(edge_at_5, pos, nrm);
    for (int i = 0; i < W * H; i++) {
        occl[i] = pos[4 * i + 3] < 5.0f ? 0.25f : 1.0f;
        ids[i] = pos[4 * i + 3] < 5.0f ? 7.0f : 3.0f;
    }
    f.mask_occl = occl;
    f.mask_id = ids;
    f.mask_on = 1;
    obs__frame_half(&f, &hf);
    /* the driver's to set: a half frame reads no full-size plane */
    assert_null(hf.mask_occl);
    assert_null(hf.mask_id);
    int picks[2] = {0, 0}; /* in the block of columns 4, 5: the far, the near side */
    for (int hy = 0; hy < hf.height; hy++)
        for (int hx = 0; hx < hf.width; hx++) {
            long k = obs__half_source(&f, pos, hx, hy);
            size_t h = (size_t)hy * hf.width + hx;
            assert_true(k >= 0);
            obs__half_masks(&f, k, h, hw, hid);
            int near = pos[4 * k + 3] < 5.0f;
            assert_true(hw[h] == (near ? 0.25f : 1.0f));
            assert_true(hid[h] == (near ? 7.0f : 3.0f));
            picks[near] += hx == 2;
        }
    assert_true(picks[0] > 0 && picks[1] > 0); /* the checkerboard keeps both */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_checkerboard),
        cmocka_unit_test(test_twin),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_masks_follow_depth),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
