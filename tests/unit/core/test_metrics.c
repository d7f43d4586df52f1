/* Image comparison metrics (core/ground/metrics.c) against closed forms and
 * against shared/tools/aometrics.py, the project's referee. */
#include "testutil.h"

#include <math.h>

#include "obscura/metrics.h"

/* cmocka 1.1.5 (Debian 12) has no assert_double_equal, and its
 * assert_float_equal compares in float. */
#define assert_near(actual, expected, tol)                                          \
    do {                                                                           \
        double a_ = (actual), e_ = (expected), t_ = (tol);                         \
        if (!(fabs(a_ - e_) <= t_))                                                \
            fail_msg("%s = %.17g, expected %.17g +- %g", #actual, a_, e_, t_);     \
    } while (0)

/* A w x h image of `channels` floats per pixel, all zero. */
static obs_image new_image(int w, int h, int channels)
{
    size_t n = (size_t)w * (size_t)h * (size_t)channels;
    obs_image img = {w, h, channels, calloc(n, sizeof(float))};
    assert_non_null(img.data);
    return img;
}

static float *px(obs_image *img, int x, int y)
{
    return img->data + ((size_t)y * (size_t)img->width + (size_t)x) * (size_t)img->channels;
}

/* A deterministic pattern in [0.25, 0.75], exact in binary. */
static float pattern(int x, int y)
{
    return 0.25f + (float)((x * 7 + y * 13) % 17) / 32.0f;
}

/* xorshift32: deterministic noise, identical on every platform. */
static uint32_t rng_next(uint32_t *s)
{
    uint32_t x = *s;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    return *s = x;
}

/* Uniform in [-1, 1). */
static double rng_uniform(uint32_t *s)
{
    return (double)rng_next(s) / 2147483648.0 - 1.0;
}

static void test_identical(void **state)
{
    (void)state;
    static const int sizes[][2] = {{32, 24}, {1, 1}, {1, 7}, {7, 1}, {3, 2}, {6, 6}};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        int w = sizes[i][0], h = sizes[i][1];
        obs_image a = new_image(w, h, 1), b = new_image(w, h, 1);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                *px(&a, x, y) = *px(&b, x, y) = pattern(x, y);
        obs_metrics m;
        char err[OBS_ERR_LEN] = "";
        assert_int_equal(obs_metrics_compute(&a, &b, NULL, &m, err), OBS_OK);
        assert_int_equal(m.count, (long long)w * h);
        assert_true(m.mse == 0.0);
        assert_true(m.mae == 0.0);
        assert_true(m.bias == 0.0);
        assert_near(m.psnr, 120.0, 1e-9); /* mse floored at 1e-12 */
        assert_near(m.ssim, 1.0, 1e-15);
        if (w * h > 1) /* one pixel has no variance: corr is 0 */
            assert_near(m.corr, 1.0, 1e-12);
        obs_image_free(&a);
        obs_image_free(&b);
    }
}

static void test_constant_offset(void **state)
{
    (void)state;
    int w = 40, h = 30;
    obs_image a = new_image(w, h, 1), b = new_image(w, h, 1);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            *px(&a, x, y) = pattern(x, y) * 0.5f + 0.25f; /* exact, in [0.375, 0.625] */
            *px(&b, x, y) = *px(&a, x, y) + 0.125f;       /* exact */
        }
    obs_metrics m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_metrics_compute(&a, &b, NULL, &m, err), OBS_OK);
    assert_near(m.mse, 0.125 * 0.125, 1e-12);
    assert_near(m.mae, 0.125, 1e-12);
    assert_near(m.bias, 0.125, 1e-12);
    assert_near(m.psnr, 10.0 * log10(64.0), 1e-9);
    assert_near(m.corr, 1.0, 1e-9);
    assert_true(m.ssim > 0.0 && m.ssim < 1.0);

    /* Swapped: bias is candidate minus truth, so it changes sign. */
    assert_int_equal(obs_metrics_compute(&b, &a, NULL, &m, err), OBS_OK);
    assert_near(m.bias, -0.125, 1e-12);
    assert_near(m.mae, 0.125, 1e-12);
    obs_image_free(&a);
    obs_image_free(&b);
}

/* Flat images: every blur is the constant itself and the variances vanish,
 * so SSIM is (2 ua ub + C1) / (ua^2 + ub^2 + C1). */
static void test_ssim_flat(void **state)
{
    (void)state;
    int w = 20, h = 13;
    obs_image a = new_image(w, h, 1), b = new_image(w, h, 1);
    for (size_t i = 0; i < (size_t)w * h; i++) {
        a.data[i] = 0.5f;
        b.data[i] = 0.25f;
    }
    obs_metrics m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_metrics_compute(&a, &b, NULL, &m, err), OBS_OK);
    double c1 = 0.01 * 0.01;
    assert_near(m.ssim, (2 * 0.5 * 0.25 + c1) / (0.25 + 0.0625 + c1), 1e-9);
    assert_true(m.corr == 0.0); /* a constant image has no correlation */
    obs_image_free(&a);
    obs_image_free(&b);
}

