/* One engine for every table of named, typed settings: the frame
 * parameters (obscura/params.h), the bake's and the dynamic bake's
 * (obscura/bake.h, obscura/dynamic.h) and obscurad's options.  A table
 * is rows (an X-macro expanded where the struct lives); each row names a
 * field of that struct by offset and says its type, default, range,
 * choices and doc.  The engine finds rows by name, parses and checks a
 * value into the field, fills defaults, and formats a field back; the
 * help texts, the README tables and GET /v1/params walk the rows.
 * Public so that the daemon and the protocol use it without core's
 * internal headers. */
#ifndef OBSCURA_TABLE_H
#define OBSCURA_TABLE_H

#include <stddef.h>
#include <stdint.h>

#include "obscura/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What a field holds and how its text is read.  The order of the first
 * four is the index of GET /v1/params' type names. */
typedef enum obs_table_type {
    OBS_TABLE_FLOAT,  /* float; a decimal number in [min, max] */
    OBS_TABLE_INT,    /* int; a decimal number that is whole, in [min, max];
                         with choices "2|4|8", only those numbers */
    OBS_TABLE_ENUM,   /* int; the index of the value among choices "a|b|c" */
    OBS_TABLE_MAT4,   /* float[16]; 16 numbers, commas and/or spaces; no default */
    OBS_TABLE_STRING, /* char[max + 1]; at most max characters */
    OBS_TABLE_WHOLE,  /* int; digits only (strtoll), in [min, max] */
    OBS_TABLE_SIZE    /* int64_t; digits and an optional k, m or g (x 1024^n) */
} obs_table_type;

typedef struct obs_table_row {
    const char *name;    /* snake_case; flags use the same name with '-' */
    obs_table_type type;
    const char *def;     /* default as text, for help and docs */
    double min, max;     /* numbers: the range; STRING: max is the longest length */
    const char *choices; /* ENUM: "a|b|c"; INT: the numbers allowed, or NULL */
    const char *doc;
    size_t offset;       /* of the field in the table's struct */
} obs_table_row;

/* A table of rows and how its messages read. */
typedef struct obs_table {
    const obs_table_row *rows;
    int count;
    const char *noun;      /* "parameter", "bake parameter", "option": the messages' subject */
    const char *hint;      /* after "unknown NOUN 'x'": "" or " (... lists them)" */
    unsigned enum_base;    /* 1: ENUM index 1 is the first choice and 0 means "default"; or 0 */
    unsigned strict;       /* 1: an empty value is missing; no blanks after a number */
    /* Offset of a uint64_t in the struct whose bit i says row i was given
     * (obs_table_set sets it, obs_table_defaults keeps those rows), or
     * OBS_TABLE_NO_MASK: a zero field takes its default. */
    size_t given;
} obs_table;
#define OBS_TABLE_NO_MASK ((size_t)-1)

/* 1 when row name a is the first blen characters of b, '-' and '_' alike
 * (for tables of other rows: the HTTP request options). */
int obs_table_name_eq(const char *a, const char *b, size_t blen);
/* Names compare with '-' and '_' alike.  NULL when unknown (or name NULL). */
const obs_table_row *obs_table_find(const obs_table *t, const char *name);
/* The same over the first len characters of name ("--name=value"). */
const obs_table_row *obs_table_find_n(const obs_table *t, const char *name, size_t len);
/* 1-based index of value among "a|b|c", 0 when absent. */
int obs_table_choice(const char *choices, const char *value);

/* Parses value into the row's field of base, checking type and range;
 * the field is left alone on error.  The messages name the row and
 * what it accepts ("parameter radius: 'x' is not a number in [0, 10]"). */
obs_status obs_table_parse(const obs_table *t, const obs_table_row *r, void *base,
                           const char *value, char err[OBS_ERR_LEN]);
/* Finds name (else "unknown NOUN 'name'HINT"), then obs_table_parse, and
 * marks the row given in the mask.  *row (if non-NULL) is the row found. */
obs_status obs_table_set(const obs_table *t, void *base, const char *name, const char *value,
                         const obs_table_row **row, char err[OBS_ERR_LEN]);
/* The message of a value out of the row's range: what obs_table_parse
 * says of it; for checking fields set without it. */
obs_status obs_table_range_error(const obs_table *t, const obs_table_row *r, const char *value,
                                 char err[OBS_ERR_LEN]);

/* Checks every field of base against its row (a struct filled without
 * obs_table_parse); the message names the first field out of range. */
obs_status obs_table_check(const obs_table *t, const void *base, char err[OBS_ERR_LEN]);

/* Every row not given (the mask) whose field is zero takes its default
 * (MAT4 rows have none). */
void obs_table_defaults(const obs_table *t, void *base);

/* The field of row r in base as text: %g, %d, the choice's name ("?"
 * when out of range), the matrix as "a,b,...", the string. */
void obs_table_format(const obs_table *t, const obs_table_row *r, const void *base, char *buf,
                      size_t len);

#ifdef __cplusplus
}
#endif

#endif
