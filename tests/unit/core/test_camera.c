/* Camera conventions: the view-space position the prep pass reconstructs
 * from depth and camera is where the camera puts the point.  Checked on a
 * synthetic point and on Blender's own world-space Position channel. */
#include <math.h>

#include "testutil.h"

#include "camera/camera.h"
#include "methods/methods.h"
#include "obscura/io.h"

static obs__frame setup(obs_gbuffer *gb, const char *normal_space)
{
    obs_params p = {0}, rp;
    obs__frame f;
    char err[OBS_ERR_LEN] = "";
    if (normal_space)
        obs_param_set(&p, "normal_space", normal_space, err);
    obs_params_resolve(&p, &rp);
    if (obs__frame_setup(NULL, gb, &rp, &f, err) != OBS_OK)
        fail_msg("frame setup: %s", err);
    return f;
}

/* A known point: the camera at (1, 2, 3) looking down world -Z.  Project a
 * point to find its pixel, move it to that pixel's centre, and check the
 * prep pass puts it back in view space at the right place for every depth
 * mode. */
static void test_known_point(void **state)
{
    (void)state;
    float depth = 0;
    obs_gbuffer gb = {0};
    gb.width = 64;
    gb.height = 48;
    gb.depth = (obs_plane){&depth, 1, 0};
    obs_camera_from_fov(40.0f, 64.0f / 48.0f, 0.5f, 50.0f, &gb.camera);
    obs__mat4_identity(gb.camera.world_to_camera);
    gb.camera.world_to_camera[3] = -1.0f;
    gb.camera.world_to_camera[7] = -2.0f;
    gb.camera.world_to_camera[11] = -3.0f;
    gb.camera.has_world_to_camera = 1;

    const int px = 40, py = 13;
    float ndc[2];
    obs__frame f = setup(&gb, NULL);
    obs__px_ndc(&f, px, py, ndc);
    /* pixel (40, 13): x right of centre, y above it (rows go down) */
    assert_true(ndc[0] > 0 && ndc[1] > 0);
    /* the point at planar depth 7 on that pixel's ray, built from the
     * inverse projection independently of the prep code */
    float inv[16], clip[4] = {ndc[0] * 7.0f, ndc[1] * 7.0f, 0, 7.0f}, v[4];
    const float *P = gb.camera.projection;
    clip[2] = P[10] * -7.0f + P[11]; /* clip z of view z = -7 */
    assert_int_equal(obs__mat4_invert(P, inv), 0);
    obs__mat4_apply(inv, clip, v);
    assert_float_equal(v[2] / v[3], -7.0f, 1e-4f);

    float out[4];
    obs__prep_position(&f, 7.0f, px, py, out);
    assert_float_equal(out[0], v[0] / v[3], 1e-5f);
    assert_float_equal(out[1], v[1] / v[3], 1e-5f);
    assert_float_equal(out[2], -7.0f, 1e-5f);
    assert_float_equal(out[3], 7.0f, 1e-6f);

    /* radial: the same point given by its distance from the camera */
    float radial = sqrtf(out[0] * out[0] + out[1] * out[1] + 49.0f), out2[4];
    obs_params p = {0};
    char err[OBS_ERR_LEN];
    obs_param_set(&p, "depth_mode", "radial", err);
    obs_params rp;
    obs_params_resolve(&p, &rp);
    assert_int_equal(obs__frame_setup(NULL, &gb, &rp, &f, err), OBS_OK);
    obs__prep_position(&f, radial, px, py, out2);
    for (int k = 0; k < 4; k++)
        assert_float_equal(out2[k], out[k], 1e-4f);

    /* ndc: the point's OpenGL depth-buffer value */
    float zw = (clip[2] / clip[3]) * 0.5f + 0.5f;
    obs_param_set(&p, "depth_mode", "ndc", err);
    obs_params_resolve(&p, &rp);
    assert_int_equal(obs__frame_setup(NULL, &gb, &rp, &f, err), OBS_OK);
    obs__prep_position(&f, zw, px, py, out2);
    for (int k = 0; k < 4; k++)
        assert_float_equal(out2[k], out[k], 1e-3f);

    /* background: sky, zero, NaN, and ndc's far plane */
    obs__prep_position(&f, 1.0f, px, py, out2);
    assert_float_equal(out2[3], 0.0f, 0.0f);
    obs_param_set(&p, "depth_mode", "planar", err);
    obs_params_resolve(&p, &rp);
    assert_int_equal(obs__frame_setup(NULL, &gb, &rp, &f, err), OBS_OK);
    obs__prep_position(&f, 1e10f, px, py, out2);
    assert_float_equal(out2[3], 0.0f, 0.0f);
    obs__prep_position(&f, 0.0f, px, py, out2);
    assert_float_equal(out2[3], 0.0f, 0.0f);
    obs__prep_position(&f, NAN, px, py, out2);
    assert_float_equal(out2[3], 0.0f, 0.0f);
}

