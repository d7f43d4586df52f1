/* Frames of every renderer read right with no flags: the Blender scene
 * room_small rewritten by this test in each preset's convention (channel
 * names, depth convention, normal space, header keys, camera attributes)
 * gives the AO of the original within 1e-4; the real Arnold frame's
 * camera is detected in Arnold's NDC convention; each sanity warning
 * fires on a crafted input and on none of the Blender scenes. */
#include <math.h>

#include "gl_testutil.h"

#include "camera/camera.h"
#include "methods/methods.h"
#include "internal.h"
#include "obscura/deep.h"
#include "obscura/obscura.h"

/* How one renderer writes the scene. */
typedef enum { CAM_STANDARD, CAM_ARNOLD, CAM_VRAY } cam_style;
typedef struct rewrite {
    const char *preset;     /* the preset the reader is to detect */
    const char *depth;      /* channel names */
    const char *normal;     /* prefix of .X/.Y/.Z */
    const char *color;      /* prefix of .R/.G/.B; "" the bare R, G, B */
    obs_depth_mode depth_mode;
    obs_normal_space space;
    const char *key, *value; /* a string attribute that names the renderer */
    cam_style cam;
} rewrite;

static const rewrite rewrites[] = {
    {"arnold", "Z", "N", "", OBS_DEPTH_PLANAR, OBS_NORMALS_WORLD, "arnold/version", "Arnold 5.4", CAM_ARNOLD},
    {"vray", "Z", "normals", "diffuse", OBS_DEPTH_PLANAR, OBS_NORMALS_CAMERA, "vrayInfo/camera", "default", CAM_VRAY},
    {"renderman", "z", "Nn", "Ci", OBS_DEPTH_PLANAR, OBS_NORMALS_CAMERA, "software", "RenderMan 24.1", CAM_STANDARD},
    {"redshift", "Z", "N", "DiffuseFilter", OBS_DEPTH_PLANAR, OBS_NORMALS_WORLD, "rs/version", "3.5", CAM_STANDARD},
    {"karma", "depth", "N", "C", OBS_DEPTH_PLANAR, OBS_NORMALS_WORLD, "software", "Houdini Karma XPU", CAM_STANDARD},
    {"mantra", "Pz", "N", "C", OBS_DEPTH_PLANAR, OBS_NORMALS_CAMERA, "software", "Houdini Mantra 19", CAM_STANDARD},
    {"octane", "Z", "Normal", "Diffuse filter", OBS_DEPTH_PLANAR, OBS_NORMALS_WORLD, "software", "OctaneRender 2022", CAM_STANDARD},
    {"nuke", "depth.Z", "N", "", OBS_DEPTH_INVERSE, OBS_NORMALS_WORLD, "nuke/node_hash", "1f2e3d", CAM_STANDARD},
};

/* One float channel of w x h values. */
typedef struct plane {
    char name[64];
    float *data;
} plane;

/* Writes a scanline EXR of float channels with the given string and
 * matrix attributes (NULL names end the lists). */
static void write_exr(const char *path, int w, int h, plane *pl, int np, const char *const *keys,
                      const char *const *values, const char *const *mnames, const float (*m)[16],
                      const char *fname, float fvalue, const char *fname2, float fvalue2)
{
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    int part = 0;
    int32_t lines = 1;
    exr_chunk_info_t ci;
    exr_encode_pipeline_t enc;
    int started = 0;
    assert_int_equal(exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init), EXR_ERR_SUCCESS);
    assert_int_equal(exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part), EXR_ERR_SUCCESS);
    assert_int_equal(exr_initialize_required_attr_simple(ctx, part, w, h, EXR_COMPRESSION_ZIP), EXR_ERR_SUCCESS);
    exr_set_longname_support(ctx, 1);
    for (int c = 0; c < np; c++)
        assert_int_equal(exr_add_channel(ctx, part, pl[c].name, EXR_PIXEL_FLOAT,
                                         EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1), EXR_ERR_SUCCESS);
    for (int k = 0; keys && keys[k]; k++)
        assert_int_equal(exr_attr_set_string(ctx, part, keys[k], values[k]), EXR_ERR_SUCCESS);
    for (int k = 0; mnames && mnames[k]; k++) {
        exr_attr_m44f_t a;
        memcpy(a.m, m[k], sizeof a.m);
        assert_int_equal(exr_attr_set_m44f(ctx, part, mnames[k], &a), EXR_ERR_SUCCESS);
    }
    if (fname)
        assert_int_equal(exr_attr_set_float(ctx, part, fname, fvalue), EXR_ERR_SUCCESS);
    if (fname2)
        assert_int_equal(exr_attr_set_float(ctx, part, fname2, fvalue2), EXR_ERR_SUCCESS);
    assert_int_equal(exr_write_header(ctx), EXR_ERR_SUCCESS);
    assert_int_equal(exr_get_scanlines_per_chunk(ctx, part, &lines), EXR_ERR_SUCCESS);
    for (int y = 0; y < h; y += lines) {
        assert_int_equal(exr_write_scanline_chunk_info(ctx, part, y, &ci), EXR_ERR_SUCCESS);
        assert_int_equal(started ? exr_encoding_update(ctx, part, &ci, &enc)
                                 : exr_encoding_initialize(ctx, part, &ci, &enc), EXR_ERR_SUCCESS);
        started = 1;
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            for (int k = 0; k < np; k++)
                if (strcmp(ch->channel_name, pl[k].name) == 0)
                    ch->encode_from_ptr = (const uint8_t *)(pl[k].data + (size_t)ci.start_y * w);
            ch->user_pixel_stride = sizeof(float);
            ch->user_line_stride = w * (int32_t)sizeof(float);
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = sizeof(float);
        }
        assert_int_equal(exr_encoding_choose_default_routines(ctx, part, &enc), EXR_ERR_SUCCESS);
        assert_int_equal(exr_encoding_run(ctx, part, &enc), EXR_ERR_SUCCESS);
    }
    exr_encoding_destroy(ctx, &enc);
    assert_int_equal(exr_finish(&ctx), EXR_ERR_SUCCESS);
}

