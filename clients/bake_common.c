/* What obscura bake and obscura bake-dynamic share: see bake_common.h. */
#include "bake_common.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "flags.h"
#include "obscura/dynamic.h"
#include "obscura/obscura.h"

/* The tables' own functions take their own struct: these pass it on. */
static obs_status bake_set(void *p, const char *name, const char *value, char err[OBS_ERR_LEN])
{
    return obs_bake_param_set(p, name, value, err);
}
static void bake_resolve(const void *in, void *out) { obs_bake_params_resolve(in, out); }
static void bake_format(const void *p, const obs_bake_param_info *pi, char *buf, size_t len)
{
    obs_bake_param_format(p, pi, buf, len);
}
static obs_status dyn_set(void *p, const char *name, const char *value, char err[OBS_ERR_LEN])
{
    return obs_dyn_param_set(p, name, value, err);
}
static void dyn_resolve(const void *in, void *out) { obs_dyn_params_resolve(in, out); }
static void dyn_format(const void *p, const obs_bake_param_info *pi, char *buf, size_t len)
{
    obs_dyn_param_format(p, pi, buf, len);
}

const cli_param_table cli_bake_table = {obs_bake_param_count, obs_bake_param_at,
                                        obs_bake_param_find,  bake_set,
                                        bake_resolve,         bake_format};
const cli_param_table cli_dyn_table = {obs_dyn_param_count, obs_dyn_param_at, obs_dyn_param_find,
                                       dyn_set,             dyn_resolve,      dyn_format};

void cli_bake_list_params(const cli_param_table *t, int markdown)
{
    union {
        obs_bake_params bake;
        obs_dyn_params dyn;
    } p; /* the defaults of either table */
    t->resolve(NULL, &p);
    if (markdown)
        printf("| flag | default | range | meaning |\n| --- | --- | --- | --- |\n");
    for (int i = 0; i < t->count(); i++) {
        const obs_bake_param_info *pi = t->at(i);
        char def[64];
        t->format(&p, pi, def, sizeof def);
        cli_param_row(pi, def, markdown);
    }
}

/* The command's options without a value: 1 when key is one. */
static int own_flag(const cli_bake_cmd *c, const char *key)
{
    for (int k = 0; c->flags && c->flags[k]; k++)
        if (!strcmp(key, c->flags[k])) {
            c->flag_vals[k] = 1;
            return 1;
        }
    return 0;
}

/* An option with a value, shared or the command's own: 1 when key is one. */
static int take_value(const cli_bake_cmd *c, const char *key, const char *val, cli_bake_args *a)
{
    if (!strcmp(key, "o") || !strcmp(key, "output")) {
        a->out = val;
    } else if (!strcmp(key, "shard")) {
        cli_parse_shard(c->name, val, &a->shard, &a->shards);
    } else if (!strcmp(key, "report")) {
        a->report = val;
    } else if (!strcmp(key, "decorators")) {
        a->decorators = val;
    } else {
        for (const cli_bake_str *o = c->strs; o && o->key; o++)
            if (!strcmp(key, o->key)) {
                *o->val = val;
                return 1;
            }
        if (c->option && c->option(c->user, key, val))
            return 1;
        if (!c->table->find(key))
            return 0;
        char err[OBS_ERR_LEN] = "";
        if (c->table->set(c->params, key, val, err) != OBS_OK)
            cli_die_usage(c->name, "%s", err);
    }
    return 1;
}

/* An unknown option: a usage error naming the nearest of the shared
 * options, the command's own and its table's ("--rayz": did you mean
 * --rays?), as obscura ao does (flags.h). */
