/* The parameter table of obscura bake-dynamic (OBS_DYN_PARAM_TABLE,
 * obscura/dynamic.h): its rows; parsing, defaults and formatting are the
 * table engine's (core/table.c), as for the bake's table. */
#include "obscura/dynamic.h"

#define STR(x) #x
#define DEF_FLOAT(d) STR(d)
#define DEF_INT(d) STR(d)
#define DEF_ENUM(d) d

static const obs_table_row rows[] = {
#define X(name, type, def, lo, hi, choices, doc)                                    \
    {#name, OBS_TABLE_##type, DEF_##type(def), lo, hi, choices, doc,               \
     offsetof(obs_dyn_params, name)},
    OBS_DYN_PARAM_TABLE(X)
#undef X
};
#define LEN ((int)(sizeof rows / sizeof rows[0]))
_Static_assert(LEN <= 64, "obs_dyn_params.set has 64 bits");

static const obs_table table = {
    .rows = rows, .count = LEN, .noun = "bake-dynamic parameter", .hint = "", .enum_base = 1,
    .strict = 1, /* an empty value is missing; no blank may follow a number */
    .given = offsetof(obs_dyn_params, set)};

int obs_dyn_param_count(void) { return LEN; }

const obs_bake_param_info *obs_dyn_param_at(int i) { return i >= 0 && i < LEN ? &rows[i] : NULL; }

const obs_bake_param_info *obs_dyn_param_find(const char *name)
{
    return obs_table_find(&table, name);
}

obs_status obs_dyn_param_set(obs_dyn_params *p, const char *name, const char *value,
                             char err[OBS_ERR_LEN])
{
    return obs_table_set(&table, p, name, value, NULL, err);
}

void obs_dyn_params_resolve(const obs_dyn_params *in, obs_dyn_params *out)
{
    obs_dyn_params r = in ? *in : (obs_dyn_params){0};
    obs_table_defaults(&table, &r);
    *out = r;
}

void obs_dyn_param_format(const obs_dyn_params *p, const obs_bake_param_info *pi, char *buf,
                          size_t len)
{
    obs_table_format(&table, pi, p, buf, len);
}
