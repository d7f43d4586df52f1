/* The parameter table: metadata, parsing, defaults, range checks. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

#define OBS__STR(x) #x
#define OBS__DEF_FLOAT(d) OBS__STR(d)
#define OBS__DEF_INT(d) OBS__STR(d)
#define OBS__DEF_ENUM(d) d
#define OBS__DEF_MAT4(d) "unset"

static const obs_param_info table[] = {
#define X(name, type, def, lo, hi, choices, doc)                                   \
    {#name, OBS_PARAM_##type, OBS__DEF_##type(def), lo, hi, choices, doc,         \
     offsetof(obs_params, name)},
    OBS_PARAM_TABLE(X)
#undef X
};

#define TABLE_LEN ((int)(sizeof table / sizeof table[0]))

int obs_param_count(void) { return TABLE_LEN; }

const obs_param_info *obs_param_at(int i)
{
    return i >= 0 && i < TABLE_LEN ? &table[i] : NULL;
}

/* Compares names treating '-' and '_' as the same character. */
static int name_eq(const char *a, const char *b)
{
    for (; *a && *b; a++, b++) {
        char ca = *a == '-' ? '_' : *a, cb = *b == '-' ? '_' : *b;
        if (ca != cb)
            return 0;
    }
    return *a == *b;
}

const obs_param_info *obs_param_find(const char *name)
{
    for (int i = 0; name && i < TABLE_LEN; i++)
        if (name_eq(table[i].name, name))
            return &table[i];
    return NULL;
}

/* Index (1-based) of `value` in the '|'-separated list, 0 if absent. */
static int choice_index(const char *choices, const char *value)
{
    size_t vlen = strlen(value);
    int idx = 1;
    for (const char *p = choices; *p; idx++) {
        const char *end = strchr(p, '|');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        if (len == vlen && strncmp(p, value, len) == 0)
            return idx;
        if (!end)
            break;
        p = end + 1;
    }
    return 0;
}

/* Writes choice number idx (1-based) into buf. */
static void choice_name(const char *choices, int idx, char *buf, size_t len)
{
    const char *p = choices;
    for (int i = 1; i < idx && p; i++) {
        p = strchr(p, '|');
        if (p)
            p++;
    }
    if (!p || idx < 1) {
        snprintf(buf, len, "?");
        return;
    }
    const char *end = strchr(p, '|');
    int n = end ? (int)(end - p) : (int)strlen(p);
    snprintf(buf, len, "%.*s", n, p);
}

static int parse_double(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || errno == ERANGE || !isfinite(v))
        return -1;
    while (isspace((unsigned char)*end))
        end++;
    if (*end)
        return -1;
    *out = v;
    return 0;
}

/* INT parameters with choices take only the listed numbers. */
static int int_allowed(const obs_param_info *pi, int v)
{
    if (!pi->choices)
        return 1;
    for (const char *c = pi->choices; *c;) {
        char *end;
        long n = strtol(c, &end, 10);
        if (end == c)
            return 0;
        if (n == v)
            return 1;
        c = *end == '|' ? end + 1 : end;
    }
    return 0;
}

static obs_status range_error(const obs_param_info *pi, const char *value, char err[OBS_ERR_LEN])
{
    if (pi->type == OBS_PARAM_INT && pi->choices)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "parameter %s: '%s' is not one of %s",
                         pi->name, value, pi->choices);
    if (pi->type == OBS_PARAM_INT)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "parameter %s: '%s' is not an integer in [%g, %g]", pi->name,
                         value, pi->min, pi->max);
    return obs__fail(err, OBS_INVALID_ARGUMENT, "parameter %s: '%s' is not a number in [%g, %g]",
                     pi->name, value, pi->min, pi->max);
}

obs_status obs_param_set(obs_params *p, const char *name, const char *value,
                         char err[OBS_ERR_LEN])
{
    const obs_param_info *pi = obs_param_find(name);
    if (!pi)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "unknown parameter '%s'", name ? name : "");
    if (!value)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "parameter %s needs a value", pi->name);
    char *field = (char *)p + pi->offset;
    double v;

    switch (pi->type) {
    case OBS_PARAM_FLOAT:
        if (parse_double(value, &v) != 0 || v < pi->min || v > pi->max)
            return range_error(pi, value, err);
        *(float *)field = (float)v;
        return OBS_OK;
    case OBS_PARAM_INT:
        if (parse_double(value, &v) != 0 || v != floor(v) || v < pi->min || v > pi->max ||
            !int_allowed(pi, (int)v))
            return range_error(pi, value, err);
        *(int *)field = (int)v;
        return OBS_OK;
    case OBS_PARAM_ENUM: {
        int idx = choice_index(pi->choices, value);
        if (!idx)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "parameter %s: '%s' is not one of %s",
                             pi->name, value, pi->choices);
        *(int *)field = idx;
        return OBS_OK;
    }
    case OBS_PARAM_MAT4: {
        /* 16 numbers separated by commas and/or spaces. */
        float m[16];
        const char *s = value;
        for (int i = 0; i < 16; i++) {
            char *end;
            while (isspace((unsigned char)*s) || *s == ',')
                s++;
            errno = 0;
            double d = strtod(s, &end);
            if (end == s || errno == ERANGE || !isfinite(d))
                return obs__fail(err, OBS_INVALID_ARGUMENT,
                                 "parameter %s: expected 16 numbers, number %d is missing or invalid",
                                 pi->name, i + 1);
            m[i] = (float)d;
            s = end;
        }
        while (isspace((unsigned char)*s) || *s == ',')
            s++;
        if (*s)
            return obs__fail(err, OBS_INVALID_ARGUMENT,
                             "parameter %s: expected 16 numbers, found more", pi->name);
        memcpy(field, m, sizeof m);
        if (pi->offset == offsetof(obs_params, world_to_camera))
            p->has_world_to_camera = 1;
        return OBS_OK;
    }
    }
    return obs__fail(err, OBS_INVALID_ARGUMENT, "parameter %s has an unknown type", pi->name);
}

