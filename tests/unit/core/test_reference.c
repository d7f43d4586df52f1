/* The ray-traced AO reference (Embree): closed forms on meshes built here
 * (a crease and a slab, the canonical configurations of bench/QUALITY.md),
 * determinism, argument errors, and agreement with Cycles' AO pass of the
 * room scene (shared data). */
#include <math.h>

#include "testutil.h"

#include "obscura/io.h"
#include "obscura/reference.h"
#include "obscura/scene.h"

#define PI 3.14159265358979323846

/* Quads (4 corners each) as an in-memory scene; 2 triangles per quad. */
static void quads(obs_scene *s, const float (*corners)[4][3], int n)
{
    memset(s, 0, sizeof *s);
    s->vertex_count = 4 * (size_t)n;
    s->triangle_count = 2 * (size_t)n;
    s->positions = malloc(s->vertex_count * 3 * sizeof(float));
    s->indices = malloc(s->triangle_count * 3 * sizeof(uint32_t));
    assert_non_null(s->positions);
    assert_non_null(s->indices);
    for (int q = 0; q < n; q++) {
        memcpy(s->positions + 12 * q, corners[q], 12 * sizeof(float));
        const uint32_t b = 4 * (uint32_t)q, t[6] = {b, b + 1, b + 2, b, b + 2, b + 3};
        memcpy(s->indices + 6 * q, t, sizeof t);
    }
    char err[OBS_ERR_LEN] = "";
    if (obs_scene_check(s, err) != OBS_OK)
        fail_msg("%s", err);
}

/* A camera 5 m above the origin looking down (-Z), +Y up in the image. */
static void top_camera(obs_camera *cam, float aspect)
{
    obs_camera_from_fov(60.0f, aspect, 0.1f, 100.0f, cam);
    cam->world_to_camera[11] = -5.0f;
    cam->has_world_to_camera = 1;
}

/* AO at G-buffer points on the floor (normal +Z) at the given x. */
static void ao_at_points(const obs_scene *s, const float *xs, int n, float y, int spp, float *ao)
{
    obs_image pos = {n, 1, 3, calloc(3 * (size_t)n, sizeof(float))};
    obs_image nrm = {n, 1, 3, calloc(3 * (size_t)n, sizeof(float))};
    obs_image out = {0};
    obs_camera cam;
    char err[OBS_ERR_LEN] = "";
    top_camera(&cam, 1.0f);
    for (int i = 0; i < n; i++) {
        pos.data[3 * i] = xs[i];
        pos.data[3 * i + 1] = y;
        nrm.data[3 * i + 2] = 1.0f;
    }
    obs_reference_view v = {.camera = &cam, .position = &pos, .normal = &nrm};
    obs_reference_desc d = {.distance = 0.5f, .spp = spp, .seed = 7};
    if (obs_reference_render(s, &v, &d, &out, NULL, err) != OBS_OK)
        fail_msg("%s", err);
    memcpy(ao, out.data, (size_t)n * sizeof(float));
    obs_image_free(&out);
    obs_image_free(&pos);
    obs_image_free(&nrm);
}

/* Within 4 binomial standard errors of the exact value (+ float slack). */
static void near_exact(float est, double exact, int spp, const char *what, double x)
{
    double tol = 4.0 * sqrt(exact * (1.0 - exact) / spp) + 2e-3;
    if (fabs(est - exact) > tol)
        fail_msg("%s at x/D = %.2f: %.4f, exact %.4f (tolerance %.4f)", what, x, (double)est,
                 exact, tol);
}

/* Crease: a floor point at distance x from a wall.  A cosine-weighted
 * direction projects to a uniform point of the unit disk (Malley), and the
 * ray hits the wall within D iff that point's component towards the wall
 * exceeds a = x/D: O = (acos a - a sqrt(1 - a^2)) / pi, the circular
 * segment.  Slab: a ceiling at height h blocks iff cos(theta) >= h/D:
 * O = 1 - (h/D)^2. */
