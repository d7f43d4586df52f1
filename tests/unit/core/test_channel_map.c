/* Channel maps: presets, auto-detection, explicit names and the errors
 * that name what was looked for. */
#include "testutil.h"

#include "io/exr_internal.h"

#define N(a) ((int)(sizeof(a) / sizeof((a)[0])))

static int idx_of(const char *const *names, int n, const char *name)
{
    for (int i = 0; i < n; i++)
        if (strcmp(names[i], name) == 0)
            return i;
    return -2; /* never equal to a "not found" -1 */
}

static void test_presets_list(void **state)
{
    (void)state;
    assert_string_equal(obs_channel_presets[0], "auto");
    assert_string_equal(obs_channel_presets[1], "blender");
    assert_string_equal(obs_channel_presets[2], "generic");
    /* the renderers of core/io/presets.c, each a row there */
    for (int i = 3; obs_channel_presets[i]; i++)
        assert_non_null(obs__preset_find(obs_channel_presets[i]));
    assert_string_equal(obs_channel_presets[10], "nuke");
    assert_null(obs_channel_presets[11]);
}

/* Blender's multilayer order (alphabetical, as EXR stores it). */
static const char *const blender[] = {
    "ViewLayer.AO.B", "ViewLayer.AO.G", "ViewLayer.AO.R",
    "ViewLayer.Combined.A", "ViewLayer.Combined.B", "ViewLayer.Combined.G", "ViewLayer.Combined.R",
    "ViewLayer.Depth.Z", "ViewLayer.DiffCol.B", "ViewLayer.DiffCol.G", "ViewLayer.DiffCol.R",
    "ViewLayer.Normal.X", "ViewLayer.Normal.Y", "ViewLayer.Normal.Z",
    "ViewLayer.Position.X", "ViewLayer.Position.Y", "ViewLayer.Position.Z"};

static void test_blender_auto(void **state)
{
    (void)state;
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__channel_map_resolve(NULL, blender, N(blender), &m, err), OBS_OK);
    assert_string_equal(m.preset, "blender");
    assert_int_equal(m.depth, idx_of(blender, N(blender), "ViewLayer.Depth.Z"));
    assert_int_equal(m.normal[0], idx_of(blender, N(blender), "ViewLayer.Normal.X"));
    assert_int_equal(m.normal[2], idx_of(blender, N(blender), "ViewLayer.Normal.Z"));
    /* the beauty (Combined, with its alpha) wins over DiffCol */
    assert_int_equal(m.color[0], idx_of(blender, N(blender), "ViewLayer.Combined.R"));
    assert_int_equal(m.color[2], idx_of(blender, N(blender), "ViewLayer.Combined.B"));
    assert_int_equal(m.color[3], idx_of(blender, N(blender), "ViewLayer.Combined.A"));

    obs_channel_map map = {.preset = "blender"};
    assert_int_equal(obs__channel_map_resolve(&map, blender, N(blender), &m, err), OBS_OK);
    assert_string_equal(m.preset, "blender");
}

static void test_blender_other_layer_combined(void **state)
{
    (void)state;
    static const char *const names[] = {"Render.Combined.A", "Render.Combined.B",
                                        "Render.Combined.G", "Render.Combined.R",
                                        "Render.Depth.Z", "Render.Normal.X"};
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__channel_map_resolve(NULL, names, N(names), &m, err), OBS_OK);
    assert_string_equal(m.preset, "blender");
    assert_int_equal(m.depth, 4);
    assert_int_equal(m.normal[0], -1); /* only X: no normal */
    assert_int_equal(m.color[0], 3);
    assert_int_equal(m.color[1], 2);
    assert_int_equal(m.color[2], 1);
    assert_int_equal(m.color[3], 0);
}

static void test_generic(void **state)
{
    (void)state;
    static const char *const names[] = {"A", "B", "G", "N.X", "N.Y", "N.Z", "R", "Z"};
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__channel_map_resolve(NULL, names, N(names), &m, err), OBS_OK);
    assert_string_equal(m.preset, "generic");
    assert_int_equal(m.depth, 7);
    assert_int_equal(m.normal[0], 3);
    assert_int_equal(m.normal[1], 4);
    assert_int_equal(m.normal[2], 5);
    assert_int_equal(m.color[0], 6);
    assert_int_equal(m.color[1], 2);
    assert_int_equal(m.color[2], 1);
    assert_int_equal(m.color[3], 0);
}

