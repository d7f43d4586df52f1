/* obscurad's option table: its rows, config files, flags and --help;
 * parsing, range checks and formatting are the table engine's
 * (obscura/table.h). */
#include "config.h"

#include <ctype.h>
#include <errno.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#define CHOICES_STRING(n) NULL
#define CHOICES_INT(n) NULL
#define CHOICES_SIZE(n) NULL
#define CHOICES_ENUM(n) OBSD_CHOICES_##n

static const obs_table_row rows[] = {
#define X(name, type, lo, hi, def, doc)                                                            \
    {#name, OBSD_OPT_##type, def, (double)(lo), (double)(hi), CHOICES_##type(name), doc,           \
     offsetof(obsd_config, name)},
    OBSD_CONFIG_TABLE(X)
#undef X
};

#define TABLE_LEN ((int)(sizeof rows / sizeof rows[0]))

/* ENUM values count from 0 (OBSD_LOG_ERROR is 0); the file and flags
 * record what was given in obsd_config.set, not in a mask. */
static const obs_table table = {.rows = rows, .count = TABLE_LEN, .noun = "option",
                                .hint = " (obscurad --help lists them)", .enum_base = 0,
                                .given = OBS_TABLE_NO_MASK};

int obsd_opt_count(void) { return TABLE_LEN; }

const obsd_opt_info *obsd_opt_at(int i)
{
    return i >= 0 && i < TABLE_LEN ? &rows[i] : NULL;
}

const obsd_opt_info *obsd_opt_find(const char *name) { return obs_table_find(&table, name); }

void obsd_config_defaults(obsd_config *c)
{
    memset(c, 0, sizeof *c);
    obs_table_defaults(&table, c); /* every field is zero: each takes its default */
}

obs_status obsd_config_set(obsd_config *c, const char *name, const char *value,
                           char err[OBS_ERR_LEN])
{
    const obs_table_row *r;
    obs_status s = obs_table_set(&table, c, name, value ? value : "", &r, err);
    if (s == OBS_OK)
        c->set[r - rows] = 1;
    return s;
}

obs_status obsd_config_load(obsd_config *c, const char *path, char err[OBS_ERR_LEN])
{
    FILE *f = fopen(path, "r");
    char line[1024], msg[OBS_ERR_LEN];
    int lineno = 0;
    obs_status s = OBS_OK;
    if (!f) {
        snprintf(err, OBS_ERR_LEN, "config %s: %s", path, strerror(errno));
        return OBS_IO;
    }
    while (fgets(line, sizeof line, f)) {
        lineno++;
        size_t n = strlen(line);
        if (n == sizeof line - 1 && line[n - 1] != '\n') {
            s = obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s:%d: line longer than %d characters",
                               path, lineno, (int)sizeof line - 2);
            break;
        }
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        char *p = line;
        while (isspace((unsigned char)*p))
            p++;
        if (!*p)
            continue;
        char *name = p;
        while (*p && !isspace((unsigned char)*p))
            p++;
        size_t name_len = (size_t)(p - name);
        while (isspace((unsigned char)*p))
            p++;
        char *value = p, *end = p + strlen(p);
        while (end > value && isspace((unsigned char)end[-1]))
            *--end = '\0';
        /* a value may be quoted to hold spaces or be empty */
        if (end - value >= 2 && value[0] == '"' && end[-1] == '"') {
            end[-1] = '\0';
            value++;
        }
        name[name_len] = '\0';
        if (obsd_config_set(c, name, value, msg) != OBS_OK) {
            s = obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s:%d: %s", path, lineno, msg);
            break;
        }
    }
    fclose(f);
    return s;
}

obs_status obsd_config_args(obsd_config *c, int argc, char **argv, int *help,
                            char err[OBS_ERR_LEN])
{
    char msg[OBS_ERR_LEN];
    *help = 0;
    /* The file first, so that flags override it wherever they stand. */
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *path = NULL;
        if (!strcmp(a, "--config")) {
            if (i + 1 >= argc)
                return obs_status_fail(err, OBS_INVALID_ARGUMENT, "--config needs a file");
            path = argv[++i];
        } else if (!strncmp(a, "--config=", 9)) {
            path = a + 9;
        }
        if (path) {
            obs_status s = obsd_config_load(c, path, err);
            if (s != OBS_OK)
                return s;
        }
    }
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            *help = 1;
            continue;
        }
        if (!strcmp(a, "--config")) {
            i++;
            continue;
        }
        if (!strncmp(a, "--config=", 9))
            continue;
        if (strncmp(a, "--", 2) != 0 || !a[2])
            return obs_status_fail(err, OBS_INVALID_ARGUMENT, "unexpected argument '%s'", a);
        const char *eq = strchr(a + 2, '=');
        size_t n = eq ? (size_t)(eq - a - 2) : strlen(a + 2);
        const obsd_opt_info *o = obs_table_find_n(&table, a + 2, n);
        if (!o)
            return obs_status_fail(err, OBS_INVALID_ARGUMENT,
                                  "unknown option '%.*s' (obscurad --help lists them)", (int)n + 2,
                                  a);
        const char *value;
        if (eq)
            value = eq + 1;
        else if (i + 1 < argc)
            value = argv[++i];
        else
            return obs_status_fail(err, OBS_INVALID_ARGUMENT, "option --%s needs a value", o->name);
        if (obsd_config_set(c, o->name, value, msg) != OBS_OK)
            return obs_status_fail(err, OBS_INVALID_ARGUMENT, "%s", msg);
    }
    return OBS_OK;
}

void obsd_config_format(const obsd_config *c, const obsd_opt_info *o, char *buf, size_t len)
{
    obs_table_format(&table, o, c, buf, len);
}

/* What --help shows after the flag: the choices, or the value's kind. */
static const char *arg_name(const obsd_opt_info *o)
{
    switch (o->type) {
    case OBSD_OPT_ENUM: return o->choices;
    case OBSD_OPT_INT: return "N";
    case OBSD_OPT_SIZE: return "SIZE"; /* takes k, m, g */
    default: return "STRING";
    }
}

void obsd_config_help(FILE *f)
{
    fprintf(f, "obscurad %s: the obscura daemon (one GL context, frames over HTTP and the binary protocol)\n\n"
               "usage: obscurad [--config FILE] [--OPTION VALUE]...\n\n"
               "Every option is also a config-file line 'name value' (# comments);\n"
               "flags override the file.\n\n"
               "options:\n",
            OBS_VERSION);
    fprintf(f, "  %-26s %s\n", "--config FILE", "read options from FILE first");
    for (int i = 0; i < TABLE_LEN; i++) {
        const obsd_opt_info *o = &rows[i];
        char left[64], range[96] = "";
        snprintf(left, sizeof left, "--%s %s", o->name, arg_name(o));
        for (char *p = left + 2; *p && *p != ' '; p++)
            if (*p == '_')
                *p = '-';
        if (o->type == OBSD_OPT_INT || o->type == OBSD_OPT_SIZE)
            snprintf(range, sizeof range, ", %lld..%lld", (long long)o->min, (long long)o->max);
        fprintf(f, "  %-26s %s (default %s%s%s%s)\n", left, o->doc, o->def[0] ? "" : "\"", o->def,
                o->def[0] ? "" : "\"", range);
    }
    fprintf(f, "  %-26s %s\n", "--help", "this text");
}

_Static_assert(sizeof rows / sizeof rows[0] <= sizeof ((obsd_config *)0)->set,
               "obsd_config.set has a slot per option");
