/* Multi-bounce AO (Jimenez et al. 2016, eq 10; core/chain/multibounce.c):
 * the fit against its published coefficients at albedo 0, 0.5 and 1, the
 * result's image and composite on the CPU device and through GL, and no
 * colour plane (no image, a warning). */
#include <math.h>

#include "gl_testutil.h"

#include "chain/multibounce.h"
#include "obscura/io.h"

/* The fit's published coefficients (the paper's eq 10, XeGTAO's and
 * HDRP's constants), worked out by hand at three albedos:
 *
 *   rho   a = 2.0404 rho - 0.3324   b = -4.7951 rho + 0.6417   c = 2.7552 rho + 0.6903
 *   0     -0.3324                    0.6417                      0.6903
 *   0.5    0.6878                   -1.75585                     2.0679
 *   1      1.7080                   -4.1534                      3.4455
 *
 * and A' = max(A, a A^3 + b A^2 + c A), e.g. rho 0.5, A 0.5:
 * 0.6878/8 - 1.75585/4 + 2.0679/2 = 0.085975 - 0.4389625 + 1.03395 = 0.6809625. */
static void test_published_fit(void **state)
{
    static const float coef[3][4] = {
        {0.0f, -0.3324f, 0.6417f, 0.6903f},
        {0.5f, 0.6878f, -1.75585f, 2.0679f},
        {1.0f, 1.7080f, -4.1534f, 3.4455f},
    };
    /* by hand from the table: (rho, A, A') */
    static const float hand[][3] = {
        {0.0f, 0.25f, 0.25f},      /* cubic 0.20750 < A */
        {0.0f, 0.75f, 0.75f},      /* cubic 0.73846 < A */
        {0.0f, 1.0f, 1.0f},        /* cubic 0.9996 < A */
        {0.5f, 0.5f, 0.6809625f},  /* worked above */
        {0.5f, 1.0f, 1.0f},        /* cubic 0.99985 */
        {1.0f, 0.5f, 0.8979f},     /* 1.708/8 - 4.1534/4 + 3.4455/2 = 0.2135 - 1.03835 + 1.72275 */
        {1.0f, 1.0f, 1.0001f},     /* cubic 1.0001 */
    };
    (void)state;
    for (int r = 0; r < 3; r++)
        for (int k = 0; k <= 4; k++) {
            float A = 0.25f * k, rho[3] = {coef[r][0], coef[r][0], coef[r][0]}, out[3];
            float cubic = ((coef[r][1] * A + coef[r][2]) * A + coef[r][3]) * A;
            float want = cubic > A ? cubic : A;
            obs__multibounce(A, rho, out);
            print_message("rho %.1f A %.2f: %.6f (published coefficients %.6f)\n", coef[r][0], A,
                          out[0], want);
            assert_float_equal(out[0], want, 2e-6f);
            assert_float_equal(out[1], out[0], 0.0f);
            assert_float_equal(out[2], out[0], 0.0f);
        }
    for (size_t h = 0; h < sizeof hand / sizeof hand[0]; h++) {
        float rho[3] = {hand[h][0], hand[h][0], hand[h][0]}, out[3];
        obs__multibounce(hand[h][1], rho, out);
        assert_float_equal(out[0], hand[h][2], 2e-6f);
    }
    /* rho 0 never brightens above the AO in (0, 1) except by rounding at
     * 1; rho 1 brightens every A in (0, 1); f(1) = 1 within the fit's
     * rounding of its coefficients (the sums above) */
    for (int k = 1; k < 20; k++) {
        float A = k / 20.0f, lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, o0[3], o1[3];
        obs__multibounce(A, lo, o0);
        obs__multibounce(A, hi, o1);
        assert_true(o0[0] >= A && o0[0] < A + 0.02f);
        assert_true(o1[0] > A + 0.01f && o1[0] <= 1.0005f);
    }
    /* per channel: a red albedo brightens red alone */
    float red[3] = {0.9f, 0.0f, 0.0f}, o[3];
    obs__multibounce(0.5f, red, o);
    assert_true(o[0] > 0.6f && o[1] == 0.5f && o[2] == 0.5f);
}

static void run(obs_ctx *ctx, const obs_gbuffer *gb, const char *mb, unsigned out, obs_result *r)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(&p, "multibounce", mb, err), OBS_OK);
    obs_status s = ctx ? obs_run(ctx, gb, &p, out, r, err) : obs_run_cpu(gb, &p, out, r, err);
    if (s != OBS_OK)
        fail_msg("run: %s", err);
}

/* On room_small (its beauty as the albedo): the image is the fit of the
 * AO and the colour, pixel by pixel, on the CPU device; the composite is
 * the colour times it; GL's composite and image match the CPU's; with
 * multibounce off and only AO asked there is no image; the image alone
 * (OBS_OUTPUT_MULTIBOUNCE) needs no AO in the result. */