static void test_generic_alternatives(void **state)
{
    (void)state;
    static const char *const a[] = {"N.B", "N.G", "N.R", "depth.Z"};
    static const char *const b[] = {"Depth.Z", "Normal.X", "Normal.Y", "Normal.Z", "R", "G"};
    static const char *const c[] = {"Z", "normal.X", "normal.Y", "normal.Z", "B", "G", "R"};
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    obs_channel_map generic = {.preset = "generic"};

    assert_int_equal(obs__channel_map_resolve(&generic, a, N(a), &m, err), OBS_OK);
    assert_int_equal(m.depth, 3);
    assert_int_equal(m.normal[0], 2); /* N.R is x */
    assert_int_equal(m.normal[2], 0);
    assert_int_equal(m.color[0], -1);

    assert_int_equal(obs__channel_map_resolve(&generic, b, N(b), &m, err), OBS_OK);
    assert_int_equal(m.depth, 0);
    assert_int_equal(m.normal[1], 2);
    assert_int_equal(m.color[0], -1); /* no B: no colour */

    assert_int_equal(obs__channel_map_resolve(&generic, c, N(c), &m, err), OBS_OK);
    assert_int_equal(m.normal[0], 1);
    assert_int_equal(m.color[0], 6);
    assert_int_equal(m.color[3], -1);
}

static void test_auto_prefers_blender(void **state)
{
    (void)state;
    static const char *const names[] = {"R", "G", "B", "Z", "ViewLayer.Depth.Z"};
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__channel_map_resolve(NULL, names, N(names), &m, err), OBS_OK);
    assert_string_equal(m.preset, "blender");
    assert_int_equal(m.depth, 4);
    obs_channel_map generic = {.preset = "generic"};
    assert_int_equal(obs__channel_map_resolve(&generic, names, N(names), &m, err), OBS_OK);
    assert_int_equal(m.depth, 3);
    assert_int_equal(m.color[0], 0);
}

static void test_explicit_override(void **state)
{
    (void)state;
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    obs_channel_map map = {.depth = "ViewLayer.Position.Z",
                           .color = {"ViewLayer.Combined.R", "ViewLayer.Combined.G",
                                     "ViewLayer.Combined.B", NULL}};
    assert_int_equal(obs__channel_map_resolve(&map, blender, N(blender), &m, err), OBS_OK);
    assert_string_equal(m.preset, "blender"); /* normals still come from the preset */
    assert_int_equal(m.depth, idx_of(blender, N(blender), "ViewLayer.Position.Z"));
    assert_int_equal(m.normal[0], idx_of(blender, N(blender), "ViewLayer.Normal.X"));
    assert_int_equal(m.color[0], idx_of(blender, N(blender), "ViewLayer.Combined.R"));
    assert_int_equal(m.color[3], -1); /* explicit colour without alpha */

    /* nothing from any preset: "explicit" */
    static const char *const odd[] = {"depth_m", "nx", "ny", "nz"};
    obs_channel_map map2 = {.depth = "depth_m", .normal = {"nx", "ny", "nz"}};
    assert_int_equal(obs__channel_map_resolve(&map2, odd, N(odd), &m, err), OBS_OK);
    assert_string_equal(m.preset, "explicit");
    assert_int_equal(m.depth, 0);
    assert_int_equal(m.normal[2], 3);
    assert_int_equal(m.color[0], -1);
}

/* A preset plane that would reuse an explicitly named channel is dropped,
 * not reported as a clash. */
static void test_explicit_wins_over_preset(void **state)
{
    (void)state;
    static const char *const names[] = {"A", "B", "G", "R"};
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    obs_channel_map map = {.depth = "R", .normal = {"A", "B", "G"}};
    assert_int_equal(obs__channel_map_resolve(&map, names, N(names), &m, err), OBS_OK);
    assert_int_equal(m.depth, 3);
    assert_int_equal(m.normal[0], 0);
    assert_int_equal(m.color[0], -1); /* generic's R, G, B gave way */
    assert_int_equal(m.color[3], -1);

    obs_channel_map alpha = {.depth = "A"};
    assert_int_equal(obs__channel_map_resolve(&alpha, names, N(names), &m, err), OBS_OK);
    assert_int_equal(m.depth, 0);
    assert_int_equal(m.color[0], 3); /* colour stays, its alpha gives way */
    assert_int_equal(m.color[3], -1);
}

