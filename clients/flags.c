/* How the CLI's commands read their flags: see flags.h. */
#include "flags.h"

#include <stdio.h>
#include <string.h>

int cli_edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    int row[64];
    if (lb >= sizeof row / sizeof row[0] || la >= 64)
        return 1 << 20; /* no option is that long */
    for (size_t j = 0; j <= lb; j++)
        row[j] = (int)j;
    for (size_t i = 1; i <= la; i++) {
        int diag = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= lb; j++) {
            int up = row[j];
            int best = diag + (a[i - 1] != b[j - 1]);
            if (up + 1 < best)
                best = up + 1;
            if (row[j - 1] + 1 < best)
                best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[lb];
}

int cli_flag_value(int argc, char **argv, int *i, const char *name, const char **value)
{
    const char *a = argv[*i];
    size_t n = strlen(name);
    if (a[0] != '-')
        return 0;
    a += a[1] == '-' ? 2 : 1;
    if (strncmp(a, name, n) != 0)
        return 0;
    if (a[n] == '=') {
        *value = a + n + 1;
        return 1;
    }
    if (a[n] != '\0')
        return 0;
    if (*i + 1 >= argc)
        return -1;
    *value = argv[++*i];
    return 1;
}

int cli_is_switch(const char *arg, const char *name)
{
    return arg[0] == '-' && arg[1] == '-' && strcmp(arg + 2, name) == 0;
}

/* --name=VALUE of a switch (--solve-camera=0): VALUE, else NULL. */
static const char *switch_value(const char *arg, const char *name)
{
    size_t n = strlen(name);
    return arg[0] == '-' && arg[1] == '-' && strncmp(arg + 2, name, n) == 0 && arg[2 + n] == '='
               ? arg + 3 + n
               : NULL;
}

int cli_request_flag(int argc, char **argv, int *i, obs_http_request *r,
                     const obs_http_option **which, char err[OBS_ERR_LEN])
{
    for (const obs_http_option *op = obs_http_options; op->name; op++) {
        char flag[64];
        const char *v = NULL;
        int k;
        snprintf(flag, sizeof flag, "%s", op->name);
        for (char *c = flag; *c; c++)
            if (*c == '_')
                *c = '-';
        /* a switch means 1, as an empty query value does */
        if (op->kind == OBS_HTTP_OPT_BOOL && (v = switch_value(argv[*i], flag)))
            k = 1;
        else
            k = op->kind == OBS_HTTP_OPT_BOOL ? cli_is_switch(argv[*i], flag)
                                              : cli_flag_value(argc, argv, i, flag, &v);
        if (k == 0)
            continue;
        if (which)
            *which = op;
        if (k < 0) {
            snprintf(err, OBS_ERR_LEN, "option --%s needs a value", flag);
            return -1;
        }
        return obs_http_option_set(r, op, v, OBS_HTTP_CLI, err) == OBS_OK ? 1 : -1;
    }
    return 0;
}

void cli_suggest_start(cli_suggest *s, const char *arg)
{
    const char *name = arg + strspn(arg, "-");
    snprintf(s->word, sizeof s->word, "%.*s", (int)strcspn(name, "="), name);
    s->best[0] = '\0';
    s->best_d = 3;
}

void cli_suggest_try(cli_suggest *s, const char *name)
{
    char cand[64];
    snprintf(cand, sizeof cand, "%s", name);
    for (char *p = cand; *p; p++)
        *p = *p == '_' ? '-' : *p;
    int d = cli_edit_distance(s->word, cand);
    if (d < s->best_d && d < (int)strlen(s->word)) {
        s->best_d = d;
        snprintf(s->best, sizeof s->best, "%s%s", cand[1] ? "--" : "-", cand);
    }
}