static void test_correlation_sign(void **state)
{
    (void)state;
    int w = 16, h = 9;
    obs_image a = new_image(w, h, 1), b = new_image(w, h, 1);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            *px(&a, x, y) = pattern(x, y);
            *px(&b, x, y) = 1.0f - pattern(x, y);
        }
    obs_metrics m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_metrics_compute(&a, &b, NULL, &m, err), OBS_OK);
    assert_near(m.corr, -1.0, 1e-9);
    assert_true(m.ssim < 0.0);
    obs_image_free(&a);
    obs_image_free(&b);
}

/* Uniform noise in [-s, s] around a flat truth: E[d^2] = s^2/3,
 * E|d| = s/2, E[d] = 0.  With 65536 pixels the sampling error of the MSE
 * is about 0.35% (sd of d^2 is s^2 sqrt(4/45)); the tolerances are > 5 sd. */
static void test_noise(void **state)
{
    (void)state;
    int w = 256, h = 256;
    double s = 0.2;
    obs_image a = new_image(w, h, 1), b = new_image(w, h, 1);
    uint32_t seed = 0x9e3779b9u;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        a.data[i] = 0.5f;
        b.data[i] = (float)(0.5 + s * rng_uniform(&seed));
    }
    obs_metrics m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_metrics_compute(&a, &b, NULL, &m, err), OBS_OK);
    double mse = s * s / 3.0;
    assert_near(m.mse, mse, 0.02 * mse);
    assert_near(m.mae, s / 2.0, 0.002);
    assert_near(m.bias, 0.0, 0.003);
    assert_near(m.psnr, 10.0 * log10(1.0 / m.mse), 1e-9);
    assert_true(m.corr == 0.0);
    assert_true(m.ssim > 0.0 && m.ssim < 1.0);
    obs_image_free(&a);
    obs_image_free(&b);
}

static void test_mask(void **state)
{
    (void)state;
    int w = 40, h = 30;
    size_t n = (size_t)w * h;
    obs_image a = new_image(w, h, 1), b = new_image(w, h, 1);
    unsigned char *mask = malloc(n);
    assert_non_null(mask);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            mask[i] = x < w / 2;
            *px(&a, x, y) = pattern(x, y);
            /* Inside: identical; outside: far off, out of range too. */
            *px(&b, x, y) = mask[i] ? pattern(x, y) : 3.0f - 5.0f * pattern(x, y);
        }
    obs_metrics m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_metrics_compute(&a, &b, mask, &m, err), OBS_OK);
    assert_int_equal(m.count, (long long)n / 2);
    assert_true(m.mse == 0.0 && m.mae == 0.0 && m.bias == 0.0);
    /* Unselected pixels are 1.0 in both images before the blur. */
    assert_near(m.ssim, 1.0, 1e-15);
    assert_near(m.corr, 1.0, 1e-12);

    /* With differences inside, what lies outside changes nothing. */
    for (size_t i = 0; i < n; i++)
        if (mask[i])
            b.data[i] = a.data[i] * 0.75f + 0.1f;
    obs_metrics m1, m2;
    assert_int_equal(obs_metrics_compute(&a, &b, mask, &m1, err), OBS_OK);
    for (size_t i = 0; i < n; i++)
        if (!mask[i]) {
            a.data[i] = -7.0f;
            b.data[i] = (float)(i % 3);
        }
    assert_int_equal(obs_metrics_compute(&a, &b, mask, &m2, err), OBS_OK);
    assert_memory_equal(&m1, &m2, sizeof m1);
    assert_true(m1.mse > 0.0);

    free(mask);
    obs_image_free(&a);
    obs_image_free(&b);
}

static void test_clamp(void **state)
{
    (void)state;
    obs_image a = new_image(4, 1, 1), b = new_image(4, 1, 1);
    static const float va[4] = {-0.5f, 1.5f, 0.25f, 2.0f};
    static const float vb[4] = {0.0f, 1.0f, 0.25f, 1.0f};
    memcpy(a.data, va, sizeof va);
    memcpy(b.data, vb, sizeof vb);
    obs_metrics m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_metrics_compute(&a, &b, NULL, &m, err), OBS_OK);
    assert_true(m.mse == 0.0 && m.mae == 0.0);
    assert_near(m.ssim, 1.0, 1e-15);

    /* -1 vs 2 clamps to 0 vs 1: a difference of 1, not 3. */
    for (int i = 0; i < 4; i++) {
        a.data[i] = -1.0f;
        b.data[i] = 2.0f;
    }
    assert_int_equal(obs_metrics_compute(&a, &b, NULL, &m, err), OBS_OK);
    assert_near(m.mse, 1.0, 1e-15);
    assert_near(m.mae, 1.0, 1e-15);
    assert_near(m.bias, 1.0, 1e-15);
    assert_near(m.psnr, 0.0, 1e-12);
    obs_image_free(&a);
    obs_image_free(&b);
}

