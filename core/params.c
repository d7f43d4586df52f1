/* The parameter table (OBS_PARAM_TABLE, obscura/params.h): its rows, the
 * quality presets and what each method fixes; parsing, defaults and range
 * checks are the table engine's (core/table.c). */
#include <string.h>

#include "internal.h"

#define OBS__STR(x) #x
#define OBS__DEF_FLOAT(d) OBS__STR(d)
#define OBS__DEF_INT(d) OBS__STR(d)
#define OBS__DEF_ENUM(d) d
#define OBS__DEF_MAT4(d) "unset"
#define OBS__DEF_STRING(d) d

static const obs_table_row rows[] = {
#define X(name, type, def, lo, hi, choices, doc)                                   \
    {#name, OBS_TABLE_##type, OBS__DEF_##type(def), lo, hi, choices, doc,          \
     offsetof(obs_params, name)},
    OBS_PARAM_TABLE(X)
#undef X
};

#define TABLE_LEN ((int)(sizeof rows / sizeof rows[0]))

/* Zero means "default" (no mask); the engine's messages read "parameter
 * radius: 'x' is not a number in [...]". */
static const obs_table table = {.rows = rows, .count = TABLE_LEN, .noun = "parameter", .hint = "",
                                .enum_base = 1, .given = OBS_TABLE_NO_MASK};

int obs_param_count(void) { return TABLE_LEN; }

const obs_param_info *obs_param_at(int i)
{
    return i >= 0 && i < TABLE_LEN ? &rows[i] : NULL;
}

const obs_param_info *obs_param_find(const char *name) { return obs_table_find(&table, name); }

obs_status obs_param_set(obs_params *p, const char *name, const char *value,
                         char err[OBS_ERR_LEN])
{
    const obs_table_row *r;
    obs_status s = obs_table_set(&table, p, name, value, &r, err);
    if (s == OBS_OK && r->offset == offsetof(obs_params, world_to_camera))
        p->has_world_to_camera = 1;
    return s;
}

void obs_param_format(const obs_params *p, const obs_param_info *pi, char *buf, size_t len)
{
    obs_table_format(&table, pi, p, buf, len);
}

/* Which methods a parameter belongs to (bits 1 << obs_method); the
 * parameters not listed belong to every method.  A value that agrees
 * with what the method fixes (adaptive off with method vao) is no
 * conflict. */
#define M(m) (1u << OBS_METHOD_##m)
static const struct {
    size_t offset;
    unsigned methods;
    int allowed; /* the one value every other method accepts; 0: none */
    const char *why;
} method_params[] = {
    {offsetof(obs_params, samples), M(VAOPP) | M(VAO), 0,
     "the VAO sample sets; hemisphere takes hemisphere_samples, angle angle_pairs, hbao "
     "hbao_directions and hbao_steps, gtao gtao_slices and gtao_steps"},
    {offsetof(obs_params, ao_definition), M(VAOPP) | M(VAO), 0,
     "it converts the volumetric obscurance of VAO (section 3)"},
    {offsetof(obs_params, adaptive), M(VAOPP), OBS_OFF, "adaptive sampling is VAO++'s (4.1)"},
    {offsetof(obs_params, adaptive_diameter), M(VAOPP), 0, "adaptive sampling is VAO++'s (4.1)"},
    {offsetof(obs_params, culling), M(VAOPP), OBS_CULLING_OFF,
     "the culling pre-pass is VAO++'s (4.2)"},
    {offsetof(obs_params, culling_epsilon), M(VAOPP), 0, "the culling pre-pass is VAO++'s (4.2)"},
    {offsetof(obs_params, range_check), M(VAOPP), OBS_OFF,
     "the depth range check is VAO++'s (4.4, eq 4)"},
    {offsetof(obs_params, range_u), M(VAOPP), 0, "the depth range check is VAO++'s (4.4, eq 4)"},
    {offsetof(obs_params, range_distance), M(VAOPP), 0,
     "the depth range check is VAO++'s (4.4, eq 4)"},
    {offsetof(obs_params, bleeding), M(VAOPP) | M(VAO), OBS_BLEEDING_OFF,
     "colour bleeding (4.7) gathers the colour at the VAO samples"},
    {offsetof(obs_params, hemisphere_samples), M(HEMISPHERE), 0, "it is method hemisphere's"},
    {offsetof(obs_params, hemisphere_bias), M(HEMISPHERE), 0, "it is method hemisphere's"},
    {offsetof(obs_params, angle_pairs), M(ANGLE), 0, "it is method angle's"},
    {offsetof(obs_params, angle_acos), M(ANGLE), 0, "it is method angle's"},
    {offsetof(obs_params, hbao_directions), M(HBAO), 0, "it is method hbao's"},
    {offsetof(obs_params, hbao_steps), M(HBAO), 0, "it is method hbao's"},
    {offsetof(obs_params, hbao_angle_bias), M(HBAO), 0, "it is method hbao's"},
    {offsetof(obs_params, gtao_slices), M(GTAO), 0, "it is method gtao's"},
    {offsetof(obs_params, gtao_steps), M(GTAO), 0, "it is method gtao's"},
    {offsetof(obs_params, gtao_radius_multiplier), M(GTAO), 0, "it is method gtao's"},
    {offsetof(obs_params, gtao_falloff), M(GTAO), 0, "it is method gtao's"},
    {offsetof(obs_params, gtao_thin), M(GTAO), 0, "it is method gtao's"},
    {offsetof(obs_params, gtao_power), M(GTAO), 0, "it is method gtao's"},
    {offsetof(obs_params, gtao_heuristics), M(GTAO), 0, "it is method gtao's"},
};
#undef M

