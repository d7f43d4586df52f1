/* The CPU device's vectorised kernels against the scalar twins they
 * stand for: the low-pass filter (VAO++ 4.6) in SIMD lanes
 * (obs__blur_dnz, obs__blur) against obs__blur_pixel pixel by pixel, bit
 * for bit, on a synthetic frame with background, depth edges and odd
 * sizes (the rows' scalar ends), at several filter radii, with and
 * without ao_definition rays' conversion in its vertical sweep; the VAO
 * estimator's samples in SIMD lanes (obs__vao_estimate_dnz) against the
 * twin's obs__vao_estimate at every pixel of room_small, bit for bit, for
 * every sample set and the depth range check's forms. */
#include <math.h>

#include "testutil.h"
#include "chain/frame.h"
#include "chain/passes.h"
#include "chain/prep_cpu.h"
#include "chain/vao_cpu.h"
#include "methods/methods.h"
#include "obscura/io.h"

enum { W = 301, H = 77 };

/* ao_definition rays' conversion in lanes against the twin (test_rays_rows) */
#define RAYS_TOL 1e-6f

/* Depths in steps (edges over the threshold), holes of background. */
static void scene(float *pos, float *dnz, float *ao)
{
    unsigned s = 12345u;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + x;
            s = s * 1103515245u + 12345u;
            float d = 2.0f + (float)((x / 17 + y / 11) % 4) * 0.7f + (float)(s >> 16) * 1e-6f;
            if ((x * 7 + y * 3) % 23 == 0)
                d = 0.0f; /* background */
            pos[4 * i] = (float)x * 0.01f;
            pos[4 * i + 1] = (float)y * 0.01f;
            pos[4 * i + 2] = -d;
            pos[4 * i + 3] = d;
            dnz[2 * i] = d;
            dnz[2 * i + 1] = 1.0f;
            ao[i] = (float)((s >> 8) & 0xffff) / 65535.0f;
        }
}

static void test_blur_bit_for_bit(void **state)
{
    static float pos[4 * W * H], dnz[2 * W * H], ao[W * H], a1[W * H], a2[W * H], a3[W * H],
        ref[W * H], tmp[W * H];
    (void)state;
    scene(pos, dnz, ao);
    for (int radius = 1; radius <= 7; radius += 3) {
        obs__frame f;
        memset(&f, 0, sizeof f);
        f.width = W;
        f.height = H;
        f.radius = 0.5f;
        f.blur_radius = radius;
        for (int k = 0; k <= radius; k++)
            f.blur_w[k] = expf(-0.5f * (float)(k * k) / 2.0f);
        /* the scalar twin, pixel by pixel */
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                tmp[y * W + x] = obs__blur_pixel(&f, pos, ao, x, y, 1, 0);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                ref[y * W + x] = obs__blur_pixel(&f, pos, tmp, x, y, 0, 1);
        memcpy(a1, ao, sizeof ao);
        memcpy(a2, ao, sizeof ao);
        memmove(a1, obs__blur_dnz(&f, pos, dnz, a1, tmp, 0), sizeof a1); /* the fused bands */
        obs__blur(&f, pos, a2, tmp);
        memcpy(a3, ao, sizeof ao);
        /* ao_definition rays in the vertical sweep */
        memmove(a3, obs__blur_dnz(&f, pos, dnz, a3, tmp, 1), sizeof a3);
        for (int i = 0; i < W * H; i++) {
            float rays = obs__rays_from_volume(ref[i]);
            if (!(fabsf(a3[i] - rays) <= RAYS_TOL)) /* the lanes' conversion, test_rays_rows */
                fail_msg("radius %d, rays, pixel (%d, %d): %.9g, the twin %.9g", radius, i % W,
                         i / W, a3[i], rays);
            if (memcmp(&a1[i], &ref[i], sizeof(float)) || memcmp(&a2[i], &ref[i], sizeof(float)))
                fail_msg("radius %d, pixel (%d, %d): %.9g and %.9g, the twin %.9g", radius, i % W,
                         i / W, a1[i], a2[i], ref[i]);
        }
    }
}

