/* The reference's obscurance mode (reference.h): eq 1 of the bake's paper
 * per pixel.  A plane is 1 at both distances, a crease matches the closed
 * form, the blend is b short + (1 - b) long, and argument errors. */
#include <math.h>

#include "testutil.h"

#include "core/obscurance_crease.h"
#include "obscura/io.h"
#include "obscura/reference.h"
#include "obscura/scene.h"

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

/* A camera 5 m above the origin looking down (-Z). */
static void top_camera(obs_camera *cam, float aspect)
{
    obs_camera_from_fov(60.0f, aspect, 0.1f, 100.0f, cam);
    cam->world_to_camera[11] = -5.0f;
    cam->has_world_to_camera = 1;
}

static obs_reference_desc obscurance(float dshort, float dlong, float blend, int rays)
{
    obs_reference_desc d = {.spp = rays, .seed = 3, .obscurance = 1, .blend = blend};
    d.obscurance_distance[0] = dshort;
    d.obscurance_distance[1] = dlong;
    return d;
}

/* An open plane: every ray misses, AO 1 at both distances and blended;
 * three channels; the depth of the plane under every pixel. */
static void test_plane_is_one(void **state)
{
    (void)state;
    const float floor_q[1][4][3] = {{{-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}}};
    obs_scene s;
    obs_camera cam;
    obs_image ao = {0}, z = {0};
    char err[OBS_ERR_LEN] = "";
    quads(&s, floor_q, 1);
    top_camera(&cam, 1.0f);
    obs_reference_view v = {.camera = &cam, .width = 16, .height = 16};
    obs_reference_desc d = obscurance(2.0f, 300.0f, 0.03f, 32);
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, &z, err), OBS_OK);
    assert_int_equal(ao.channels, 3);
    for (int i = 0; i < 16 * 16; i++) {
        for (int c = 0; c < 3; c++)
            assert_float_equal(ao.data[3 * i + c], 1.0f, 1e-6f);
        assert_float_equal(z.data[i], 5.0f, 1e-3f);
    }
    obs_image_free(&ao);
    obs_image_free(&z);
    obs_scene_free(&s);
}

/* Floor z = 0 for x < 0 and a wall x = 0 (6 m: what it misses weighs
 * 2^-(6/0.5) at most).  At floor points h from the wall eq 1 is the
 * closed form crease_ao(h, d) (obscurance_crease.h), whatever the
 * winding (hits count on either side).  Rays: 256 per point, rho in
 * [0, 1], so one point's error has sigma <= 0.5 / 16 for independent
 * rays; the mean over the points must lie within 4 sigma / sqrt(n), each
 * point within sigma (the bake's ray lattice is stratified, so the error
 * is below the independent rays' sigma: 0.007 measured).
 * The blend channel is b short + (1 - b) long exactly. */
static void test_crease(void **state)
{
    (void)state;
    const float crease[2][4][3] = {{{-6, -6, 0}, {0, -6, 0}, {0, 6, 0}, {-6, 6, 0}},
                                   {{0, -6, 0}, {0, -6, 6}, {0, 6, 6}, {0, 6, 0}}};
    enum { NH = 8, NY = 24, N = NH * NY };
    const float hs[NH] = {0.005f, 0.02f, 0.05f, 0.1f, 0.2f, 0.35f, 0.6f, 1.0f};
    const float D[2] = {0.25f, 0.5f}, blend = 0.3f;
    const int rays = 256;
    obs_scene s;
    obs_camera cam;
    char err[OBS_ERR_LEN] = "";
    quads(&s, crease, 2);
    top_camera(&cam, 1.0f);
    obs_image pos = {N, 1, 3, calloc(3 * N, sizeof(float))};
    obs_image nrm = {N, 1, 3, calloc(3 * N, sizeof(float))};
    obs_image ao = {0};
    for (int i = 0; i < N; i++) {
        pos.data[3 * i] = -hs[i % NH];
        pos.data[3 * i + 1] = -2.0f + 4.0f * (float)(i / NH) / NY;
        nrm.data[3 * i + 2] = 1.0f;
    }
    obs_reference_view v = {.camera = &cam, .position = &pos, .normal = &nrm};
    obs_reference_desc d = obscurance(D[0], D[1], blend, rays);
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_OK);
    assert_int_equal(ao.channels, 3);
    const double sigma = 0.5 / sqrt((double)rays);
    for (int c = 0; c < 2; c++) {
        double sum = 0.0, worst = 0.0;
        for (int i = 0; i < N; i++) {
            double e = ao.data[3 * i + 1 + c] - crease_ao(hs[i % NH], D[c]);
            sum += e;
            worst = fmax(worst, fabs(e));
        }
        print_message("crease, d = %.2f: mean error %+.5f, worst %.4f (sigma %.4f, %d points)\n",
                      (double)D[c], sum / N, worst, sigma, N);
        assert_true(fabs(sum / N) < 4.0 * sigma / sqrt((double)N));
        assert_true(worst < sigma);
    }
    /* next to the crease the closed form is near 1/2 for every d (on the
     * wall's own plane a ray's origin would sit on the wall), and the
     * points further out are lighter */
    assert_true(fabs(ao.data[1] - 0.5f) < 0.05);
    assert_true(ao.data[3 * (NH - 1) + 1] > ao.data[3 * 2 + 1]);
    for (int i = 0; i < N; i++) {
        const float *o = ao.data + 3 * i;
        assert_float_equal(o[0], blend * o[1] + (1.0f - blend) * o[2], 1e-6f);
    }
    obs_image_free(&ao);
    obs_image_free(&pos);
    obs_image_free(&nrm);
    obs_scene_free(&s);
}