/* A data window that starts inside the display window: pixel (0, 0) of
 * the planes is display pixel (ox, oy), and lands on the same ray. */
static void test_data_window_offset(void **state)
{
    (void)state;
    float depth = 0;
    obs_gbuffer full = {0}, part;
    full.width = 64;
    full.height = 48;
    full.depth = (obs_plane){&depth, 1, 0};
    obs_camera_from_fov(40.0f, 64.0f / 48.0f, 0.5f, 50.0f, &full.camera);
    part = full;
    part.width = 10;
    part.height = 8;
    part.display_x = 30;
    part.display_y = 20;
    part.display_width = 64;
    part.display_height = 48;
    obs__frame ff = setup(&full, "camera"), fp = setup(&part, "camera");
    float a[4], b[4];
    obs__prep_position(&ff, 3.0f, 33, 25, a);
    obs__prep_position(&fp, 3.0f, 3, 5, b);
    for (int k = 0; k < 4; k++)
        assert_float_equal(a[k], b[k], 1e-6f);
}

/* Blender wrote the world-space position of every pixel: transformed by
 * world_to_camera it must be the view position the prep pass gets from
 * Depth.Z and the camera JSON. */
static void test_blender_positions(void **state)
{
    (void)state;
    const char *path = TESTDATA "/room_small.exr";
    obs_gbuffer_file gf = {0};
    obs_image pos[3];
    char err[OBS_ERR_LEN] = "";
    static const char *const names[3] = {"ViewLayer.Position.X", "ViewLayer.Position.Y",
                                         "ViewLayer.Position.Z"};
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &gf, err), OBS_OK);
    assert_int_equal(obs_camera_read_json(TESTDATA "/room_small.camera.json", &gf.gb.camera, NULL,
                                          NULL, err),
                     OBS_OK);
    for (int k = 0; k < 3; k++)
        assert_int_equal(obs_exr_read_channel(path, names[k], NULL, &pos[k], err), OBS_OK);

    obs__frame f = setup(&gf.gb, NULL);
    const float *M = gf.gb.camera.world_to_camera;
    int n = 0, good = 0;
    double worst = 0;
    for (int y = 0; y < gf.gb.height; y++)
        for (int x = 0; x < gf.gb.width; x++) {
            size_t i = (size_t)y * gf.gb.width + x;
            float raw = *obs__plane_px(&gf.gb.depth, gf.gb.width, x, y), v[4];
            obs__prep_position(&f, raw, x, y, v);
            if (v[3] <= 0)
                continue;
            float w[4] = {pos[0].data[i], pos[1].data[i], pos[2].data[i], 1.0f}, c[4];
            obs__mat4_apply(M, w, c);
            double e = sqrt((c[0] - v[0]) * (c[0] - v[0]) + (c[1] - v[1]) * (c[1] - v[1]) +
                            (c[2] - v[2]) * (c[2] - v[2]));
            n++;
            good += e < 1e-3 * v[3]; /* within 0.1 % of the distance */
            if (e > worst)
                worst = e;
        }
    print_message("room_small: %d of %d geometry pixels within 0.1 %% of Blender's position, worst %.2e m\n",
                  good, n, worst);
    assert_true(n > 10000);
    /* measured: every pixel, worst 1.1e-4 m (Blender's pixel filter is
     * 0.01 wide, so even edge pixels hold one surface) */
    assert_true(good >= 0.999 * n);
    for (int k = 0; k < 3; k++)
        obs_image_free(&pos[k]);
    obs_gbuffer_free(&gf);
}

/* World normals carried into view space agree with normals reconstructed
 * from depth on flat surfaces: the normal matrix is the right one. */
static void test_world_normals_match_geometry(void **state)
{
    (void)state;
    obs_gbuffer_file gf = {0};
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_gbuffer_read_exr(TESTDATA "/room_small.exr", NULL, NULL, &gf, err), OBS_OK);
    assert_int_equal(obs_camera_read_json(TESTDATA "/room_small.camera.json", &gf.gb.camera, NULL,
                                          NULL, err),
                     OBS_OK);
    obs_gbuffer nonormals = gf.gb;
    nonormals.normal.data = NULL;
    obs__frame fw = setup(&gf.gb, NULL), fr = setup(&nonormals, NULL);
    int w = gf.gb.width, h = gf.gb.height, n = 0, agree = 0;
    float *pos = malloc(sizeof(float) * 4 * w * h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            obs__prep_position(&fw, *obs__plane_px(&gf.gb.depth, w, x, y), x, y, pos + 4 * (y * w + x));
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            if (pos[4 * (y * w + x) + 3] <= 0)
                continue;
            float a[3], b[3];
            obs__prep_normal(&fw, pos, obs__plane_px(&gf.gb.normal, w, x, y), x, y, a);
            obs__prep_normal(&fr, pos, NULL, x, y, b);
            n++;
            agree += a[0] * b[0] + a[1] * b[1] + a[2] * b[2] > 0.95f;
        }
    print_message("room_small: world->view normals agree with depth-derived ones (cos > 0.95) on %.1f %% of pixels\n",
                  100.0 * agree / n);
    assert_true(agree > 0.85 * n);
    free(pos);
    obs_gbuffer_free(&gf);
}

