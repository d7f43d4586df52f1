/* EGL surfaceless against OSMesa: two backends, one answer.
 *
 * This is the one test that loads two Mesa drivers into one process
 * (libOSMesa carries its own copy of gallium/llvmpipe beside the EGL
 * driver's).  Together they leave ~1 KB of driver state that LeakSanitizer
 * reports from llvmpipe's JIT code; each alone does not (the CLI runs under
 * LeakSanitizer with either backend in tests/e2e).  So leak checking is
 * off for this binary only; ASan and UBSan still check everything else. */
#include "gl_testutil.h"

const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "detect_leaks=0"; }

/* EGL surfaceless and OSMesa both run Mesa's llvmpipe: the same AO. */
static void test_backends_agree(void **state)
{
    obs_result r[2];
    obs_gbuffer_file gf = {0};
    char err[OBS_ERR_LEN] = "";
    const obs_backend b[2] = {OBS_BACKEND_OSMESA, OBS_BACKEND_EGL_SURFACELESS};
    (void)state;
    load(scenes[0], &gf);
    for (int i = 0; i < 2; i++) {
        obs_ctx *ctx = make_ctx(b[i]);
        obs_ctx_info info;
        obs_ctx_get_info(ctx, &info);
        assert_int_equal(info.backend, b[i]);
        print_message("%s: %s, %s\n", obs_backend_name(b[i]), info.gl_version, info.gl_renderer);
        assert_int_equal(obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &r[i], err), OBS_OK);
        obs_ctx_destroy(ctx);
    }
    double mean, frac;
    diff(&r[0].ao, &r[1].ao, &mean, &frac);
    print_message("egl-surfaceless vs osmesa: mean |diff| %.2e, %.3f %% of pixels > 1e-3\n", mean, 100 * frac);
    assert_true(mean < 1e-5);
    assert_true(frac < 1e-3);
    obs_result_free(&r[0]);
    obs_result_free(&r[1]);
    obs_gbuffer_free(&gf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_backends_agree),
    };
    return cmocka_run_group_tests_name("backends", tests, NULL, NULL);
}
