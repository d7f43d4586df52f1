/* Guards against silent wrong answers (issue 29, items 2-4): depth
 * impossible for the depth mode, no geometry, a radius out of scale with
 * the depth, AO near 1 everywhere after the run; warnings ordered by
 * cause (a missing world_to_camera before, and instead of, the
 * derived-normals comparison); the colour plane: the beauty by default,
 * --color beauty|albedo. */
#include "testutil.h"

#include <math.h>

#include "internal.h"
#include "io/exr_internal.h"
#include "obscura/deep.h"
#include "obscura/io.h"

#define ROOM TESTDATA "/room_small.exr"

static void load_room(obs_gbuffer_file *gf)
{
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_gbuffer_read_exr(ROOM, NULL, NULL, gf, err), OBS_OK);
}

/* The room with its camera JSON, as `obscura ao --camera` reads it (into
 * the G-buffer's camera); default parameters. */
static void room_params(obs_gbuffer_file *gf, obs_params *p)
{
    char err[OBS_ERR_LEN] = "";
    memset(p, 0, sizeof *p);
    assert_int_equal(obs_camera_read_json(TESTDATA "/room_small.camera.json", &gf->gb.camera,
                                          NULL, NULL, err), OBS_OK);
}

static int has(const obs_exr_info *info, const char *what)
{
    for (int i = 0; i < info->warning_count; i++)
        if (strstr(info->warnings[i], what))
            return i + 1;
    return 0;
}

static void set(obs_params *p, const char *name, const char *value)
{
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(p, name, value, err), OBS_OK);
}

/* The room as given: no warning; its depth range and starting radius. */
static void test_room_clean(void **state)
{
    (void)state;
    obs_gbuffer_file gf = {0};
    obs_params p;
    obs_depth_range r;
    load_room(&gf);
    room_params(&gf, &p);
    obs_exr_info info = {0};
    assert_int_equal(obs_gbuffer_sanity(&gf.gb, &p, &info), 0);
    assert_int_equal(obs_gbuffer_depth_range(&gf.gb, &p, &r), 0);
    print_message("room_small: depth %g..%g median %g over %ld pixels\n", r.min, r.max, r.median,
                  r.geometry);
    assert_true(r.geometry > 70000 && r.min > 2.0 && r.max < 9.0);
    assert_true(r.median > 5.0 && r.median < 6.0);
    /* a tenth of the median depth: the default radius 0.5 on this room */
    assert_true(fabs(obs_radius_suggest(&r) - 0.5) < 0.1);
    obs_gbuffer_free(&gf);
}

/* Planar depth read as ndc or normalized: every pixel background. */
static void test_impossible_depth(void **state)
{
    (void)state;
    static const char *const modes[] = {"ndc", "normalized"};
    obs_gbuffer_file gf = {0};
    load_room(&gf);
    for (int m = 0; m < 2; m++) {
        obs_params p;
        room_params(&gf, &p);
        set(&p, "depth_mode", modes[m]);
        obs_exr_info info = {0};
        assert_true(obs_gbuffer_sanity(&gf.gb, &p, &info) >= 1);
        print_message("%s: %s\n", modes[m], info.warnings[0]);
        assert_int_equal(has(&info, "impossible under --depth-mode"), 1);
        assert_true(has(&info, "--depth-mode planar"));
    }
    obs_gbuffer_free(&gf);
}

/* Every depth value background (Blender's sky, 1e10). */
static void test_no_geometry(void **state)
{
    (void)state;
    obs_gbuffer_file gf = {0};
    obs_params p;
    load_room(&gf);
    room_params(&gf, &p);
    for (int y = 0; y < gf.gb.height; y++)
        for (int x = 0; x < gf.gb.width; x++)
            *(float *)obs__plane_px(&gf.gb.depth, gf.gb.width, x, y) = 1e10f;
    obs_exr_info info = {0};
    assert_true(obs_gbuffer_sanity(&gf.gb, &p, &info) >= 1);
    print_message("%s\n", info.warnings[0]);
    assert_int_equal(has(&info, "no geometry"), 1);
    obs_gbuffer_free(&gf);
}

static void test_radius_out_of_scale(void **state)
{
    (void)state;
    obs_gbuffer_file gf = {0};
    load_room(&gf);
    static const struct {
        const char *radius, *expect;
    } cases[] = {{"0.001", "under 1/1000 of the median depth"},
                 {"50", "above the median depth"}};
    for (int c = 0; c < 2; c++) {
        obs_params p;
        room_params(&gf, &p);
        set(&p, "radius", cases[c].radius);
        obs_exr_info info = {0};
        assert_int_equal(obs_gbuffer_sanity(&gf.gb, &p, &info), 1);
        print_message("%s\n", info.warnings[0]);
        assert_true(has(&info, cases[c].expect));
        assert_true(has(&info, "start from --radius 0.5"));
    }
    obs_gbuffer_free(&gf);
}

