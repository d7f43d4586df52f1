/* The parameter table of obscura bake-dynamic (OBS_DYN_PARAM_TABLE,
 * obscura/dynamic.h): metadata, parsing, defaults; the same code as the
 * bake table's (params.c) over its own rows. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "obscura/dynamic.h"

#define STR(x) #x
#define DEF_FLOAT(d) STR(d)
#define DEF_INT(d) STR(d)
#define DEF_ENUM(d) d

static const obs_bake_param_info table[] = {
#define X(name, type, def, lo, hi, choices, doc)                                    \
    {#name, DEF_##type(def), choices, doc, OBS_BAKE_PARAM_##type, lo, hi,          \
     offsetof(obs_dyn_params, name)},
    OBS_DYN_PARAM_TABLE(X)
#undef X
};
#define LEN ((int)(sizeof table / sizeof table[0]))
_Static_assert(sizeof table / sizeof table[0] <= 64, "obs_dyn_params.set has 64 bits");

int obs_dyn_param_count(void) { return LEN; }

const obs_bake_param_info *obs_dyn_param_at(int i) { return i >= 0 && i < LEN ? &table[i] : NULL; }

static int name_eq(const char *a, const char *b)
{
    for (; *a && *b; a++, b++)
        if ((*a == '-' ? '_' : *a) != (*b == '-' ? '_' : *b))
            return 0;
    return *a == *b;
}

const obs_bake_param_info *obs_dyn_param_find(const char *name)
{
    for (int i = 0; name && i < LEN; i++)
        if (name_eq(table[i].name, name))
            return &table[i];
    return NULL;
}

/* 1-based index of value among choices "a|b|c", 0 when absent. */
static int choice_index(const char *choices, const char *value)
{
    size_t n = strlen(value);
    int idx = 1;
    for (const char *p = choices; p; idx++) {
        const char *end = strchr(p, '|');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        if (len == n && !strncmp(p, value, n))
            return idx;
        p = end ? end + 1 : NULL;
    }
    return 0;
}

obs_status obs_dyn_param_set(obs_dyn_params *p, const char *name, const char *value,
                              char err[OBS_ERR_LEN])
{
    const obs_bake_param_info *pi = obs_dyn_param_find(name);
    if (!pi)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "unknown bake-dynamic parameter '%s'",
                         name ? name : "");
    if (!value || !*value)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "bake-dynamic parameter %s needs a value", pi->name);
    char *field = (char *)p + pi->offset;
    if (pi->type == OBS_BAKE_PARAM_ENUM) {
        int idx = choice_index(pi->choices, value);
        if (!idx)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "bake-dynamic parameter %s: '%s' is not one of %s",
                             pi->name, value, pi->choices);
        *(int *)field = idx;
    } else {
        char *end;
        errno = 0;
        double v = strtod(value, &end);
        int bad = end == value || *end || errno == ERANGE || !isfinite(v) || v < pi->min ||
                  v > pi->max || (pi->type == OBS_BAKE_PARAM_INT && v != floor(v));
        if (bad)
            return obs__fail(err, OBS_INVALID_ARGUMENT,
                             "bake-dynamic parameter %s: '%s' is not %s in [%g, %g]", pi->name, value,
                             pi->type == OBS_BAKE_PARAM_INT ? "an integer" : "a number", pi->min,
                             pi->max);
        if (pi->type == OBS_BAKE_PARAM_INT)
            *(int *)field = (int)v;
        else
            *(float *)field = (float)v;
    }
    p->set |= (uint64_t)1 << (pi - table);
    return OBS_OK;
}

void obs_dyn_params_resolve(const obs_dyn_params *in, obs_dyn_params *out)
{
    obs_dyn_params r = in ? *in : (obs_dyn_params){0};
    for (int i = 0; i < LEN; i++) {
        const obs_bake_param_info *pi = &table[i];
        char *field = (char *)&r + pi->offset;
        if (r.set >> i & 1)
            continue;
        if (pi->type == OBS_BAKE_PARAM_ENUM)
            *(int *)field = *(int *)field ? *(int *)field : choice_index(pi->choices, pi->def);
        else if (pi->type == OBS_BAKE_PARAM_INT)
            *(int *)field = *(int *)field ? *(int *)field : atoi(pi->def);
        else
            *(float *)field = *(float *)field != 0.0f ? *(float *)field : strtof(pi->def, NULL);
    }
    *out = r;
}

void obs_dyn_param_format(const obs_dyn_params *p, const obs_bake_param_info *pi, char *buf,
                           size_t len)
{
    const char *field = (const char *)p + pi->offset;
    if (pi->type == OBS_BAKE_PARAM_FLOAT) {
        snprintf(buf, len, "%g", *(const float *)field);
    } else if (pi->type == OBS_BAKE_PARAM_INT) {
        snprintf(buf, len, "%d", *(const int *)field);
    } else {
        int idx = *(const int *)field;
        const char *c = pi->choices;
        for (int i = 1; i < idx && c; i++)
            if ((c = strchr(c, '|')))
                c++;
        const char *end = c ? strchr(c, '|') : NULL;
        snprintf(buf, len, "%.*s", c ? (int)(end ? (size_t)(end - c) : strlen(c)) : 1,
                 c ? c : "?");
    }
}