static void test_closed_forms(void **state)
{
    (void)state;
    const int spp = 4096;
    enum { N = 6 };
    const float D = 0.5f, xs[N] = {0.01f, 0.05f, 0.1f, 0.25f, 0.4f, 0.6f};
    float xw[N], ao[N];
    obs_scene s;

    /* floor z = 0 for x < 0 and the wall x = 0, facing -X */
    const float crease[2][4][3] = {{{-5, -5, 0}, {0, -5, 0}, {0, 5, 0}, {-5, 5, 0}},
                                   {{0, -5, 0}, {0, -5, 3}, {0, 5, 3}, {0, 5, 0}}};
    quads(&s, crease, 2);
    for (int i = 0; i < N; i++)
        xw[i] = -xs[i] * D;
    ao_at_points(&s, xw, N, 0.0f, spp, ao);
    for (int i = 0; i < N; i++) {
        double a = xs[i], o = a < 1 ? (acos(a) - a * sqrt(1 - a * a)) / PI : 0;
        near_exact(ao[i], 1.0 - o, spp, "crease", a);
    }
    obs_scene_free(&s);

    /* floor and a ceiling at height h (its winding does not matter) */
    for (int i = 0; i < N; i++) {
        const float h = (xs[i] + 0.1f) * D;
        const float slab[2][4][3] = {{{-5, -5, 0}, {5, -5, 0}, {5, 5, 0}, {-5, 5, 0}},
                                     {{-5, -5, h}, {5, -5, h}, {5, 5, h}, {-5, 5, h}}};
        float x0 = 0.0f;
        quads(&s, slab, 2);
        ao_at_points(&s, &x0, 1, 0.0f, spp, ao);
        double r = h / D, exact = r < 1 ? r * r : 1.0;
        near_exact(ao[0], exact, spp, "slab", r);
        obs_scene_free(&s);
    }
}

/* Camera rays: the image depends on the seed only, not on the thread
 * count; the depth is the planar view depth; misses are AO 1, sky depth. */
static void test_deterministic(void **state)
{
    (void)state;
    const float box[3][4][3] = {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}},
                                {{0.2f, -0.5f, 0}, {0.2f, -0.5f, 0.4f}, {0.2f, 0.5f, 0.4f}, {0.2f, 0.5f, 0}},
                                {{-0.3f, -0.5f, 0.3f}, {0.1f, -0.5f, 0.3f}, {0.1f, 0.5f, 0.3f}, {-0.3f, 0.5f, 0.3f}}};
    obs_scene s;
    obs_camera cam;
    obs_image a = {0}, b = {0}, c = {0}, z = {0};
    char err[OBS_ERR_LEN] = "";
    quads(&s, box, 3);
    top_camera(&cam, 1.5f);
    obs_reference_view v = {.camera = &cam, .width = 48, .height = 32};
    obs_reference_desc d = {.distance = 0.5f, .spp = 16, .seed = 1, .threads = 1};
    assert_int_equal(obs_reference_render(&s, &v, &d, &a, &z, err), OBS_OK);
    d.threads = 3;
    assert_int_equal(obs_reference_render(&s, &v, &d, &b, NULL, err), OBS_OK);
    assert_memory_equal(a.data, b.data, 48 * 32 * sizeof(float));
    d.seed = 2;
    assert_int_equal(obs_reference_render(&s, &v, &d, &c, NULL, err), OBS_OK);
    assert_true(memcmp(a.data, c.data, 48 * 32 * sizeof(float)) != 0);

    int sky = 0, occluded = 0;
    for (int i = 0; i < 48 * 32; i++) {
        assert_true(a.data[i] >= 0.0f && a.data[i] <= 1.0f);
        if (z.data[i] >= 1e9f) {
            sky++;
            assert_float_equal(a.data[i], 1.0f, 0);
        } else {
            assert_true(z.data[i] > 4.5f && z.data[i] <= 5.0f + 1e-4f);
            occluded += a.data[i] < 1.0f;
        }
    }
    assert_true(sky > 0);
    assert_true(occluded > 0);
    obs_image_free(&a);
    obs_image_free(&b);
    obs_image_free(&c);
    obs_image_free(&z);
    obs_scene_free(&s);
}

/* Normals against the winding (every vertex normal pointing into the side
 * the camera does not see): the AO is that of the geometric normals, as
 * the --gbuffer points' (turned to face the viewer).  It was 0 wherever
 * such a triangle was seen: every cosine ray around the normal lay below
 * the surface. */