/* The focal length written with an Arnold camera, times this (a header
 * that disagrees with itself when not 1). */
static double focal_scale = 1.0;

/* room_small in renderer r's convention, written to `path`. */
static void write_rewrite(const rewrite *r, const obs_gbuffer *gb, const char *path)
{
    int w = gb->width, h = gb->height;
    size_t px = (size_t)w * h;
    plane pl[7];
    int np = 0;
    const obs_camera *cam = &gb->camera;
    const float *W = cam->world_to_camera, *P = cam->projection;
    for (int k = 0; k < 7; k++)
        assert_non_null(pl[k].data = malloc(px * sizeof(float)));
    snprintf(pl[np++].name, sizeof pl[0].name, "%s", r->depth);
    for (int k = 0; k < 3; k++)
        snprintf(pl[np++].name, sizeof pl[0].name, "%s.%c", r->normal, "XYZ"[k]);
    for (int k = 0; k < 3; k++)
        snprintf(pl[np++].name, sizeof pl[0].name, "%s%s%c", r->color, *r->color ? "." : "", "RGB"[k]);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            float d = *obs__plane_px(&gb->depth, w, x, y);
            const float *n = obs__plane_px(&gb->normal, w, x, y);
            const float *c = obs__plane_px(&gb->color, w, x, y);
            pl[0].data[i] = r->depth_mode == OBS_DEPTH_INVERSE ? 1.0f / d : d;
            for (int k = 0; k < 3; k++) {
                pl[1 + k].data[i] = r->space == OBS_NORMALS_CAMERA
                                        ? W[k * 4] * n[0] + W[k * 4 + 1] * n[1] + W[k * 4 + 2] * n[2]
                                        : n[k];
                pl[4 + k].data[i] = c[k];
            }
        }
    /* the camera in the renderer's attributes */
    static const float F[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1};
    float wtc[16], ndc[16], t[16], q[16];
    const char *names[3] = {NULL, NULL, NULL};
    float m[2][16];
    const char *keys[] = {r->key, NULL}, *values[] = {r->value, NULL};
    double tx = 1.0 / P[0]; /* tan of the horizontal half-angle */
    if (r->cam == CAM_VRAY) {
        float inv[16];
        assert_int_equal(obs__mat4_invert(W, inv), 0);
        obs__mat4_transpose(inv, m[0]);
        names[0] = "cameraTransform";
        write_exr(path, w, h, pl, np, keys, values, names, (const float (*)[16])m, "cameraFov",
                  (float)(360.0 / M_PI * atan(tx)), NULL, 0);
    } else {
        obs__exr_camera_matrices(cam, wtc, ndc);
        if (r->cam == CAM_ARNOLD) { /* -1..1, y up: the clip x, y rows */
            memcpy(q, P, sizeof q);
            obs__mat4_mul(q, W, t);
            obs__mat4_transpose(t, ndc);
        }
        (void)F;
        memcpy(m[0], wtc, sizeof wtc);
        memcpy(m[1], ndc, sizeof ndc);
        names[0] = "worldToCamera";
        names[1] = "worldToNDC";
        /* Arnold writes the lens too: aperture / (2 focal) = tan */
        write_exr(path, w, h, pl, np, keys, values, names, (const float (*)[16])m,
                  r->cam == CAM_ARNOLD ? "CameraFocalLength" : NULL, (float)(focal_scale * 0.5 / tx),
                  r->cam == CAM_ARNOLD ? "CameraFilmApertureHorizontal" : NULL, 1.0f);
    }
    for (int k = 0; k < 7; k++)
        free(pl[k].data);
}