/* After the run: AO of `value` on the geometry, 1 on the background. */
static void fill_ao(const obs_gbuffer *gb, obs_image *ao, float value)
{
    ao->width = gb->width;
    ao->height = gb->height;
    ao->channels = 1;
    ao->data = malloc((size_t)gb->width * gb->height * sizeof(float));
    assert_non_null(ao->data);
    for (int y = 0; y < gb->height; y++)
        for (int x = 0; x < gb->width; x++) {
            float d = *obs__plane_px(&gb->depth, gb->width, x, y);
            ao->data[(size_t)y * gb->width + x] = d > 0.0f && d < 1e9f ? value : 1.0f;
        }
}

static void test_result_near_one(void **state)
{
    (void)state;
    obs_gbuffer_file gf = {0};
    obs_params p;
    obs_image ao;
    load_room(&gf);
    room_params(&gf, &p);
    static const struct {
        float value;
        const char *expect; /* NULL: no warning */
    } cases[] = {{1.0f, "no pixel is occluded"},
                 {0.997f, "AO is above 0.99 almost everywhere"},
                 {0.95f, NULL}};
    for (int c = 0; c < 3; c++) {
        fill_ao(&gf.gb, &ao, cases[c].value);
        obs_exr_info info = {0};
        int n = obs_result_sanity(&ao, &gf.gb, NULL, &p, &info);
        print_message("AO %g: %s\n", cases[c].value, n ? info.warnings[0] : "no warning");
        assert_int_equal(n, cases[c].expect != NULL);
        if (cases[c].expect) {
            assert_true(has(&info, cases[c].expect));
            assert_true(has(&info, "radius 0.5"));
            assert_true(has(&info, "median 5.4"));
        }
        obs_image_free(&ao);
    }
    obs_gbuffer_free(&gf);
}

/* The real case: the Arnold deep frame's depth range (tests/data copy of
 * ../shared/data/renderers/arnold/sample2.exr). */
static void test_deep_range(void **state)
{
    (void)state;
    obs_deep_image d = {0};
    obs_depth_range r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_deep_read_exr(TESTDATA "/arnold_sample2.exr", NULL, &d, err), OBS_OK);
    assert_int_equal(obs_deep_depth_range(&d, &r), 0);
    print_message("arnold_sample2: depth %g..%g median %g\n", r.min, r.max, r.median);
    assert_true(r.min > 6.0 && r.max < 20.0 && r.median > 9.0 && r.median < 10.0);
    obs_image ao = {d.width, d.height, 1, malloc((size_t)d.width * d.height * sizeof(float))};
    assert_non_null(ao.data);
    for (int i = 0; i < d.width * d.height; i++)
        ao.data[i] = d.offset[i + 1] > d.offset[i] ? 0.997f : 1.0f;
    obs_exr_info info = {0};
    assert_int_equal(obs_result_sanity(&ao, NULL, &d, NULL, &info), 1);
    assert_true(has(&info, "start from --radius 0.9"));
    obs_image_free(&ao);
    obs_deep_free(&d);
}

/* Item 3: world-space normals with no world_to_camera (README's
 * `--fov-y 50` example): that cause first, and no derived-normals
 * comparison, which it makes meaningless. */
static void test_cause_first(void **state)
{
    (void)state;
    obs_gbuffer_file gf = {0};
    obs_params p = {0};
    load_room(&gf);
    set(&p, "fov_y", "50");
    obs_exr_info info = {0};
    int n = obs_gbuffer_sanity(&gf.gb, &p, &info);
    for (int i = 0; i < n; i++)
        print_message("warning %d: %s\n", i, info.warnings[i]);
    assert_int_equal(has(&info, "no world_to_camera"), 1);
    assert_false(has(&info, "normals disagree"));
    assert_int_equal(n, 1);
    obs_gbuffer_free(&gf);
}

/* Item 4: the colour plane is the beauty by default; --color beauty and
 * --color albedo ask for either by name. */
static const char *const blender[] = {
    "ViewLayer.Combined.A", "ViewLayer.Combined.B", "ViewLayer.Combined.G", "ViewLayer.Combined.R",
    "ViewLayer.Depth.Z", "ViewLayer.DiffCol.B", "ViewLayer.DiffCol.G", "ViewLayer.DiffCol.R",
    "ViewLayer.Normal.X", "ViewLayer.Normal.Y", "ViewLayer.Normal.Z"};
#define NB ((int)(sizeof blender / sizeof blender[0]))

