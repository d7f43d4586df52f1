/* obscurad's option table: parsing, config files, flags and --help. */
#include "config.h"
#include "internal.h"

#include <ctype.h>
#include <stdarg.h>
#include <errno.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#define CHOICES_backend "auto|egl-device|egl-surfaceless|osmesa"
#define CHOICES_log_level "error|warn|info|debug"
#define CHOICES_STRING(n) NULL
#define CHOICES_INT(n) NULL
#define CHOICES_SIZE(n) NULL
#define CHOICES_ENUM(n) CHOICES_##n

static const obsd_opt_info table[] = {
#define X(name, type, lo, hi, def, doc)                                                            \
    {#name, OBSD_OPT_##type, (int64_t)(lo), (int64_t)(hi), def, CHOICES_##type(name), doc,         \
     offsetof(obsd_config, name)},
    OBSD_CONFIG_TABLE(X)
#undef X
};

#define TABLE_LEN ((int)(sizeof table / sizeof table[0]))

int obsd_opt_count(void) { return TABLE_LEN; }

const obsd_opt_info *obsd_opt_at(int i)
{
    return i >= 0 && i < TABLE_LEN ? &table[i] : NULL;
}

static int name_eq(const char *a, const char *b, size_t blen)
{
    size_t i = 0;
    for (; a[i] && i < blen; i++) {
        char ca = a[i] == '-' ? '_' : a[i], cb = b[i] == '-' ? '_' : b[i];
        if (ca != cb)
            return 0;
    }
    return a[i] == '\0' && i == blen;
}

static const obsd_opt_info *find_n(const char *name, size_t len)
{
    for (int i = 0; i < TABLE_LEN; i++)
        if (name_eq(table[i].name, name, len))
            return &table[i];
    return NULL;
}

const obsd_opt_info *obsd_opt_find(const char *name)
{
    return name ? find_n(name, strlen(name)) : NULL;
}

/* Index of `value` in "a|b|c", or -1. */
static int choice_index(const char *choices, const char *value)
{
    int idx = 0;
    size_t n = strlen(value);
    for (const char *s = choices; s; idx++) {
        const char *bar = strchr(s, '|');
        size_t len = bar ? (size_t)(bar - s) : strlen(s);
        if (len == n && strncmp(s, value, n) == 0)
            return idx;
        s = bar ? bar + 1 : NULL;
    }
    return -1;
}

static obs_status set_opt(obsd_config *c, const obsd_opt_info *o, const char *value,
                          char err[OBS_ERR_LEN])
{
    char *field = (char *)c + o->offset;
    switch (o->type) {
    case OBSD_OPT_STRING:
        if ((int64_t)strlen(value) > o->max)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "option %s: value is longer than %lld characters", o->name,
                        (long long)o->max);
        snprintf(field, OBSD_STR_LEN, "%s", value);
        return OBS_OK;
    case OBSD_OPT_INT:
    case OBSD_OPT_SIZE: {
        char *end;
        errno = 0;
        long long v = strtoll(value, &end, 10);
        if (end == value || errno == ERANGE)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "option %s: '%s' is not a number in [%lld, %lld]", o->name, value,
                        (long long)o->min, (long long)o->max);
        if (o->type == OBSD_OPT_SIZE && *end) {
            int shift = 0;
            switch (tolower((unsigned char)*end)) {
            case 'k': shift = 10; break;
            case 'm': shift = 20; break;
            case 'g': shift = 30; break;
            default: shift = -1; break;
            }
            if (shift < 0 || end[1] != '\0' || v < 0 || v > (INT64_MAX >> shift))
                return obs__fail(err, OBS_INVALID_ARGUMENT, "option %s: '%s' is not a size (a number, optionally with k, m "
                            "or g) in [%lld, %lld]", o->name, value, (long long)o->min,
                            (long long)o->max);
            v <<= shift;
            end += 1;
        }
        if (*end)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "option %s: '%s' is not a number in [%lld, %lld]", o->name, value,
                        (long long)o->min, (long long)o->max);
        if (v < o->min || v > o->max)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "option %s: %s is out of range [%lld, %lld]", o->name, value,
                        (long long)o->min, (long long)o->max);
        if (o->type == OBSD_OPT_INT)
            *(int *)(void *)field = (int)v;
        else
            *(int64_t *)(void *)field = v;
        return OBS_OK;
    }
    case OBSD_OPT_ENUM: {
        int idx = choice_index(o->choices, value);
        if (idx < 0)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "option %s: '%s' is not one of %s", o->name, value, o->choices);
        *(int *)(void *)field = idx;
        return OBS_OK;
    }
    }
    return obs__fail(err, OBS_INVALID_ARGUMENT, "option %s has an unknown type", o->name);
}