static double max_diff(const obs_image *a, const obs_image *b)
{
    double m = 0;
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    for (size_t i = 0; i < (size_t)a->width * a->height * a->channels; i++)
        m = fmax(m, fabs((double)a->data[i] - b->data[i]));
    return m;
}

static void test_presets_round_trip(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_EGL_SURFACELESS);
    obs_gbuffer_file room = {0};
    obs_result ref;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    load(scenes[0], &room);
    assert_int_equal(obs_run(ctx, &room.gb, NULL, OBS_OUTPUT_AO, &ref, err), OBS_OK);
    for (size_t i = 0; i < sizeof rewrites / sizeof rewrites[0]; i++) {
        const rewrite *r = &rewrites[i];
        char name[64];
        snprintf(name, sizeof name, "rewrite_%s.exr", r->preset);
        const char *path = obs_test_tmp_file(name, NULL);
        write_rewrite(r, &room.gb, path);
        obs_gbuffer_file gf = {0};
        if (obs_gbuffer_read_exr(path, NULL, NULL, &gf, err) != OBS_OK)
            fail_msg("%s: %s", r->preset, err);
        assert_string_equal(gf.info.renderer, r->preset);
        assert_string_equal(gf.info.preset, r->preset);
        assert_string_equal(gf.info.depth, r->depth);
        assert_non_null(gf.gb.normal.data);
        assert_non_null(gf.gb.color.data);
        assert_int_equal(gf.info.camera_arnold, r->cam == CAM_ARNOLD);
        assert_true(gf.gb.camera.has_projection && gf.gb.camera.has_world_to_camera);
        obs_exr_info before = gf.info;
        assert_int_equal(obs_gbuffer_sanity(&gf.gb, NULL, &gf.info), 0);
        assert_int_equal(before.warning_count, 0);
        obs_result res;
        assert_int_equal(obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &res, err), OBS_OK);
        /* 1/Z in float does not give back Z exactly (a relative 1e-7),
         * which moves a few samples across an edge (max 1.6e-4 against the
         * original): the inverse file is compared with the AO of the depths
         * it can hold, 1 / float(1 / Z), read as planar. */
        obs_result held = {0};
        float *zf = NULL;
        if (r->depth_mode == OBS_DEPTH_INVERSE) {
            obs_gbuffer g = room.gb;
            size_t px = (size_t)g.width * g.height;
            assert_non_null(zf = malloc(px * sizeof *zf));
            for (int y = 0; y < g.height; y++)
                for (int x = 0; x < g.width; x++) {
                    volatile float inv = 1.0f / *obs__plane_px(&room.gb.depth, g.width, x, y);
                    zf[(size_t)y * g.width + x] = 1.0f / inv;
                }
            g.depth = (obs_plane){zf, 1, 0};
            assert_int_equal(obs_run(ctx, &g, NULL, OBS_OUTPUT_AO, &held, err), OBS_OK);
            print_message("%-9s max |AO - AO(blender)| %.2e (float 1/Z rounding)\n", r->preset,
                          max_diff(&res.ao, &ref.ao));
        }
        double m = max_diff(&res.ao, held.ao.data ? &held.ao : &ref.ao);
        obs_result_free(&held);
        free(zf);
        print_message("%-9s camera: %s; max |AO - AO(blender)| %.2e\n", r->preset,
                      gf.info.camera_source, m);
        assert_true(m < 1e-4);
        /* the same file read as the standard says (no preset, planar,
         * world) is wrong wherever the conventions differ */
        if (r->depth_mode != OBS_DEPTH_PLANAR || r->space != OBS_NORMALS_WORLD) {
            obs_params p = {0};
            obs_result bad;
            assert_int_equal(obs_param_set(&p, "depth_mode", "planar", err), OBS_OK);
            assert_int_equal(obs_param_set(&p, "normal_space", "world", err), OBS_OK);
            assert_int_equal(obs_run(ctx, &gf.gb, &p, OBS_OUTPUT_AO, &bad, err), OBS_OK);
            assert_true(max_diff(&bad.ao, &ref.ao) > 0.05);
            /* ... and the sanity check says so */
            obs_exr_info info = {0};
            assert_true(obs_gbuffer_sanity(&gf.gb, &p, &info) >= 1);
            obs_result_free(&bad);
        }
        obs_result_free(&res);
        obs_gbuffer_free(&gf);
    }
    obs_result_free(&ref);
    obs_gbuffer_free(&room);
    obs_ctx_destroy(ctx);
}

/* The real Arnold 4.2 frame (tests/data, MIT): its worldToNDC is in
 * Arnold's -1..1 convention, which the reader detects (the forward axis
 * lands at NDC (0, 0)) and which agrees with the header's focal length
 * and aperture.  The AO with no flags equals the AO with the correct
 * explicit field of view (2 atan(aperture / (2 focal)), worldToCamera
 * kept) within 1e-3 mean and 0.05 at any pixel: the two projections
 * differ only by the float rounding of worldToNDC and its off-axis terms
 * (1e-7), which can move a sample across a depth edge (one sample of 16
 * is 1/16 of the estimate). */