/* room_small's prep planes by the twins, and the packed plane. */
static void room_planes(obs__plan *pl, obs_gbuffer_file *gf, const char *const *set, float **pos,
                        float **nrm, float **dnz)
{
    char err[OBS_ERR_LEN] = "";
    obs_params p = {0};
    if (obs_gbuffer_read_exr(TESTDATA "/room_small.exr", NULL, NULL, gf, err) != OBS_OK ||
        obs_camera_read_json(TESTDATA "/room_small.camera.json", &gf->gb.camera, NULL, NULL,
                             err) != OBS_OK)
        fail_msg("room_small: %s", err);
    for (int k = 0; set[k]; k += 2)
        assert_int_equal(obs_param_set(&p, set[k], set[k + 1], err), OBS_OK);
    if (obs__plan_init(pl, NULL, &gf->gb, &p, OBS_OUTPUT_AO, err) != OBS_OK)
        fail_msg("%s", err);
    const obs__frame *f = &pl->f;
    const size_t n = (size_t)f->width * (size_t)f->height;
    *pos = malloc(n * 4 * sizeof(float));
    *nrm = malloc(n * 3 * sizeof(float));
    *dnz = malloc(n * 2 * sizeof(float));
    assert_true(*pos && *nrm && *dnz);
    for (int y = 0; y < f->height; y++)
        for (int x = 0; x < f->width; x++)
            obs__prep_position(f, *obs__plane_px(&gf->gb.depth, f->width, x, y), x, y,
                               *pos + 4 * ((size_t)y * f->width + x));
    for (size_t i = 0; i < n; i++) {
        int x = (int)(i % (size_t)f->width), y = (int)(i / (size_t)f->width);
        obs__prep_normal(f, *pos, obs__plane_px(&gf->gb.normal, f->width, x, y), x, y,
                         *nrm + 3 * i);
        (*dnz)[2 * i] = (*pos)[4 * i + 3];
        (*dnz)[2 * i + 1] = (*nrm)[3 * i + 2];
    }
}

static void free_planes(obs_gbuffer_file *gf, float *pos, float *nrm, float *dnz)
{
    free(pos);
    free(nrm);
    free(dnz);
    obs_gbuffer_free(gf);
}

/* The pixels with geometry, in an order of their own: a stride of 7919 (a
 * prime) through the frame, so chunks of lanes mix rows and the border;
 * returns how many. */
static int stride_list(const obs__frame *f, const float *pos, int *px)
{
    const size_t npx = (size_t)f->width * (size_t)f->height;
    int m = 0;
    for (size_t k = 0, i = 0; k < npx; k++, i = (i + 7919) % npx)
        if (pos[4 * i + 3] > 0.0f)
            px[m++] = (int)i;
    return m;
}

static void test_vao_bit_for_bit(void **state)
{
    static const char *const sets[][5] = {
        {"range_check", "on", NULL},
        {"range_check", "off", NULL},
        {"range_distance", "normal", NULL},
    };
    (void)state;
    for (size_t s = 0; s < sizeof sets / sizeof sets[0]; s++) {
        obs__plan pl;
        obs_gbuffer_file gf = {0};
        float *pos, *nrm, *dnz;
        room_planes(&pl, &gf, sets[s], &pos, &nrm, &dnz);
        const obs__frame *f = &pl.f;
        long compared = 0;
        for (int ns = 2; ns <= 32; ns *= 2) {
            const float *xy = f->sample_table + 2 * (ns - 2);
            for (int y = 0; y < f->height; y++)
                for (int x = 0; x < f->width; x++) {
                    size_t i = (size_t)y * f->width + x;
                    if (!(pos[4 * i + 3] > 0.0f))
                        continue;
                    float bleed[3];
                    float a = obs__vao_estimate_dnz(f, pos, nrm, dnz, NULL, x, y, pos + 4 * i,
                                                    nrm + 3 * i, ns, xy, bleed);
                    float b = obs__vao_estimate(f, pos, nrm, x, y, pos + 4 * i, nrm + 3 * i, ns,
                                                xy);
                    if (memcmp(&a, &b, sizeof a))
                        fail_msg("%s %s, %d samples, pixel (%d, %d): %.9g, the twin %.9g",
                                 sets[s][0], sets[s][1], ns, x, y, a, b);
                    compared++;
                }
        }
        assert_true(compared > 1000);
        free_planes(&gf, pos, nrm, dnz);
    }
}

