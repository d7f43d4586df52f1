/* The scene loader (assimp) and the G-buffer rasteriser: camera-matrix
 * conventions on a mesh built here, error cases, and agreement with
 * Blender's depth and normal passes of the room scene (shared data). */
#include <math.h>
#include <openexr.h>

#include "testutil.h"

#include "obscura/io.h"
#include "obscura/scene.h"

#define W 96
#define H 64

static obs_ctx *ctx;

static int setup(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    if (obs_ctx_create(NULL, &ctx, err) != OBS_OK) {
        fprintf(stderr, "no GL context: %s\n", err);
        return -1;
    }
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    obs_ctx_destroy(ctx);
    return 0;
}

/* A floor (z = 0, 4 x 4 m) and a tilted quad above it, as an OBJ with
 * vertex normals; the floor's winding faces +Z. */
static const char *const scene_obj =
    "# floor and a tilted panel\n"
    "v -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\n"
    "v -0.5 -0.2 0.3\nv 0.5 -0.2 0.3\nv 0.5 0.4 0.9\nv -0.5 0.4 0.9\n"
    "vn 0 0 1\nvn 0 -0.7071068 0.7071068\n"
    "f 1//1 2//1 3//1 4//1\n"
    "f 5//2 6//2 7//2 8//2\n";

/* A camera at (1.5, -3, 2.5) looking at the origin, +Z up. */
static void look_at_camera(obs_camera *cam)
{
    const float eye[3] = {1.5f, -3.0f, 2.5f};
    float f[3] = {-eye[0], -eye[1], -eye[2]}, up[3] = {0, 0, 1}, s[3], u[3];
    float lf = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; k++)
        f[k] /= lf;
    s[0] = f[1] * up[2] - f[2] * up[1];
    s[1] = f[2] * up[0] - f[0] * up[2];
    s[2] = f[0] * up[1] - f[1] * up[0];
    float ls = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int k = 0; k < 3; k++)
        s[k] /= ls;
    u[0] = s[1] * f[2] - s[2] * f[1];
    u[1] = s[2] * f[0] - s[0] * f[2];
    u[2] = s[0] * f[1] - s[1] * f[0];
    obs_camera_from_fov(45.0f, (float)W / H, 0.1f, 100.0f, cam);
    float *m = cam->world_to_camera;
    for (int k = 0; k < 3; k++) {
        m[k] = s[k];
        m[4 + k] = u[k];
        m[8 + k] = -f[k];
    }
    m[3] = -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    m[7] = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    m[11] = f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2];
    m[12] = m[13] = m[14] = 0.0f;
    m[15] = 1.0f;
    cam->has_world_to_camera = 1;
}

