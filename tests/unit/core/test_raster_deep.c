/* The A-buffer rasteriser (obs_raster_deep: per-pixel linked lists, OITAO
 * section IV-A) against the flat one, node counts of stacked quads, the
 * deep EXR writer read back by core/io/exr_deep.c, the per-sample object
 * IDs (--ids) read back by the deep object masks, opacity specs and
 * materials, the ray-traced reference with transparency on an analytic
 * case, and multi-layer against single-layer AO on a scene with a
 * transparent pane (built here; the Blender room when ../shared is
 * present). */
#include <math.h>

#include "testutil.h"

#include "obscura/deep.h"
#include "obscura/io.h"
#include "obscura/mask.h"
#include "obscura/metrics.h"
#include "obscura/reference.h"
#include "obscura/scene.h"

/* The mesh of room.obj made transparent (see bench/QUALITY.md). */
#define ROOM_TRANSPARENT "Cube.012"

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

/* ---- scenes built here ------------------------------------------------------ */

typedef struct builder {
    float pos[3 * 256];
    uint32_t idx[3 * 256];
    float alpha[256];
    int nv, nt;
} builder;

/* A quad a, b, c, d (two triangles) of opacity alpha. */
static void quad(builder *b, const float v[4][3], float alpha)
{
    int v0 = b->nv;
    for (int k = 0; k < 4; k++)
        memcpy(b->pos + 3 * b->nv++, v[k], 3 * sizeof(float));
    static const int tri[6] = {0, 1, 2, 0, 2, 3};
    for (int t = 0; t < 2; t++) {
        for (int k = 0; k < 3; k++)
            b->idx[3 * b->nt + k] = (uint32_t)(v0 + tri[3 * t + k]);
        b->alpha[b->nt++] = alpha;
    }
}

/* An axis-aligned box from lo to hi (five faces: no bottom). */
static void box(builder *b, const float lo[3], const float hi[3], float alpha)
{
    const float x0 = lo[0], y0 = lo[1], z0 = lo[2], x1 = hi[0], y1 = hi[1], z1 = hi[2];
    const float f[5][4][3] = {
        {{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}},
        {{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}},
        {{x1, y1, z0}, {x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}},
        {{x0, y1, z0}, {x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}},
        {{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}},
    };
    for (int k = 0; k < 5; k++)
        quad(b, f[k], alpha);
}

/* The builder's triangles as a scene (borrowing its arrays); opacity only
 * when some triangle is not opaque. */
static obs_scene as_scene(builder *b)
{
    char err[OBS_ERR_LEN] = "";
    int any = 0;
    for (int t = 0; t < b->nt; t++)
        any |= b->alpha[t] < 1.0f;
    obs_scene s = {.vertex_count = (size_t)b->nv, .positions = b->pos,
                   .triangle_count = (size_t)b->nt, .indices = b->idx,
                   .opacity = any ? b->alpha : NULL};
    assert_int_equal(obs_scene_check(&s, err), OBS_OK);
    return s;
}

static void look_at(const float eye[3], const float at[3], float fov, int w, int h,
                    obs_camera *cam)
{
    float f[3] = {at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]}, up[3] = {0, 0, 1}, s[3], u[3];
    if (fabsf(f[0]) < 1e-6f && fabsf(f[1]) < 1e-6f) { /* looking straight down */
        up[1] = 1.0f;
        up[2] = 0.0f;
    }
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
    obs_camera_from_fov(fov, (float)w / (float)h, 0.05f, 100.0f, cam);
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

static int count_at(const obs_deep_image *d, int x, int y)
{
    size_t i = (size_t)y * d->width + x;
    return (int)(d->offset[i + 1] - d->offset[i]);
}

static const float *samples_at(const obs_deep_image *d, int x, int y)
{
    return d->samples + d->offset[(size_t)y * d->width + x] * OBS_DEEP_CH;
}

/* ---- PPLL against the flat raster ------------------------------------------- */

/* A floor, a box and a tilted opaque panel: the front node of every pixel
 * is the flat G-buffer's surface (depth and normal), and a pixel has a
 * node exactly where the flat raster has geometry. */
