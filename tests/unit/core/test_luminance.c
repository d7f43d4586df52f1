/* Luminance sensitivity (VAO++ section 4.3, eq 3): eq 3 against a table
 * computed by hand, a bright pixel losing its occlusion on a synthetic
 * G-buffer, no colour plane, and the GL pass against its CPU twin on real
 * input. */
#include <math.h>

#include "gl_testutil.h"

#include "chain/frame.h"
#include "obscura/io.h"
#include "synth_corner.h"

/* Eq 3: AO_L = AO (1 - min(1, max(0, lum - threshold + width)) / (2 width))^sigma,
 * AO there the occlusion; ours is 1 - occlusion, so out = 1 - (1 - ao) * factor.
 * Every row below has ao = 0.4 (occlusion 0.6), worked by hand:
 *
 *  mode  colour          lum     thr  width sigma  max(0,lum-thr+w)  min(1,.)/(2w)   base     factor     out
 *  value 0.1 grey        0.1     0.5  0.3   1      0 (-0.1)          0               1        1          0.4
 *  value 0.5 grey        0.5     0.5  0.3   1      0.3               0.3/0.6 = 0.5   0.5      0.5        1-0.6*0.5   = 0.7
 *  value 0.5 grey        0.5     0.5  0.3   2      0.3               0.5             0.5      0.25       1-0.6*0.25  = 0.85
 *  value 0.65 grey       0.65    0.5  0.3   1      0.45              0.75            0.25     0.25       0.85
 *  value 0.65 grey       0.65    0.5  0.3   0.5    0.45              0.75            0.25     0.5        0.7
 *  value 0.9 grey        0.9     0.5  0.3   1      0.7               0.7/0.6 = 1.167 -0.167   0 (clamp)  1
 *  value 2.0 grey        2.0     0.5  0.8   1      2.3 -> min 1      1/1.6 = 0.625   0.375    0.375      1-0.6*0.375 = 0.775
 *  value 0.25 grey       0.25    0.2  0.1   3      0.15              0.15/0.2 = 0.75 0.25     0.015625   1-0.6*0.015625 = 0.990625
 *  lum   (1, 0, 0)       0.2126  0.5  0.3   1      0.0126            0.021           0.979    0.979      1-0.6*0.979 = 0.4126
 *  value (1, 0, 0)       1       0.5  0.3   1      0.8               1.333           -0.333   0          1
 *  lum   (0.2, 0.9, 0.4) 0.71508 0.5  0.3   1      0.51508           0.858467        0.141533 0.141533   1-0.6*0.141533 = 0.915080
 *
 * (Rec. 709: 0.2126*0.2 + 0.7152*0.9 + 0.0722*0.4 = 0.04252 + 0.64368 + 0.02888 = 0.71508.)
 *
 * The row with width 0.8 shows the printed form's min(1, .) acting before
 * the division: with 2 width > 1 the occlusion never vanishes entirely. */
static void test_eq3_table(void **state)
{
    static const struct {
        int mode; /* 1 lum, 2 value */
        float rgb[3], thr, width, sigma, out;
    } rows[] = {
        {2, {0.1f, 0.1f, 0.1f}, 0.5f, 0.3f, 1.0f, 0.4f},
        {2, {0.5f, 0.5f, 0.5f}, 0.5f, 0.3f, 1.0f, 0.7f},
        {2, {0.5f, 0.5f, 0.5f}, 0.5f, 0.3f, 2.0f, 0.85f},
        {2, {0.65f, 0.65f, 0.65f}, 0.5f, 0.3f, 1.0f, 0.85f},
        {2, {0.65f, 0.65f, 0.65f}, 0.5f, 0.3f, 0.5f, 0.7f},
        {2, {0.9f, 0.9f, 0.9f}, 0.5f, 0.3f, 1.0f, 1.0f},
        {2, {2.0f, 2.0f, 2.0f}, 0.5f, 0.8f, 1.0f, 0.775f},
        {2, {0.25f, 0.25f, 0.25f}, 0.2f, 0.1f, 3.0f, 0.990625f},
        {1, {1.0f, 0.0f, 0.0f}, 0.5f, 0.3f, 1.0f, 0.4126f},
        {2, {1.0f, 0.0f, 0.0f}, 0.5f, 0.3f, 1.0f, 1.0f},
        {1, {0.2f, 0.9f, 0.4f}, 0.5f, 0.3f, 1.0f, 0.915080f},
    };
    (void)state;
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        obs__frame f = {0};
        f.luminance = rows[i].mode;
        f.lum_threshold = rows[i].thr;
        f.lum_width = rows[i].width;
        f.lum_sigma = rows[i].sigma;
        float got = obs__luminance_ao(&f, 0.4f, rows[i].rgb);
        print_message("eq 3 row %zu: %.6f (hand %.6f)\n", i, got, rows[i].out);
        assert_float_equal(got, rows[i].out, 2e-5f);
    }
}