static void test_result_and_twin(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    obs_gbuffer_file gf = {0};
    obs_result cpu, gl, off, alone;
    unsigned out = OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE;
    (void)state;
    load(scenes[0], &gf);
    const obs_gbuffer *gb = &gf.gb;
    run(NULL, gb, "on", out, &cpu);
    run(ctx, gb, "on", out, &gl);
    run(NULL, gb, "off", out, &off);
    run(NULL, gb, "off", OBS_OUTPUT_MULTIBOUNCE, &alone);
    assert_null(off.multibounce.data);
    assert_non_null(cpu.multibounce.data);
    assert_null(alone.ao.data);
    assert_non_null(alone.multibounce.data);
    size_t n = (size_t)cpu.ao.width * cpu.ao.height, brighter = 0;
    double worst = 0.0, worst_c = 0.0;
    for (size_t i = 0; i < n; i++) {
        int x = (int)(i % cpu.ao.width), y = (int)(i / cpu.ao.width);
        const float *c = obs__plane_px(&gb->color, gb->width, x, y);
        float rho[3], m[3];
        for (int k = 0; k < 3; k++)
            rho[k] = fminf(fmaxf(c[k], 0.0f), 1.0f);
        obs__multibounce(cpu.ao.data[i], rho, m);
        for (int k = 0; k < 3; k++) {
            worst = fmax(worst, fabs(m[k] - cpu.multibounce.data[3 * i + k]));
            worst_c = fmax(worst_c, fabs(c[k] * m[k] - cpu.composite.data[4 * i + k]));
            assert_true(cpu.multibounce.data[3 * i + k] >= cpu.ao.data[i]);
            assert_true(alone.multibounce.data[3 * i + k] == cpu.multibounce.data[3 * i + k]);
        }
        brighter += cpu.multibounce.data[3 * i + 1] > cpu.ao.data[i] + 1e-3f;
        /* multibounce off: the composite is the colour times the AO */
        assert_float_equal(off.composite.data[4 * i], c[0] * off.ao.data[i], 1e-6f);
    }
    double mean, frac, cmean, cfrac;
    diff(&gl.multibounce, &cpu.multibounce, &mean, &frac);
    diff(&gl.composite, &cpu.composite, &cmean, &cfrac);
    print_message("room_small: multi-bounce brighter than the AO at %.1f %% of pixels; worst "
                  "|image - fit| %.2e, |composite - colour x fit| %.2e; GL vs CPU: image mean "
                  "%.2e (%.3f %% > 1e-3), composite mean %.2e\n",
                  100.0 * brighter / n, worst, worst_c, mean, 100 * frac, cmean);
    assert_true(brighter > n / 50);
    assert_true(worst < 1e-6);
    assert_true(worst_c < 1e-6);
    /* the bounds of test_gl_twin.c: the AO itself may differ at border
     * rounding */
    assert_true(mean < 1e-3 && frac < 0.02);
    assert_true(cmean < 1e-3);
    obs_result_free(&cpu);
    obs_result_free(&gl);
    obs_result_free(&off);
    obs_result_free(&alone);
    obs_gbuffer_free(&gf);
    obs_ctx_destroy(ctx);
}

/* No colour plane: no image, the AO as without the fit, and
 * obs_result_sanity's warning naming the parameter. */
static void test_no_colour(void **state)
{
    obs_gbuffer_file gf = {0};
    obs_result on, off;
    obs_exr_info info = {0};
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    (void)state;
    load(scenes[0], &gf);
    obs_gbuffer g = gf.gb;
    g.color.data = NULL;
    run(NULL, &g, "on", OBS_OUTPUT_AO | OBS_OUTPUT_MULTIBOUNCE, &on);
    run(NULL, &g, "off", OBS_OUTPUT_AO, &off);
    assert_null(on.multibounce.data);
    assert_memory_equal(on.ao.data, off.ao.data, sizeof(float) * g.width * g.height);
    assert_int_equal(obs_param_set(&p, "multibounce", "on", err), OBS_OK);
    int added = obs_result_sanity(&on.ao, &g, NULL, &p, &info);
    assert_true(added >= 1);
    int found = 0;
    for (int i = 0; i < info.warning_count; i++)
        found |= strstr(info.warnings[i], "multibounce on needs a colour plane") != NULL;
    assert_true(found);
    obs_result_free(&on);
    obs_result_free(&off);
    obs_gbuffer_free(&gf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_published_fit),
        cmocka_unit_test(test_result_and_twin),
        cmocka_unit_test(test_no_colour),
    };
    return cmocka_run_group_tests_name("multibounce", tests, NULL, NULL);
}