static void test_front_equals_flat(void **state)
{
    (void)state;
    enum { W = 96, H = 64 };
    builder b = {0};
    const float floor_[4][3] = {{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}};
    const float panel[4][3] = {{-0.5f, -0.2f, 0.3f}, {0.5f, -0.2f, 0.3f}, {0.5f, 0.4f, 0.9f},
                               {-0.5f, 0.4f, 0.9f}};
    const float lo[3] = {0.6f, 0.3f, 0}, hi[3] = {1.1f, 0.9f, 0.5f};
    quad(&b, floor_, 1);
    quad(&b, panel, 1);
    box(&b, lo, hi, 1);
    obs_scene s = as_scene(&b);
    obs_camera cam;
    const float eye[3] = {1.5f, -3.0f, 2.5f}, at[3] = {0, 0, 0};
    look_at(eye, at, 45, W, H, &cam);
    obs_raster r;
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    if (obs_raster_gbuffer(ctx, &s, &cam, W, H, &r, err) != OBS_OK ||
        obs_raster_deep(ctx, &s, &cam, W, H, &d, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(d.width, W);
    assert_int_equal(d.height, H);
    assert_true(d.has_normal && d.has_alpha && !d.has_color);
    assert_true(d.camera.has_projection);
    int covered = 0, layered = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + x;
            int n = count_at(&d, x, y);
            if (r.depth.data[i] >= 1e9f) {
                assert_int_equal(n, 0);
                continue;
            }
            covered++;
            layered += n > 1;
            assert_true(n >= 1);
            const float *f = samples_at(&d, x, y);
            assert_float_equal(f[OBS_DEEP_Z], r.depth.data[i], 1e-5 * r.depth.data[i]);
            assert_float_equal(f[OBS_DEEP_ZBACK], f[OBS_DEEP_Z], 0);
            assert_float_equal(f[OBS_DEEP_A], 1.0f, 0);
            for (int k = 0; k < 3; k++)
                assert_float_equal(f[OBS_DEEP_NX + k], r.normal.data[3 * i + k], 1e-4);
            for (int k = 1; k < n; k++)
                assert_true(f[k * OBS_DEEP_CH] >= f[(k - 1) * OBS_DEEP_CH]);
        }
    print_message("front node = flat raster at %d pixels (%d with more than one node)\n", covered,
                  layered);
    assert_true(covered > W * H / 3);
    assert_true(layered > 100); /* the panel and the box over the floor */
    obs_deep_free(&d);
    obs_raster_free(&r);
}

/* Three stacked quads parallel to the image plane (camera at the origin
 * looking down -Z), footprints overlapping by known amounts: the node
 * count of each pixel is the number of footprints holding its centre,
 * the nodes front to back with their opacities.  Together they make more
 * than two fragments per pixel: the node pool is grown and the pass drawn
 * again. */
static void test_stacked_quads(void **state)
{
    (void)state;
    enum { W = 64, H = 48 };
    obs_camera cam;
    obs_camera_from_fov(60.0f, (float)W / H, 0.1f, 100.0f, &cam);
    for (int k = 0; k < 16; k++)
        cam.world_to_camera[k] = k % 5 == 0 ? 1.0f : 0.0f;
    cam.has_world_to_camera = 1;
    /* footprints in NDC x (all of y), depth 2, 3, 4 */
    const float ndc[3][2] = {{-1.2f, 0.5f}, {-0.6f, 1.2f}, {-1.2f, 1.2f}}, z[3] = {2, 3, 4},
                alpha[3] = {0.25f, 0.5f, 1.0f};
    const float sx = cam.projection[0], sy = cam.projection[5];
    builder b = {0};
    for (int q = 0; q < 3; q++) {
        float x0 = ndc[q][0] * z[q] / sx, x1 = ndc[q][1] * z[q] / sx, y1 = 1.2f * z[q] / sy;
        const float v[4][3] = {{x0, -y1, -z[q]}, {x1, -y1, -z[q]}, {x1, y1, -z[q]}, {x0, y1, -z[q]}};
        quad(&b, v, alpha[q]);
    }
    obs_scene s = as_scene(&b);
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    if (obs_raster_deep(ctx, &s, &cam, W, H, &d, err) != OBS_OK)
        fail_msg("%s", err);
    long total = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float cx = ((float)x + 0.5f) / W * 2.0f - 1.0f;
            int want = 0, in[3];
            for (int q = 0; q < 3; q++)
                want += in[q] = cx > ndc[q][0] && cx < ndc[q][1];
            if (fabsf(cx - 0.5f) < 1e-3f || fabsf(cx + 0.6f) < 1e-3f)
                continue; /* a pixel centre on an edge */
            int n = count_at(&d, x, y);
            total += n;
            assert_int_equal(n, want);
            const float *f = samples_at(&d, x, y);
            for (int q = 0, k = 0; q < 3; q++) {
                if (!in[q])
                    continue;
                assert_float_equal(f[k * OBS_DEEP_CH + OBS_DEEP_Z], z[q], 1e-4);
                assert_float_equal(f[k * OBS_DEEP_CH + OBS_DEEP_A], alpha[q], 0);
                assert_float_equal(f[k * OBS_DEEP_CH + OBS_DEEP_NZ], 1.0f, 1e-5); /* facing the camera */
                /* counter-clockwise seen from the camera: a front face */
                assert_float_equal(f[k * OBS_DEEP_CH + OBS_DEEP_FACING], 1.0f, 0);
                k++;
            }
        }
    print_message("stacked quads: %ld nodes over %d pixels\n", total, W * H);
    assert_true(total > 2L * W * H); /* the pool had to grow */
    obs_deep_free(&d);
}