static void run(const obs_gbuffer *gb, const char *mode, obs_result *r)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(&p, "normal_space", "camera", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "luminance", mode, err), OBS_OK);
    if (obs_run_cpu(gb, &p, OBS_OUTPUT_AO, r, err) != OBS_OK)
        fail_msg("obs_run_cpu: %s", err);
}

/* The floor-wall crease in three vertical stripes of grey: 0.2 (below
 * threshold - width: untouched), 0.5 (the threshold: occlusion halved,
 * sigma 1), 1.0 (above threshold + width: no occlusion). */
static void test_bright_pixel_less_occlusion(void **state)
{
    static sc_scene s;
    obs_result off, on, nocol;
    (void)state;
    sc_render(&s);
    for (int y = 0; y < SC_H; y++)
        for (int x = 0; x < SC_W; x++) {
            float g = x < SC_W / 3 ? 0.2f : x < 2 * SC_W / 3 ? 0.5f : 1.0f;
            for (int k = 0; k < 3; k++)
                s.color[4 * (y * SC_W + x) + k] = g;
        }
    run(&s.gb, "off", &off);
    run(&s.gb, "lum", &on);
    double occ[3] = {0, 0, 0};
    for (int y = 0; y < SC_H; y++)
        for (int x = 0; x < SC_W; x++) {
            size_t i = (size_t)y * SC_W + x;
            int stripe = x < SC_W / 3 ? 0 : x < 2 * SC_W / 3 ? 1 : 2;
            float a = off.ao.data[i], b = on.ao.data[i];
            occ[stripe] += 1.0 - a;
            if (stripe == 0)
                assert_float_equal(b, a, 1e-6f);
            else if (stripe == 1)
                assert_float_equal(1.0f - b, 0.5f * (1.0f - a), 1e-6f);
            else
                assert_true(b == 1.0f);
        }
    /* the crease is occluded in every stripe without the correction */
    print_message("occlusion summed per stripe, luminance off: %.1f %.1f %.1f\n", occ[0], occ[1],
                  occ[2]);
    for (int k = 0; k < 3; k++)
        assert_true(occ[k] > 10.0);

    /* no colour plane: luminance sensitivity is off */
    obs_gbuffer g = s.gb;
    g.color.data = NULL;
    run(&g, "lum", &nocol);
    assert_memory_equal(nocol.ao.data, off.ao.data, sizeof(float) * SC_W * SC_H);
    obs_result_free(&off);
    obs_result_free(&on);
    obs_result_free(&nocol);
}

/* The debug output (OBS_OUTPUT_LUMINANCE) on real input: the factor of
 * eq 3 per pixel, from the GL pass and from the CPU twin; it explains the
 * whole change of the AO, ao_on = 1 - (1 - ao_off) * factor, pixel by
 * pixel; it is 1 everywhere when the term is off. */
static void test_debug_output(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    obs_gbuffer_file gf = {0};
    obs_result off, on, cpu;
    char err[OBS_ERR_LEN] = "";
    unsigned out = OBS_OUTPUT_AO | OBS_OUTPUT_LUMINANCE;
    (void)state;
    load(scenes[0], &gf);
    obs_params p = {0};
    assert_int_equal(obs_run(ctx, &gf.gb, &p, out, &off, err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "luminance", "lum", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "lum_threshold", "0.8", err), OBS_OK);
    assert_int_equal(obs_run(ctx, &gf.gb, &p, out, &on, err), OBS_OK);
    assert_int_equal(obs_run_cpu(&gf.gb, &p, out, &cpu, err), OBS_OK);
    size_t n = (size_t)off.ao.width * off.ao.height, partial = 0, changed = 0;
    double worst = 0.0;
    for (size_t i = 0; i < n; i++) {
        float k = on.luminance.data[i];
        assert_true(off.luminance.data[i] == 1.0f);
        assert_true(k >= 0.0f && k <= 1.0f);
        partial += k > 0.01f && k < 0.99f;
        changed += on.ao.data[i] != off.ao.data[i];
        double want = 1.0 - (1.0 - off.ao.data[i]) * k;
        worst = fmax(worst, fabs(want - on.ao.data[i]));
    }
    double mean, frac;
    diff(&on.luminance, &cpu.luminance, &mean, &frac);
    print_message("room_small, threshold 0.8: factor strictly between 0 and 1 at %.1f %% of "
                  "pixels, AO changed at %.1f %%; worst |ao_on - (1 - (1 - ao_off) k)| %.2e; "
                  "GL vs CPU factor: mean |diff| %.2e\n",
                  100.0 * partial / n, 100.0 * changed / n, worst, mean);
    assert_true(partial > n / 20); /* the term does act on this scene */
    assert_true(changed > n / 20);
    assert_true(worst < 1e-5);
    assert_true(mean < 1e-6);
    obs_result_free(&off);
    obs_result_free(&on);
    obs_result_free(&cpu);
    obs_gbuffer_free(&gf);
    obs_ctx_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_eq3_table),
        cmocka_unit_test(test_bright_pixel_less_occlusion),
        cmocka_unit_test(test_debug_output),
    };
    return cmocka_run_group_tests_name("luminance", tests, NULL, NULL);
}
