/* What a context keeps between frames: obs_ctx_kept_bytes counts the
 * texture storage of the last frame's targets (flat and deep), and
 * obs_ctx_trim releases it over a budget without changing the next
 * frame's result. */
#include "gl_testutil.h"

#include "context.h"
#include "obscura/deep.h"

/* The chain's targets of an AO-only frame, w x h, normals given: the 7
 * full-size textures run_gl.c makes for it (their formats' texel sizes)
 * and the culling pre-pass's one at 1/8 size.  Colour, the composite and
 * the debug outputs are made on the first frame that asks for them. */
static unsigned long long chain_bytes(int w, int h)
{
    const unsigned long long px = (unsigned long long)w * h;
    const unsigned long long per_px = 4 /* depth */ + 16 /* normal */ + 16 /* viewpos */ +
                                      16 /* vnormal */ + 8 /* dz */ + 8 /* ao */ + 8 /* blur */;
    const unsigned long long cull = (unsigned long long)((w + 7) / 8) * ((h + 7) / 8) * 4;
    return px * per_px + cull;
}

static void test_flat(void **state)
{
    (void)state;
    obs_gbuffer_file gf;
    load(scenes[0], &gf);
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_ctx_kept_bytes(ctx), 0);
    obs_result a, b;
    assert_int_equal(obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &a, err), OBS_OK);
    const unsigned long long kept = obs_ctx_kept_bytes(ctx);
    assert_int_equal(kept, chain_bytes(gf.gb.width, gf.gb.height));
    print_message("%dx%d: %llu bytes kept\n", gf.gb.width, gf.gb.height, kept);

    /* under the budget: nothing released */
    unsigned long long objects = ctx->gl_objects_created;
    assert_int_equal(obs_ctx_trim(ctx, kept, err), OBS_OK);
    assert_int_equal(obs_ctx_kept_bytes(ctx), kept);
    /* over it: released, the next frame allocates again, same AO */
    assert_int_equal(obs_ctx_trim(ctx, kept - 1, err), OBS_OK);
    assert_int_equal(obs_ctx_kept_bytes(ctx), 0);
    assert_int_equal(obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &b, err), OBS_OK);
    assert_true(ctx->gl_objects_created > objects);
    assert_int_equal(obs_ctx_kept_bytes(ctx), kept);
    assert_memory_equal(a.ao.data, b.ao.data, (size_t)gf.gb.width * gf.gb.height * sizeof(float));
    obs_result_free(&a);
    obs_result_free(&b);

    /* a composite: colour and the composite target added (16 bytes a
     * pixel each), kept for the next frames */
    const unsigned long long px = (unsigned long long)gf.gb.width * gf.gb.height;
    assert_non_null(gf.gb.color.data);
    assert_int_equal(obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE, &a, err),
                     OBS_OK);
    assert_int_equal(obs_ctx_kept_bytes(ctx), kept + 32 * px);
    obs_result_free(&a);

    /* ao_resolution half, after a trim: the full set without prep planes
     * (40 bytes a pixel), the half set with them */
    assert_int_equal(obs_ctx_trim(ctx, 0, err), OBS_OK);
    obs_params p = {0}; /* zero: every default */
    assert_int_equal(obs_param_set(&p, "ao_resolution", "half", err), OBS_OK);
    assert_int_equal(obs_run(ctx, &gf.gb, &p, OBS_OUTPUT_AO, &a, err), OBS_OK);
    const int hw = (gf.gb.width + 1) / 2, hh = (gf.gb.height + 1) / 2;
    const unsigned long long half_set = (unsigned long long)hw * hh * (4 + 8 + 8 + 16 + 16 + 8) +
                                        (unsigned long long)((hw + 7) / 8) * ((hh + 7) / 8) * 4;
    assert_int_equal(obs_ctx_kept_bytes(ctx), chain_bytes(gf.gb.width, gf.gb.height) - 40 * px +
                                                  half_set);
    print_message("half: %llu bytes kept\n", obs_ctx_kept_bytes(ctx));
    obs_result_free(&a);
    obs_ctx_destroy(ctx);
    obs_gbuffer_free(&gf);
}

static void test_deep(void **state)
{
    (void)state;
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    if (obs_deep_read_exr(TESTDATA "/deep_small.exr", NULL, &d, err) != OBS_OK)
        fail_msg("%s", err);
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    obs_params p = {0};
    assert_int_equal(obs_param_set(&p, "deep_layers", "3", err), OBS_OK);
    obs_deep_result r;
    assert_int_equal(obs_deep_run(ctx, &d, &p, &r, err), OBS_OK);
    /* the nodes' positions and normals (two RGBA32F arrays of 3 layers),
     * the intervals' ends (an R32F array of 3 layers), the front and blend
     * AO and the blur's plane between its passes (RG32F) */
    const unsigned long long want = (unsigned long long)d.width * d.height * (16 * 2 * 3 + 4 * 3 + 3 * 8);
    assert_int_equal(obs_ctx_kept_bytes(ctx), want);
    assert_int_equal(obs_ctx_trim(ctx, 0, err), OBS_OK);
    assert_int_equal(obs_ctx_kept_bytes(ctx), 0);
    obs_deep_result_free(&r);
    obs_ctx_destroy(ctx);
    obs_deep_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flat),
        cmocka_unit_test(test_deep),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