static void test_arnold_frame(void **state)
{
    const char *path = TESTDATA "/arnold_sample2.exr";
    obs_deep_image d = {0};
    obs_exr_info info = {0};
    obs_camera cam;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    assert_int_equal(obs_exr_describe_camera(path, 0, &info, &cam, err), OBS_OK);
    assert_string_equal(info.renderer, "arnold");
    assert_int_equal(info.camera_arnold, 1);
    assert_non_null(strstr(info.camera_check, "agrees"));
    assert_int_equal(info.warning_count, 0);
    /* the larger frame of the same set (../shared, when present): its
     * camera 23 units away once made the perspective test fail */
    char big[512];
    snprintf(big, sizeof big, "%s/renderers/arnold/sample1.exr", obs_test_shared());
    if (obs_test_exists(big)) {
        obs_exr_info i1 = {0};
        obs_camera c1;
        assert_int_equal(obs_exr_describe_camera(big, 0, &i1, &c1, err), OBS_OK);
        assert_int_equal(i1.camera_arnold, 1);
        assert_non_null(strstr(i1.camera_check, "agrees"));
        assert_float_equal(c1.projection[14], -1.0, 1e-6);
    } else {
        print_message("%s is absent: sample1 not checked\n", big);
    }
    assert_int_equal(obs_deep_read_exr(path, NULL, &d, err), OBS_OK);
    assert_int_equal(d.camera.has_projection, 1);
    /* focal 0.972222, aperture 1: tan(fov/2) = 1 / (2 * 0.972222) */
    double fov = 360.0 / M_PI * atan(1.0 / (2.0 * 0.972222));
    assert_float_equal(d.camera.projection[5], 1.0 / tan(fov * M_PI / 360.0), 1e-4);

    obs_ctx *ctx = make_ctx(OBS_BACKEND_EGL_SURFACELESS);
    obs_params explicit = {0};
    obs_deep_result a, b;
    char v[32];
    snprintf(v, sizeof v, "%.6f", fov);
    assert_int_equal(obs_param_set(&explicit, "fov_y", v, err), OBS_OK);
    assert_int_equal(obs_deep_run(ctx, &d, NULL, &a, err), OBS_OK);
    assert_int_equal(obs_deep_run(ctx, &d, &explicit, &b, err), OBS_OK);
    double mean, frac, m = max_diff(&a.ao_blend, &b.ao_blend);
    diff(&a.ao_blend, &b.ao_blend, &mean, &frac);
    print_message("arnold sample2: no flags vs --fov-y %s: mean %.2e, max %.2e, %.3f %% > 1e-3\n",
                  v, mean, m, 100 * frac);
    assert_true(mean < 1e-3);
    assert_true(m < 0.05);
    obs_deep_result_free(&a);
    obs_deep_result_free(&b);
    obs_ctx_destroy(ctx);
    obs_deep_free(&d);
}

/* Each warning on a crafted copy of room_small; none on the scenes. */
static void test_sanity_warnings(void **state)
{
    (void)state;
    for (size_t s = 0; s < sizeof scenes / sizeof scenes[0]; s++) {
        obs_gbuffer_file gf = {0};
        load(scenes[s], &gf);
        assert_int_equal(gf.info.warning_count, 0);
        assert_int_equal(obs_gbuffer_sanity(&gf.gb, NULL, &gf.info), 0);
        obs_gbuffer_free(&gf);
    }
    obs_gbuffer_file gf = {0};
    load(scenes[0], &gf);
    /* an Arnold header whose focal length says another field of view */
    const char *path = obs_test_tmp_file("arnold_bad_lens.exr", NULL);
    obs_gbuffer_file bad = {0};
    char err[OBS_ERR_LEN] = "";
    focal_scale = 1.5;
    write_rewrite(&rewrites[0], &gf.gb, path);
    focal_scale = 1.0;
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &bad, err), OBS_OK);
    print_message("bad lens: %s\n", bad.info.warning_count ? bad.info.warnings[0] : "(none)");
    assert_int_equal(bad.info.warning_count, 1);
    assert_non_null(strstr(bad.info.warnings[0], "disagrees with itself"));
    assert_non_null(strstr(bad.info.camera_check, "DISAGREES"));
    assert_int_equal(bad.info.camera_arnold, 1); /* the forward axis decides */
    obs_gbuffer_free(&bad);

    int w = gf.gb.width, h = gf.gb.height;
    size_t px = (size_t)w * h;
    float *depth = malloc(px * sizeof *depth), *nrm = malloc(px * 3 * sizeof *nrm);
    assert_non_null(depth);
    assert_non_null(nrm);
    const float *W = gf.gb.camera.world_to_camera;
    struct {
        const char *what, *expect;
    } cases[] = {
        {"normalized", "depth looks normalized"},
        {"inverse", "depth looks inverse"},
        {"half normals", "not unit length"},
        {"camera normals", "normals look camera-space"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        obs_gbuffer g = gf.gb;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t i = (size_t)y * w + x;
                float d = *obs__plane_px(&gf.gb.depth, w, x, y);
                const float *n = obs__plane_px(&gf.gb.normal, w, x, y);
                depth[i] = c == 0 ? (d < 1e9f ? d / 100.0f : 1.0f) : c == 1 ? 1.0f / d : d;
                for (int k = 0; k < 3; k++)
                    nrm[i * 3 + k] = c == 2 ? 0.5f * n[k]
                                     : c == 3 ? W[k * 4] * n[0] + W[k * 4 + 1] * n[1] + W[k * 4 + 2] * n[2]
                                              : n[k];
            }
        g.depth = (obs_plane){depth, 1, 0};
        g.normal = (obs_plane){nrm, 3, 0};
        obs_exr_info info = {0};
        int n = obs_gbuffer_sanity(&g, NULL, &info);
        print_message("%s: %d warning(s): %s\n", cases[c].what, n, n ? info.warnings[0] : "");
        assert_true(n >= 1);
        int found = 0;
        for (int k = 0; k < info.warning_count; k++)
            found |= strstr(info.warnings[k], cases[c].expect) != NULL;
        assert_true(found);
    }
    free(depth);
    free(nrm);
    obs_gbuffer_free(&gf);
}

