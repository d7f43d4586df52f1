/* The table engine (obscura/table.h): one parser, range check, default
 * and formatter per field type, shared by every table of settings. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "obscura/table.h"

int obs_table_name_eq(const char *a, const char *b, size_t blen)
{
    size_t i = 0;
    for (; a[i] && i < blen; i++) {
        char ca = a[i] == '-' ? '_' : a[i], cb = b[i] == '-' ? '_' : b[i];
        if (ca != cb)
            return 0;
    }
    return a[i] == '\0' && i == blen;
}

const obs_table_row *obs_table_find_n(const obs_table *t, const char *name, size_t len)
{
    for (int i = 0; name && i < t->count; i++)
        if (obs_table_name_eq(t->rows[i].name, name, len))
            return &t->rows[i];
    return NULL;
}

const obs_table_row *obs_table_find(const obs_table *t, const char *name)
{
    return name ? obs_table_find_n(t, name, strlen(name)) : NULL;
}

int obs_table_choice(const char *choices, const char *value)
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

/* Writes choice number idx (1-based) into buf, "?" when there is none. */
static void choice_name(const char *choices, int idx, char *buf, size_t len)
{
    const char *p = choices;
    for (int i = 1; i < idx && p; i++)
        if ((p = strchr(p, '|')))
            p++;
    if (!p || idx < 1) {
        snprintf(buf, len, "?");
        return;
    }
    const char *end = strchr(p, '|');
    snprintf(buf, len, "%.*s", end ? (int)(end - p) : (int)strlen(p), p);
}

/* strtod's number, finite, nothing after it but (unless strict) blanks. */
static int parse_number(const char *s, unsigned strict, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || errno == ERANGE || !isfinite(v))
        return -1;
    while (!strict && isspace((unsigned char)*end))
        end++;
    if (*end)
        return -1;
    *out = v;
    return 0;
}

/* INT rows with choices take only the listed numbers. */
static int int_allowed(const obs_table_row *r, int v)
{
    if (!r->choices)
        return 1;
    for (const char *c = r->choices; *c;) {
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

obs_status obs_table_range_error(const obs_table *t, const obs_table_row *r, const char *value,
                                 char err[OBS_ERR_LEN])
{
    const char *n = t->noun;
    /* an INT row with a list of numbers reads as choices */
    if (r->type == OBS_TABLE_ENUM || (r->type == OBS_TABLE_INT && r->choices))
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s %s: '%s' is not one of %s", n,
                              r->name, value, r->choices);
    /* a number outside the range says so; only text that is no number
     * is called one */
    double v;
    int number = parse_number(value, 0, &v) == 0;
    if (number && (r->type == OBS_TABLE_FLOAT || r->type == OBS_TABLE_INT) &&
        (v < r->min || v > r->max))
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s %s: %s is outside [%g, %g]", n,
                              r->name, value, r->min, r->max);
    switch (r->type) {
    case OBS_TABLE_INT:
        return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                              "%s %s: '%s' is not an integer in [%g, %g]", n, r->name, value,
                              r->min, r->max);
    case OBS_TABLE_WHOLE:
    case OBS_TABLE_SIZE:
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s %s: %s is out of range [%lld, %lld]",
                              n, r->name, value, (long long)r->min, (long long)r->max);
    case OBS_TABLE_STRING:
        return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                              "%s %s: value is longer than %lld characters", n, r->name,
                              (long long)r->max);
    default:
        return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                              "%s %s: '%s' is not a number in [%g, %g]", n, r->name, value,
                              r->min, r->max);
    }
}

/* 16 numbers separated by commas and/or spaces. */
static obs_status parse_mat4(const obs_table *t, const obs_table_row *r, float m[16],
                             const char *value, char err[OBS_ERR_LEN])
{
    const char *s = value;
    for (int i = 0; i < 16; i++) {
        char *end;
        while (isspace((unsigned char)*s) || *s == ',')
            s++;
        errno = 0;
        double d = strtod(s, &end);
        if (end == s || errno == ERANGE || !isfinite(d))
            return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                                  "%s %s: expected 16 numbers, number %d is missing or invalid",
                                  t->noun, r->name, i + 1);
        m[i] = (float)d;
        s = end;
    }
    while (isspace((unsigned char)*s) || *s == ',')
        s++;
    if (*s)
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s %s: expected 16 numbers, found more",
                              t->noun, r->name);
    return OBS_OK;
}