static void test_normals_against_winding(void **state)
{
    (void)state;
    const float box[2][4][3] = {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}},
                                {{0.2f, -0.5f, 0}, {0.2f, -0.5f, 0.4f}, {0.2f, 0.5f, 0.4f}, {0.2f, 0.5f, 0}}};
    obs_scene s;
    obs_camera cam;
    obs_image plain = {0}, against = {0};
    char err[OBS_ERR_LEN] = "";
    quads(&s, box, 2);
    top_camera(&cam, 1.5f);
    obs_reference_view v = {.camera = &cam, .width = 48, .height = 32};
    obs_reference_desc d = {.distance = 0.5f, .spp = 16, .seed = 1, .threads = 1};
    assert_int_equal(obs_reference_render(&s, &v, &d, &plain, NULL, err), OBS_OK);
    /* the floor's normals -Z (its winding faces +Z, the camera), the
     * wall's +X (its winding faces -X, the camera at x = 0) */
    s.normals = calloc(3 * s.vertex_count, sizeof(float));
    assert_non_null(s.normals);
    for (int i = 0; i < 4; i++) {
        s.normals[3 * i + 2] = -1.0f;
        s.normals[3 * (4 + i)] = 1.0f;
    }
    assert_int_equal(obs_reference_render(&s, &v, &d, &against, NULL, err), OBS_OK);
    float mean = 0.0f;
    for (int i = 0; i < 48 * 32; i++)
        mean += against.data[i] / (48 * 32);
    print_message("AO mean %.3f with the normals against the winding\n", (double)mean);
    assert_memory_equal(plain.data, against.data, 48 * 32 * sizeof(float));
    obs_image_free(&plain);
    obs_image_free(&against);
    obs_scene_free(&s);
}

static void test_errors(void **state)
{
    (void)state;
    const float floor_q[1][4][3] = {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}};
    obs_scene s, empty = {0};
    obs_camera cam, none = {0};
    obs_image ao = {0};
    char err[OBS_ERR_LEN] = "";
    quads(&s, floor_q, 1);
    top_camera(&cam, 1.0f);
    obs_reference_view v = {.camera = &cam, .width = 8, .height = 8};
    obs_reference_desc d = {.distance = 0.5f, .spp = 4};
    assert_int_equal(obs_reference_render(&empty, &v, &d, &ao, NULL, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "empty scene"));
    d.distance = 0.0f;
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "distance"));
    d.distance = 0.5f;
    d.spp = -1;
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_INVALID_ARGUMENT);
    d.spp = 4;
    d.threads = 1000;
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_INVALID_ARGUMENT);
    d.threads = 0;
    v.camera = &none;
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_NO_CAMERA);
    v.camera = &cam;
    v.width = 0;
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_INVALID_ARGUMENT);
    obs_image pos = {2, 1, 3, (float[6]){0}};
    v.position = &pos; /* without normals */
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_INVALID_ARGUMENT);
    assert_null(ao.data);
    obs_scene_free(&s);
}

/* A camera 1e30 above the floor: Embree aborted the process on its rays
 * (ray.valid: an origin past 1.844e18).  Refused by the scenes' bound,
 * naming the camera's position; one at 1e9 is taken.  G-buffer points
 * beyond the bound are background (AO 1), as non-finite ones are; the
 * point at 1e30 aborted the same way. */
static void test_far_camera_and_points(void **state)
{
    (void)state;
    const float floor_q[1][4][3] = {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}};
    obs_scene s;
    obs_camera cam;
    obs_image ao = {0};
    char err[OBS_ERR_LEN] = "";
    quads(&s, floor_q, 1);
    top_camera(&cam, 1.0f);
    cam.world_to_camera[11] = -1e30f;
    obs_reference_view v = {.camera = &cam, .width = 8, .height = 8};
    obs_reference_desc d = {.distance = 0.5f, .spp = 4, .threads = 1};
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_NO_CAMERA);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "the camera at (0, 0, 1e+30): a coordinate beyond +-1e9"));
    assert_null(ao.data);
    cam.world_to_camera[11] = -1e9f;
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_OK);
    obs_image_free(&ao);

    const float xs[3] = {0.0f, 1e30f, 3e38f};
    float out[3];
    ao_at_points(&s, xs, 3, 0.0f, 4, out);
    for (int i = 0; i < 3; i++)
        assert_true(out[i] == 1.0f); /* open floor; background */
    obs_scene_free(&s);
}

