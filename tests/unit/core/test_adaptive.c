/* Adaptive sampling (VAO++ section 4.1): the per-pixel sample count
 * follows the projected area of the tangent sphere's disk, 2 samples at
 * the diameter adaptive_diameter, doubling with each doubling of the
 * area, capped at the samples parameter.  Pixels near the camera keep the
 * full count and so the fixed-count AO; far pixels take fewer samples. */
#include <math.h>

#include "testutil.h"

#include "methods/methods.h"
#include "obscura/io.h"

#define W 64
#define H 48

/* A frame of W x H pixels with the projection P (NULL: fov_y 50). */
static void setup(obs__frame *f, const float *P, const obs_params *in)
{
    static float depth[W * H];
    obs_gbuffer gb = {0};
    obs_params p;
    char err[OBS_ERR_LEN] = "";
    for (int i = 0; i < W * H; i++)
        depth[i] = 5.0f;
    gb.width = W;
    gb.height = H;
    gb.depth = (obs_plane){depth, 1, 0};
    obs_params_resolve(in, &p);
    if (P) {
        memcpy(gb.camera.projection, P, sizeof gb.camera.projection);
        gb.camera.has_projection = 1;
    } else {
        p.fov_y = 50.0f;
    }
    if (obs__frame_setup(NULL, &gb, &p, f, err) != OBS_OK)
        fail_msg("frame setup: %s", err);
}

/* Perspective: the disk of radius r at view depth z has the relative
 * diameter D = r P11 / z (square pixels); the count doubles at each
 * doubling of (D / D0)^2, the same anywhere on the image plane. */
static void test_count_perspective(void **state)
{
    obs__frame f;
    obs_params in = {0};
    (void)state;
    setup(&f, NULL, &in);
    const float r = 0.5f * f.radius, D0 = 0.01f; /* the defaults */
    assert_true(f.adaptive);
    assert_int_equal(f.samples, 16);
    /* area ratio q -> count: 2 below 2, then doubling, capped at 16 */
    static const struct {
        float q;
        int n;
    } cases[] = {{0.01f, 2}, {1.0f, 2}, {1.9f, 2}, {2.1f, 4}, {3.9f, 4}, {4.1f, 8},
                 {7.9f, 8},  {8.1f, 16}, {15.9f, 16}, {16.1f, 16}, {1e4f, 16}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        /* z at which (r P11 / z)^2 / D0^2 = q */
        float z = r * f.proj[5] / (D0 * sqrtf(cases[k].q));
        for (int j = 0; j < 3; j++) {
            /* on the axis and off it: a perspective disk at fixed depth
             * has the same screen area everywhere */
            const float c[3] = {0.3f * (float)j * z, -0.2f * (float)j * z, -z};
            assert_int_equal(obs__adaptive_count(&f, c), cases[k].n);
        }
    }
    /* 32 at 4 D0 (area 16 A0) when the parameter allows 32 */
    obs_params p32 = {0};
    p32.samples = 32;
    setup(&f, NULL, &p32);
    const float c4[3] = {0, 0, -r * f.proj[5] / (D0 * 4.01f)};
    const float c3[3] = {0, 0, -r * f.proj[5] / (D0 * 3.99f)};
    assert_int_equal(obs__adaptive_count(&f, c4), 32);
    assert_int_equal(obs__adaptive_count(&f, c3), 16);
    /* a larger adaptive_diameter needs a nearer disk for the same count */
    obs_params big = {0};
    big.adaptive_diameter = 0.04f;
    setup(&f, NULL, &big);
    assert_int_equal(obs__adaptive_count(&f, c4), 2);
    /* a centre behind the camera takes the maximum */
    const float behind[3] = {0, 0, 1.0f};
    assert_int_equal(obs__adaptive_count(&f, behind), 16);
}

/* Orthographic: the disk's screen size does not change with depth, so
 * neither does the count. */
static void test_count_ortho(void **state)
{
    obs__frame f;
    obs_params in = {0};
    (void)state;
    /* half-width 40, half-height 30 world units: a disk of diameter 0.5
     * spans 0.5 / 60 of the height, q = (0.5/60 / 0.01)^2 = 0.69 -> 2 */
    const float P[16] = {1.0f / 40, 0, 0, 0, 0, 1.0f / 30, 0, 0, 0, 0, -0.02f, -1, 0, 0, 0, 1};
    /* a disk of diameter R = 0.5: radius is the AO distance D, and the
     * volume definition's kernel width is R = D (frame.h) */
    in.radius = 0.5f;
    in.ao_definition = OBS_AO_VOLUME;
    setup(&f, P, &in);
    for (float z = 1.0f; z < 100.0f; z *= 3.0f) {
        const float c[3] = {1, 2, -z};
        assert_int_equal(obs__adaptive_count(&f, c), 2);
    }
    /* a narrower view: 0.5 / 6 of the height, q = 69 -> the maximum */
    const float Q[16] = {1.0f / 4, 0, 0, 0, 0, 1.0f / 3, 0, 0, 0, 0, -0.02f, -1, 0, 0, 0, 1};
    setup(&f, Q, &in);
    for (float z = 1.0f; z < 100.0f; z *= 3.0f) {
        const float c[3] = {1, 2, -z};
        assert_int_equal(obs__adaptive_count(&f, c), 16);
    }
}

static void load(const char *exr, const char *camera, obs_gbuffer_file *gf)
{
    char err[OBS_ERR_LEN] = "";
    if (obs_gbuffer_read_exr(exr, NULL, NULL, gf, err) != OBS_OK ||
        obs_camera_read_json(camera, &gf->gb.camera, NULL, NULL, err) != OBS_OK)
        fail_msg("%s: %s", exr, err);
}

