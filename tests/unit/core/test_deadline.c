/* A deadline on each frame's GL work (obs_ctx_set_deadline): the AO pass
 * drawn in bands gives the same result as one draw; a frame past its
 * deadline stops with OBS_DEADLINE, saying how far it got, and the
 * context serves the next frame as before. */
#include <string.h>

#include "gl_testutil.h"

#include "obscura/deep.h"

static void run_ok(obs_ctx *ctx, const obs_gbuffer *gb, const obs_params *p, obs_result *r)
{
    char err[OBS_ERR_LEN] = "";
    if (obs_run(ctx, gb, p, OBS_OUTPUT_AO, r, err) != OBS_OK)
        fail_msg("%s", err);
}

static void test_flat(void **state)
{
    (void)state;
    obs_gbuffer_file gf;
    load(scenes[0], &gf);
    const size_t bytes = (size_t)gf.gb.width * gf.gb.height * sizeof(float);
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    char err[OBS_ERR_LEN] = "";
    obs_params hbao = {0};
    assert_int_equal(obs_param_set(&hbao, "method", "hbao", err), OBS_OK);
    const obs_params *methods[] = {NULL, &hbao}; /* the chain's AO pass, a method's */
    for (int m = 0; m < 2; m++) {
        obs_result whole, banded, after;
        assert_int_equal(obs_ctx_set_deadline(ctx, 0.0, err), OBS_OK);
        run_ok(ctx, &gf.gb, methods[m], &whole);
        /* a deadline far away: drawn in bands, the same bytes */
        assert_int_equal(obs_ctx_set_deadline(ctx, 3600.0, err), OBS_OK);
        run_ok(ctx, &gf.gb, methods[m], &banded);
        assert_memory_equal(whole.ao.data, banded.ao.data, bytes);
        /* a deadline shorter than any band: stopped after the first */
        obs_result cut;
        assert_int_equal(obs_ctx_set_deadline(ctx, 1e-9, err), OBS_OK);
        assert_int_equal(obs_run(ctx, &gf.gb, methods[m], OBS_OUTPUT_AO, &cut, err), OBS_DEADLINE);
        print_message("%s\n", err);
        assert_non_null(strstr(err, "AO pass was stopped after 1 of 16 bands"));
        assert_null(cut.ao.data);
        /* the next frame is whole */
        assert_int_equal(obs_ctx_set_deadline(ctx, 0.0, err), OBS_OK);
        run_ok(ctx, &gf.gb, methods[m], &after);
        assert_memory_equal(whole.ao.data, after.ao.data, bytes);
        obs_result_free(&whole);
        obs_result_free(&banded);
        obs_result_free(&after);
    }
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
    const size_t bytes = (size_t)d.width * d.height * sizeof(float);
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    obs_deep_result whole, banded, cut;
    assert_int_equal(obs_deep_run(ctx, &d, NULL, &whole, err), OBS_OK);
    assert_int_equal(obs_ctx_set_deadline(ctx, 3600.0, err), OBS_OK);
    assert_int_equal(obs_deep_run(ctx, &d, NULL, &banded, err), OBS_OK);
    assert_memory_equal(whole.ao_front.data, banded.ao_front.data, bytes);
    assert_memory_equal(whole.ao_blend.data, banded.ao_blend.data, bytes);
    assert_int_equal(obs_ctx_set_deadline(ctx, 1e-9, err), OBS_OK);
    assert_int_equal(obs_deep_run(ctx, &d, NULL, &cut, err), OBS_DEADLINE);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "deep AO pass was stopped after 1 of"));
    obs_deep_result_free(&whole);
    obs_deep_result_free(&banded);
    obs_ctx_destroy(ctx);
    obs_deep_free(&d);
}

static void test_bad_values(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_ctx_set_deadline(NULL, 1.0, err), OBS_INVALID_ARGUMENT);
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    assert_int_equal(obs_ctx_set_deadline(ctx, -1.0, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "deadline"));
    assert_int_equal(obs_ctx_set_deadline(ctx, NAN, err), OBS_INVALID_ARGUMENT);
    obs_ctx_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flat),
        cmocka_unit_test(test_deep),
        cmocka_unit_test(test_bad_values),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