void obs_param_format(const obs_params *p, const obs_param_info *pi, char *buf, size_t len)
{
    const char *field = (const char *)p + pi->offset;
    switch (pi->type) {
    case OBS_PARAM_FLOAT: snprintf(buf, len, "%g", *(const float *)field); break;
    case OBS_PARAM_INT: snprintf(buf, len, "%d", *(const int *)field); break;
    case OBS_PARAM_ENUM: choice_name(pi->choices, *(const int *)field, buf, len); break;
    case OBS_PARAM_MAT4: {
        const float *m = (const float *)field;
        size_t off = 0;
        buf[0] = '\0';
        for (int i = 0; i < 16 && off < len; i++)
            off += (size_t)snprintf(buf + off, len - off, i ? ",%g" : "%g", m[i]);
        break;
    }
    }
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
            if (table[i].offset != method_params[k].offset)
                continue;
            if (table[i].type == OBS_PARAM_FLOAT) {
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

/* The rows of --quality's preset: each parameter the request left unset
 * (0) takes the preset's value; an explicit one keeps its own. */
static void apply_quality(obs_params *r)
{
    static const struct {
        int quality;
        const char *name, *value;
    } rows[] = {
#define OBS__PRESET_ROW(q, name, value) {q, #name, value},
        OBS_QUALITY_PRESETS(OBS__PRESET_ROW)
#undef OBS__PRESET_ROW
    };
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        if (rows[k].quality != r->quality)
            continue;
        const obs_param_info *pi = obs_param_find(rows[k].name);
        obs_params set;
        memset(&set, 0, sizeof set);
        /* the rows are checked by test_params.c: each value parses */
        if (!pi || obs_param_set(&set, rows[k].name, rows[k].value, NULL) != OBS_OK)
            continue;
        char *field = (char *)r + pi->offset;
        const char *value = (const char *)&set + pi->offset;
        if (pi->type == OBS_PARAM_FLOAT ? *(float *)field == 0.0f : *(int *)field == 0)
            memcpy(field, value, pi->type == OBS_PARAM_FLOAT ? sizeof(float) : sizeof(int));
    }
}

void obs_params_resolve(const obs_params *in, obs_params *out)
{
    obs_params r;
    if (in)
        r = *in;
    else
        memset(&r, 0, sizeof r);
    apply_quality(&r);
    for (int i = 0; i < TABLE_LEN; i++) {
        const obs_param_info *pi = &table[i];
        char *field = (char *)&r + pi->offset;
        switch (pi->type) {
        case OBS_PARAM_FLOAT:
            if (*(float *)field == 0.0f)
                *(float *)field = (float)strtod(pi->def, NULL);
            break;
        case OBS_PARAM_INT:
            if (*(int *)field == 0)
                *(int *)field = (int)strtol(pi->def, NULL, 10);
            break;
        case OBS_PARAM_ENUM:
            if (*(int *)field == 0)
                *(int *)field = choice_index(pi->choices, pi->def);
            break;
        case OBS_PARAM_MAT4:
            break; /* unset stays unset: has_world_to_camera says */
        }
    }
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
        const obs_param_info *pi = &table[p->method_conflict - 1];
        const obs_param_info *mi = obs_param_find("method");
        char method[32];
        obs_param_format(p, mi, method, sizeof method);
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "parameter %s does not apply to method %s: %s; leave it unset "
                         "or pick a method it belongs to",
                         pi->name, method, method_why(pi->offset));
    }
    for (int i = 0; i < TABLE_LEN; i++) {
        const obs_param_info *pi = &table[i];
        const char *field = (const char *)p + pi->offset;
        char text[64];
        switch (pi->type) {
        case OBS_PARAM_FLOAT: {
            float v = *(const float *)field;
            /* the bounds as the float field holds them: obs_param_set
             * accepts the table's min (1e-6 parsed as a double) and stores
             * it rounded to a float, which may lie below the double */
            if (!isfinite(v) || v < (float)pi->min || v > (float)pi->max) {
                snprintf(text, sizeof text, "%g", v);
                return range_error(pi, text, err);
            }
            break;
        }
        case OBS_PARAM_INT: {
            int v = *(const int *)field;
            if (v < pi->min || v > pi->max || !int_allowed(pi, v)) {
                snprintf(text, sizeof text, "%d", v);
                return range_error(pi, text, err);
            }
            break;
        }
        case OBS_PARAM_ENUM: {
            int v = *(const int *)field;
            int n = 1;
            for (const char *c = pi->choices; *c; c++)
                n += *c == '|';
            if (v < 1 || v > n)
                return obs__fail(err, OBS_INVALID_ARGUMENT,
                                 "parameter %s: value %d is not one of %s", pi->name, v,
                                 pi->choices);
            break;
        }
        case OBS_PARAM_MAT4: {
            const float *m = (const float *)field;
            for (int k = 0; k < 16; k++)
                if (!isfinite(m[k]))
                    return obs__fail(err, OBS_INVALID_ARGUMENT,
                                     "parameter %s: element %d is not finite", pi->name, k + 1);
            break;
        }
        }
    }
    return OBS_OK;
}