static void load_test_scene(obs_scene *s)
{
    char err[OBS_ERR_LEN] = "";
    if (obs_scene_load(obs_test_tmp_file("scene.obj", scene_obj), s, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(s->triangle_count, 4);
    assert_non_null(s->normals);
    assert_null(s->albedo); /* no material in the file */
    assert_float_equal(s->bounds_min[0], -2.0f, 0);
    assert_float_equal(s->bounds_max[2], 0.9f, 1e-6);
}

/* Each pixel's position, projected by the worldToNDC the G-buffer EXR
 * carries (OpenEXR: row vectors, (0,0) top-left, (1,1) bottom-right of the
 * display window), lands on the centre of that pixel; its depth is the
 * planar view depth; the camera reads back from the header. */
static void test_conventions(void **state)
{
    (void)state;
    obs_scene scene;
    obs_camera cam;
    obs_raster r;
    char err[OBS_ERR_LEN] = "";
    load_test_scene(&scene);
    look_at_camera(&cam);
    if (obs_raster_gbuffer(ctx, &scene, &cam, W, H, &r, err) != OBS_OK)
        fail_msg("%s", err);

    static const char *const nz[] = {"Z"}, *const np[] = {"P.X", "P.Y", "P.Z"};
    obs_exr_layer layers[] = {{&r.depth, nz}, {&r.position, np}};
    const char *path = obs_test_tmp_file("raster.exr", NULL);
    assert_int_equal(obs_exr_write(path, layers, 2, OBS_EXR_FLOAT, &cam, err), OBS_OK);
    exr_context_t ex;
    exr_attr_m44f_t ndc;
    assert_int_equal(exr_start_read(&ex, path, NULL), EXR_ERR_SUCCESS);
    assert_int_equal(exr_attr_get_m44f(ex, 0, "worldToNDC", &ndc), EXR_ERR_SUCCESS);
    exr_finish(&ex);

    int covered = 0;
    double worst = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + x;
            float a = r.color.data[4 * i + 3];
            if (a == 0.0f) {
                assert_float_equal(r.depth.data[i], OBS_SKY_DEPTH, 0);
                continue;
            }
            covered++;
            const float *p = r.position.data + 3 * i;
            float q[4] = {0, 0, 0, 0};
            for (int j = 0; j < 4; j++)
                for (int k = 0; k < 4; k++)
                    q[j] += (k < 3 ? p[k] : 1.0f) * ndc.m[k * 4 + j];
            double px = q[0] / q[3] * W, py = q[1] / q[3] * H;
            worst = fmax(worst, fmax(fabs(px - (x + 0.5)), fabs(py - (y + 0.5))));
            const float *m = cam.world_to_camera;
            float zc = m[8] * p[0] + m[9] * p[1] + m[10] * p[2] + m[11];
            assert_float_equal(r.depth.data[i], -zc, 1e-4 * -zc);
            /* normals are unit, face the camera, and the two spaces agree */
            const float *n = r.normal.data + 3 * i, *nc = r.normal_cam.data + 3 * i;
            float nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            assert_float_equal(nn, 1.0f, 1e-4);
            for (int k = 0; k < 3; k++)
                assert_float_equal(nc[k], m[4 * k] * n[0] + m[4 * k + 1] * n[1] + m[4 * k + 2] * n[2], 1e-4);
            float pc[3] = {m[0] * p[0] + m[1] * p[1] + m[2] * p[2] + m[3],
                           m[4] * p[0] + m[5] * p[1] + m[6] * p[2] + m[7], zc};
            assert_true(nc[0] * pc[0] + nc[1] * pc[1] + nc[2] * pc[2] < 0.0f);
        }
    assert_true(covered > W * H / 4);
    assert_true(worst < 0.02); /* pixels */

    /* the floor is seen at the image centre's bottom half, normal +Z */
    size_t i = (size_t)(H - 4) * W + W / 2;
    assert_float_equal(r.position.data[3 * i + 2], 0.0f, 1e-5);
    assert_float_equal(r.normal.data[3 * i + 2], 1.0f, 1e-5);

    /* the camera reads back from the header */
    obs_gbuffer_file f;
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &f, err), OBS_OK);
    assert_int_equal(f.gb.camera.source, OBS_CAMERA_EXR_HEADER);
    for (int k = 0; k < 16; k++) {
        assert_float_equal(f.gb.camera.world_to_camera[k], cam.world_to_camera[k], 1e-5);
        if (k / 4 != 2) /* the z row is not stored by OpenEXR */
            assert_float_equal(f.gb.camera.projection[k], cam.projection[k], 1e-4);
    }
    obs_gbuffer_free(&f);
    obs_raster_free(&r);
    obs_scene_free(&scene);
}

/* Another aspect (obs_camera_fit_aspect, used by `obscura gbuffer
 * --width --height`): twice as wide with the same vertical field of view,
 * the middle W columns see exactly what the W x H image sees. */