void obsd_config_defaults(obsd_config *c)
{
    memset(c, 0, sizeof *c);
    for (int i = 0; i < TABLE_LEN; i++)
        (void)set_opt(c, &table[i], table[i].def, NULL); /* the table's defaults are valid */
}

obs_status obsd_config_set(obsd_config *c, const char *name, const char *value,
                           char err[OBS_ERR_LEN])
{
    const obsd_opt_info *o = obsd_opt_find(name);
    if (!o)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "unknown option '%s' (obscurad --help lists them)", name ? name : "");
    obs_status s = set_opt(c, o, value ? value : "", err);
    if (s == OBS_OK)
        c->set[o - table] = 1;
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
            s = obs__fail(err, OBS_INVALID_ARGUMENT, "%s:%d: line longer than %d characters", path, lineno, (int)sizeof line - 2);
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
            s = obs__fail(err, OBS_INVALID_ARGUMENT, "%s:%d: %s", path, lineno, msg);
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
                return obs__fail(err, OBS_INVALID_ARGUMENT, "--config needs a file");
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
            return obs__fail(err, OBS_INVALID_ARGUMENT, "unexpected argument '%s'", a);
        const char *eq = strchr(a + 2, '=');
        size_t n = eq ? (size_t)(eq - a - 2) : strlen(a + 2);
        const obsd_opt_info *o = find_n(a + 2, n);
        if (!o)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "unknown option '%.*s' (obscurad --help lists them)", (int)n + 2, a);
        const char *value;
        if (eq)
            value = eq + 1;
        else if (i + 1 < argc)
            value = argv[++i];
        else
            return obs__fail(err, OBS_INVALID_ARGUMENT, "option --%s needs a value", o->name);
        if (obsd_config_set(c, o->name, value, msg) != OBS_OK)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "%s", msg);
    }
    return OBS_OK;
}

void obsd_config_format(const obsd_config *c, const obsd_opt_info *o, char *buf, size_t len)
{
    const char *field = (const char *)c + o->offset;
    switch (o->type) {
    case OBSD_OPT_STRING: snprintf(buf, len, "%s", field); break;
    case OBSD_OPT_INT: snprintf(buf, len, "%d", *(const int *)(const void *)field); break;
    case OBSD_OPT_SIZE: snprintf(buf, len, "%lld", (long long)*(const int64_t *)(const void *)field); break;
    case OBSD_OPT_ENUM: {
        int idx = *(const int *)(const void *)field;
        const char *s = o->choices;
        for (int k = 0; k < idx && s; k++) {
            s = strchr(s, '|');
            s = s ? s + 1 : NULL;
        }
        const char *bar = s ? strchr(s, '|') : NULL;
        snprintf(buf, len, "%.*s", s ? (int)(bar ? (size_t)(bar - s) : strlen(s)) : 0, s ? s : "");
        break;
    }
    }
}

void obsd_config_help(FILE *f)
{
    static const char *const args[] = {"STRING", "N", "SIZE", "CHOICE"}; /* SIZE takes k, m, g */
    fprintf(f, "obscurad %s: the obscura daemon (one GL context, frames over HTTP and the binary protocol)\n\n"
               "usage: obscurad [--config FILE] [--OPTION VALUE]...\n\n"
               "Every option is also a config-file line 'name value' (# comments);\n"
               "flags override the file.\n\n"
               "options:\n",
            OBS_VERSION);
    fprintf(f, "  %-26s %s\n", "--config FILE", "read options from FILE first");
    for (int i = 0; i < TABLE_LEN; i++) {
        const obsd_opt_info *o = &table[i];
        char left[64], range[96] = "";
        snprintf(left, sizeof left, "--%s %s", o->name, o->type == OBSD_OPT_ENUM ? o->choices : args[o->type]);
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

_Static_assert(sizeof table / sizeof table[0] <= sizeof ((obsd_config *)0)->set,
               "obsd_config.set has a slot per option");