/* Without any camera the run is refused with a message saying what to
 * give; a field of view alone is enough. */
static void test_camera_resolution(void **state)
{
    (void)state;
    float depth = 1;
    obs_gbuffer gb = {0};
    obs_params p = {0}, rp;
    obs_camera cam;
    char err[OBS_ERR_LEN] = "";
    gb.width = gb.height = 1;
    gb.depth = (obs_plane){&depth, 1, 0};
    obs_params_resolve(&p, &rp);
    assert_int_equal(obs__camera_resolve(&gb, &rp, &cam, err), OBS_NO_CAMERA);
    assert_non_null(strstr(err, "--camera"));
    p.fov_y = 50;
    obs_params_resolve(&p, &rp);
    assert_int_equal(obs__camera_resolve(&gb, &rp, &cam, err), OBS_OK);
    assert_int_equal(cam.source, OBS_CAMERA_PARAMS);
    assert_float_equal(cam.projection[5], 1.0f / tanf(25.0f * (float)M_PI / 180.0f), 1e-5f);
    /* a world_to_camera parameter overrides the file's rotation */
    assert_int_equal(obs_param_set(&p, "world_to_camera", "0 0 1 0  0 1 0 0  -1 0 0 0  0 0 0 1", err), OBS_OK);
    obs_params_resolve(&p, &rp);
    assert_int_equal(obs__camera_resolve(&gb, &rp, &cam, err), OBS_OK);
    assert_int_equal(cam.has_world_to_camera, 1);
    assert_float_equal(cam.world_to_camera[2], 1.0f, 0.0f);
}

/* A binary request's matrices: the source says PARAMS only with a
 * projection, and the flags are 0 or 1 whatever bit carried them. */
static void test_camera_from_request(void **state)
{
    (void)state;
    obs_camera cam = {0};
    obs_camera_from_request(&cam, 1 << 5, 0);
    assert_int_equal(cam.has_world_to_camera, 1);
    assert_int_equal(cam.has_projection, 0);
    assert_int_equal(cam.source, OBS_CAMERA_NONE);
    obs_camera_from_request(&cam, 0, 1 << 6);
    assert_int_equal(cam.has_world_to_camera, 0);
    assert_int_equal(cam.has_projection, 1);
    assert_int_equal(cam.source, OBS_CAMERA_PARAMS);
}

/* The writer's attributes: none without a world_to_camera, worldToNDC
 * only with a projection, and worldToNDC maps the view axis to the
 * standard's NDC centre (0.5, 0.5). */
static void test_camera_exr_attrs(void **state)
{
    (void)state;
    obs_camera cam;
    obs__camera_attr a[OBS__CAMERA_ATTRS];
    obs_camera_from_fov(60.0f, 1.5f, 0.1f, 100.0f, &cam);
    assert_int_equal(obs__camera_exr_attrs(NULL, a), 0);
    assert_int_equal(obs__camera_exr_attrs(&cam, a), 0);
    cam.has_world_to_camera = 1;
    assert_int_equal(obs__camera_exr_attrs(&cam, a), 2);
    assert_string_equal(a[0].name, "worldToCamera");
    assert_string_equal(a[1].name, "worldToNDC");
    /* a row vector (0, 0, -1, 1) in front of the camera, through worldToNDC */
    const float x[4] = {0, 0, -1, 1};
    float y[4] = {0, 0, 0, 0};
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 4; r++)
            y[c] += x[r] * a[1].m[4 * r + c];
    assert_float_equal(y[0] / y[3], 0.5f, 1e-6f);
    assert_float_equal(y[1] / y[3], 0.5f, 1e-6f);
    cam.has_projection = 0;
    assert_int_equal(obs__camera_exr_attrs(&cam, NULL), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_known_point),
        cmocka_unit_test(test_data_window_offset),
        cmocka_unit_test(test_blender_positions),
        cmocka_unit_test(test_world_normals_match_geometry),
        cmocka_unit_test(test_camera_resolution),
        cmocka_unit_test(test_camera_from_request),
        cmocka_unit_test(test_camera_exr_attrs),
    };
    return cmocka_run_group_tests_name("camera", tests, NULL, NULL);
}