static void test_fit_aspect(void **state)
{
    (void)state;
    obs_scene scene;
    obs_camera cam, wide;
    obs_raster a, b;
    char err[OBS_ERR_LEN] = "";
    load_test_scene(&scene);
    look_at_camera(&cam);
    wide = cam;
    assert_int_equal(obs_camera_fit_aspect(&wide, W, H), 0); /* already fits */
    assert_int_equal(obs_camera_fit_aspect(&wide, 2 * W, H), 1);
    assert_float_equal(wide.projection[0], cam.projection[0] / 2, 1e-6);
    assert_float_equal(wide.projection[5], cam.projection[5], 0);
    if (obs_raster_gbuffer(ctx, &scene, &cam, W, H, &a, err) != OBS_OK ||
        obs_raster_gbuffer(ctx, &scene, &wide, 2 * W, H, &b, err) != OBS_OK)
        fail_msg("%s", err);
    int same = 0, covered = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float da = a.depth.data[(size_t)y * W + x];
            float db = b.depth.data[(size_t)y * 2 * W + x + W / 2];
            covered += da < OBS_SKY_DEPTH;
            same += fabsf(da - db) <= 1e-4f * da;
        }
    print_message("fit aspect: %d of %d pixels equal (%d with geometry)\n", same, W * H, covered);
    assert_true(covered > W * H / 4);
    assert_true(same >= W * H - W * H / 1000); /* a rasterisation tie may differ */
    /* an off-centre projection is left alone */
    obs_camera off = cam;
    off.projection[2] = 0.1f;
    assert_int_equal(obs_camera_fit_aspect(&off, 2 * W, H), 0);
    assert_float_equal(off.projection[0], cam.projection[0], 0);
    obs_raster_free(&a);
    obs_raster_free(&b);
    obs_scene_free(&scene);
}

/* A triangle seen from its back gets its normal flipped towards the
 * camera; albedo from a material; OFF, PLY and glTF. */
