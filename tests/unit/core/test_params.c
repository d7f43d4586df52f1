/* The parameter table: lookup, parsing, ranges, defaults. */
#include "testutil.h"

#include "obscura/obscura.h"

static void test_zero_means_defaults(void **state)
{
    (void)state;
    obs_params in = {0}, p;
    char err[OBS_ERR_LEN];
    obs_params_resolve(&in, &p);
    assert_float_equal(p.radius, 0.5f, 0.0f);
    assert_int_equal(p.samples, 16);
    assert_int_equal(p.depth_mode, OBS_DEPTH_PLANAR);
    assert_int_equal(p.normal_space, OBS_NORMALS_WORLD);
    assert_float_equal(p.unit_scale, 1.0f, 0.0f);
    assert_float_equal(p.fov_y, 0.0f, 0.0f);
    assert_int_equal(p.has_world_to_camera, 0);
    assert_int_equal(obs_params_check(&p, err), OBS_OK);
    /* NULL is the same as zeroed */
    obs_params q;
    obs_params_resolve(NULL, &q);
    assert_memory_equal(&p, &q, sizeof p);
}

static void test_set_and_format(void **state)
{
    (void)state;
    obs_params p = {0};
    char err[OBS_ERR_LEN], buf[256];
    assert_int_equal(obs_param_set(&p, "radius", "0.25", err), OBS_OK);
    assert_float_equal(p.radius, 0.25f, 0.0f);
    assert_int_equal(obs_param_set(&p, "samples", "8", err), OBS_OK);
    assert_int_equal(p.samples, 8);
    /* flags spell names with '-' */
    assert_int_equal(obs_param_set(&p, "depth-mode", "radial", err), OBS_OK);
    assert_int_equal(p.depth_mode, OBS_DEPTH_RADIAL);
    assert_int_equal(obs_param_set(&p, "normal_space", "camera", err), OBS_OK);
    assert_int_equal(p.normal_space, OBS_NORMALS_CAMERA);
    obs_param_format(&p, obs_param_find("depth_mode"), buf, sizeof buf);
    assert_string_equal(buf, "radial");
    obs_param_format(&p, obs_param_find("samples"), buf, sizeof buf);
    assert_string_equal(buf, "8");

    assert_int_equal(obs_param_set(&p, "world-to-camera", "1,0,0,0, 0,1,0,0, 0,0,1,-5, 0,0,0,1", err),
                     OBS_OK);
    assert_int_equal(p.has_world_to_camera, 1);
    assert_float_equal(p.world_to_camera[11], -5.0f, 0.0f);
}

