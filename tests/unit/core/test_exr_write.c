/* EXR output: round trips through the reader (half and float, channels
 * by name, obscura/version), camera attributes in OpenEXR's conventions,
 * and errors. */
#include "testutil.h"

#include <math.h>
#include <openexr.h>

#include "internal.h"
#include "io/exr_internal.h"
#include "obscura/io.h"

#define W 37
#define H 23

static const char *tmp_path(const char *name)
{
    static char path[2][512];
    static int i;
    i = (i + 1) % 2;
    snprintf(path[i], sizeof path[i], "%s/%s", obs_test_tmp(), name);
    return path[i];
}

/* Channel c of pixel i: distinct per channel, fractional, some outside [0,1]. */
static float value(int c, int i)
{
    return (float)c * 1.5f - 0.25f + (float)i * 0.0137f;
}

static obs_image make_image(int channels, int first_channel)
{
    obs_image img = {W, H, channels, malloc(sizeof(float) * W * H * (size_t)channels)};
    for (int i = 0; i < W * H; i++)
        for (int c = 0; c < channels; c++)
            img.data[i * channels + c] = value(first_channel + c, i);
    return img;
}

static void check_channel(const char *path, const char *name, int c, float tol)
{
    obs_image img;
    char err[OBS_ERR_LEN] = "";
    if (obs_exr_read_channel(path, name, NULL, &img, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(img.width, W);
    assert_int_equal(img.height, H);
    for (int i = 0; i < W * H; i++) {
        float want = value(c, i);
        if (fabsf(img.data[i] - want) > tol * fmaxf(1.0f, fabsf(want)))
            fail_msg("%s[%d] = %.7g, wrote %.7g", name, i, img.data[i], want);
    }
    obs_image_free(&img);
}

static void round_trip(obs_exr_pixel pixel, float tol)
{
    obs_image ao = make_image(1, 0), comp = make_image(4, 1);
    static const char *const ao_names[] = {"AO.Y"};
    static const char *const rgba[] = {"R", "G", "B", "A"};
    obs_exr_layer layers[] = {{&ao, ao_names}, {&comp, rgba}};
    const char *path = tmp_path(pixel == OBS_EXR_HALF ? "half.exr" : "float.exr");
    char err[OBS_ERR_LEN] = "";
    if (obs_exr_write(path, layers, 2, pixel, NULL, err) != OBS_OK)
        fail_msg("%s", err);
    check_channel(path, "AO.Y", 0, tol);
    check_channel(path, "R", 1, tol);
    check_channel(path, "G", 2, tol);
    check_channel(path, "B", 3, tol);
    check_channel(path, "A", 4, tol);

    char **names = NULL;
    assert_int_equal(obs_exr_list_channels(path, &names, err), OBS_OK);
    static const char *const sorted[] = {"A", "AO.Y", "B", "G", "R"};
    for (int i = 0; i < 5; i++)
        assert_string_equal(names[i], sorted[i]);
    assert_null(names[5]);
    obs_strv_free(names);

    /* the file says what it holds: ZIP, the pixel type asked for, and
     * which obscura wrote it (obscura/version, the one key without
     * provenance options) */
    exr_context_t ctx;
    exr_compression_t c;
    const exr_attr_chlist_t *cl;
    const exr_attribute_t *v = NULL, *m = NULL;
    assert_int_equal(exr_start_read(&ctx, path, NULL), EXR_ERR_SUCCESS);
    assert_int_equal(exr_get_compression(ctx, 0, &c), EXR_ERR_SUCCESS);
    assert_int_equal(c, EXR_COMPRESSION_ZIP);
    assert_int_equal(exr_get_channels(ctx, 0, &cl), EXR_ERR_SUCCESS);
    assert_int_equal(cl->entries[0].pixel_type, pixel == OBS_EXR_HALF ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT);
    assert_int_equal(exr_get_attribute_by_name(ctx, 0, "obscura/version", &v), EXR_ERR_SUCCESS);
    assert_int_equal(v->type, EXR_ATTR_STRING);
    assert_string_equal(v->string->str, OBS_VERSION);
    assert_int_not_equal(exr_get_attribute_by_name(ctx, 0, "obscura/method", &m), EXR_ERR_SUCCESS);
    exr_finish(&ctx);
    obs_image_free(&ao);
    obs_image_free(&comp);
}

/* Each compression by name: the file says it, its pixels come back
 * (lossless: exactly as the pixel type holds them), and the bytes are the
 * same whatever the number of threads compressing the chunks.  The image
 * is tall enough for many chunks (ZIP: 16 lines, PIZ: 32). */
static void test_compressions(void **state)
{
    (void)state;
    enum { CW = 61, CH = 203 };
    obs_image img = {CW, CH, 2, malloc(sizeof(float) * CW * CH * 2)};
    for (int i = 0; i < CW * CH * 2; i++)
        img.data[i] = (float)((i * 7919) % 1000) / 999.0f; /* in [0, 1], as AO */
    static const char *const names[] = {"AO.Y", "X.Y"};
    obs_exr_layer layer = {&img, names};
    static const exr_compression_t want[] = {EXR_COMPRESSION_ZIP,  EXR_COMPRESSION_NONE, EXR_COMPRESSION_RLE,
                                             EXR_COMPRESSION_ZIPS, EXR_COMPRESSION_ZIP,  EXR_COMPRESSION_PIZ};
    char err[OBS_ERR_LEN] = "";
    for (int c = OBS_EXR_ZIP_DEFAULT; c <= OBS_EXR_PIZ; c++)
        for (int px = 0; px < 2; px++) {
            obs_exr_options o = {.pixel = px ? OBS_EXR_FLOAT : OBS_EXR_HALF, .compression = c, .threads = 1};
            obs_bytes one, many;
            if (obs_exr_write_ex_mem(&layer, 1, &o, &one, err) != OBS_OK)
                fail_msg("%s: %s", obs_exr_compression_name(c), err);
            o.threads = 4;
            assert_int_equal(obs_exr_write_ex_mem(&layer, 1, &o, &many, err), OBS_OK);
            assert_int_equal(one.size, many.size);
            assert_memory_equal(one.data, many.data, one.size);
            exr_context_t ctx;
            obs__exr_mem m = {one.data, one.size};
            exr_compression_t got;
            int64_t size;
            assert_int_equal(obs__exr_open(NULL, &m, &ctx, &size, err), OBS_OK);
            assert_int_equal(exr_get_compression(ctx, 0, &got), EXR_ERR_SUCCESS);
            assert_int_equal(got, want[c]);
            exr_finish(&ctx);
            for (int ch = 0; ch < 2; ch++) {
                obs_image back;
                assert_int_equal(obs_exr_read_channel_mem(one.data, one.size, names[ch], NULL, &back, err), OBS_OK);
                for (int i = 0; i < CW * CH; i++) {
                    float v = img.data[i * 2 + ch];
                    /* half: the nearest half, within half a spacing (2^-12 below 1) */
                    if (px ? back.data[i] != v : fabsf(back.data[i] - v) > 1.0f / 4096.0f)
                        fail_msg("%s %s %s[%d] = %.7g, wrote %.7g", obs_exr_compression_name(c),
                                 px ? "float" : "half", names[ch], i, back.data[i], v);
                }
                obs_image_free(&back);
            }
            obs_bytes_free(&one);
            obs_bytes_free(&many);
        }
    obs_image_free(&img);
}

/* Names both ways; an unknown name is -1; dwaa, which OpenEXR 3.1's C API
 * cannot code, is refused by name before anything is written. */
static void test_compression_names(void **state)
{
    (void)state;
    static const char *const names[] = {"none", "rle", "zips", "zip", "piz", "dwaa"};
    for (int i = 0; i < 6; i++)
        assert_string_equal(obs_exr_compression_name((obs_exr_compression)obs_exr_compression_parse(names[i])),
                            names[i]);
    assert_string_equal(obs_exr_compression_name(OBS_EXR_ZIP_DEFAULT), "zip");
    assert_int_equal(obs_exr_compression_parse("ZIP"), -1);
    assert_int_equal(obs_exr_compression_parse("b44"), -1);
    assert_int_equal(obs_exr_compression_parse(NULL), -1);
    char err[OBS_ERR_LEN] = "";
    int maj = 0, min = 0, patch = 0;
    exr_get_library_version(&maj, &min, &patch, NULL);
    obs_status s = obs_exr_compression_check(OBS_EXR_DWAA, err);
    if (maj == 3 && min < 2) {
        assert_int_equal(s, OBS_UNSUPPORTED);
        assert_non_null(strstr(err, "dwaa"));
        obs_image img = make_image(1, 0);
        static const char *const n[] = {"AO.Y"};
        obs_exr_layer layer = {&img, n};
        obs_exr_options o = {.compression = OBS_EXR_DWAA};
        obs_bytes b = {0};
        assert_int_equal(obs_exr_write_ex_mem(&layer, 1, &o, &b, err), OBS_UNSUPPORTED);
        assert_non_null(strstr(err, "dwaa"));
        assert_null(b.data);
        obs_image_free(&img);
    } else {
        assert_int_equal(s, OBS_OK);
    }
    assert_int_equal(obs_exr_compression_check((obs_exr_compression)99, err), OBS_INVALID_ARGUMENT);
}

static void test_round_trip_float(void **state)
{
    (void)state;
    round_trip(OBS_EXR_FLOAT, 0.0f);
}

static void test_round_trip_half(void **state)
{
    (void)state;
    round_trip(OBS_EXR_HALF, 1.0f / 1024.0f); /* half: 11-bit significand */
}

/* Names in no particular order land on the right data; long names too. */
static void test_names_any_order(void **state)
{
    (void)state;
    obs_image img = make_image(3, 0);
    static const char *const names[] = {"Zeta", "alpha", "a.very.long.channel.name.beyond.31.chars"};
    obs_exr_layer layer = {&img, names};
    const char *path = tmp_path("order.exr");
    char err[OBS_ERR_LEN] = "";
    if (obs_exr_write(path, &layer, 1, OBS_EXR_FLOAT, NULL, err) != OBS_OK)
        fail_msg("%s", err);
    check_channel(path, "Zeta", 0, 0.0f);
    check_channel(path, "alpha", 1, 0.0f);
    check_channel(path, names[2], 2, 0.0f);
    obs_image_free(&img);
}

static void test_errors(void **state)
{
    (void)state;
    obs_image a = make_image(1, 0), b = make_image(2, 0);
    static const char *const one[] = {"Y"};
    static const char *const two[] = {"U", "Y"};
    static const char *const unnamed[] = {NULL};
    char err[OBS_ERR_LEN] = "";
    const char *path = tmp_path("bad.exr");

    obs_exr_layer dup[] = {{&a, one}, {&b, two}};
    assert_int_equal(obs_exr_write(path, dup, 2, OBS_EXR_HALF, NULL, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "'Y'"));

    b.width = W - 1;
    obs_exr_layer sizes[] = {{&a, one}, {&b, two}};
    assert_int_equal(obs_exr_write(path, sizes, 2, OBS_EXR_HALF, NULL, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "layer 1"));
    b.width = W;

    obs_exr_layer noname = {&a, unnamed};
    assert_int_equal(obs_exr_write(path, &noname, 1, OBS_EXR_HALF, NULL, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_exr_write(path, NULL, 0, OBS_EXR_HALF, NULL, err), OBS_INVALID_ARGUMENT);

    obs_exr_layer ok = {&a, one};
    err[0] = '\0';
    assert_int_equal(obs_exr_write("/nonexistent-dir/x.exr", &ok, 1, OBS_EXR_HALF, NULL, err), OBS_IO);
    assert_non_null(strstr(err, "/nonexistent-dir/x.exr"));
    obs_image_free(&a);
    obs_image_free(&b);
}

/* A rigid world-to-camera (the room camera) and a 50-degree projection
 * survive write + read, and the written worldToNDC puts a world point
 * where our projection * world_to_camera does. */
static void test_camera_round_trip(void **state)
{
    (void)state;
    obs_camera cam;
    obs_camera_from_fov(50.0f, (float)W / H, 0.1f, 1000.0f, &cam);
    const float wtc[16] = {0.7912850f, 0.6114476f, 0.0f, -0.1007087f,
                           -0.1289842f, 0.1669206f, 0.9774972f, -0.7922407f,
                           0.5976883f, -0.7734788f, 0.2109488f, -4.3877349f,
                           0.0f, 0.0f, 0.0f, 1.0f};
    memcpy(cam.world_to_camera, wtc, sizeof wtc);
    cam.has_world_to_camera = 1;

    obs_image z = make_image(1, 0);
    static const char *const zname[] = {"Z"};
    obs_exr_layer layer = {&z, zname};
    const char *path = tmp_path("camera.exr");
    char err[OBS_ERR_LEN] = "";
    if (obs_exr_write(path, &layer, 1, OBS_EXR_FLOAT, &cam, err) != OBS_OK)
        fail_msg("%s", err);

    obs_gbuffer_file f;
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &f, err), OBS_OK);
    const obs_camera *got = &f.gb.camera;
    assert_int_equal(got->source, OBS_CAMERA_EXR_HEADER);
    assert_int_equal(got->has_world_to_camera, 1);
    assert_int_equal(got->has_projection, 1);
    for (int i = 0; i < 16; i++) {
        assert_float_equal(got->world_to_camera[i], cam.world_to_camera[i], 1e-5);
        assert_float_equal(got->projection[i], cam.projection[i], 1e-4);
    }
    obs_gbuffer_free(&f);

    /* the raw attributes, in OpenEXR's row-vector conventions */
    exr_context_t ctx;
    exr_attr_m44f_t ndc, ewtc;
    assert_int_equal(exr_start_read(&ctx, path, NULL), EXR_ERR_SUCCESS);
    assert_int_equal(exr_attr_get_m44f(ctx, 0, "worldToNDC", &ndc), EXR_ERR_SUCCESS);
    assert_int_equal(exr_attr_get_m44f(ctx, 0, "worldToCamera", &ewtc), EXR_ERR_SUCCESS);
    exr_finish(&ctx);

    float inv[16], pv[16];
    assert_int_equal(obs__mat4_invert(cam.world_to_camera, inv), 0);
    obs__mat4_mul(cam.projection, cam.world_to_camera, pv);
    static const float in_cam[][3] = {{0, 0, -2}, {0.5f, -0.3f, -3}, {-1.2f, 0.8f, -7}, {3, 2, -40}};
    for (int k = 0; k < 4; k++) {
        float pc[4] = {in_cam[k][0], in_cam[k][1], in_cam[k][2], 1}, pw[4], clip[4];
        obs__mat4_apply(inv, pc, pw);
        obs__mat4_apply(pv, pw, clip);
        /* OpenGL NDC to EXR NDC: (0,0) top-left, (1,1) bottom-right */
        float ex = (clip[0] / clip[3] + 1.0f) * 0.5f, ey = (1.0f - clip[1] / clip[3]) * 0.5f;
        float q[4] = {0, 0, 0, 0}, e[4] = {0, 0, 0, 0};
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                q[j] += pw[i] * ndc.m[i * 4 + j]; /* p' = p M */
                e[j] += pw[i] * ewtc.m[i * 4 + j];
            }
        assert_true(q[3] > 0.0f);
        assert_float_equal(q[0] / q[3], ex, 1e-4);
        assert_float_equal(q[1] / q[3], ey, 1e-4);
        /* EXR camera space: +Z forward, so our -Z becomes +Z */
        assert_float_equal(e[0], pc[0], 1e-4);
        assert_float_equal(e[1], pc[1], 1e-4);
        assert_float_equal(e[2], -pc[2], 1e-4);
    }

    /* a view without a projection writes worldToCamera only */
    cam.has_projection = 0;
    assert_int_equal(obs_exr_write(path, &layer, 1, OBS_EXR_HALF, &cam, err), OBS_OK);
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &f, err), OBS_OK);
    assert_int_equal(f.gb.camera.has_world_to_camera, 1);
    assert_int_equal(f.gb.camera.has_projection, 0);
    obs_gbuffer_free(&f);

    /* no world_to_camera: nothing written */
    obs_camera_from_fov(50.0f, 1.0f, 0.1f, 1000.0f, &cam);
    assert_int_equal(obs_exr_write(path, &layer, 1, OBS_EXR_HALF, &cam, err), OBS_OK);
    assert_int_equal(obs_gbuffer_read_exr(path, NULL, NULL, &f, err), OBS_OK);
    assert_int_equal(f.gb.camera.source, OBS_CAMERA_NONE);
    obs_gbuffer_free(&f);
    obs_image_free(&z);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_float),
        cmocka_unit_test(test_round_trip_half),
        cmocka_unit_test(test_compressions),
        cmocka_unit_test(test_compression_names),
        cmocka_unit_test(test_names_any_order),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_camera_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