static void test_backface_albedo_formats(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_scene s;
    obs_camera cam;
    obs_raster r;
    /* the floor wound clockwise seen from above: its normal (file) is -Z */
    const char *mtl = "newmtl red\nKd 0.8 0.1 0.05\n";
    const char *obj = "mtllib back.mtl\nusemtl red\n"
                      "v -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\nvn 0 0 -1\n"
                      "f 1//1 4//1 3//1 2//1\n";
    obs_test_tmp_file("back.mtl", mtl);
    if (obs_scene_load(obs_test_tmp_file("back.obj", obj), &s, err) != OBS_OK)
        fail_msg("%s", err);
    assert_non_null(s.albedo);
    assert_float_equal(s.albedo[0], 0.8f, 1e-6);
    look_at_camera(&cam);
    assert_int_equal(obs_raster_gbuffer(ctx, &s, &cam, W, H, &r, err), OBS_OK);
    assert_int_equal(r.has_albedo, 1);
    size_t i = (size_t)(H - 4) * W + W / 2;
    assert_float_equal(r.normal.data[3 * i + 2], 1.0f, 1e-5);
    assert_float_equal(r.color.data[4 * i + 0], 0.8f, 1e-6);
    assert_float_equal(r.color.data[4 * i + 2], 0.05f, 1e-6);
    assert_float_equal(r.color.data[4 * i + 3], 1.0f, 0);
    obs_raster_free(&r);
    obs_scene_free(&s);

    /* OFF and ASCII PLY: the same quad, no normals in the file (made per
     * face by the loader) */
    const char *off = "OFF\n4 1 0\n-2 -2 0\n2 -2 0\n2 2 0\n-2 2 0\n4 0 1 2 3\n";
    const char *ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                      "property float y\nproperty float z\nelement face 1\n"
                      "property list uchar int vertex_indices\nend_header\n"
                      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_int_equal(obs_scene_load(obs_test_tmp_file("quad.off", off), &s, err), OBS_OK);
    assert_int_equal(s.triangle_count, 2);
    obs_scene_free(&s);
    assert_int_equal(obs_scene_load(obs_test_tmp_file("tri.ply", ply), &s, err), OBS_OK);
    assert_int_equal(s.triangle_count, 1);
    assert_float_equal(fabsf(s.normals[2]), 1.0f, 1e-5);
    obs_scene_free(&s);

    /* glTF: a node translation (z + 1) is applied, the PBR base colour is
     * the albedo */
    const char *gltf =
        "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"scene\":0,"
        "\"nodes\":[{\"mesh\":0,\"translation\":[0,0,1]}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0}]}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.2,0.4,0.6,1]}}],"
        "\"buffers\":[{\"byteLength\":44,\"uri\":\"data:application/octet-stream;base64,"
        "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
        "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
        "\"min\":[0,0,0],\"max\":[1,1,0]},"
        "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}";
    if (obs_scene_load(obs_test_tmp_file("tri.gltf", gltf), &s, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(s.triangle_count, 1);
    assert_float_equal(s.bounds_min[2], 1.0f, 0);
    assert_non_null(s.albedo);
    assert_float_equal(s.albedo[1], 0.4f, 1e-6);
    obs_scene_free(&s);
}

static void test_errors(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_scene s;
    obs_camera cam;
    obs_raster r;
    assert_int_equal(obs_scene_load("tests/data/no-such-mesh.obj", &s, err), OBS_IO);
    assert_non_null(strstr(err, "no-such-mesh.obj"));
    assert_int_equal(obs_scene_load(obs_test_tmp_file("junk.ply", "ply\nthis is not a mesh\n"), &s, err),
                     OBS_BAD_FILE);
    assert_int_equal(obs_scene_load(obs_test_tmp_file("empty.obj", "# nothing\nv 0 0 0\n"), &s, err),
                     OBS_BAD_FILE);
    assert_int_equal(obs_scene_load(obs_test_tmp_file("lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n"), &s, err),
                     OBS_BAD_FILE);
    assert_non_null(strstr(err, "no triangles"));
    assert_null(s.positions);

    /* a scene built in memory with a bad index */
    float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    uint32_t idx[3] = {0, 1, 3};
    obs_scene m = {.vertex_count = 3, .positions = pos, .triangle_count = 1, .indices = idx};
    assert_int_equal(obs_scene_check(&m, err), OBS_BAD_FILE);
    idx[2] = 2;
    assert_int_equal(obs_scene_check(&m, err), OBS_OK);

    /* no camera, bad size, empty scene */
    memset(&cam, 0, sizeof cam);
    assert_int_equal(obs_raster_gbuffer(ctx, &m, &cam, W, H, &r, err), OBS_NO_CAMERA);
    look_at_camera(&cam);
    assert_int_equal(obs_raster_gbuffer(ctx, &m, &cam, 0, H, &r, err), OBS_INVALID_ARGUMENT);
    obs_scene e = {0};
    assert_int_equal(obs_raster_gbuffer(ctx, &e, &cam, W, H, &r, err), OBS_INVALID_ARGUMENT);
    /* the in-memory triangle without normals renders (geometric normal) */
    assert_int_equal(obs_raster_gbuffer(ctx, &m, &cam, W, H, &r, err), OBS_OK);
    obs_raster_free(&r);
    /* a camera 1e30 away (its translation): it drew nothing, with exit 0,
     * and gbuffer's header lost the camera; refused by the scenes' bound */
    cam.world_to_camera[11] -= 1e30f;
    assert_int_equal(obs_raster_gbuffer(ctx, &m, &cam, W, H, &r, err), OBS_NO_CAMERA);
    assert_non_null(strstr(err, "a coordinate beyond +-1e9"));
    assert_null(r.depth.data);
}

/* Depth and normals of room.obj rasterised with room.camera.json against
 * Blender's passes in room.exr.  Blender's passes are filtered over a
 * pixel footprint (Cycles' 1.5 px Blackman-Harris filter, 128 samples), so
 * pixels at silhouettes and creases mix two surfaces; "interior" pixels
 * are those whose 3x3 neighbourhood in Blender's passes is one smooth
 * surface (depth within 2 % of the centre, normals within 10 degrees). */
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
    obs_raster r;
    int cw, ch;
    if (obs_scene_load(path, &s, err) != OBS_OK)
        fail_msg("%s", err);
    snprintf(path, sizeof path, "%s/room.camera.json", dir);
    assert_int_equal(obs_camera_read_json(path, &cam, &cw, &ch, err), OBS_OK);
    if (obs_raster_gbuffer(ctx, &s, &cam, cw, ch, &r, err) != OBS_OK)
        fail_msg("%s", err);

    obs_image bz = {0}, bn[3] = {{0}};
    static const char *const nn[] = {"ViewLayer.Normal.X", "ViewLayer.Normal.Y", "ViewLayer.Normal.Z"};
    snprintf(path, sizeof path, "%s/room.exr", dir);
    assert_int_equal(obs_exr_read_channel(path, "ViewLayer.Depth.Z", NULL, &bz, err), OBS_OK);
    for (int k = 0; k < 3; k++)
        assert_int_equal(obs_exr_read_channel(path, nn[k], NULL, &bn[k], err), OBS_OK);
    assert_int_equal(bz.width, cw);
    assert_int_equal(bz.height, ch);

    long geo = 0, both = 0, depth_ok = 0, normal_ok = 0, in = 0, in_depth = 0, in_normal = 0;
    for (int y = 0; y < ch; y++)
        for (int x = 0; x < cw; x++) {
            size_t i = (size_t)y * cw + x;
            float zb = bz.data[i], zo = r.depth.data[i];
            int gb = zb < 1e9f, go = zo < 1e9f;
            geo += gb || go;
            if (!gb || !go)
                continue;
            both++;
            float nb[3] = {bn[0].data[i], bn[1].data[i], bn[2].data[i]};
            const float *no = r.normal.data + 3 * i;
            float lb = sqrtf(nb[0] * nb[0] + nb[1] * nb[1] + nb[2] * nb[2]);
            float cosang = lb > 0 ? (nb[0] * no[0] + nb[1] * no[1] + nb[2] * no[2]) / lb : -1.0f;
            /* depth within 0.1 % (1 mm at 1 m); normals within 2 degrees */
            int dok = fabsf(zo - zb) <= 1e-3f * zb, nok = cosang >= cosf(2.0f * 3.14159265f / 180);
            depth_ok += dok;
            normal_ok += nok;
            int interior = x > 0 && y > 0 && x < cw - 1 && y < ch - 1;
            for (int dy = -1; dy <= 1 && interior; dy++)
                for (int dx = -1; dx <= 1 && interior; dx++) {
                    size_t j = (size_t)(y + dy) * cw + (x + dx);
                    float c = (bn[0].data[j] * nb[0] + bn[1].data[j] * nb[1] + bn[2].data[j] * nb[2]) / lb;
                    interior = fabsf(bz.data[j] - zb) <= 0.02f * zb && c >= cosf(10.0f * 3.14159265f / 180);
                }
            in += interior;
            in_depth += interior && dok;
            in_normal += interior && nok;
        }
    printf("room: %ld pixels with geometry, %ld in both; depth within 0.1%%: %.2f%% (interior "
           "%.3f%% of %ld), normals within 2 deg: %.2f%% (interior %.3f%%)\n",
           geo, both, 100.0 * depth_ok / both, 100.0 * in_depth / in, in, 100.0 * normal_ok / both,
           100.0 * in_normal / in);
    assert_true(both > 0.95 * geo);
    assert_true(in > 0.8 * both);
    assert_true(in_depth > 0.99 * in);
    assert_true(in_normal > 0.99 * in);

    obs_image_free(&bz);
    for (int k = 0; k < 3; k++)
        obs_image_free(&bn[k]);
    obs_raster_free(&r);
    obs_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_conventions),
        cmocka_unit_test(test_fit_aspect),
        cmocka_unit_test(test_backface_albedo_formats),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_blender_room),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