static void test_errors_name_the_parameter(void **state)
{
    (void)state;
    obs_params p = {0};
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_param_set(&p, "samples", "64", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "samples"));
    assert_non_null(strstr(err, "2|4|8|16|32")); /* the sizes of section 4.5 */
    assert_int_equal(obs_param_set(&p, "samples", "3.5", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_param_set(&p, "radius", "abc", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "radius"));
    assert_non_null(strstr(err, "'abc' is not a number"));
    assert_int_equal(obs_param_set(&p, "radius", "-1", err), OBS_INVALID_ARGUMENT);
    /* a number out of range reads as one: "500 is outside [0, 179]" */
    assert_int_equal(obs_param_set(&p, "fov_y", "500", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "fov_y: 500 is outside [0, 179]"));
    assert_int_equal(obs_param_set(&p, "radius", "nan", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_param_set(&p, "radius", "1e999", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_param_set(&p, "depth_mode", "linear", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "planar|radial|ndc"));
    assert_int_equal(obs_param_set(&p, "nope", "1", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "nope"));
    assert_int_equal(obs_param_set(&p, "world_to_camera", "1,2,3", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_param_set(&p, "world_to_camera", "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17", err),
                     OBS_INVALID_ARGUMENT);
    /* nothing was changed by the failed calls */
    obs_params zero = {0};
    assert_memory_equal(&p, &zero, sizeof p);

    /* a struct filled by hand is checked field by field */
    obs_params q;
    obs_params_resolve(NULL, &q);
    q.samples = 40;
    assert_int_equal(obs_params_check(&q, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "samples"));
    obs_params_resolve(NULL, &q);
    q.depth_mode = 7;
    assert_int_equal(obs_params_check(&q, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "depth_mode"));
}

static void test_table_is_complete(void **state)
{
    (void)state;
    assert_true(obs_param_count() >= 9);
    for (int i = 0; i < obs_param_count(); i++) {
        const obs_param_info *pi = obs_param_at(i);
        assert_non_null(pi->name);
        assert_non_null(pi->doc);
        assert_true(strlen(pi->doc) > 10);
        assert_ptr_equal(obs_param_find(pi->name), pi);
        if (pi->type == OBS_PARAM_ENUM)
            assert_non_null(pi->choices);
        if (pi->type == OBS_PARAM_FLOAT || pi->type == OBS_PARAM_INT)
            assert_true(pi->min <= pi->max);
    }
    assert_null(obs_param_at(-1));
    assert_null(obs_param_at(obs_param_count()));
}

/* Each enumerated parameter: its enum and its choices come from one list
 * (OBS_*_LIST in params.h); every choice parses to its enum value,
 * formats back to its name, and the choices hold no other name. */
static void check_choice(const char *param, const char *choice, int value, int *count)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "", back[64];
    const obs_param_info *pi = obs_param_find(param);
    assert_non_null(pi);
    assert_int_equal(pi->type, OBS_PARAM_ENUM);
    if (obs_param_set(&p, param, choice, err) != OBS_OK)
        fail_msg("%s=%s: %s", param, choice, err);
    assert_int_equal(*(const int *)((const char *)&p + pi->offset), value);
    obs_param_format(&p, pi, back, sizeof back);
    assert_string_equal(back, choice);
    (*count)++;
}

static int choice_count(const char *param)
{
    int n = 1;
    for (const char *c = obs_param_find(param)->choices; *c; c++)
        n += *c == '|';
    return n;
}

static void test_enums_agree_with_choices(void **state)
{
    (void)state;
    int enums = 0;
#define CHOICE(value, choice) check_choice(param, #choice, value, &n);
#define ENUM(name, LIST)                                                       \
    {                                                                          \
        const char *param = #name;                                             \
        int n = 0;                                                             \
        LIST(CHOICE)                                                           \
        assert_int_equal(n, choice_count(param));                              \
        enums++;                                                               \
    }
    OBS_PARAM_ENUMS(ENUM)
#undef ENUM
#undef CHOICE
    /* every ENUM row of the table has its list in OBS_PARAM_ENUMS */
    int rows = 0;
    for (int i = 0; i < obs_param_count(); i++)
        rows += obs_param_at(i)->type == OBS_PARAM_ENUM;
    assert_int_equal(enums, rows);
}

/* --quality: each preset row parses; a preset sets what the request left
 * unset, an explicit parameter wins, default sets nothing. */
static void test_quality_presets(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
#define ROW_PARSES(q, name, value)                                             \
    {                                                                          \
        obs_params t = {0};                                                    \
        assert_int_equal(obs_param_set(&t, #name, value, err), OBS_OK);        \
    }
    OBS_QUALITY_PRESETS(ROW_PARSES)
#define EXACT_PARSES(name, value) ROW_PARSES(0, name, value)
    OBS_DEEP_GTAO_EXACT(EXACT_PARSES) /* the rows of deep gtao with intervals */
#undef EXACT_PARSES
#undef ROW_PARSES
    obs_params p = {0}, r, d;
    obs_params_resolve(NULL, &d);
    assert_int_equal(obs_param_set(&p, "quality", "preview", err), OBS_OK);
    obs_params_resolve(&p, &r);
    assert_int_equal(r.ao_resolution, OBS_RESOLUTION_HALF);
    assert_int_equal(r.samples, d.samples);
    assert_int_equal(obs_param_set(&p, "ao_resolution", "full", err), OBS_OK);
    obs_params_resolve(&p, &r);
    assert_int_equal(r.ao_resolution, OBS_RESOLUTION_FULL); /* explicit wins */

    obs_params h = {0};
    assert_int_equal(obs_param_set(&h, "quality", "reference", err), OBS_OK);
    assert_int_equal(obs_param_set(&h, "samples", "8", err), OBS_OK);
    obs_params_resolve(&h, &r);
    assert_int_equal(r.samples, 8);
    assert_int_equal(r.adaptive, OBS_OFF);
    assert_int_equal(r.culling, OBS_CULLING_OFF);

    obs_params s = {0};
    assert_int_equal(obs_param_set(&s, "quality", "default", err), OBS_OK);
    obs_params_resolve(&s, &r);
    d.quality = r.quality;
    d.method_conflict = r.method_conflict;
    assert_memory_equal(&r, &d, sizeof r);
    assert_int_equal(obs_param_set(&s, "quality", "best", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "preview|default|high|reference"));
}

/* A FLOAT parameter set to the bounds its range error names (%g) is
 * accepted by obs_params_check too, under a method it belongs to: the
 * bound parsed as a double and stored as a float may round below it. */
static void test_float_bounds_accepted(void **state)
{
    (void)state;
    const obs_param_info *method = obs_param_find("method");
    for (int i = 0; i < obs_param_count(); i++) {
        const obs_param_info *pi = obs_param_at(i);
        if (pi->type != OBS_PARAM_FLOAT)
            continue;
        for (int end = 0; end < 2; end++) {
            char value[32], name[32], err[OBS_ERR_LEN] = "";
            snprintf(value, sizeof value, "%g", end ? pi->max : pi->min);
            int accepted = 0;
            const char *c = method->choices;
            while (*c && !accepted) {
                size_t len = strcspn(c, "|");
                snprintf(name, sizeof name, "%.*s", (int)len, c);
                c += len + (c[len] == '|');
                obs_params p = {0}, r;
                assert_int_equal(obs_param_set(&p, "method", name, err), OBS_OK);
                assert_int_equal(obs_param_set(&p, pi->name, value, err), OBS_OK);
                obs_params_resolve(&p, &r);
                accepted = obs_params_check(&r, err) == OBS_OK;
            }
            if (!accepted)
                fail_msg("%s %s: set, then refused by every method: %s", pi->name, value, err);
        }
    }
}

static void test_status_names(void **state)
{
    (void)state;
    assert_string_equal(obs_status_name(OBS_OK), "OK");
    assert_string_equal(obs_status_name(OBS_MISSING_CHANNEL), "MISSING_CHANNEL");
    assert_string_equal(obs_status_name((obs_status)999), "UNKNOWN");
    for (int s = 0; s < OBS_STATUS_COUNT; s++)
        assert_true(strlen(obs_status_message((obs_status)s)) > 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_zero_means_defaults),
        cmocka_unit_test(test_set_and_format),
        cmocka_unit_test(test_errors_name_the_parameter),
        cmocka_unit_test(test_table_is_complete),
        cmocka_unit_test(test_enums_agree_with_choices),
        cmocka_unit_test(test_quality_presets),
        cmocka_unit_test(test_float_bounds_accepted),
        cmocka_unit_test(test_status_names),
    };
    return cmocka_run_group_tests_name("params", tests, NULL, NULL);
}