static void test_errors(void **state)
{
    (void)state;
    obs_image a = new_image(4, 3, 1), b = new_image(3, 4, 1), c = new_image(4, 3, 3);
    obs_metrics m;
    obs_image diff;
    char err[OBS_ERR_LEN] = "";

    assert_int_equal(obs_metrics_compute(&a, &b, NULL, &m, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "4x3"));
    assert_non_null(strstr(err, "3x4"));
    assert_int_equal(m.count, 0);

    err[0] = '\0';
    assert_int_equal(obs_metrics_diff_image(&a, &b, &diff, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "3x4"));
    assert_null(diff.data);

    err[0] = '\0';
    assert_int_equal(obs_metrics_compute(&a, &c, NULL, &m, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "channels"));

    unsigned char none[12] = {0};
    err[0] = '\0';
    assert_int_equal(obs_metrics_compute(&a, &a, none, &m, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "mask selects no pixels"));

    assert_int_equal(obs_metrics_compute(&a, NULL, NULL, &m, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_metrics_compute(&a, &a, NULL, NULL, NULL), OBS_INVALID_ARGUMENT);

    obs_image_free(&a);
    obs_image_free(&b);
    obs_image_free(&c);
}

static void test_diff_image(void **state)
{
    (void)state;
    obs_image a = new_image(3, 1, 1), b = new_image(3, 1, 1), d;
    static const float va[3] = {0.5f, 0.2f, -1.0f};
    static const float vb[3] = {0.625f, 0.9f, 0.0f}; /* e = 0.5, 1 (capped), 0 */
    memcpy(a.data, va, sizeof va);
    memcpy(b.data, vb, sizeof vb);
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_metrics_diff_image(&a, &b, &d, err), OBS_OK);
    assert_int_equal(d.width, 3);
    assert_int_equal(d.height, 1);
    assert_int_equal(d.channels, 3);
    static const float want[9] = {0.5f, 0.5f, 0.5f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 1.0f};
    for (int i = 0; i < 9; i++)
        assert_near(d.data[i], want[i], 1e-6);
    obs_image_free(&d);
    assert_null(d.data);
    obs_image_free(&a);
    obs_image_free(&b);
}

/* A 16x16 pair (exact in binary; b runs outside [0,1] to exercise the
 * clamp) and a mask, measured by aometrics.py's own ssim() with its
 * procedure.  The expected values come from, in the repository root:
 *
 * /usr/bin/python3 -c '
 * import ast, numpy as np
 * t = ast.parse(open("../shared/tools/aometrics.py").read()); ns = {"np": np}
 * exec(compile(ast.Module([f for f in t.body if getattr(f, "name", "") == "ssim"], []),
 *              "aometrics", "exec"), ns)
 * y, x = np.mgrid[0:16, 0:16]
 * a = np.clip((x * 7 + y * 13) % 17 / 16.0, 0, 1)
 * b = np.clip(((x * 7 + y * 13) % 17 + (x * 3 + y * 5) % 5 - 2) / 16.0, 0, 1)
 * m = ~(((x >= 11) & (y <= 4)) | ((x + y) % 9 == 0))
 * print(repr(ns["ssim"](a, b).mean()),
 *       repr(ns["ssim"](np.where(m, a, 1.0), np.where(m, b, 1.0))[m].mean()), m.sum())'
 *
 * -> 0.9621828473209286 0.9700106416023272 205   (numpy 1.24.2, Debian 12)
 *
 * numpy's exp() may differ from libm's by an ulp, hence the tolerance. */
static void test_ssim_matches_aometrics(void **state)
{
    (void)state;
    int w = 16, h = 16;
    obs_image a = new_image(w, h, 1), b = new_image(w, h, 1);
    unsigned char mask[16 * 16];
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int k = (x * 7 + y * 13) % 17;
            *px(&a, x, y) = (float)k / 16.0f;
            *px(&b, x, y) = (float)(k + (x * 3 + y * 5) % 5 - 2) / 16.0f;
            mask[y * w + x] = !((x >= 11 && y <= 4) || (x + y) % 9 == 0);
        }
    obs_metrics m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_metrics_compute(&a, &b, NULL, &m, err), OBS_OK);
    assert_near(m.ssim, 0.9621828473209286, 1e-12);
    assert_int_equal(obs_metrics_compute(&a, &b, mask, &m, err), OBS_OK);
    assert_int_equal(m.count, 205);
    assert_near(m.ssim, 0.9700106416023272, 1e-12);
    obs_image_free(&a);
    obs_image_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_identical),
        cmocka_unit_test(test_constant_offset),
        cmocka_unit_test(test_ssim_flat),
        cmocka_unit_test(test_correlation_sign),
        cmocka_unit_test(test_noise),
        cmocka_unit_test(test_mask),
        cmocka_unit_test(test_clamp),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_diff_image),
        cmocka_unit_test(test_ssim_matches_aometrics),
    };
    return cmocka_run_group_tests_name("metrics", tests, NULL, NULL);
}