/* A tile's pixels in lanes over the sample set (obs__vao_estimate_pixels)
 * and their counts in lanes (obs__vao_counts): the twin's results bit for
 * bit, for every set size, on lists of pixels in an order of their own (a
 * stride through the frame, so chunks mix rows and the image's border)
 * and of lengths that leave a partial chunk. */
static void test_vao_pixels_bit_for_bit(void **state)
{
    static const char *const sets[][5] = {
        {"range_check", "on", NULL},
        {"range_check", "off", NULL},
        {"range_distance", "normal", NULL},
        {"adaptive_diameter", "0.2", NULL},
    };
    (void)state;
    for (size_t s = 0; s < sizeof sets / sizeof sets[0]; s++) {
        obs__plan pl;
        obs_gbuffer_file gf = {0};
        float *pos, *nrm, *dnz;
        room_planes(&pl, &gf, sets[s], &pos, &nrm, &dnz);
        const obs__frame *f = &pl.f;
        const size_t npx = (size_t)f->width * (size_t)f->height;
        int *px = malloc(npx * sizeof(int)), *cnt = malloc(npx * sizeof(int));
        float *ao = malloc(npx * sizeof(float));
        assert_true(px && cnt && ao);
        const int m = stride_list(f, pos, px);
        assert_true(m > 1000);
        int counts_seen = 0;
        obs__vao_counts(f, pos, nrm, px, m, cnt);
        for (int j = 0; j < m; j++) {
            if (cnt[j] != obs__vao_count(f, pos + 4 * (size_t)px[j], nrm + 3 * (size_t)px[j]))
                fail_msg("%s %s, pixel %d: count %d, the twin's %d", sets[s][0], sets[s][1],
                         px[j], cnt[j],
                         obs__vao_count(f, pos + 4 * (size_t)px[j], nrm + 3 * (size_t)px[j]));
            counts_seen |= cnt[j];
        }
        if (s == 3)
            assert_true(counts_seen & 2); /* a diameter that gives some pixels 2 samples */
        for (int ns = 2; ns <= 32; ns *= 2) {
            const float *xy = f->sample_table + 2 * (ns - 2);
            for (int len = m - 5; len <= m; len += 5) { /* a partial last chunk, then m */
                for (size_t i = 0; i < npx; i++)
                    ao[i] = -1.0f;
                obs__vao_estimate_pixels(f, pos, nrm, dnz, px, len, ns, xy, ao);
                for (int j = 0; j < len; j++) {
                    const int i = px[j], x = i % f->width, y = i / f->width;
                    float b = obs__vao_estimate(f, pos, nrm, x, y, pos + 4 * (size_t)i,
                                                nrm + 3 * (size_t)i, ns, xy);
                    if (memcmp(&ao[i], &b, sizeof b))
                        fail_msg("%s %s, %d samples, pixel (%d, %d): %.9g, the twin %.9g",
                                 sets[s][0], sets[s][1], ns, x, y, ao[i], b);
                }
                for (int j = len; j < m; j++) /* only the listed pixels written */
                    assert_true(ao[px[j]] == -1.0f);
            }
        }
        free(px);
        free(cnt);
        free(ao);
        free_planes(&gf, pos, nrm, dnz);
    }
}

/* The prep pass's rows in lanes (obs__prep_position_row,
 * obs__prep_normal_row) against obs__prep_position and obs__prep_normal,
 * bit for bit, in every depth mode, on room_small's rows with raw values
 * of every kind put in (background, 0, negative, NaN, infinities, 1 and
 * past, tiny) and a zero normal. */