/* With a near distance D: AO_NEAR is the reference's AO at D (a crease's
 * closed form: a floor point x from the wall is blocked where the disk
 * point's component towards the wall exceeds x / D, O = (acos a -
 * a sqrt(1 - a^2)) / pi, a = x / D; reference.c's ray estimator, binomial
 * within 4 standard errors) and AO_BOTH = AO_NEAR x AO_LONG exactly. */
static void test_near(void **state)
{
    (void)state;
    const float crease[2][4][3] = {{{-6, -6, 0}, {0, -6, 0}, {0, 6, 0}, {-6, 6, 0}},
                                   {{0, -6, 0}, {0, -6, 6}, {0, 6, 6}, {0, 6, 0}}};
    enum { N = 5 };
    const float xs[N] = {0.02f, 0.1f, 0.25f, 0.4f, 0.7f}, D = 0.5f;
    const int spp = 4096;
    obs_scene s;
    obs_camera cam;
    char err[OBS_ERR_LEN] = "";
    quads(&s, crease, 2);
    top_camera(&cam, 1.0f);
    obs_image pos = {N, 1, 3, calloc(3 * N, sizeof(float))};
    obs_image nrm = {N, 1, 3, calloc(3 * N, sizeof(float))};
    obs_image ao = {0};
    for (int i = 0; i < N; i++) {
        pos.data[3 * i] = -xs[i] * D;
        nrm.data[3 * i + 2] = 1.0f;
    }
    obs_reference_view v = {.camera = &cam, .position = &pos, .normal = &nrm};
    obs_reference_desc d = obscurance(0.25f, 3.0f, 0.1f, spp);
    d.obscurance_near = D;
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_OK);
    assert_int_equal(ao.channels, 5);
    for (int i = 0; i < N; i++) {
        const float *o = ao.data + 5 * i;
        double a = xs[i], exact = 1.0 - (acos(a) - a * sqrt(1 - a * a)) / 3.14159265358979;
        double tol = 4.0 * sqrt(exact * (1.0 - exact) / spp) + 2e-3;
        print_message("near AO at x/D = %.2f: %.4f, closed form %.4f\n", a, (double)o[3], exact);
        assert_true(fabs(o[3] - exact) < tol);
        assert_float_equal(o[4], o[3] * o[2], 1e-6f);
        assert_true(o[2] < 1.0f); /* the long distance sees the wall too */
    }
    d.obscurance_near = -1.0f;
    obs_image bad = {0};
    assert_int_equal(obs_reference_render(&s, &v, &d, &bad, NULL, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "near"));
    obs_image_free(&ao);
    obs_image_free(&pos);
    obs_image_free(&nrm);
    obs_scene_free(&s);
}

/* The image depends on the seed, not on the thread count. */
static void test_deterministic(void **state)
{
    (void)state;
    const float box[2][4][3] = {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}},
                                {{0.2f, -0.5f, 0}, {0.2f, -0.5f, 0.4f}, {0.2f, 0.5f, 0.4f}, {0.2f, 0.5f, 0}}};
    obs_scene s;
    obs_camera cam;
    obs_image a = {0}, b = {0}, c = {0};
    char err[OBS_ERR_LEN] = "";
    quads(&s, box, 2);
    top_camera(&cam, 1.0f);
    obs_reference_view v = {.camera = &cam, .width = 24, .height = 24};
    obs_reference_desc d = obscurance(0.5f, 4.0f, 0.5f, 16);
    d.threads = 1;
    assert_int_equal(obs_reference_render(&s, &v, &d, &a, NULL, err), OBS_OK);
    d.threads = 3;
    assert_int_equal(obs_reference_render(&s, &v, &d, &b, NULL, err), OBS_OK);
    assert_memory_equal(a.data, b.data, 3 * 24 * 24 * sizeof(float));
    d.seed = 4;
    assert_int_equal(obs_reference_render(&s, &v, &d, &c, NULL, err), OBS_OK);
    assert_true(memcmp(a.data, c.data, 3 * 24 * 24 * sizeof(float)) != 0);
    obs_image_free(&a);
    obs_image_free(&b);
    obs_image_free(&c);
    obs_scene_free(&s);
}

static void test_errors(void **state)
{
    (void)state;
    const float floor_q[1][4][3] = {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}};
    obs_scene s;
    obs_camera cam;
    obs_image ao = {0};
    char err[OBS_ERR_LEN] = "";
    quads(&s, floor_q, 1);
    top_camera(&cam, 1.0f);
    obs_reference_view v = {.camera = &cam, .width = 4, .height = 4};
    obs_reference_desc d = obscurance(0.0f, 300.0f, 0.03f, 4);
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "short distance"));
    d = obscurance(2.0f, NAN, 0.03f, 4);
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "long distance"));
    d = obscurance(2.0f, 300.0f, 1.5f, 4);
    assert_int_equal(obs_reference_render(&s, &v, &d, &ao, NULL, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "blend"));
    assert_null(ao.data);
    obs_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plane_is_one),
        cmocka_unit_test(test_crease),
        cmocka_unit_test(test_near),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
