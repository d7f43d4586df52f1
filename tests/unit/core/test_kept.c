/* What a context keeps between frames: obs_ctx_kept_bytes counts the
 * texture storage of the last frame's targets (flat and deep), and
 * obs_ctx_trim releases it over a budget without changing the next
 * frame's result. */
#include "gl_testutil.h"

#include "context.h"
#include "obscura/deep.h"

/* The chain's targets for w x h: the 13 full-size textures run_gl.c
 * allocates (their formats' texel sizes) and the culling pre-pass's one
 * at 1/8 size. */
static unsigned long long chain_bytes(int w, int h)
{
    const unsigned long long px = (unsigned long long)w * h;
    const unsigned long long per_px = 4 /* depth */ + 16 /* normal */ + 16 /* color */ +
                                      16 /* viewpos */ + 16 /* vnormal */ + 8 /* dz */ +
                                      8 /* ao */ + 16 /* composite */ + 8 /* blur */ +
                                      4 /* count */ + 4 /* cull mask */ + 16 /* bleed */ +
                                      4 /* luminance factor */;
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
     * the front and blend AO and the blur's plane between its passes (RG32F) */
    const unsigned long long want = (unsigned long long)d.width * d.height * (16 * 2 * 3 + 3 * 8);
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