/* --fov-x and --focal-length with --aperture make the camera --fov-y
 * does for the same lens. */
static void test_lens_parameters(void **state)
{
    obs_gbuffer_file gf = {0};
    obs_params a = {0}, b = {0}, c = {0}, ra, rb, rc;
    obs_camera ca, cb, cc;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    load(scenes[0], &gf);
    double aspect = (double)gf.gb.width / gf.gb.height;
    double tx = tan(50.0 * M_PI / 360.0) * aspect; /* fov_y 50 */
    char v[32];
    assert_int_equal(obs_param_set(&a, "fov_y", "50", err), OBS_OK);
    snprintf(v, sizeof v, "%.9g", 360.0 / M_PI * atan(tx));
    assert_int_equal(obs_param_set(&b, "fov_x", v, err), OBS_OK);
    assert_int_equal(obs_param_set(&c, "focal_length", "35", err), OBS_OK);
    snprintf(v, sizeof v, "%.9g", 70.0 * tx);
    assert_int_equal(obs_param_set(&c, "aperture", v, err), OBS_OK);
    obs_params_resolve(&a, &ra);
    obs_params_resolve(&b, &rb);
    obs_params_resolve(&c, &rc);
    assert_int_equal(obs__camera_resolve(&gf.gb, &ra, &ca, err), OBS_OK);
    assert_int_equal(obs__camera_resolve(&gf.gb, &rb, &cb, err), OBS_OK);
    assert_int_equal(obs__camera_resolve(&gf.gb, &rc, &cc, err), OBS_OK);
    for (int i = 0; i < 16; i++) {
        assert_float_equal(ca.projection[i], cb.projection[i], 1e-4);
        assert_float_equal(ca.projection[i], cc.projection[i], 1e-4);
    }
    obs_gbuffer_free(&gf);
}

/* P from depth and camera: the view point of each pixel (the prep pass's
 * CPU twin) taken back to the world.  `fisheye` bends the rays by an
 * equidistant fisheye mapping instead (a camera no pinhole explains). */
static float *position_from_depth(const obs_gbuffer *gb, int fisheye)
{
    char err[OBS_ERR_LEN] = "";
    obs_params p;
    obs__frame f;
    float inv[16];
    obs_params_resolve(NULL, &p);
    assert_int_equal(obs__frame_setup(NULL, gb, &p, &f, err), OBS_OK);
    assert_int_equal(obs__mat4_invert(gb->camera.world_to_camera, inv), 0);
    float *P = malloc((size_t)gb->width * gb->height * 3 * sizeof *P);
    assert_non_null(P);
    for (int y = 0; y < gb->height; y++)
        for (int x = 0; x < gb->width; x++) {
            float v[4], wv[4], o[4];
            obs__prep_position(&f, *obs__plane_px(&gb->depth, gb->width, x, y), x, y, v);
            if (fisheye && v[3] > 0.0f) { /* angle from the axis = 1.2 * pinhole's tangent */
                double r = sqrt(v[0] * v[0] + v[1] * v[1]) / v[3], th = 1.2 * r;
                double k = r > 0 ? tan(th) / r : 1.0;
                v[0] = (float)(v[0] * k);
                v[1] = (float)(v[1] * k);
            }
            wv[0] = v[0], wv[1] = v[1], wv[2] = v[2], wv[3] = 1.0f;
            obs__mat4_apply(inv, wv, o);
            memcpy(P + ((size_t)y * gb->width + x) * 3, o, 3 * sizeof *o);
        }
    return P;
}