/* Digits (strtoll), and for SIZE an optional k, m or g: x 1024^n. */
static obs_status parse_whole(const obs_table *t, const obs_table_row *r, const char *value,
                              long long *out, char err[OBS_ERR_LEN])
{
    long long lo = (long long)r->min, hi = (long long)r->max;
    char *end;
    errno = 0;
    long long v = strtoll(value, &end, 10);
    if (end == value || errno == ERANGE)
        goto not_number;
    if (r->type == OBS_TABLE_SIZE && *end) {
        int shift = -1;
        switch (tolower((unsigned char)*end)) {
        case 'k': shift = 10; break;
        case 'm': shift = 20; break;
        case 'g': shift = 30; break;
        }
        if (shift < 0 || end[1] != '\0' || v < 0 || v > (INT64_MAX >> shift))
            return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                                  "%s %s: '%s' is not a size (a number, optionally with k, m "
                                  "or g) in [%lld, %lld]", t->noun, r->name, value, lo, hi);
        v <<= shift;
        end += 1;
    }
    if (*end)
        goto not_number;
    if (v < lo || v > hi)
        return obs_table_range_error(t, r, value, err);
    *out = v;
    return OBS_OK;
not_number:
    return obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s %s: '%s' is not a number in [%lld, %lld]",
                          t->noun, r->name, value, lo, hi);
}

obs_status obs_table_parse(const obs_table *t, const obs_table_row *r, void *base,
                           const char *value, char err[OBS_ERR_LEN])
{
    char *field = (char *)base + r->offset;
    if (!value || (t->strict && !*value))
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s %s needs a value", t->noun, r->name);
    double v;
    long long w = 0;
    switch (r->type) {
    case OBS_TABLE_FLOAT:
        if (parse_number(value, t->strict, &v) != 0 || v < r->min || v > r->max)
            return obs_table_range_error(t, r, value, err);
        *(float *)(void *)field = (float)v;
        return OBS_OK;
    case OBS_TABLE_INT:
        if (parse_number(value, t->strict, &v) != 0 || v != floor(v) || v < r->min ||
            v > r->max || !int_allowed(r, (int)v))
            return obs_table_range_error(t, r, value, err);
        *(int *)(void *)field = (int)v;
        return OBS_OK;
    case OBS_TABLE_ENUM: {
        int idx = obs_table_choice(r->choices, value);
        if (!idx)
            return obs_table_range_error(t, r, value, err);
        *(int *)(void *)field = idx - 1 + (int)t->enum_base;
        return OBS_OK;
    }
    case OBS_TABLE_MAT4: {
        float m[16];
        obs_status s = parse_mat4(t, r, m, value, err);
        if (s == OBS_OK)
            memcpy(field, m, sizeof m);
        return s;
    }
    case OBS_TABLE_STRING:
        if ((double)strlen(value) > r->max)
            return obs_table_range_error(t, r, value, err);
        snprintf(field, (size_t)r->max + 1, "%s", value);
        return OBS_OK;
    case OBS_TABLE_WHOLE:
    case OBS_TABLE_SIZE: {
        obs_status s = parse_whole(t, r, value, &w, err);
        if (s == OBS_OK && r->type == OBS_TABLE_WHOLE)
            *(int *)(void *)field = (int)w;
        else if (s == OBS_OK)
            *(int64_t *)(void *)field = w;
        return s;
    }
    }
    return obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s %s has an unknown type", t->noun,
                          r->name);
}

obs_status obs_table_set(const obs_table *t, void *base, const char *name, const char *value,
                         const obs_table_row **row, char err[OBS_ERR_LEN])
{
    const obs_table_row *r = obs_table_find(t, name);
    if (row)
        *row = r;
    if (!r)
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "unknown %s '%s'%s", t->noun,
                              name ? name : "", t->hint);
    obs_status s = obs_table_parse(t, r, base, value, err);
    if (s == OBS_OK && t->given != OBS_TABLE_NO_MASK)
        *(uint64_t *)(void *)((char *)base + t->given) |= (uint64_t)1 << (r - t->rows);
    return s;
}

