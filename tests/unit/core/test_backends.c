/* EGL surfaceless against OSMesa: two backends, one answer.
 *
 * This is the one test that loads two Mesa drivers into one process
 * (libOSMesa carries its own copy of gallium/llvmpipe beside the EGL
 * driver's).  Together they leave ~1 KB of driver state that LeakSanitizer
 * reports from llvmpipe's JIT code; each alone does not (the CLI runs under
 * LeakSanitizer with either backend in tests/e2e).  So leak checking is
 * off for this binary only; ASan and UBSan still check everything else. */
#include <math.h>

#include "testutil.h"

#include "io.h"

const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "detect_leaks=0"; }

static const char *const scenes[] = {TESTDATA "/room_small", TESTDATA "/yard_small"};

static void load(const char *stem, obs_gbuffer_file *gf)
{
    char path[512], err[OBS_ERR_LEN] = "";
    snprintf(path, sizeof path, "%s.exr", stem);
    if (obs_gbuffer_read_exr(path, NULL, NULL, gf, err) != OBS_OK)
        fail_msg("%s: %s", path, err);
    snprintf(path, sizeof path, "%s.camera.json", stem);
    if (obs_camera_read_json(path, &gf->gb.camera, NULL, NULL, err) != OBS_OK)
        fail_msg("%s: %s", path, err);
}

static obs_ctx *make_ctx(obs_backend b)
{
    obs_ctx *ctx = NULL;
    char err[OBS_ERR_LEN] = "";
    obs_ctx_desc d = {.backend = b};
    if (obs_ctx_create(&d, &ctx, err) != OBS_OK)
        fail_msg("%s: %s", obs_backend_name(b), err);
    return ctx;
}

/* Mean |a - b| and the fraction of pixels differing by more than 1e-3. */
static void diff(const obs_image *a, const obs_image *b, double *mean, double *frac)
{
    size_t n = (size_t)a->width * a->height * a->channels, big = 0;
    double sum = 0;
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    for (size_t i = 0; i < n; i++) {
        double d = fabs((double)a->data[i] - b->data[i]);
        sum += d;
        big += d > 1e-3;
    }
    *mean = sum / n;
    *frac = (double)big / n;
}

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