/* 1 + the table index of the first parameter in `in` (given: non-zero)
 * that does not apply to `method`; 0 if none. */
static int method_conflict(const obs_params *in, int method)
{
    if (!in || method < OBS_METHOD_VAOPP || method >= OBS_METHOD_COUNT)
        return 0;
    for (size_t k = 0; k < sizeof method_params / sizeof method_params[0]; k++) {
        if (method_params[k].methods & (1u << method))
            continue;
        const char *field = (const char *)in + method_params[k].offset;
        int given = 0, agrees = 0;
        for (int i = 0; i < TABLE_LEN; i++) {
            if (rows[i].offset != method_params[k].offset)
                continue;
            if (rows[i].type == OBS_PARAM_FLOAT) {
                given = *(const float *)field != 0.0f;
            } else {
                int v = *(const int *)field;
                given = v != 0;
                agrees = method_params[k].allowed && v == method_params[k].allowed;
            }
            if (given && !agrees)
                return i + 1;
        }
    }
    return 0;
}

static const char *method_why(size_t offset)
{
    for (size_t k = 0; k < sizeof method_params / sizeof method_params[0]; k++)
        if (method_params[k].offset == offset)
            return method_params[k].why;
    return "";
}

void obs__params_fill(obs_params *r, const char *name, const char *value)
{
    const obs_param_info *pi = obs_param_find(name);
    obs_params set;
    memset(&set, 0, sizeof set);
    /* the rows are checked by test_params.c: each value parses */
    if (!pi || obs_param_set(&set, name, value, NULL) != OBS_OK)
        return;
    char *field = (char *)r + pi->offset;
    const char *v = (const char *)&set + pi->offset;
    if (pi->type == OBS_PARAM_FLOAT ? *(float *)field == 0.0f : *(int *)field == 0)
        memcpy(field, v, pi->type == OBS_PARAM_FLOAT ? sizeof(float) : sizeof(int));
}

/* The rows of --quality's preset: each parameter the request left unset
 * (0) takes the preset's value; an explicit one keeps its own. */
static void apply_quality(obs_params *r)
{
    static const struct {
        int quality;
        const char *name, *value;
    } presets[] = {
#define OBS__PRESET_ROW(q, name, value) {q, #name, value},
        OBS_QUALITY_PRESETS(OBS__PRESET_ROW)
#undef OBS__PRESET_ROW
    };
    for (size_t k = 0; k < sizeof presets / sizeof presets[0]; k++)
        if (presets[k].quality == r->quality)
            obs__params_fill(r, presets[k].name, presets[k].value);
}

void obs_params_resolve(const obs_params *in, obs_params *out)
{
    obs_params r;
    if (in)
        r = *in;
    else
        memset(&r, 0, sizeof r);
    apply_quality(&r);
    obs_table_defaults(&table, &r);
    /* A struct resolved before keeps its verdict: its fields are no
     * longer what a request gave. */
    if (!in || in->method_conflict == 0) {
        int c = method_conflict(in, r.method);
        r.method_conflict = c ? c : -1;
    }
    /* What the method fixes: adaptive sampling (4.1), culling (4.2) and
     * the depth range check (4.4) are VAO++'s; plain VAO (section 3) and
     * the other methods run without them.  Bleeding (4.7) gathers the
     * colour at the VAO samples: VAO and VAO++ only. */
    if (r.method != OBS_METHOD_VAOPP) {
        r.adaptive = OBS_OFF;
        r.culling = OBS_CULLING_OFF;
        r.range_check = OBS_OFF;
    }
    if (r.method != OBS_METHOD_VAOPP && r.method != OBS_METHOD_VAO)
        r.bleeding = OBS_BLEEDING_OFF;
    *out = r;
}

void obs__params_for_gbuffer(const obs_params *in, const obs_gbuffer *gb, obs_params *out)
{
    obs_params q;
    if (in)
        q = *in;
    else
        memset(&q, 0, sizeof q);
    if (gb && q.depth_mode == OBS_DEPTH_DEFAULT)
        q.depth_mode = gb->depth_mode;
    if (gb && q.normal_space == OBS_NORMALS_DEFAULT)
        q.normal_space = gb->normal_space;
    obs_params_resolve(&q, out);
}

obs_status obs_params_check(const obs_params *p, char err[OBS_ERR_LEN])
{
    if (p->method_conflict > 0 && p->method_conflict <= TABLE_LEN) {
        const obs_param_info *pi = &rows[p->method_conflict - 1];
        const obs_param_info *mi = obs_param_find("method");
        char method[32];
        obs_param_format(p, mi, method, sizeof method);
        return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                         "parameter %s does not apply to method %s: %s; leave it unset "
                         "or pick a method it belongs to",
                         pi->name, method, method_why(pi->offset));
    }
    return obs_table_check(&table, p, err);
}