/* One field against its row; text holds the value for the message. */
static obs_status check_row(const obs_table *t, const obs_table_row *r, const char *field,
                            char err[OBS_ERR_LEN])
{
    char text[64];
    switch (r->type) {
    case OBS_TABLE_FLOAT: {
        float v = *(const float *)(const void *)field;
        /* the bounds as the float field holds them: obs_table_parse
         * accepts the row's min (1e-6 parsed as a double) and stores it
         * rounded to a float, which may lie below the double */
        if (isfinite(v) && v >= (float)r->min && v <= (float)r->max)
            return OBS_OK;
        snprintf(text, sizeof text, "%g", v);
        return obs_table_range_error(t, r, text, err);
    }
    case OBS_TABLE_INT:
    case OBS_TABLE_WHOLE: {
        int v = *(const int *)(const void *)field;
        if (v >= r->min && v <= r->max && int_allowed(r, v))
            return OBS_OK;
        snprintf(text, sizeof text, "%d", v);
        return obs_table_range_error(t, r, text, err);
    }
    case OBS_TABLE_ENUM: {
        int v = *(const int *)(const void *)field - (int)t->enum_base, n = 1;
        for (const char *c = r->choices; *c; c++)
            n += *c == '|';
        if (v >= 0 && v < n)
            return OBS_OK;
        return obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s %s: value %d is not one of %s",
                              t->noun, r->name, v + (int)t->enum_base, r->choices);
    }
    case OBS_TABLE_MAT4: {
        const float *m = (const float *)(const void *)field;
        for (int k = 0; k < 16; k++)
            if (!isfinite(m[k]))
                return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                                      "%s %s: element %d is not finite", t->noun, r->name, k + 1);
        return OBS_OK;
    }
    case OBS_TABLE_STRING: return OBS_OK; /* parsing kept it short */
    case OBS_TABLE_SIZE: {
        int64_t v = *(const int64_t *)(const void *)field;
        if (v >= (long long)r->min && v <= (long long)r->max)
            return OBS_OK;
        snprintf(text, sizeof text, "%lld", (long long)v);
        return obs_table_range_error(t, r, text, err);
    }
    }
    return OBS_OK;
}

obs_status obs_table_check(const obs_table *t, const void *base, char err[OBS_ERR_LEN])
{
    for (int i = 0; i < t->count; i++) {
        obs_status s = check_row(t, &t->rows[i], (const char *)base + t->rows[i].offset, err);
        if (s != OBS_OK)
            return s;
    }
    return OBS_OK;
}

void obs_table_defaults(const obs_table *t, void *base)
{
    uint64_t keep = 0;
    if (t->given != OBS_TABLE_NO_MASK)
        memcpy(&keep, (const char *)base + t->given, sizeof keep);
    for (int i = 0; i < t->count; i++) {
        const obs_table_row *r = &t->rows[i];
        char *field = (char *)base + r->offset;
        if (i < 64 && (keep >> i & 1))
            continue;
        switch (r->type) {
        case OBS_TABLE_FLOAT:
            if (*(float *)(void *)field == 0.0f)
                *(float *)(void *)field = (float)strtod(r->def, NULL);
            break;
        case OBS_TABLE_INT:
            if (*(int *)(void *)field == 0)
                *(int *)(void *)field = (int)strtol(r->def, NULL, 10);
            break;
        case OBS_TABLE_ENUM:
            if (*(int *)(void *)field == 0)
                *(int *)(void *)field =
                    obs_table_choice(r->choices, r->def) - 1 + (int)t->enum_base;
            break;
        case OBS_TABLE_MAT4:
            break; /* unset stays unset */
        case OBS_TABLE_STRING:
            if (!*field)
                (void)obs_table_parse(t, r, base, r->def, NULL);
            break;
        case OBS_TABLE_WHOLE:
            if (*(int *)(void *)field == 0)
                (void)obs_table_parse(t, r, base, r->def, NULL);
            break;
        case OBS_TABLE_SIZE:
            if (*(int64_t *)(void *)field == 0)
                (void)obs_table_parse(t, r, base, r->def, NULL);
            break;
        }
    }
}

void obs_table_format(const obs_table *t, const obs_table_row *r, const void *base, char *buf,
                      size_t len)
{
    const char *field = (const char *)base + r->offset;
    switch (r->type) {
    case OBS_TABLE_FLOAT: snprintf(buf, len, "%g", *(const float *)(const void *)field); break;
    case OBS_TABLE_INT:
    case OBS_TABLE_WHOLE: snprintf(buf, len, "%d", *(const int *)(const void *)field); break;
    case OBS_TABLE_ENUM:
        choice_name(r->choices, *(const int *)(const void *)field + 1 - (int)t->enum_base, buf,
                    len);
        break;
    case OBS_TABLE_MAT4: {
        const float *m = (const float *)(const void *)field;
        size_t off = 0;
        buf[0] = '\0';
        for (int i = 0; i < 16 && off < len; i++)
            off += (size_t)snprintf(buf + off, len - off, i ? ",%g" : "%g", m[i]);
        break;
    }
    case OBS_TABLE_STRING: snprintf(buf, len, "%s", field); break;
    case OBS_TABLE_SIZE:
        snprintf(buf, len, "%lld", (long long)*(const int64_t *)(const void *)field);
        break;
    }
}