/* On a real frame (CPU twin, blur off so that each pixel is its own):
 * every pixel whose disk is surely at least the diameter of the maximum
 * count (judged from its depth alone, the sphere centre lying within r of
 * the surface) takes the full count and gives the fixed-count AO; every
 * pixel whose disk is surely smaller takes fewer samples. */
static double check_scene(const char *exr, const char *camera, int samples, float diameter)
{
    obs_gbuffer_file gf = {0};
    obs_result fixed, adapt;
    obs_params p = {0}, rp;
    obs__frame f;
    char err[OBS_ERR_LEN] = "";
    load(exr, camera, &gf);
    p.samples = samples;
    p.adaptive_diameter = diameter;
    /* the kernel width R = 0.5 these expectations were built for: radius
     * is the AO distance D, and the volume definition's R = D (frame.h);
     * the bounds below (fractions surely far) were set for it */
    p.radius = 0.5f;
    p.ao_definition = OBS_AO_VOLUME;
    p.blur = OBS_OFF;
    p.culling = OBS_CULLING_OFF; /* 4.2 would cap culled pixels at 4 samples */
    p.adaptive = OBS_OFF;
    unsigned out = OBS_OUTPUT_AO | OBS_OUTPUT_SAMPLE_COUNT;
    assert_int_equal(obs_run_cpu(&gf.gb, &p, out, &fixed, err), OBS_OK);
    p.adaptive = OBS_ON;
    assert_int_equal(obs_run_cpu(&gf.gb, &p, out, &adapt, err), OBS_OK);
    obs_params_resolve(&p, &rp);
    assert_int_equal(obs__frame_setup(NULL, &gf.gb, &rp, &f, err), OBS_OK);

    const float r = 0.5f * f.radius, D0 = rp.adaptive_diameter;
    /* D^2 z^2 of a perspective disk: r^2 P00 P11 vw / vh */
    const double k = (double)r * r * f.proj[0] * f.proj[5] * f.viewport[2] / f.viewport[3];
    const double qmax = samples / 2; /* area ratio of the maximum count */
    long geo = 0, near = 0, far = 0, full = 0, hist[6] = {0};
    double max_diff = 0, sum_diff = 0;
    for (int y = 0; y < gf.gb.height; y++)
        for (int x = 0; x < gf.gb.width; x++) {
            size_t i = (size_t)y * gf.gb.width + x;
            float d = *obs__plane_px(&gf.gb.depth, gf.gb.width, x, y);
            int n = (int)adapt.sample_count.data[i];
            if (!(d > 0.0f) || d >= OBS_BACKGROUND_DEPTH) {
                assert_int_equal(n, 0);
                continue;
            }
            geo++;
            assert_int_equal((int)fixed.sample_count.data[i], samples);
            assert_true(n >= 2 && n <= samples && (n & (n - 1)) == 0);
            for (int b = 0; b < 6; b++)
                hist[b] += n == 1 << (b + 1);
            double diff = fabs((double)adapt.ao.data[i] - fixed.ao.data[i]);
            sum_diff += diff;
            if (n == samples) { /* the same set as the fixed count */
                full++;
                max_diff = fmax(max_diff, diff);
            }
            double zfar = d + r, znear = d - r;
            if (k / (zfar * zfar) / ((double)D0 * D0) >= qmax * 1.001) {
                near++;
                assert_int_equal(n, samples);
                assert_true(diff <= 1e-6);
            } else if (znear > 0 && k / (znear * znear) / ((double)D0 * D0) < qmax * 0.999) {
                far++;
                assert_true(n < samples);
            }
        }
    print_message("%s, samples %d, diameter %g: %ld geometry px: %.1f %% surely near (full count), %.1f %% "
                  "surely far (fewer); counts 2/4/8/16/32: %ld/%ld/%ld/%ld/%ld; mean samples %.2f "
                  "of %d; full-count px max |AO - fixed| %.1e; mean over all %.2e\n",
                  exr, samples, D0, geo, 100.0 * near / geo, 100.0 * far / geo, hist[0], hist[1],
                  hist[2], hist[3], hist[4],
                  (2.0 * hist[0] + 4.0 * hist[1] + 8.0 * hist[2] + 16.0 * hist[3] + 32.0 * hist[4]) /
                      geo,
                  samples, max_diff, sum_diff / geo);
    assert_true(max_diff <= 1e-6);
    assert_true(near > 0);
    obs_result_free(&fixed);
    obs_result_free(&adapt);
    obs_gbuffer_free(&gf);
    return (double)far / geo;
}

static void test_real_scenes(void **state)
{
    (void)state;
    /* the defaults: the room is near throughout, the yard's far end
     * takes fewer samples when 32 are allowed */
    check_scene(TESTDATA "/room_small.exr", TESTDATA "/room_small.camera.json", 16, 0.01f);
    assert_true(check_scene(TESTDATA "/yard_small.exr", TESTDATA "/yard_small.camera.json", 32,
                            0.01f) > 0.01);
    /* a larger diameter: a good part of the room takes fewer */
    assert_true(check_scene(TESTDATA "/room_small.exr", TESTDATA "/room_small.camera.json", 32,
                            0.04f) > 0.2);
    char exr[512], cam[512];
    snprintf(exr, sizeof exr, "%s/blender/yard.exr", obs_test_shared());
    snprintf(cam, sizeof cam, "%s/blender/yard.camera.json", obs_test_shared());
    if (obs_test_exists(exr) && obs_test_exists(cam))
        assert_true(check_scene(exr, cam, 16, 0.01f) > 0.005);
    else
        print_message("shared yard scene absent: skipped\n");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_count_perspective),
        cmocka_unit_test(test_count_ortho),
        cmocka_unit_test(test_real_scenes),
    };
    return cmocka_run_group_tests_name("adaptive", tests, NULL, NULL);
}