static void die_unknown(const cli_bake_cmd *c, const char *arg)
{
    static const char *const shared[] = {"o", "output", "shard", "report", "decorators", "params",
                                         "params-markdown", "quiet", "q", "progress", "merge", NULL};
    char shown[256];
    cli_suggest sg;
    cli_suggest_start(&sg, arg);
    for (int k = 0; shared[k]; k++)
        cli_suggest_try(&sg, shared[k]);
    for (int k = 0; c->flags && c->flags[k]; k++)
        cli_suggest_try(&sg, c->flags[k]);
    for (const cli_bake_str *o = c->strs; o && o->key; o++)
        cli_suggest_try(&sg, o->key);
    for (int k = 0; k < c->table->count(); k++)
        cli_suggest_try(&sg, c->table->at(k)->name);
    cli_escape(arg, shown, sizeof shown);
    cli_die_usage(c->name, "unknown option '%s'%s%s%s ('obscura %s --params' lists the parameters)", shown,
                  sg.best[0] ? "; did you mean " : "", sg.best, sg.best[0] ? "?" : "", c->name);
}

int cli_bake_parse(const cli_bake_cmd *c, int argc, char **argv, cli_bake_args *a)
{
    *a = (cli_bake_args){.shard = -1};
    /* --threads (main took it: cli_take_threads) is the table's threads
     * parameter too, so the report says the count that ran */
    obs_threads_info ti;
    obs_threads_get(&ti);
    char tv[16], terr[OBS_ERR_LEN];
    snprintf(tv, sizeof tv, "%d", ti.limit);
    if (ti.limit && c->table->find("threads") && c->table->set(c->params, "threads", tv, terr) != OBS_OK)
        cli_die_usage(c->name, "%s", terr);
    int merging = 0;
    a->parts = calloc((size_t)argc + 1, sizeof *a->parts);
    if (!a->parts)
        cli_die_usage(c->name, "out of memory");
    for (int i = 0; i < argc; i++) {
        const char *arg = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if ((arg[0] != '-' || !arg[1]) && merging) {
            a->parts[a->nparts++] = arg; /* --merge PART...: up to the next option */
            continue;
        }
        merging = 0;
        if (arg[0] != '-' || !arg[1]) {
            if (a->in)
                cli_die_usage(c->name, "more than one level ('%s' and '%s')", a->in, arg);
            a->in = arg;
            continue;
        }
        const char *name = arg + (arg[1] == '-' ? 2 : 1);
        char key[64];
        const char *eq = strchr(name, '=');
        snprintf(key, sizeof key, "%.*s", eq ? (int)(eq - name) : (int)strlen(name), name);
        if (eq)
            val = eq + 1;
        int takes = 1;
        if (!strcmp(key, "params") || !strcmp(key, "params-markdown")) {
            cli_bake_list_params(c->table, key[6] != '\0');
            free(a->parts);
            a->parts = NULL;
            return 0;
        } else if (own_flag(c, key)) {
            takes = 0;
        } else if (!strcmp(key, "quiet") || !strcmp(key, "q")) {
            a->quiet = 1, takes = 0;
        } else if (!strcmp(key, "progress") && val) {
            if (strcmp(val, "plain") && strcmp(val, "percent"))
                cli_die_usage(c->name, "--progress: '%s' is not plain or percent", val);
            a->progress.percent = !strcmp(val, "percent");
        } else if (!strcmp(key, "merge")) {
            merging = a->merge = 1, takes = 0;
            if (eq && *val)
                a->parts[a->nparts++] = val;
        } else if (!val) {
            cli_die_usage(c->name, "option --%s needs a value", key);
        } else if (!take_value(c, key, val, a)) {
            die_unknown(c, arg);
        }
        if (takes && !eq)
            i++;
    }
    return 1;
}

void cli_bake_check(const cli_bake_cmd *c, const cli_bake_args *a)
{
    if (!a->in)
        cli_die_usage(c->name, "no level file");
    if (!a->out && a->shards)
        cli_die_usage(c->name, "no part file (-o PART)");
    if (!a->out)
        cli_die_usage(c->name, "no output file (-o %s)", c->out_hint);
    if (a->merge && !a->nparts)
        cli_die_usage(c->name, "--merge needs the part files (--merge PART...)");
    if (a->shards && a->nparts)
        cli_die_usage(c->name, "--shard traces a part, --merge reads them: not both");
}

