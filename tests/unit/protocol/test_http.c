/* HTTP request parsing, status mapping and JSON bodies (protocol/http.c). */
#include "testutil.h"

#include <cjson/cJSON.h>

#include "../../../protocol/http.h"

static void test_defaults(void **state)
{
    (void)state;
    obs_http_request r;
    obs_http_request_init(&r);
    assert_int_equal(r.outputs, OBS_OUTPUT_AO);
    assert_int_equal(r.format, OBS_HTTP_EXR);
    assert_int_equal(r.png_bits, 8);
    assert_int_equal(r.float_exr, 0);
    assert_null(r.map.preset);
    assert_null(r.map.depth);
    assert_int_equal(obs_http_request_check(&r, NULL), OBS_OK);
}

static void test_table_params(void **state)
{
    (void)state;
    obs_http_request r;
    char err[OBS_ERR_LEN] = "";
    obs_http_request_init(&r);
    assert_int_equal(obs_http_request_set(&r, "radius", "0.25", err), OBS_OK);
    assert_int_equal(obs_http_request_set(&r, "fov-y", "50", err), OBS_OK); /* '-' or '_' */
    assert_int_equal(obs_http_request_set(&r, "depth_mode", "radial", err), OBS_OK);
    assert_int_equal(obs_http_request_set(&r, "world_to_camera", "1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1", err), OBS_OK);
    assert_true(r.params.radius == 0.25f);
    assert_true(r.params.fov_y == 50.0f);
    assert_int_equal(r.params.depth_mode, OBS_DEPTH_RADIAL);
    assert_int_equal(r.params.has_world_to_camera, 1);
}