/* ---- the deep EXR writer ------------------------------------------------------ */

/* A floor (two triangles, opaque) and a pane standing on it (two, alpha
 * 0.5), seen from above one side, w x h. */
static obs_scene floor_and_pane(builder *b, int w, int h, obs_camera *cam)
{
    const float floor_[4][3] = {{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}};
    const float pane[4][3] = {{-1, -0.5f, 0}, {1, -0.5f, 0}, {1, -0.5f, 1}, {-1, -0.5f, 1}};
    quad(b, floor_, 1);
    quad(b, pane, 0.5f);
    const float eye[3] = {0.5f, -3.0f, 1.5f}, at[3] = {0, 0, 0.3f};
    look_at(eye, at, 50, w, h, cam);
    return as_scene(b);
}

/* What obs_deep_write_exr() writes, obs_deep_read_exr() reads: every
 * sample exactly (float channels), the flags, the camera. */
static void test_write_roundtrip(void **state)
{
    (void)state;
    enum { W = 40, H = 30 };
    builder b = {0};
    obs_camera cam;
    obs_scene s = floor_and_pane(&b, W, H, &cam);
    float albedo[3 * 8];
    for (int v = 0; v < 8; v++)
        for (int k = 0; k < 3; k++)
            albedo[3 * v + k] = v < 4 ? 0.8f : (k == 0 ? 0.9f : 0.1f);
    s.albedo = albedo;
    obs_deep_image d, e;
    char err[OBS_ERR_LEN] = "", path[512];
    if (obs_raster_deep(ctx, &s, &cam, W, H, &d, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(d.has_color, 1);
    snprintf(path, sizeof path, "%s/deep_roundtrip.exr", obs_test_tmp());
    if (obs_deep_write_exr(path, &d, err) != OBS_OK)
        fail_msg("%s", err);
    int deep = 0;
    assert_int_equal(obs_exr_is_deep(path, &deep, err), OBS_OK);
    assert_int_equal(deep, 1);
    if (obs_deep_read_exr(path, NULL, &e, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(e.width, W);
    assert_int_equal(e.height, H);
    assert_int_equal(e.display_width, W);
    assert_true(e.has_alpha && e.has_color && e.has_normal && e.has_facing && !e.has_zback);
    assert_memory_equal(e.offset, d.offset, ((size_t)W * H + 1) * sizeof *d.offset);
    assert_true(d.offset[(size_t)W * H] > (uint64_t)W * H / 2);
    int pane_px = 0;
    for (uint64_t k = 0; k < d.offset[(size_t)W * H]; k++) {
        const float *a = d.samples + k * OBS_DEEP_CH, *c = e.samples + k * OBS_DEEP_CH;
        for (int ch = 0; ch < OBS_DEEP_CH; ch++)
            assert_float_equal(c[ch], a[ch], 0);
        if (a[OBS_DEEP_A] == 0.5f) { /* the pane: colour premultiplied */
            pane_px++;
            assert_float_equal(a[OBS_DEEP_R], 0.45f, 1e-6);
        }
    }
    assert_true(pane_px > 50);
    assert_true(e.camera.has_world_to_camera && e.camera.has_projection);
    for (int k = 0; k < 16; k++) {
        assert_float_equal(e.camera.world_to_camera[k], cam.world_to_camera[k], 1e-5);
        if (k / 4 != 2) /* the z row is not stored by OpenEXR */
            assert_float_equal(e.camera.projection[k], cam.projection[k], 1e-4);
    }
    /* errors: no image, a path that cannot be written */
    assert_int_equal(obs_deep_write_exr(path, NULL, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_deep_write_exr("/nonexistent-dir/x.exr", &d, err), OBS_IO);
    assert_non_null(strstr(err, "/nonexistent-dir/x.exr"));
    obs_deep_free(&d);
    obs_deep_free(&e);
}

/* gbuffer --deep --ids: every sample's object (1 + its mesh's index),
 * written as a per-sample channel by obs_deep_write_exr_extra and read
 * back by the deep object masks at every sample: the pane left out of
 * the occluders weighs exactly its own samples 0. */
static void test_deep_ids(void **state)
{
    (void)state;
    enum { W = 40, H = 30 };
    builder b = {0};
    obs_camera cam;
    obs_scene s = floor_and_pane(&b, W, H, &cam);
    obs_scene_mesh meshes[2] = {{.name = "floor", .first_triangle = 0, .triangle_count = 2},
                                {.name = "pane", .first_triangle = 2, .triangle_count = 2}};
    s.meshes = meshes;
    s.mesh_count = 2;
    obs_deep_image d, e;
    float *ids = NULL;
    char err[OBS_ERR_LEN] = "", path[512];
    if (obs_raster_deep_ids(ctx, &s, &cam, W, H, &d, &ids, err) != OBS_OK)
        fail_msg("%s", err);
    const uint64_t n = d.offset[(size_t)W * H];
    int panes = 0;
    for (uint64_t k = 0; k < n; k++) { /* the pane is the one of alpha 0.5 */
        assert_true(ids[k] == (d.samples[k * OBS_DEEP_CH + OBS_DEEP_A] == 0.5f ? 2.0f : 1.0f));
        panes += ids[k] == 2.0f;
    }
    assert_true(panes > 50 && (uint64_t)panes < n);
    snprintf(path, sizeof path, "%s/deep_ids.exr", obs_test_tmp());
    const obs_deep_channel id = {"id", ids, 1};
    if (obs_deep_write_exr_extra(path, &d, &id, 1, NULL, err) != OBS_OK)
        fail_msg("%s", err);
    if (obs_deep_read_exr(path, NULL, &e, err) != OBS_OK)
        fail_msg("%s", err);
    obs_params p = {0};
    assert_int_equal(obs_param_set(&p, "occluders", "!id:id=2", err), OBS_OK);
    if (obs_deep_read_masks(&e, path, NULL, 0, &p, NULL, err) != OBS_OK)
        fail_msg("%s", err);
    assert_non_null(e.occluders);
    for (uint64_t k = 0; k < n; k++)
        assert_true(e.occluders[k] == (ids[k] == 2.0f ? 0.0f : 1.0f));
    free(ids);
    obs_deep_free(&d);
    obs_deep_free(&e);
}

/* ---- opacity: specs and materials ------------------------------------------------ */

static void test_opacity_specs(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_scene s;
    /* two named objects; the pane's material has d 0.4 (OBJ opacity) */
    obs_test_tmp_file("glass.mtl", "newmtl glass\nKd 0.9 0.9 1\nd 0.4\nnewmtl white\nKd 1 1 1\nd 1\n");
    const char *obj = obs_test_tmp_file("panes.obj",
                                "mtllib glass.mtl\n"
                                "o floor\nusemtl white\nv -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\n"
                                "f 1 2 3 4\n"
                                "o pane\nusemtl glass\nv -1 0 0\nv 1 0 0\nv 1 0 1\nv -1 0 1\n"
                                "f 5 6 7 8\n");
    if (obs_scene_load(obj, &s, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(s.mesh_count, 2);
    int pane = strcmp(s.meshes[0].name, "pane") == 0 ? 0 : 1;
    assert_string_equal(s.meshes[pane].name, "pane");
    assert_string_equal(s.meshes[1 - pane].name, "floor");
    assert_non_null(s.opacity);
    const size_t pt = s.meshes[pane].first_triangle, ft = s.meshes[1 - pane].first_triangle;
    assert_float_equal(s.opacity[pt], 0.4f, 1e-6);
    assert_float_equal(s.opacity[ft], 1.0f, 0);

    /* overrides, in order */
    assert_int_equal(obs_scene_set_opacity(&s, "0.25", err), OBS_OK);
    assert_float_equal(s.opacity[ft], 0.25f, 0);
    assert_int_equal(obs_scene_set_opacity(&s, "fl*=1", err), OBS_OK);
    assert_float_equal(s.opacity[ft], 1.0f, 0);
    assert_float_equal(s.opacity[pt + 1], 0.25f, 0);
    assert_int_equal(obs_scene_set_opacity(&s, "pane=0.5", err), OBS_OK);
    assert_float_equal(s.opacity[pt], 0.5f, 0);
    assert_float_equal(s.opacity[pt + 1], 0.5f, 0);

    /* errors */
    static const char *const bad[] = {"", "1.5", "-0.1", "x", "pane=", "=0.5", "pane=0.5x",
                                      "nan"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        err[0] = 0;
        assert_int_equal(obs_scene_set_opacity(&s, bad[k], err), OBS_INVALID_ARGUMENT);
        assert_true(err[0] != 0);
    }
    assert_int_equal(obs_scene_set_opacity(&s, "sofa=0.5", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "'sofa'"));
    assert_non_null(strstr(err, "'pane'")); /* the names there are */
    assert_float_equal(s.opacity[pt], 0.5f, 0); /* unchanged */
    obs_scene_free(&s);

    /* glTF: base colour alpha counts with alphaMode BLEND only */
    for (int blend = 0; blend < 2; blend++) {
        char gltf[2048];
        snprintf(gltf, sizeof gltf,
                 "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"scene\":0,"
                 "\"nodes\":[{\"mesh\":0,\"name\":\"glass\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,"
                 "\"material\":0}]}],"
                 "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.2,0.4,0.6,0.3]}%s}],"
                 "\"buffers\":[{\"byteLength\":44,\"uri\":\"data:application/octet-stream;base64,"
                 "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=\"}],"
                 "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
                 "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
                 "\"min\":[0,0,0],\"max\":[1,1,0]},"
                 "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}",
                 blend ? ",\"alphaMode\":\"BLEND\"" : "");
        if (obs_scene_load(obs_test_tmp_file("glass.gltf", gltf), &s, err) != OBS_OK)
            fail_msg("%s", err);
        if (blend) {
            assert_non_null(s.opacity);
            assert_float_equal(s.opacity[0], 0.3f, 1e-6);
        } else {
            assert_null(s.opacity);
        }
        if (obs_scene_set_opacity(&s, "glass=0.7", err) != OBS_OK)
            fail_msg("%s", err);
        assert_float_equal(s.opacity[0], 0.7f, 0);
        obs_scene_free(&s);
    }
}

/* ---- the reference with transparency --------------------------------------------- */

/* A floor (z = 0) under a slab of opacity alpha at height h < D, both
 * 200 m wide (infinite for rays of length D): a cosine-weighted ray from
 * the floor reaches the slab within D when cos(theta) > h / D, which has
 * probability 1 - (h/D)^2 (cos^2 is uniform for cosine weighting), so the
 * floor's AO is 1 - alpha (1 - (h/D)^2) (reference.h: transmittance).
 * From a camera above, the slab (AO 1: nothing above it) is blended over
 * the floor: alpha + (1 - alpha) (1 - alpha (1 - (h/D)^2)). */
static void test_reference_slab(void **state)
{
    (void)state;
    enum { W = 32, H = 32 };
    const float h = 0.25f, D = 0.5f, alpha = 0.5f, blocked = 1.0f - (h / D) * (h / D);
    builder b = {0};
    const float floor_[4][3] = {{-100, -100, 0}, {100, -100, 0}, {100, 100, 0}, {-100, 100, 0}};
    const float slab[4][3] = {{-100, -100, h}, {100, -100, h}, {100, 100, h}, {-100, 100, h}};
    quad(&b, floor_, 1);
    quad(&b, slab, alpha);
    obs_scene s = as_scene(&b);
    obs_camera cam;
    const float eye[3] = {0, 0, 2}, at[3] = {0, 0, 0};
    look_at(eye, at, 40, W, H, &cam);

    /* floor points (a G-buffer), opaque and transparent slab */
    obs_image pos = {0}, nrm = {0}, ao = {0};
    pos.width = nrm.width = W;
    pos.height = nrm.height = H;
    pos.channels = nrm.channels = 3;
    pos.data = malloc(sizeof(float) * 3 * W * H);
    nrm.data = malloc(sizeof(float) * 3 * W * H);
    for (int i = 0; i < W * H; i++) {
        float p[3] = {(float)(i % W) * 0.1f - 1.6f, (float)(i / W) * 0.1f - 1.6f, 0};
        float n[3] = {0, 0, 1};
        memcpy(pos.data + 3 * i, p, sizeof p);
        memcpy(nrm.data + 3 * i, n, sizeof n);
    }
    char err[OBS_ERR_LEN] = "";
    obs_reference_desc desc = {.distance = D, .spp = 64, .seed = 7, .threads = 2};
    obs_reference_view points = {.camera = &cam, .position = &pos, .normal = &nrm};
    obs_reference_view camera = {.camera = &cam, .width = W, .height = H};
    const float want[3] = {1.0f - blocked, 1.0f - alpha * blocked,
                           alpha + (1.0f - alpha) * (1.0f - alpha * blocked)};
    for (int c = 0; c < 3; c++) {
        s.opacity = c == 0 ? NULL : b.alpha;
        if (obs_reference_render(&s, c < 2 ? &points : &camera, &desc, &ao, NULL, err) != OBS_OK)
            fail_msg("%s", err);
        double mean = 0;
        for (int i = 0; i < W * H; i++)
            mean += ao.data[i];
        mean /= W * H;
        /* 65536 rays of variance <= 1/4: standard error <= 0.002 */
        print_message("slab case %d: mean AO %.4f, expected %.4f\n", c, mean, (double)want[c]);
        assert_float_equal(mean, want[c], 0.01);
        obs_image_free(&ao);
    }
    obs_image_free(&pos);
    obs_image_free(&nrm);
}

/* ---- multi-layer against single-layer AO ------------------------------------------ */

typedef struct errors {
    double mse_multi, mse_single, ssim_multi, ssim_single;
    double see_multi, see_single; /* MSE where the front surface is see-through */
    int see_n;                    /* those pixels */
} errors;

/* The A-buffer's multi-layer and single-layer AO (CPU twin) against the
 * reference with transparency, over the pixels with geometry, and over
 * those whose front surface is see-through (front sample's alpha < 1):
 * where the layers behind it are what multi-layer AO adds. */
static void measure(const obs_scene *s, const obs_camera *cam, int w, int h, float radius, int spp,
                    errors *e)
{
    char err[OBS_ERR_LEN] = "";
    obs_deep_image d;
    obs_deep_result multi, single;
    obs_image ref, depth;
    if (obs_raster_deep(ctx, s, cam, w, h, &d, err) != OBS_OK)
        fail_msg("%s", err);
    obs_params p = {0};
    p.radius = radius;
    if (obs_deep_run_cpu(&d, &p, &multi, err) != OBS_OK)
        fail_msg("%s", err);
    p.deep_mode = OBS_DEEP_SINGLE;
    if (obs_deep_run_cpu(&d, &p, &single, err) != OBS_OK)
        fail_msg("%s", err);
    obs_reference_view view = {.camera = cam, .width = w, .height = h};
    obs_reference_desc desc = {.distance = radius, .spp = spp, .seed = 1};
    if (obs_reference_render(s, &view, &desc, &ref, &depth, err) != OBS_OK)
        fail_msg("%s", err);
    unsigned char *mask = malloc((size_t)w * h), *see = malloc((size_t)w * h);
    e->see_n = 0;
    for (int i = 0; i < w * h; i++) {
        mask[i] = depth.data[i] < 1e9f;
        see[i] = mask[i] && d.offset[i + 1] > d.offset[i] &&
                 d.samples[d.offset[i] * OBS_DEEP_CH + OBS_DEEP_A] < 1.0f;
        e->see_n += see[i];
    }
    obs_metrics m1, m2, s1, s2;
    assert_int_equal(obs_metrics_compute(&ref, &multi.ao_blend, mask, &m1, err), OBS_OK);
    assert_int_equal(obs_metrics_compute(&ref, &single.ao_blend, mask, &m2, err), OBS_OK);
    assert_int_equal(obs_metrics_compute(&ref, &multi.ao_blend, see, &s1, err), OBS_OK);
    assert_int_equal(obs_metrics_compute(&ref, &single.ao_blend, see, &s2, err), OBS_OK);
    e->mse_multi = m1.mse;
    e->mse_single = m2.mse;
    e->ssim_multi = m1.ssim;
    e->ssim_single = m2.ssim;
    e->see_multi = s1.mse;
    e->see_single = s2.mse;
    free(mask);
    free(see);
    obs_image_free(&ref);
    obs_image_free(&depth);
    obs_deep_result_free(&multi);
    obs_deep_result_free(&single);
    obs_deep_free(&d);
}

/* A floor, a wall, a box and a half-transparent pane in front of them:
 * behind the pane, single-layer AO sees the pane only; multi-layer AO sees
 * the box and the creases through it, as the reference does. */
static void test_pane_multi_beats_single(void **state)
{
    (void)state;
    enum { W = 96, H = 72 };
    builder b = {0};
    const float floor_[4][3] = {{-3, -3, 0}, {3, -3, 0}, {3, 2, 0}, {-3, 2, 0}};
    const float wall[4][3] = {{-3, 2, 0}, {3, 2, 0}, {3, 2, 2}, {-3, 2, 2}};
    const float pane[4][3] = {{-1, 0, 0}, {1, 0, 0}, {1, 0, 0.9f}, {-1, 0, 0.9f}};
    const float lo[3] = {-0.4f, 0.25f, 0}, hi[3] = {0.3f, 0.8f, 0.6f};
    quad(&b, floor_, 1);
    quad(&b, wall, 1);
    box(&b, lo, hi, 1);
    quad(&b, pane, 0.5f);
    obs_scene s = as_scene(&b);
    obs_camera cam;
    const float eye[3] = {0.4f, -2.6f, 1.4f}, at[3] = {0, 0.5f, 0.3f};
    look_at(eye, at, 45, W, H, &cam);
    errors e;
    measure(&s, &cam, W, H, 0.5f, 32, &e);
    print_message("pane: MSE multi %.5f single %.5f, SSIM multi %.4f single %.4f; behind the pane "
                  "(%d px): MSE multi %.5f single %.5f\n",
                  e.mse_multi, e.mse_single, e.ssim_multi, e.ssim_single, e.see_n, e.see_multi,
                  e.see_single);
    assert_true(e.mse_multi < e.mse_single);
    assert_true(e.see_multi < e.see_single);
}

/* The Blender room (../shared/data/blender) with one mesh made
 * half-transparent, at a quarter of the camera's size. */
static void test_blender_room(void **state)
{
    (void)state;
    char path[600], err[OBS_ERR_LEN] = "";
    snprintf(path, sizeof path, "%s/blender/room.obj", obs_test_shared());
    if (!obs_test_exists(path))
        skip();
    obs_scene s;
    obs_camera cam;
    int cw, ch;
    if (obs_scene_load(path, &s, err) != OBS_OK)
        fail_msg("%s", err);
    snprintf(path, sizeof path, "%s/blender/room.camera.json", obs_test_shared());
    assert_int_equal(obs_camera_read_json(path, &cam, &cw, &ch, err), OBS_OK);
    if (obs_scene_set_opacity(&s, ROOM_TRANSPARENT "=0.5", err) != OBS_OK)
        fail_msg("%s", err);
    errors e;
    measure(&s, &cam, cw / 4, ch / 4, 0.5f, 16, &e);
    print_message("room (%s at 0.5): MSE multi %.5f single %.5f, SSIM multi %.4f single %.4f; "
                  "behind the mesh (%d px): MSE multi %.5f single %.5f\n",
                  ROOM_TRANSPARENT, e.mse_multi, e.mse_single, e.ssim_multi, e.ssim_single, e.see_n,
                  e.see_multi, e.see_single);
    /* Over the whole image the two tie here (bench/QUALITY.md): the
     * sofa is a small part of it, and multi-layer AO also darkens opaque
     * pixels next to the sofa, whose samples meet its back layers, a bit
     * more than the reference.  Behind the sofa, where the layers it
     * sees are the whole difference, it must win. */
    assert_true(e.see_multi < e.see_single);
    obs_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_front_equals_flat),
        cmocka_unit_test(test_stacked_quads),
        cmocka_unit_test(test_write_roundtrip),
        cmocka_unit_test(test_deep_ids),
        cmocka_unit_test(test_opacity_specs),
        cmocka_unit_test(test_reference_slab),
        cmocka_unit_test(test_pane_multi_beats_single),
        cmocka_unit_test(test_blender_room),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