int cli_bake_load(cli_bake_args *a, size_t max_triangles, char err[OBS_ERR_LEN])
{
    obs_status s;
    if (a->decorators && (s = cli_read_text(a->decorators, &a->decor_text, err)) != OBS_OK)
        return cli_input_fail(s, a->decorators, err);
    double t0 = cli_now_s();
    s = obs_bake_load(a->in, max_triangles, &a->sc, err);
    if (s != OBS_OK)
        return cli_input_fail(s, a->in, err);
    a->loaded = 1;
    a->load_s = cli_now_s() - t0;
    a->progress.start = cli_now_s();
    a->progress.last = 0.0;
    a->progress.pct_last = -1;
    return EXIT_OK;
}

int cli_bake_shows_progress(const cli_bake_args *a)
{
    return a->progress.percent || (!a->quiet && isatty(2));
}

void cli_bake_args_free(cli_bake_args *a)
{
    if (a->loaded)
        obs_bake_scene_free(&a->sc);
    free(a->decor_text);
    free(a->parts);
}

int cli_bake_fail(const cli_bake_args *a, obs_status s, char err[OBS_ERR_LEN])
{
    return a->nparts ? cli_input_fail(s, a->in, err) : cli_fail(s, a->in, err);
}

cJSON *cli_bake_report_new(const char *level, const cli_param_table *t, const void *p)
{
    cJSON *r = cJSON_CreateObject();
    cJSON_AddStringToObject(r, "level", level);
    cJSON *par = cJSON_AddObjectToObject(r, "params");
    for (int i = 0; i < t->count(); i++) {
        const obs_bake_param_info *pi = t->at(i);
        char v[64];
        t->format(p, pi, v, sizeof v);
        if (pi->type == OBS_BAKE_PARAM_ENUM)
            cJSON_AddStringToObject(par, pi->name, v);
        else
            cJSON_AddNumberToObject(par, pi->name, strtod(v, NULL));
    }
    return r;
}

void cli_bake_report_decorators(cJSON *r, const size_t nodes[4])
{
    cJSON *dn = cJSON_AddObjectToObject(r, "decorator_nodes");
    static const char *const names[4] = {"none", "shrub", "tree", "small"};
    for (int k = 0; k < 4; k++)
        cJSON_AddNumberToObject(dn, names[k], (double)nodes[k]);
}

void cli_bake_report_counts(cJSON *o, const void *stats, const cli_count *rows, size_t n)
{
    for (size_t i = 0; i < n; i++)
        cJSON_AddNumberToObject(o, rows[i].key,
                                (double)*(const size_t *)((const char *)stats + rows[i].offset));
}

int cli_bake_report_write(const char *cmd, const char *path, cJSON *r)
{
    char *txt = cJSON_Print(r);
    cJSON_Delete(r);
    FILE *f = txt ? fopen(path, "w") : NULL;
    int ok = f && fputs(txt, f) >= 0 && fputc('\n', f) != EOF;
    if (f && fclose(f) != 0)
        ok = 0;
    free(txt);
    if (!ok)
        fprintf(stderr, "obscura: error: %s: %s: cannot write the report: %s\n", cmd, path,
                strerror(errno));
    return ok;
}

int cli_progress_due(cli_progress *p, size_t done, size_t total, double *t)
{
    *t = cli_now_s();
    if (p->percent) {
        cli_progress_percent(&p->pct_last, (long)done, (long)total);
        return 0;
    }
    if (*t - p->last < 0.5 && done < total)
        return 0;
    p->last = *t;
    return 1;
}

void cli_progress_end(size_t done, size_t total)
{
    if (done >= total)
        fprintf(stderr, "\n");
}