static void test_color_roles(void **state)
{
    (void)state;
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    obs_channel_map map = {0};
    assert_int_equal(obs__channel_map_resolve(&map, blender, NB, &m, err), OBS_OK);
    assert_int_equal(m.color[0], 3); /* ViewLayer.Combined.R */
    assert_int_equal(m.color[3], 0); /* with its alpha */
    map.color[0] = "beauty";
    assert_int_equal(obs__channel_map_resolve(&map, blender, NB, &m, err), OBS_OK);
    assert_int_equal(m.color[0], 3);
    map.color[0] = "albedo";
    assert_int_equal(obs__channel_map_resolve(&map, blender, NB, &m, err), OBS_OK);
    assert_int_equal(m.color[0], 7); /* ViewLayer.DiffCol.R */
    assert_int_equal(m.color[3], -1);
    /* a Blender file without the beauty: the albedo by default ... */
    map.color[0] = NULL;
    assert_int_equal(obs__channel_map_resolve(&map, blender + 4, NB - 4, &m, err), OBS_OK);
    assert_int_equal(m.color[0], 3); /* DiffCol.R of the shorter list */
    /* ... but asked for by name, an error that says what was looked for */
    map.color[0] = "beauty";
    assert_int_equal(obs__channel_map_resolve(&map, blender + 4, NB - 4, &m, err),
                     OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "--color beauty"));
    /* a renderer row: V-Ray's beauty R,G,B,A, its albedo "diffuse" */
    static const char *const vray[] = {"A", "B", "G", "R", "Z", "diffuse.B", "diffuse.G",
                                       "diffuse.R", "normals.X", "normals.Y", "normals.Z"};
    obs_channel_map vm = {.preset = "vray"};
    assert_int_equal(obs__channel_map_resolve(&vm, vray, 11, &m, err), OBS_OK);
    assert_int_equal(m.color[0], 3);
    assert_int_equal(m.color[3], 0);
    vm.color[0] = "albedo";
    assert_int_equal(obs__channel_map_resolve(&vm, vray, 11, &m, err), OBS_OK);
    assert_int_equal(m.color[0], 7);
    /* generic has no albedo */
    obs_channel_map gm = {.preset = "generic", .color = {"albedo"}};
    assert_int_equal(obs__channel_map_resolve(&gm, vray, 11, &m, err), OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "--color albedo"));
    /* a partial list is still an error, naming the keywords */
    obs_channel_map pm = {.color = {"R", "G"}};
    assert_int_equal(obs__channel_map_resolve(&pm, vray, 11, &m, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "beauty or albedo"));
}

/* room_small read by default: the composite's colour is the render
 * (Combined: the sky is lit), not the albedo (DiffCol: the sky black). */
static void test_room_beauty(void **state)
{
    (void)state;
    obs_gbuffer_file gf = {0}, ga = {0};
    char err[OBS_ERR_LEN] = "";
    obs_channel_map albedo = {.color = {"albedo"}};
    load_room(&gf);
    assert_int_equal(obs_gbuffer_read_exr(ROOM, &albedo, NULL, &ga, err), OBS_OK);
    assert_string_equal(gf.info.color[0], "ViewLayer.Combined.R");
    assert_string_equal(ga.info.color[0], "ViewLayer.DiffCol.R");
    double sky_beauty = 0.0, sky_albedo = 0.0;
    long sky = 0;
    for (int y = 0; y < gf.gb.height; y++)
        for (int x = 0; x < gf.gb.width; x++)
            if (*obs__plane_px(&gf.gb.depth, gf.gb.width, x, y) >= 1e9f) {
                sky_beauty += obs__plane_px(&gf.gb.color, gf.gb.width, x, y)[1];
                sky_albedo += obs__plane_px(&ga.gb.color, ga.gb.width, x, y)[1];
                sky++;
            }
    print_message("room_small sky (%ld px): mean green %.3f beauty, %.3f albedo\n", sky,
                  sky ? sky_beauty / sky : 0.0, sky ? sky_albedo / sky : 0.0);
    assert_true(sky > 0 && sky_albedo / sky < 0.05 && sky_beauty / sky > 0.5);
    obs_gbuffer_free(&gf);
    obs_gbuffer_free(&ga);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_room_clean),
        cmocka_unit_test(test_impossible_depth),
        cmocka_unit_test(test_no_geometry),
        cmocka_unit_test(test_radius_out_of_scale),
        cmocka_unit_test(test_result_near_one),
        cmocka_unit_test(test_deep_range),
        cmocka_unit_test(test_cause_first),
        cmocka_unit_test(test_color_roles),
        cmocka_unit_test(test_room_beauty),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