static void test_bad_params(void **state)
{
    (void)state;
    obs_http_request r;
    char err[OBS_ERR_LEN] = "";
    obs_http_request_init(&r);
    assert_int_equal(obs_http_request_set(&r, "samples", "64", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "samples"));
    assert_int_equal(obs_http_request_set(&r, "radius", "abc", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "radius"));
    assert_int_equal(obs_http_request_set(&r, "frobnicate", "1", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "frobnicate"));
    assert_int_equal(obs_http_request_set(&r, "output", "all", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "ao|composite|both"));
    assert_int_equal(obs_http_request_set(&r, "format", "tiff", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_http_request_set(&r, "png_bits", "12", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_http_request_set(&r, "preset", "maya", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_http_request_set(&r, "normal", "N.X,N.Y", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_http_request_set(&r, "normal", "N.X,,N.Z", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_http_request_set(&r, "color", "R,G,B,A,X", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_http_request_set(&r, "depth", "", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_http_request_set(&r, "", "1", err), OBS_INVALID_ARGUMENT);
    char longname[200];
    memset(longname, 'x', sizeof longname - 1);
    longname[sizeof longname - 1] = '\0';
    assert_int_equal(obs_http_request_set(&r, "depth", longname, err), OBS_INVALID_ARGUMENT);
    /* nothing half-set: still the defaults */
    assert_int_equal(r.outputs, OBS_OUTPUT_AO);
    assert_null(r.map.depth);
}

static void test_options(void **state)
{
    (void)state;
    obs_http_request r;
    char err[OBS_ERR_LEN] = "";
    obs_http_request_init(&r);
    assert_int_equal(obs_http_request_set(&r, "output", "both", err), OBS_OK);
    assert_int_equal(r.outputs, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE);
    assert_int_equal(obs_http_request_check(&r, err), OBS_OK);
    assert_int_equal(obs_http_request_set(&r, "format", "png", err), OBS_OK);
    assert_int_equal(obs_http_request_check(&r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "one output"));
    assert_int_equal(obs_http_request_set(&r, "output", "composite", err), OBS_OK);
    assert_int_equal(obs_http_request_check(&r, err), OBS_OK);
    assert_int_equal(obs_http_request_set(&r, "png-bits", "16", err), OBS_OK);
    assert_int_equal(r.png_bits, 16);
    assert_int_equal(obs_http_request_set(&r, "float", "1", err), OBS_OK);
    assert_int_equal(r.float_exr, 1);
    /* a switch's words too (the Python client's True/False) */
    assert_int_equal(obs_http_request_set(&r, "float", "off", err), OBS_OK);
    assert_int_equal(r.float_exr, 0);
    assert_int_equal(obs_http_request_set(&r, "float", "on", err), OBS_OK);
    assert_int_equal(r.float_exr, 1);
    assert_int_equal(obs_http_request_set(&r, "float", "yes", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "0|1|true|false|on|off"));
    /* compression: auto (0) by default, each name, a bad one named */
    assert_int_equal(r.compression, OBS_EXR_ZIP_DEFAULT);
    static const char *const comp[] = {"none", "rle", "zips", "zip", "piz"};
    for (int i = 0; i < 5; i++) {
        assert_int_equal(obs_http_request_set(&r, "compression", comp[i], err), OBS_OK);
        assert_int_equal(r.compression, obs_exr_compression_parse(comp[i]));
        assert_int_equal(obs_http_request_check(&r, err), OBS_OK);
    }
    assert_int_equal(obs_http_request_set(&r, "compression", "b44", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "compression"));
    assert_non_null(strstr(err, "none|rle|zips|zip|piz"));
    assert_int_equal(obs_http_request_set(&r, "compression", "dwaa", err), OBS_OK);
    if (obs_exr_compression_check(OBS_EXR_DWAA, err) != OBS_OK) { /* OpenEXR 3.1: a 400 naming it */
        assert_int_equal(obs_http_request_check(&r, err), OBS_INVALID_ARGUMENT);
        assert_non_null(strstr(err, "dwaa"));
    }
    assert_int_equal(obs_http_request_set(&r, "compression", "auto", err), OBS_OK);
    assert_int_equal(r.compression, OBS_EXR_ZIP_DEFAULT);
    assert_int_equal(obs_http_request_set(&r, "preset", "blender", err), OBS_OK);
    assert_string_equal(r.map.preset, "blender");
    assert_int_equal(obs_http_request_set(&r, "depth", "Z", err), OBS_OK);
    assert_string_equal(r.map.depth, "Z");
    assert_int_equal(obs_http_request_set(&r, "normal", "N.X,N.Y,N.Z", err), OBS_OK);
    assert_string_equal(r.map.normal[2], "N.Z");
    assert_int_equal(obs_http_request_set(&r, "color", "R,G,B", err), OBS_OK);
    assert_string_equal(r.map.color[2], "B");
    assert_null(r.map.color[3]);
    assert_int_equal(obs_http_request_set(&r, "color", "R,G,B,A", err), OBS_OK);
    assert_string_equal(r.map.color[3], "A");
}

/* The rows of obs_http_options: names unique and not the parameter
 * table's (a row would hide the parameter), every default parses and is
 * what obs_http_request_init() set. */
static void test_option_table(void **state)
{
    (void)state;
    int rows = 0;
    for (const obs_http_option *op = obs_http_options; op->name; op++, rows++) {
        obs_http_request r, d;
        char err[OBS_ERR_LEN] = "";
        assert_null(obs_param_find(op->name));
        assert_ptr_equal(obs_http_option_find(op->name), op);
        for (const obs_http_option *o2 = op + 1; o2->name; o2++)
            assert_string_not_equal(op->name, o2->name);
        assert_non_null(op->def);
        assert_non_null(op->doc);
        if (op->kind == OBS_HTTP_OPT_NAMES) {
            assert_true(op->min >= 1 && op->min <= op->max);
            assert_true(op->names || op->what);
            continue;
        }
        obs_http_request_init(&d);
        obs_http_request_init(&r);
        assert_int_equal(obs_http_option_set(&r, op, op->def, OBS_HTTP_QUERY, err), OBS_OK);
        assert_memory_equal(&r, &d, sizeof r);
    }
    assert_int_equal(rows, 17);
    assert_ptr_equal(obs_http_option_find("png-bits"), obs_http_option_find("png_bits"));
    assert_null(obs_http_option_find("radius"));
    assert_null(obs_http_option_find(NULL));
}

/* layer= and append=: parsed by their rows, checked with the rest of the
 * request (a layer name; append needs an EXR answer). */
static void test_output_options(void **state)
{
    (void)state;
    obs_http_request r;
    char err[OBS_ERR_LEN] = "";
    obs_http_request_init(&r);
    assert_null(r.layer);
    assert_int_equal(r.append, 0);
    assert_int_equal(obs_http_request_set(&r, "layer", "occ", err), OBS_OK);
    assert_int_equal(obs_http_request_set(&r, "append", "", err), OBS_OK);
    assert_string_equal(r.layer, "occ");
    assert_int_equal(r.append, 1);
    assert_int_equal(obs_http_request_check(&r, err), OBS_OK);
    assert_int_equal(obs_http_request_set(&r, "format", "png", err), OBS_OK);
    assert_int_equal(obs_http_request_check(&r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "append=1"));
    assert_int_equal(obs_http_request_set(&r, "append", "0", err), OBS_OK);
    assert_int_equal(obs_http_request_check(&r, err), OBS_OK);
    assert_int_equal(obs_http_request_set(&r, "layer", "a.", err), OBS_OK);
    assert_int_equal(obs_http_request_check(&r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "layer name 'a.'"));
    assert_int_equal(obs_http_request_set(&r, "layer", "", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_http_request_set(&r, "append", "2", err), OBS_INVALID_ARGUMENT);
    /* output=deep: the deep EXR alone (the query takes one output) */
    obs_http_request_init(&r);
    assert_int_equal(obs_http_request_set(&r, "output", "deep", err), OBS_OK);
    assert_int_equal(obs_http_request_check(&r, err), OBS_OK);
    assert_int_equal(obs_http_request_set(&r, "format", "png", err), OBS_OK);
    assert_int_equal(obs_http_request_check(&r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "output=deep answers one deep EXR"));
    assert_int_equal(obs_http_request_set(&r, "format", "exr", err), OBS_OK);
    assert_int_equal(obs_http_request_set(&r, "append", "1", err), OBS_OK);
    assert_int_equal(obs_http_request_check(&r, err), OBS_INVALID_ARGUMENT);
}

/* The CLI takes the debug outputs and a comma list of outputs; a query
 * one of ao|composite|both. */
static void test_option_from(void **state)
{
    (void)state;
    const obs_http_option *out = obs_http_option_find("output");
    obs_http_request r;
    char err[OBS_ERR_LEN] = "";
    obs_http_request_init(&r);
    assert_int_equal(obs_http_option_set(&r, out, "ao,samples,,cull", OBS_HTTP_CLI, err), OBS_OK);
    assert_int_equal(r.outputs, OBS_OUTPUT_AO | OBS_OUTPUT_SAMPLE_COUNT | OBS_OUTPUT_CULL_MASK);
    assert_int_equal(obs_http_option_set(&r, out, "bleed,luminance", OBS_HTTP_CLI, err), OBS_OK);
    assert_int_equal(r.outputs, OBS_OUTPUT_BLEED | OBS_OUTPUT_LUMINANCE);
    assert_int_equal(obs_http_option_set(&r, out, "ao,depth", OBS_HTTP_CLI, err), OBS_INVALID_ARGUMENT);
    assert_string_equal(err, "parameter output: 'depth' is not one of "
                             "ao|composite|both|samples|cull|bleed|luminance|multibounce|bent|aovs|deep");
    assert_int_equal(obs_http_option_set(&r, out, ",", OBS_HTTP_CLI, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(r.outputs, OBS_OUTPUT_BLEED | OBS_OUTPUT_LUMINANCE); /* unchanged */
    assert_int_equal(obs_http_request_set(&r, "output", "samples", err), OBS_INVALID_ARGUMENT);
    assert_string_equal(err, "parameter output: 'samples' is not one of ao|composite|both|multibounce|bent|aovs|deep");
    assert_int_equal(obs_http_request_set(&r, "output", "ao,composite", err), OBS_INVALID_ARGUMENT);
    /* a refused list of names leaves the earlier one */
    assert_int_equal(obs_http_request_set(&r, "normal", "A,B,C", err), OBS_OK);
    assert_int_equal(obs_http_request_set(&r, "normal", "X,Y", err), OBS_INVALID_ARGUMENT);
    assert_string_equal(err, "parameter normal: 'X,Y' is not three channel names X,Y,Z");
    assert_string_equal(r.map.normal[0], "A");
    assert_string_equal(r.normal[1], "B");
    /* one name is taken whole, commas and all */
    assert_int_equal(obs_http_request_set(&r, "depth", "a,b", err), OBS_OK);
    assert_string_equal(r.map.depth, "a,b");
}

static void test_status_map(void **state)
{
    (void)state;
    const char *code;
    assert_int_equal(obs_http_status_of(OBS_INVALID_ARGUMENT, &code), 400);
    assert_int_equal(obs_http_status_of(OBS_TOO_LARGE, &code), 413);
    assert_int_equal(obs_http_status_of(OBS_UNSUPPORTED, &code), 415);
    assert_int_equal(obs_http_status_of(OBS_MISSING_CHANNEL, &code), 422);
    assert_string_equal(code, "missing_channel");
    assert_int_equal(obs_http_status_of(OBS_NO_CAMERA, &code), 422);
    assert_string_equal(code, "no_camera");
    assert_int_equal(obs_http_status_of(OBS_BAD_FILE, &code), 422);
    assert_string_equal(code, "bad_file");
    assert_int_equal(obs_http_status_of(OBS_GL_ERROR, &code), 500);
    assert_int_equal(obs_http_status_of(OBS_GL_SHADER, NULL), 500);
    for (int s = 0; s < OBS_STATUS_COUNT; s++) {
        int h = obs_http_status_of((obs_status)s, &code);
        assert_true(h >= 200 && h < 600);
        assert_non_null(code);
    }
}

static void test_json(void **state)
{
    (void)state;
    char *e = obs_http_error_json("bad_parameter", "parameter \"samples\": 64 is out of range");
    cJSON *j = cJSON_Parse(e);
    assert_non_null(j);
    cJSON *err = cJSON_GetObjectItem(j, "error");
    assert_string_equal(cJSON_GetObjectItem(err, "code")->valuestring, "bad_parameter");
    assert_non_null(strstr(cJSON_GetObjectItem(err, "message")->valuestring, "\"samples\""));
    cJSON_Delete(j);
    free(e);

    char *p = obs_http_params_json();
    j = cJSON_Parse(p);
    assert_non_null(j);
    cJSON *params = cJSON_GetObjectItem(j, "params");
    assert_int_equal(cJSON_GetArraySize(params), obs_param_count());
    for (int i = 0; i < obs_param_count(); i++) {
        cJSON *o = cJSON_GetArrayItem(params, i);
        const obs_param_info *pi = obs_param_at(i);
        assert_string_equal(cJSON_GetObjectItem(o, "name")->valuestring, pi->name);
        assert_non_null(cJSON_GetObjectItem(o, "doc"));
        assert_non_null(cJSON_GetObjectItem(o, "default"));
        if (pi->type == OBS_PARAM_FLOAT || pi->type == OBS_PARAM_INT)
            assert_true(cJSON_GetObjectItem(o, "max")->valuedouble == pi->max);
        if (pi->type == OBS_PARAM_ENUM)
            assert_true(cJSON_GetArraySize(cJSON_GetObjectItem(o, "choices")) >= 2);
    }
    /* the options as the table's rows say: type, choices of a query */
    static const struct {
        const char *name, *type, *choices;
    } want[] = {{"output", "enum", "ao|composite|both|multibounce|bent|aovs|deep"}, {"format", "enum", "exr|png"},
                {"float", "bool", "0|1"},
                {"compression", "enum", "auto|none|rle|zips|zip|piz|dwaa"},
                {"png_bits", "enum", "8|16"},
                {"png_transfer", "enum", "srgb|linear"},
                {"preset", "enum", "auto|blender|generic|arnold|vray|renderman|redshift|karma|mantra|octane|nuke"},
                {"depth", "string", NULL},
                {"normal", "string", NULL},              {"color", "string", NULL},
                {"part", "string", NULL},                {"view", "string", NULL},
                {"strict", "bool", "0|1"},               {"solve_camera", "bool", "0|1"},
                {"layer", "string", NULL},               {"append", "bool", "0|1"},
                {"baked", "string", NULL}};
    cJSON *opts = cJSON_GetObjectItem(j, "options");
    assert_int_equal(cJSON_GetArraySize(opts), 17);
    for (int i = 0; i < 17; i++) {
        cJSON *o = cJSON_GetArrayItem(opts, i), *c = cJSON_GetObjectItem(o, "choices"), *it;
        char got[128] = "";
        assert_string_equal(cJSON_GetObjectItem(o, "name")->valuestring, want[i].name);
        assert_string_equal(cJSON_GetObjectItem(o, "type")->valuestring, want[i].type);
        cJSON_ArrayForEach(it, c) {
            size_t n = strlen(got);
            snprintf(got + n, sizeof got - n, "%s%s", n ? "|" : "", it->valuestring);
        }
        if (want[i].choices)
            assert_string_equal(got, want[i].choices);
        else
            assert_null(c);
    }
    cJSON_Delete(j);
    free(p);
}

static void test_bearer(void **state)
{
    (void)state;
    assert_true(obs_http_bearer_ok("Bearer abc", "abc"));
    assert_false(obs_http_bearer_ok("Bearer abd", "abc"));
    assert_false(obs_http_bearer_ok("Bearer ab", "abc"));
    assert_false(obs_http_bearer_ok("Bearer abcd", "abc"));
    assert_false(obs_http_bearer_ok("Bearer ", "abc"));
    assert_false(obs_http_bearer_ok("Basic abc", "abc"));
    assert_false(obs_http_bearer_ok(NULL, "abc"));
    assert_false(obs_http_bearer_ok("Bearer ", ""));
}

/* %00 in a query value or name: refused, naming the parameter; the rest
 * of the value is not read as a shorter one. */
static void test_nul(void **state)
{
    (void)state;
    obs_http_request r;
    char err[OBS_ERR_LEN] = "";
    obs_http_request_init(&r);
    assert_int_equal(obs_http_request_set_n(&r, "radius", 6, "0.5\0x", 5, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "radius"));
    assert_non_null(strstr(err, "NUL"));
    assert_int_equal(obs_http_request_set_n(&r, "depth", 5, "Z\0junk", 6, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "depth"));
    assert_null(r.map.depth); /* nothing set */
    assert_int_equal(obs_http_request_set_n(&r, "dep\0th", 6, "Z", 1, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_http_request_set_n(&r, "depth", 5, "Z", 1, err), OBS_OK);
    assert_string_equal(r.map.depth, "Z");
    assert_int_equal(obs_http_value_check("float", 5, NULL, 0, err), OBS_OK);
}

/* Every byte of an error's JSON is UTF-8, whatever the message echoes. */
static void test_json_utf8(void **state)
{
    (void)state;
    char *e = obs_http_error_json("bad_parameter", "unknown parameter '\xff\xfe\xc3(\xed\xa0\x80\xf0\x9f\x98\x80'");
    assert_non_null(e);
    /* ff, fe, a lone c3, a surrogate (3 bytes): U+FFFD each; the emoji kept */
    assert_non_null(strstr(e, "'\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd(\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd"
                              "\xf0\x9f\x98\x80'"));
    free(e);
    e = obs_http_error_json("x", "caf\xc3\xa9\nline");
    assert_non_null(strstr(e, "caf\xc3\xa9\\nline")); /* valid UTF-8 kept; the newline escaped */
    free(e);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults),   cmocka_unit_test(test_table_params),
        cmocka_unit_test(test_bad_params), cmocka_unit_test(test_options),
        cmocka_unit_test(test_status_map), cmocka_unit_test(test_json),
        cmocka_unit_test(test_bearer),     cmocka_unit_test(test_option_table),
        cmocka_unit_test(test_option_from),
        cmocka_unit_test(test_output_options), cmocka_unit_test(test_nul),
        cmocka_unit_test(test_json_utf8),
    };
    return cmocka_run_group_tests_name("protocol_http", tests, NULL, NULL);
}