static void test_solve_camera(void **state)
{
    obs_gbuffer_file gf = {0};
    obs_camera cam;
    double rms, maxe;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    load(scenes[0], &gf);
    float *P = position_from_depth(&gf.gb, 0);
    obs_plane pos = {P, 3, 0};
    assert_int_equal(obs_camera_solve_position(&gf.gb, &pos, &cam, &rms, err), OBS_OK);
    assert_int_equal(obs_camera_reprojection(&gf.gb, &pos, &cam, &rms, &maxe, err), OBS_OK);
    print_message("solved from P (depth + camera): RMS %.2e px, max %.2e px\n", rms, maxe);
    assert_true(rms < 0.05 && maxe < 0.05);
    /* the camera JSON's camera: rotation, translation and lens */
    for (int i = 0; i < 12; i++)
        assert_float_equal(cam.world_to_camera[i], gf.gb.camera.world_to_camera[i], 1e-3);
    for (int i = 0; i < 8; i++)
        assert_float_equal(cam.projection[i], gf.gb.camera.projection[i], 1e-3);
    /* Blender's own Position pass solves the same camera */
    assert_non_null(gf.gb.position.data);
    assert_string_equal(gf.info.position[0], "ViewLayer.Position.X");
    assert_int_equal(obs_camera_solve_position(&gf.gb, &gf.gb.position, &cam, &rms, err), OBS_OK);
    print_message("solved from ViewLayer.Position: RMS %.2e px\n", rms);
    assert_true(rms < 0.05);
    assert_float_equal(cam.projection[5], gf.gb.camera.projection[5], 1e-3);
    /* obs_gbuffer_solve_camera: only without a camera */
    obs_gbuffer_file nocam = {0};
    assert_int_equal(obs_gbuffer_read_exr(TESTDATA "/room_small.exr", NULL, NULL, &nocam, err), OBS_OK);
    assert_int_equal(nocam.gb.camera.has_projection, 0);
    assert_int_equal(obs_gbuffer_solve_camera(&nocam, NULL, err), OBS_OK);
    assert_int_equal(nocam.gb.camera.has_projection, 1);
    assert_non_null(strstr(nocam.info.camera_source, "solved from the position pass"));
    obs_gbuffer_free(&nocam);
    free(P);

    /* a fisheye's P is refused, naming the error */
    P = position_from_depth(&gf.gb, 1);
    pos.data = P;
    assert_int_equal(obs_camera_solve_position(&gf.gb, &pos, &cam, &rms, err), OBS_NO_CAMERA);
    print_message("fisheye P: %s\n", err);
    assert_non_null(strstr(err, "not consistent with a pinhole camera"));
    /* ... and the JSON camera disagrees with it: a sanity warning */
    obs_gbuffer g = gf.gb;
    g.position = pos;
    obs_exr_info info = {0};
    assert_true(obs_gbuffer_sanity(&g, NULL, &info) >= 1);
    assert_non_null(strstr(info.warnings[0], "disagrees with the position pass"));
    free(P);
    obs_gbuffer_free(&gf);
}

/* One part of a multi-part file the test writes. */
typedef struct part_spec {
    const char *name, *view; /* view NULL: none */
    plane *pl;
    int np;
} part_spec;

