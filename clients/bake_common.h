/* What obscura bake (clients/bake.c) and obscura bake-dynamic
 * (clients/dynamic.c) share (clients/bake_common.c): the flags of a
 * parameter table, --params, --shard and --merge, the level and its
 * decorators read from files, the report's common parts, the progress
 * line's pace.  Each command keeps its own steps in its own file. */
#ifndef OBSCURA_CLIENT_BAKE_COMMON_H
#define OBSCURA_CLIENT_BAKE_COMMON_H

#include <stddef.h>

#include "obscura/bake.h"

struct cJSON;

/* One of the bake parameter tables (obscura/bake.h, obscura/dynamic.h):
 * the rows are alike, only the struct they fill differs. */
typedef struct cli_param_table {
    int (*count)(void);
    const obs_bake_param_info *(*at)(int i);
    const obs_bake_param_info *(*find)(const char *name);
    obs_status (*set)(void *p, const char *name, const char *value, char err[OBS_ERR_LEN]);
    void (*resolve)(const void *in, void *out);
    void (*format)(const void *p, const obs_bake_param_info *pi, char *buf, size_t len);
} cli_param_table;

extern const cli_param_table cli_bake_table; /* obs_bake_params */
extern const cli_param_table cli_dyn_table;  /* obs_dyn_params */

/* An option of the command's own that only names a file or a value. */
typedef struct cli_bake_str {
    const char *key;
    const char **val;
} cli_bake_str;

/* A command: its name (the messages' prefix), its table, and its own
 * options beside the shared ones. */
typedef struct cli_bake_cmd {
    const char *name;
    const char *out_hint; /* "no output file (-o OUT_HINT)" */
    const cli_param_table *table;
    void *params;               /* the desc's params the flags set */
    const char *const *flags;   /* own options without a value; NULL-ended */
    int *flag_vals;             /* set to 1 by flags[i] */
    const cli_bake_str *strs;   /* own options with a value kept as given; {NULL} ends */
    /* The rest of its own options, parsed: 1 when key was one. */
    int (*option)(void *user, const char *key, const char *val);
    void *user;
} cli_bake_cmd;

/* The pace of a progress line: every half second, and at the end. */
typedef struct cli_progress {
    double start, last;
    int percent;  /* --progress percent: "Progress: N%" lines instead */
    int pct_last; /* the last N printed, -1 none */
} cli_progress;

/* What every bake command's flags say, and the level they name once
 * cli_bake_load read it; cli_bake_args_free frees both. */
typedef struct cli_bake_args {
    const char *in, *out, *report, *decorators;
    int quiet, shard, shards, merge;
    const char **parts; /* --merge PART... */
    size_t nparts;
    obs_bake_scene sc;
    int loaded;        /* sc holds the level */
    char *decor_text;  /* --decorators' file, NUL-terminated */
    double load_s;
    cli_progress progress; /* started once the level is loaded */
} cli_bake_args;
void cli_bake_args_free(cli_bake_args *a);

/* Reads argv into a; a usage error exits.  Returns 0 when --params (or
 * --params-markdown) listed the table: the command is done (exit 0). */
int cli_bake_parse(const cli_bake_cmd *c, int argc, char **argv, cli_bake_args *a);

/* The checks both commands make once the flags are read: a level, an
 * output, the parts of --merge, not --shard with --merge. */
void cli_bake_check(const cli_bake_cmd *c, const cli_bake_args *a);

/* Reads --decorators into a->decor_text and loads the level into a->sc,
 * timing the load.  Returns EXIT_OK, or the exit code once the failure is
 * printed. */
int cli_bake_load(cli_bake_args *a, size_t max_triangles, char err[OBS_ERR_LEN]);
/* Whether the progress is shown: --progress percent, else not --quiet
 * and stderr a terminal. */
int cli_bake_shows_progress(const cli_bake_args *a);

/* The exit code of a failed bake or merge: a part that cannot be read is
 * bad input. */
int cli_bake_fail(const cli_bake_args *a, obs_status s, char err[OBS_ERR_LEN]);

/* The report: its "level" and "params" (p resolved), the decorator node
 * counts; written to path with a newline, or a message on stderr.
 * cli_bake_report_write frees r and returns 1 when written. */
struct cJSON *cli_bake_report_new(const char *level, const cli_param_table *t, const void *p);
void cli_bake_report_decorators(struct cJSON *r, const size_t nodes[4]);
/* Counts of a stats struct, one row each: a new count is one row. */
typedef struct cli_count {
    const char *key;
    size_t offset; /* of a size_t in the stats */
} cli_count;
void cli_bake_report_counts(struct cJSON *o, const void *stats, const cli_count *rows, size_t n);
int cli_bake_report_write(const char *cmd, const char *path, struct cJSON *r);

/* The --params listing of a table (README's markdown with markdown). */
void cli_bake_list_params(const cli_param_table *t, int markdown);

/* 1 when a line is due; *t is now.  Under --progress percent it prints
 * the "Progress: N%" line itself (when N changed) and returns 0. */
int cli_progress_due(cli_progress *p, size_t done, size_t total, double *t);
/* Ends the line once done reaches total. */
void cli_progress_end(size_t done, size_t total);

#endif