/* Our reference (camera rays through pixel centres, SPP rays) against
 * Cycles' AO pass of room.exr (128 samples, distance 0.5 m), over the
 * pixels both see geometry at.
 *
 * Both are Monte Carlo estimates of the same integral.  At a pixel of true
 * AO a, ours is binomial: variance a(1-a)/SPP; Cycles' (stratified,
 * 128 samples) has at most a(1-a)/128.  Their difference e = noise + s
 * (s: the systematic part) has E|e| <= sqrt(E e^2) <= sigma + |s| with
 * sigma^2 = a(1-a)(1/SPP + 1/128).  So
 *     E[MAD] <= mean(sigma) + mean|s|,
 * mean(sigma) computed here with a estimated by the two images' average.
 * The allowance for mean|s| is 0.005: Cycles averages its 128 camera rays
 * over a 1.5-pixel Blackman-Harris footprint, so at silhouettes and
 * creases (8 % of the pixels, test_raster) its AO mixes surfaces that our
 * single ray at the pixel centre does not; the rest is the ray offset at
 * contact points and the interpolated normal of coarse smooth meshes.
 * (Measured at 64 spp: MAD 0.0118 against a pure-noise expectation of
 * 0.0115 = sqrt(2/pi) mean(sigma), so the systematic part is small.)
 * The mean difference (bias) has no noise to speak of over 3e5 pixels
 * (< 1e-3): it must stay under 0.005. */
#define SPP 64
static void test_blender_room(void **state)
{
    (void)state;
    char dir[512], path[600], err[OBS_ERR_LEN] = "";
    snprintf(dir, sizeof dir, "%s/blender", obs_test_shared());
    snprintf(path, sizeof path, "%s/room.obj", dir);
    if (!obs_test_exists(path))
        skip();
    obs_scene s;
    obs_camera cam;
    int w, h;
    if (obs_scene_load(path, &s, err) != OBS_OK)
        fail_msg("%s", err);
    snprintf(path, sizeof path, "%s/room.camera.json", dir);
    assert_int_equal(obs_camera_read_json(path, &cam, &w, &h, err), OBS_OK);
    obs_image ao = {0}, z = {0}, cao = {0}, cz = {0};
    obs_reference_view v = {.camera = &cam, .width = w, .height = h};
    obs_reference_desc d = {.distance = 0.5f, .spp = SPP, .seed = 1};
    if (obs_reference_render(&s, &v, &d, &ao, &z, err) != OBS_OK)
        fail_msg("%s", err);
    snprintf(path, sizeof path, "%s/room.exr", dir);
    assert_int_equal(obs_exr_read_channel(path, "ViewLayer.AO.R", NULL, &cao, err), OBS_OK);
    assert_int_equal(obs_exr_read_channel(path, "ViewLayer.Depth.Z", NULL, &cz, err), OBS_OK);

    double sum_abs = 0, sum = 0, sum_sigma = 0;
    long n = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        if (!(cz.data[i] < 1e9f && z.data[i] < 1e9f))
            continue;
        double e = (double)ao.data[i] - cao.data[i], a = 0.5 * (ao.data[i] + cao.data[i]);
        sum_abs += fabs(e);
        sum += e;
        sum_sigma += sqrt(a * (1 - a) * (1.0 / SPP + 1.0 / 128));
        n++;
    }
    double mad = sum_abs / n, bias = sum / n, sigma = sum_sigma / n;
    double bound = sigma + 0.005;
    printf("room reference (%d spp) vs Cycles AO (128): %ld pixels, MAD %.4f, bias %+.5f; noise: "
           "mean sigma %.4f (Gaussian E|e| %.4f); bound %.4f\n",
           SPP, n, mad, bias, sigma, sigma * sqrt(2 / PI), bound);
    assert_true(n > 0.9 * (double)w * h);
    assert_true(mad < bound);
    assert_true(fabs(bias) < 0.005);

    obs_image_free(&ao);
    obs_image_free(&z);
    obs_image_free(&cao);
    obs_image_free(&cz);
    obs_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_forms),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_normals_against_winding),
        cmocka_unit_test(test_far_camera_and_points),
        cmocka_unit_test(test_blender_room),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