static void test_explicit_missing(void **state)
{
    (void)state;
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    obs_channel_map map = {.depth = "Nope.Z"};
    assert_int_equal(obs__channel_map_resolve(&map, blender, N(blender), &m, err), OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "'Nope.Z'"));
    assert_non_null(strstr(err, "the file has: ViewLayer.AO.B"));

    obs_channel_map map2 = {.normal = {"ViewLayer.Normal.X", "ViewLayer.Normal.Y", "Missing.Z"}};
    assert_int_equal(obs__channel_map_resolve(&map2, blender, N(blender), &m, err), OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "normal channel 'Missing.Z'"));
}

static void test_missing_depth(void **state)
{
    (void)state;
    static const char *const names[] = {"A", "B", "G", "R"};
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__channel_map_resolve(NULL, names, N(names), &m, err), OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "Depth.Z"));
    assert_non_null(strstr(err, "Z, depth.Z"));
    assert_non_null(strstr(err, "the file has: A, B, G, R"));

    obs_channel_map blender_only = {.preset = "blender"};
    static const char *const generic[] = {"R", "Z"};
    assert_int_equal(obs__channel_map_resolve(&blender_only, generic, N(generic), &m, err),
                     OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "ViewLayer.Depth.Z"));
    assert_int_equal(obs__channel_map_resolve(NULL, names, 0, &m, err), OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "no channels"));
}

static void test_long_list_truncated(void **state)
{
    (void)state;
    char buf[100][24];
    const char *names[100];
    for (int i = 0; i < 100; i++) {
        snprintf(buf[i], sizeof buf[i], "layer%02d.channel", i);
        names[i] = buf[i];
    }
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__channel_map_resolve(NULL, names, 100, &m, err), OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "layer00.channel, layer01.channel"));
    assert_non_null(strstr(err, ", ... (100 channels)"));
    assert_true(strlen(err) < OBS_ERR_LEN - 1);
}

static void test_bad_maps(void **state)
{
    (void)state;
    obs__channel_match m;
    char err[OBS_ERR_LEN] = "";
    obs_channel_map bad = {.preset = "maya"};
    assert_int_equal(obs__channel_map_resolve(&bad, blender, N(blender), &m, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "'maya'"));

    obs_channel_map partial = {.normal = {"ViewLayer.Normal.X", NULL, NULL}};
    assert_int_equal(obs__channel_map_resolve(&partial, blender, N(blender), &m, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "normal"));

    obs_channel_map alpha_only = {.color = {NULL, NULL, NULL, "ViewLayer.Combined.A"}};
    assert_int_equal(obs__channel_map_resolve(&alpha_only, blender, N(blender), &m, err), OBS_INVALID_ARGUMENT);

    /* explicit names clashing among themselves */
    obs_channel_map clash = {.depth = "ViewLayer.AO.R",
                             .normal = {"ViewLayer.AO.R", "ViewLayer.AO.G", "ViewLayer.AO.B"}};
    assert_int_equal(obs__channel_map_resolve(&clash, blender, N(blender), &m, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "'ViewLayer.AO.R' is mapped twice"));

    /* "" and "auto" both mean auto */
    obs_channel_map empty = {.preset = ""}, autop = {.preset = "auto"};
    assert_int_equal(obs__channel_map_resolve(&empty, blender, N(blender), &m, err), OBS_OK);
    assert_int_equal(obs__channel_map_resolve(&autop, blender, N(blender), &m, err), OBS_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_presets_list),
        cmocka_unit_test(test_blender_auto),
        cmocka_unit_test(test_blender_other_layer_combined),
        cmocka_unit_test(test_generic),
        cmocka_unit_test(test_generic_alternatives),
        cmocka_unit_test(test_auto_prefers_blender),
        cmocka_unit_test(test_explicit_override),
        cmocka_unit_test(test_explicit_wins_over_preset),
        cmocka_unit_test(test_explicit_missing),
        cmocka_unit_test(test_missing_depth),
        cmocka_unit_test(test_long_list_truncated),
        cmocka_unit_test(test_bad_maps),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