static void test_prep_rows(void **state)
{
    static const char *const modes[] = {"planar", "radial", "ndc", "inverse", "normalized"};
    static const float odd[] = {0.0f, -1.0f, NAN, INFINITY, -INFINITY, 1.0f, 1.5f, 1e-30f,
                                0.999f, 1e30f, 0.5f};
    (void)state;
    for (size_t md = 0; md < sizeof modes / sizeof modes[0]; md++) {
        const char *set[] = {"depth_mode", modes[md], NULL};
        obs__plan pl;
        obs_gbuffer_file gf = {0};
        float *pos, *nrm, *dnz;
        room_planes(&pl, &gf, set, &pos, &nrm, &dnz);
        const obs__frame *f = &pl.f;
        const int w = f->width;
        float *depth = malloc((size_t)w * 3 * sizeof(float)), *in = malloc((size_t)w * 4 * sizeof(float));
        float *p1 = malloc((size_t)w * 4 * sizeof(float)), *n1 = malloc((size_t)w * 3 * sizeof(float));
        float *d1 = malloc((size_t)w * 2 * sizeof(float));
        assert_true(depth && in && p1 && n1 && d1);
        for (int y = 0; y < f->height; y += 7) {
            for (int x = 0; x < w; x++) { /* 3 channels, the depth in the first */
                float raw = *obs__plane_px(&gf.gb.depth, w, x, y);
                depth[3 * x] = x % 5 == 0 ? odd[(x / 5 + y) % (sizeof odd / sizeof odd[0])] : raw;
                depth[3 * x + 1] = depth[3 * x + 2] = -7.0f;
                const float *nv = obs__plane_px(&gf.gb.normal, w, x, y);
                for (int k = 0; k < 3; k++)
                    in[4 * x + k] = x == 3 ? 0.0f : nv[k];
                in[4 * x + 3] = -7.0f;
            }
            obs__prep_position_row(f, depth, 3, y, p1);
            for (int x = 0; x < w; x++) {
                float want[4];
                obs__prep_position(f, depth[3 * x], x, y, want);
                if (memcmp(want, p1 + 4 * x, sizeof want))
                    fail_msg("depth %s, pixel (%d, %d), raw %g: (%g %g %g %g), the twin (%g %g "
                             "%g %g)", modes[md], x, y, depth[3 * x], p1[4 * x], p1[4 * x + 1],
                             p1[4 * x + 2], p1[4 * x + 3], want[0], want[1], want[2], want[3]);
            }
            if (!f->reconstruct_normals) {
                obs__prep_normal_row(f, p1, in, 4, n1, d1);
                for (int x = 0; x < w; x++) {
                    float want[3];
                    obs__prep_normal(f, pos, in + 4 * x, x, y, want); /* pos: not read */
                    if (memcmp(want, n1 + 3 * x, sizeof want) || d1[2 * x] != p1[4 * x + 3] ||
                        memcmp(&d1[2 * x + 1], &want[2], sizeof(float)))
                        fail_msg("depth %s, pixel (%d, %d): normal (%g %g %g), the twin (%g %g "
                                 "%g)", modes[md], x, y, n1[3 * x], n1[3 * x + 1], n1[3 * x + 2],
                                 want[0], want[1], want[2]);
                }
            }
        }
        assert_false(f->reconstruct_normals);
        free(depth);
        free(in);
        free(p1);
        free(n1);
        free(d1);
        free_planes(&gf, pos, nrm, dnz);
    }
}

/* The comparison methods in lanes (obs__method_pixels) against their
 * twins (obs__method_pixel) at every pixel with geometry of room_small,
 * bit for bit (gtao within 1e-5, with the largest difference printed), AO
 * and sample count exactly, with default and non-default
 * parameters, on a list of pixels in an order of its own with a partial
 * last chunk; methods without lanes (and object masks) leave it to the
 * twin. */