static void write_parts(const char *path, int w, int h, const part_spec *ps, int n,
                        const char **multiview, int nviews)
{
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    assert_int_equal(exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init), EXR_ERR_SUCCESS);
    for (int k = 0; k < n; k++) {
        int part = 0;
        assert_int_equal(exr_add_part(ctx, ps[k].name, EXR_STORAGE_SCANLINE, &part), EXR_ERR_SUCCESS);
        assert_int_equal(exr_initialize_required_attr_simple(ctx, part, w, h, EXR_COMPRESSION_ZIP), EXR_ERR_SUCCESS);
        for (int c = 0; c < ps[k].np; c++)
            assert_int_equal(exr_add_channel(ctx, part, ps[k].pl[c].name, EXR_PIXEL_FLOAT,
                                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1), EXR_ERR_SUCCESS);
        if (ps[k].view)
            assert_int_equal(exr_attr_set_string(ctx, part, "view", ps[k].view), EXR_ERR_SUCCESS);
        if (multiview)
            assert_int_equal(exr_attr_set_string_vector(ctx, part, "multiView", nviews, multiview), EXR_ERR_SUCCESS);
    }
    assert_int_equal(exr_write_header(ctx), EXR_ERR_SUCCESS);
    for (int k = 0; k < n; k++) {
        int32_t lines = 1;
        exr_chunk_info_t ci;
        exr_encode_pipeline_t enc;
        int started = 0;
        assert_int_equal(exr_get_scanlines_per_chunk(ctx, k, &lines), EXR_ERR_SUCCESS);
        for (int y = 0; y < h; y += lines) {
            assert_int_equal(exr_write_scanline_chunk_info(ctx, k, y, &ci), EXR_ERR_SUCCESS);
            assert_int_equal(started ? exr_encoding_update(ctx, k, &ci, &enc)
                                     : exr_encoding_initialize(ctx, k, &ci, &enc), EXR_ERR_SUCCESS);
            started = 1;
            for (int c = 0; c < enc.channel_count; c++) {
                exr_coding_channel_info_t *ch = &enc.channels[c];
                for (int q = 0; q < ps[k].np; q++)
                    if (strcmp(ch->channel_name, ps[k].pl[q].name) == 0)
                        ch->encode_from_ptr = (const uint8_t *)(ps[k].pl[q].data + (size_t)ci.start_y * w);
                ch->user_pixel_stride = sizeof(float);
                ch->user_line_stride = w * (int32_t)sizeof(float);
                ch->user_data_type = EXR_PIXEL_FLOAT;
                ch->user_bytes_per_element = sizeof(float);
            }
            assert_int_equal(exr_encoding_choose_default_routines(ctx, k, &enc), EXR_ERR_SUCCESS);
            assert_int_equal(exr_encoding_run(ctx, k, &enc), EXR_ERR_SUCCESS);
        }
        exr_encoding_destroy(ctx, &enc);
    }
    assert_int_equal(exr_finish(&ctx), EXR_ERR_SUCCESS);
}

/* room_small split over parts of two views (right the default: first in
 * multiView; the left view's depth doubled), colour and normals in parts
 * of their own: no flags reads the right view with its channels gathered
 * across parts, AO equal to the single-part file's; --view left and
 * --part pick the others. */
static void test_multipart_views(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_EGL_SURFACELESS);
    obs_gbuffer_file room = {0};
    obs_result ref, res;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    load(scenes[0], &room);
    int w = room.gb.width, h = room.gb.height;
    size_t px = (size_t)w * h;
    plane z_r = {"Z", malloc(px * 4)}, z_l = {"Z", malloc(px * 4)};
    plane n[3] = {{"N.X", malloc(px * 4)}, {"N.Y", malloc(px * 4)}, {"N.Z", malloc(px * 4)}};
    plane c[3] = {{"R", malloc(px * 4)}, {"G", malloc(px * 4)}, {"B", malloc(px * 4)}};
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            z_r.data[i] = *obs__plane_px(&room.gb.depth, w, x, y);
            z_l.data[i] = 2.0f * z_r.data[i];
            for (int k = 0; k < 3; k++) {
                n[k].data[i] = obs__plane_px(&room.gb.normal, w, x, y)[k];
                c[k].data[i] = obs__plane_px(&room.gb.color, w, x, y)[k];
            }
        }
    part_spec parts[] = {{"rgba_left", "left", c, 3},   {"depth_left", "left", &z_l, 1},
                         {"rgba_right", "right", c, 3}, {"normal_right", "right", n, 3},
                         {"depth_right", "right", &z_r, 1}};
    const char *views[] = {"right", "left"};
    const char *path = obs_test_tmp_file("views.exr", NULL);
    write_parts(path, w, h, parts, 5, views, 2);

    obs_gbuffer_file gf = {0};
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &gf, err), OBS_OK);
    assert_string_equal(gf.info.view, "right");
    assert_int_equal(gf.info.part, 4);
    assert_int_equal(gf.info.parts_read, 3);
    assert_non_null(gf.gb.normal.data);
    assert_non_null(gf.gb.color.data);
    gf.gb.camera = room.gb.camera;
    assert_int_equal(obs_run(ctx, &room.gb, NULL, OBS_OUTPUT_AO, &ref, err), OBS_OK);
    assert_int_equal(obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &res, err), OBS_OK);
    print_message("multi-part, default view right: max |AO - AO(single part)| %.2e\n",
                  max_diff(&res.ao, &ref.ao));
    assert_true(max_diff(&res.ao, &ref.ao) < 1e-4);
    obs_result_free(&res);
    obs_gbuffer_free(&gf);

    obs_channel_map left = {.view = "left"};
    assert_int_equal(obs_gbuffer_read_exr(path, &left, NULL, &gf, err), OBS_OK);
    assert_string_equal(gf.info.view, "left");
    assert_int_equal(gf.info.part, 1);
    assert_non_null(gf.gb.color.data);
    assert_null(gf.gb.normal.data);
    assert_float_equal(gf.gb.depth.data[w * (h / 2) + w / 2], z_l.data[w * (h / 2) + w / 2], 0);
    obs_gbuffer_free(&gf);

    obs_channel_map one = {.part = "depth_right"}, idx = {.part = "1"};
    assert_int_equal(obs_gbuffer_read_exr(path, &one, NULL, &gf, err), OBS_OK);
    assert_int_equal(gf.info.part, 4);
    assert_null(gf.gb.color.data);
    obs_gbuffer_free(&gf);
    assert_int_equal(obs_gbuffer_read_exr(path, &idx, NULL, &gf, err), OBS_OK);
    assert_int_equal(gf.info.part, 1);
    obs_gbuffer_free(&gf);
    obs_channel_map nope = {.view = "middle"}, nopart = {.part = "9"};
    assert_int_equal(obs_gbuffer_read_exr(path, &nope, NULL, &gf, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "no part of view 'middle'"));
    assert_int_equal(obs_gbuffer_read_exr(path, &nopart, NULL, &gf, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "depth_right"));

    free(z_r.data);
    free(z_l.data);
    for (int k = 0; k < 3; k++) {
        free(n[k].data);
        free(c[k].data);
    }
    obs_result_free(&ref);
    obs_gbuffer_free(&room);
    obs_ctx_destroy(ctx);
}

