/* A parameter table of the bake's kind and its public accessors, written
 * once: rows X(name, type, def, lo, hi, choices, doc) of struct
 * OBS__PARAM_STRUCT, whose `uint64_t set` records the rows given.  The
 * engine (obscura/table.h) does the work; this names it.  Used by the
 * bake's table (core/bake/params.c) and the dynamic bake's
 * (dyn_params.c). */
#ifndef OBSCURA_PARAM_TABLE_H
#define OBSCURA_PARAM_TABLE_H

#include "obscura/table.h"

#define OBS__PT_STR(x) #x
#define OBS__PT_DEF_FLOAT(d) OBS__PT_STR(d)
#define OBS__PT_DEF_INT(d) OBS__PT_STR(d)
#define OBS__PT_DEF_ENUM(d) d
#define OBS__PT_ROW(name, type, def, lo, hi, choices, doc)                                     \
    {#name, OBS_TABLE_##type, OBS__PT_DEF_##type(def), lo, hi, choices, doc,                  \
     offsetof(OBS__PARAM_STRUCT, name)},

/* Defines obs_P_count, obs_P_at, obs_P_find, obs_P_set, obs_Ps_resolve
 * and obs_P_format (P: bake_param, dyn_param) over TABLE's rows; NOUN
 * begins the messages ("bake parameter threads: ..."). */
#define OBS__PARAM_TABLE(P, TABLE, NOUN)                                                       \
    static const obs_table_row rows[] = {TABLE(OBS__PT_ROW)};                                  \
    _Static_assert(sizeof rows / sizeof rows[0] <= 64, "the set mask has 64 bits");           \
    /* strict: an empty value is missing; no blank may follow a number */                    \
    static const obs_table table = {.rows = rows,                                              \
                                    .count = (int)(sizeof rows / sizeof rows[0]),              \
                                    .noun = NOUN,                                              \
                                    .hint = "",                                                \
                                    .enum_base = 1,                                            \
                                    .strict = 1,                                               \
                                    .given = offsetof(OBS__PARAM_STRUCT, set)};                \
    int obs_##P##_count(void) { return table.count; }                                          \
    const obs_table_row *obs_##P##_at(int i)                                                   \
    {                                                                                          \
        return i >= 0 && i < table.count ? &rows[i] : NULL;                                    \
    }                                                                                          \
    const obs_table_row *obs_##P##_find(const char *name) { return obs_table_find(&table, name); } \
    obs_status obs_##P##_set(OBS__PARAM_STRUCT *p, const char *name, const char *value,       \
                             char err[OBS_ERR_LEN])                                            \
    {                                                                                          \
        return obs_table_set(&table, p, name, value, NULL, err);                               \
    }                                                                                          \
    void obs_##P##s_resolve(const OBS__PARAM_STRUCT *in, OBS__PARAM_STRUCT *out)             \
    {                                                                                          \
        OBS__PARAM_STRUCT r = in ? *in : (OBS__PARAM_STRUCT){0};                               \
        obs_table_defaults(&table, &r);                                                        \
        *out = r;                                                                              \
    }                                                                                          \
    void obs_##P##_format(const OBS__PARAM_STRUCT *p, const obs_table_row *pi, char *buf,     \
                          size_t len)                                                          \
    {                                                                                          \
        obs_table_format(&table, pi, p, buf, len);                                             \
    }

#endif