static void test_method_pixels(void **state)
{
    static const char *const sets[][9] = {
        {"method", "hemisphere", NULL},
        {"method", "hemisphere", "hemisphere_samples", "3", "hemisphere_bias", "0.2", NULL},
        {"method", "hbao", NULL},
        {"method", "hbao", "hbao_directions", "5", "hbao_steps", "13", "radius", "2.5", NULL},
        {"method", "hbao", "radius", "0.02", NULL}, /* a kernel within a pixel: AO 1 */
        {"method", "angle", NULL},
        {"method", "angle", "angle_acos", "linear", "angle_pairs", "11", "radius", "1.5", NULL},
        {"method", "gtao", NULL},
        {"method", "gtao", "gtao_heuristics", "off", "gtao_thin", "0.5", "gtao_steps", "7", NULL},
        {"method", "gtao", "gtao_slices", "5", "radius", "0.1", NULL},
        {"method", "angle", "angle_acos", "exact", NULL}, /* acosf: no lanes */
    };
    (void)state;
    for (size_t s = 0; s < sizeof sets / sizeof sets[0]; s++) {
        obs__plan pl;
        obs_gbuffer_file gf = {0};
        float *pos, *nrm, *dnz;
        room_planes(&pl, &gf, sets[s], &pos, &nrm, &dnz);
        const obs__frame *f = &pl.f;
        const size_t npx = (size_t)f->width * (size_t)f->height;
        int *px = malloc(npx * sizeof(int));
        float *ao = malloc(npx * sizeof(float)), *cnt = malloc(npx * sizeof(float));
        assert_true(px && ao && cnt);
        const int m = stride_list(f, pos, px) - 3; /* a partial last chunk */
        for (size_t i = 0; i < npx; i++)
            ao[i] = cnt[i] = -1.0f;
        const int lanes = obs__method_pixels(f, pos, nrm, px, m, ao, cnt);
        assert_int_equal(lanes, s < 10); /* angle's exact acos: none */
        float worst = 0.0f;
        for (int j = 0; lanes && j < m; j++) {
            const int i = px[j], x = i % f->width, y = i / f->width;
            int n = -1;
            const float want = obs__method_pixel(f, pos, nrm, x, y, &n);
            /* gtao's lanes take acos, sin and cos by polynomials: within
             * 1e-5; the others bit for bit */
            const int gtao = !strcmp(sets[s][1], "gtao");
            if ((gtao ? !(fabsf(ao[i] - want) <= 1e-5f) : memcmp(&ao[i], &want, sizeof want)) ||
                cnt[i] != (float)n)
                fail_msg("%s (set %zu), pixel (%d, %d): %.9g, %g samples; the twin %.9g, %d",
                         sets[s][1], s, x, y, ao[i], cnt[i], want, n);
            worst = fmaxf(worst, fabsf(ao[i] - want));
        }
        print_message("%s (set %zu): largest |lanes - twin| %.3g\n", sets[s][1], s, worst);
        for (int j = m; j < m + 3; j++) /* only the listed pixels written */
            assert_true(ao[px[j]] == -1.0f && cnt[px[j]] == -1.0f);
        free(px);
        free(ao);
        free(cnt);
        free_planes(&gf, pos, nrm, dnz);
    }
}

/* ao_definition rays over rows (obs__rays_rows, the conversion in lanes
 * by polynomials): within RAYS_TOL of obs__rays_from_volume (libm's acosf
 * and cosf) at every value of a sweep of [0, 1] (2^20 + 1 values; the
 * largest difference over 2^24 is 3.0e-7, where the twin itself is 2.9e-7
 * and the lanes 1.6e-7 from the double-precision value), exactly at 1 (the
 * open pixels' shortcut), unchanged (the twin's value) from 0.5 down and
 * outside [0, 1]. */
static void test_rays_rows(void **state)
{
    enum { N = (1 << 20) + 1 };
    float *v = malloc(N * sizeof(float)), *want = malloc(N * sizeof(float));
    float *in = malloc(N * sizeof(float));
    (void)state;
    assert_true(v && want && in);
    for (int i = 0; i < N; i++)
        v[i] = (float)i / (float)(N - 1);
    v[1] = nextafterf(1.0f, 0.0f);
    v[2] = -0.001f;
    v[3] = 1.5f;
    v[4] = 0.5f;
    v[5] = nextafterf(0.5f, 1.0f);
    for (int i = 0; i < N; i++) {
        want[i] = obs__rays_from_volume(v[i]);
        in[i] = v[i];
    }
    obs__rays_rows(v, N);
    for (int i = 0; i < N; i++) {
        if (!(fabsf(v[i] - want[i]) <= RAYS_TOL))
            fail_msg("value %d: %.9g, the twin %.9g", i, v[i], want[i]);
        if (!(in[i] > 0.5f && in[i] < 1.0f) && v[i] != want[i])
            fail_msg("value %d: %.9g, the twin %.9g (not converted)", i, v[i], want[i]);
    }
    free(v);
    free(want);
    free(in);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_blur_bit_for_bit),
        cmocka_unit_test(test_vao_bit_for_bit),
        cmocka_unit_test(test_vao_pixels_bit_for_bit),
        cmocka_unit_test(test_rays_rows),
        cmocka_unit_test(test_prep_rows),
        cmocka_unit_test(test_method_pixels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