/* OpenEXR's Beachball/multipart.0001.exr (../shared, when present): the
 * default view is right (the first part's view; the first part with a
 * depth is the left view's), depth from depth_right, colour gathered from
 * rgba_right. */
static void test_beachball(void **state)
{
    char path[512], err[OBS_ERR_LEN] = "";
    obs_gbuffer_file gf = {0};
    (void)state;
    snprintf(path, sizeof path, "%s/openexr-images/Beachball/multipart.0001.exr", obs_test_shared());
    if (!obs_test_exists(path)) {
        print_message("skipped: %s is absent\n", path);
        skip();
    }
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &gf, err), OBS_OK);
    assert_string_equal(gf.info.view, "right");
    assert_int_equal(gf.info.part, 5);
    assert_int_equal(gf.info.parts_read, 2);
    assert_non_null(gf.gb.color.data);
    obs_gbuffer_free(&gf);
    obs_channel_map left = {.view = "left"};
    assert_int_equal(obs_gbuffer_read_exr(path, &left, NULL, &gf, err), OBS_OK);
    assert_int_equal(gf.info.part, 1);
    obs_gbuffer_free(&gf);
}

/* The sky as renderers write it (0, inf, 1e10, 1e30; 1/Z: 0) is
 * background: AO 1 and never an occluder. */
static void test_background_values(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_EGL_SURFACELESS);
    obs_gbuffer_file gf = {0};
    char err[OBS_ERR_LEN] = "";
    (void)state;
    load(scenes[0], &gf);
    int w = gf.gb.width, h = gf.gb.height;
    float *z = malloc((size_t)w * h * sizeof *z);
    obs_result ref;
    assert_non_null(z);
    assert_int_equal(obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &ref, err), OBS_OK);
    static const float sky[] = {0.0f, INFINITY, 1e10f, 1e30f};
    for (int mode = 0; mode < 2; mode++)
        for (size_t k = 0; k < sizeof sky / sizeof sky[0]; k++) {
            int first = -1;
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++) {
                    float d = *obs__plane_px(&gf.gb.depth, w, x, y);
                    int bg = !(d < 1e9f);
                    size_t i = (size_t)y * w + x;
                    if (bg && first < 0)
                        first = (int)i;
                    /* inverse: 1/Z, the sky 0 (the only value tried there) */
                    z[i] = mode ? (bg ? 0.0f : 1.0f / d) : (bg ? sky[k] : d);
                }
            assert_true(first >= 0);
            obs_gbuffer g = gf.gb;
            g.depth = (obs_plane){z, 1, 0};
            obs_params p = {0};
            obs_result r;
            assert_int_equal(obs_param_set(&p, "depth_mode", mode ? "inverse" : "planar", err), OBS_OK);
            assert_int_equal(obs_run(ctx, &g, &p, OBS_OUTPUT_AO, &r, err), OBS_OK);
            assert_float_equal(r.ao.data[first], 1.0f, 0);
            /* ... and the rest is Blender's (sky 1e10) AO: the sky occludes nothing */
            assert_true(max_diff(&r.ao, &ref.ao) < (mode ? 1e-3 : 1e-6));
            obs_result_free(&r);
            if (mode)
                break;
        }
    free(z);
    obs_result_free(&ref);
    obs_gbuffer_free(&gf);
    obs_ctx_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_presets_round_trip),
        cmocka_unit_test(test_arnold_frame),
        cmocka_unit_test(test_sanity_warnings),
        cmocka_unit_test(test_lens_parameters),
        cmocka_unit_test(test_solve_camera),
        cmocka_unit_test(test_multipart_views),
        cmocka_unit_test(test_beachball),
        cmocka_unit_test(test_background_values),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
