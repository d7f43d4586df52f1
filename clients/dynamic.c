/* obscura bake-dynamic LEVEL -o MODEL.json: the region model of baked
 * obscurance for dynamic objects (obscura/dynamic.h), flags from its own
 * parameter table; --eval MODEL.json --at X,Y,Z --normal X,Y,Z prints the
 * AO there. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_common.h"
#include "cli.h"
#include "dynamic.h"
#include "obscura/dynamic.h"

void cli_dynamic_usage(FILE *f)
{
    fprintf(f,
            "  obscura bake-dynamic LEVEL -o MODEL.json [--regions R.json] [--report R.json]\n"
            "                  [--paths N] [--decorators D.json] [--progress percent] [--PARAM VALUE]...\n"
            "                  obscurance for dynamic objects: regions, valid points, SH at two distances,\n"
            "                  eq 4 per region, regularised (section 2.3), through the decorators\n"
            "                  as obscura bake traces them; 'obscura bake-dynamic --params'\n"
            "  obscura bake-dynamic LEVEL --shard I/N -o PART [--regions R.json] [--PARAM VALUE]...\n"
            "                  trace shard I (0 .. N-1) of the valid points into a part file\n"
            "  obscura bake-dynamic LEVEL --merge PART... -o MODEL.json [...]\n"
            "                  every shard's part read back and fitted: the unsharded model\n"
            "  obscura bake-dynamic --eval MODEL.json --at X,Y,Z --normal X,Y,Z\n"
            "                  [--sh linear|quadratic]  prints short, long and blended AO\n");
}

static int parse3(const char *s, float v[3])
{
    char *end;
    for (int k = 0; k < 3; k++) {
        errno = 0;
        double d = strtod(s, &end);
        if (end == s || errno || !isfinite(d) || (k < 2 ? *end != ',' : *end != '\0'))
            return 0;
        v[k] = (float)d;
        s = end + 1;
    }
    return 1;
}

static int eval_cmd(const char *model, const char *at, const char *normal, const char *sh)
{
    float p[3], n[3] = {0.0f, 1.0f, 0.0f};
    if (!at || !parse3(at, p))
        cli_die_usage("bake-dynamic", "--eval needs --at X,Y,Z (three numbers)");
    if (normal && !parse3(normal, n))
        cli_die_usage("bake-dynamic", "--normal '%s': expected X,Y,Z", normal);
    if (!(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0.0f))
        cli_die_usage("bake-dynamic", "--normal: a zero vector has no direction");
    obs_dyn_sh_order order = OBS_DYN_QUADRATIC;
    if (sh && !strcmp(sh, "linear"))
        order = OBS_DYN_LINEAR;
    else if (sh && strcmp(sh, "quadratic"))
        cli_die_usage("bake-dynamic", "--sh '%s': linear or quadratic", sh);
    char err[OBS_ERR_LEN] = "";
    obs_dyn_model m;
    obs_status s = obs_dyn_model_read(model, &m, err);
    if (s != OBS_OK)
        return cli_input_fail(s, model, err);
    float ao[3];
    int r = obs_dyn_eval(&m, p, n, order, ao);
    if (r < 0) {
        obs_dyn_model_free(&m);
        return cli_fail(OBS_INVALID_ARGUMENT, model, "the model has no region with a model");
    }
    printf("%.6f\n", ao[2]);
    fprintf(stderr, "obscura: bake-dynamic: region %d (model %d), short %.6f, long %.6f, "
                    "blend %.3f\n", r, m.regions[r].model, ao[0], ao[1], m.blend);
    obs_dyn_model_free(&m);
    return EXIT_OK;
}

static cJSON *pair(double a, double b)
{
    cJSON *o = cJSON_CreateArray();
    cJSON_AddItemToArray(o, cJSON_CreateNumber(a));
    cJSON_AddItemToArray(o, cJSON_CreateNumber(b));
    return o;
}

#define COUNT(key, field) {key, offsetof(obs_dyn_stats, field)}

static void report_counts(cJSON *r, const obs_dyn_stats *st)
{
    static const cli_count counts[] = {
        COUNT("regions", regions),
        COUNT("edges", edges),
        COUNT("models", models),
        COUNT("regions_absorbed", regions_absorbed),
        COUNT("regions_without_points", regions_without_points),
        COUNT("grid_points", grid_points),
        COUNT("points_inside", points_inside),
        COUNT("points_hidden", points_hidden),
        COUNT("points_backface", points_backface),
        COUNT("points_valid", points_valid),
        COUNT("centre_of_mass_kept", centre_of_mass_kept),
    };
    cJSON *c = cJSON_AddObjectToObject(r, "counts");
    cli_bake_report_counts(c, st, counts, sizeof counts / sizeof *counts);
    cJSON_AddNumberToObject(c, "rays", (double)st->rays);
}

/* eq 4's fit, in and out of sample, and the jumps at the boundaries
 * before and after the regularisation. */
static void report_fit(cJSON *r, const obs_dyn_stats *st)
{
    cJSON *f = cJSON_AddObjectToObject(r, "fit_rms");
    cJSON_AddNumberToObject(f, "eq4", st->fit_rms);
    cJSON_AddNumberToObject(f, "eq4_regularised", st->fit_rms_regularised);
    if (st->holdout_points) {
        cJSON *h = cJSON_AddObjectToObject(r, "holdout_rms");
        cJSON_AddNumberToObject(h, "points", (double)st->holdout_points);
        cJSON_AddNumberToObject(h, "eq4", st->holdout_eq4);
        cJSON_AddNumberToObject(h, "constant", st->holdout_constant);
        cJSON_AddNumberToObject(h, "gradient", st->holdout_gradient);
    }
    cJSON *j = cJSON_AddObjectToObject(r, "boundary_jump");
    cJSON_AddItemToObject(j, "mean", pair(st->jump_mean[0], st->jump_mean[1]));
    cJSON_AddItemToObject(j, "max", pair(st->jump_max[0], st->jump_max[1]));
    cJSON_AddItemToObject(j, "energy", pair(st->energy[0], st->energy[1]));
}

/* --paths: objects moved along paths through the model. */
static void report_paths(cJSON *r, const obs_dyn_path_stats *ps)
{
    cJSON *pa = cJSON_AddObjectToObject(r, "paths");
    cJSON_AddNumberToObject(pa, "paths", (double)ps->paths);
    cJSON_AddNumberToObject(pa, "points", (double)ps->points);
    cJSON_AddNumberToObject(pa, "crossings", (double)ps->crossings);
    cJSON_AddItemToObject(pa, "rms_linear_quadratic", pair(ps->rms[0], ps->rms[1]));
    cJSON_AddItemToObject(pa, "bias_linear_quadratic", pair(ps->bias[0], ps->bias[1]));
    cJSON_AddNumberToObject(pa, "rms_point_sh", ps->rms_point_sh);
    cJSON_AddNumberToObject(pa, "rms_quadratic_unregularised", ps->rms_unregularised);
    const char *names[3] = {"unregularised", "regularised", "regularised_blended"};
    for (int k = 0; k < 3; k++) {
        cJSON *o = cJSON_AddObjectToObject(pa, names[k]);
        cJSON_AddNumberToObject(o, "crossing_mean", ps->cross_mean[k]);
        cJSON_AddNumberToObject(o, "crossing_max", ps->cross_max[k]);
        cJSON_AddNumberToObject(o, "step_mean", ps->step_mean[k]);
    }
}

static int write_report(const char *path, const char *level, const obs_dyn_params *p,
                        const obs_dyn_stats *st, const obs_dyn_path_stats *ps, double load_s)
{
    cJSON *r = cli_bake_report_new(level, &cli_dyn_table, p);
    cli_bake_report_decorators(r, st->decorator_nodes); /* as obscura bake's report */
    cJSON *sec = cJSON_AddObjectToObject(r, "seconds");
    cJSON_AddNumberToObject(sec, "load", load_s);
    for (int i = 0; i < OBS_DYN_STAGE_COUNT; i++)
        cJSON_AddNumberToObject(sec, obs_dyn_stage_name(i), st->seconds[i]);
    report_counts(r, st);
    report_fit(r, st);
    if (ps)
        report_paths(r, ps);
    return cli_bake_report_write("bake-dynamic", path, r);
}

static void on_progress(void *user, size_t done, size_t total)
{
    cli_progress *p = user;
    double t;
    if (!cli_progress_due(p, done, total, &t))
        return;
    fprintf(stderr, "\robscura: bake-dynamic: traced %zu / %zu points, %.1f s", done, total,
            t - p->start);
    cli_progress_end(done, total);
}

/* What the steps of one obscura bake-dynamic share. */
typedef struct dyn_run {
    cli_bake_args a;
    const char *regions, *eval, *at, *normal, *sh;
    int paths, path_steps, path_rays;
    float tau;
    obs_dyn_desc desc;
    obs_dyn_params p; /* resolved */
    char err[OBS_ERR_LEN];
} dyn_run;

/* --paths, --path-steps, --path-rays, --tau: the path measurement's. */
static int dyn_option(void *user, const char *key, const char *val)
{
    dyn_run *d = user;
    char *end;
    if (!strcmp(key, "paths") || !strcmp(key, "path-steps") || !strcmp(key, "path-rays")) {
        long v = strtol(val, &end, 10);
        if (*end || v < (key[4] ? 2 : 0) || v > 100000)
            cli_die_usage("bake-dynamic", "--%s '%s': an integer in %d..100000", key, val,
                          key[4] ? 2 : 0);
        *(!strcmp(key, "paths") ? &d->paths : !strcmp(key, "path-steps") ? &d->path_steps
                                                                           : &d->path_rays) = (int)v;
        return 1;
    }
    if (strcmp(key, "tau"))
        return 0;
    double v = strtod(val, &end);
    if (*end || !(v >= 0.0) || v > 1e6)
        cli_die_usage("bake-dynamic", "--tau '%s': the blender's decay in steps, >= 0", val);
    d->tau = (float)v;
    return 1;
}

/* The flags; --eval is a command of its own, the rest checked here.
 * 0: done (--params listed), 1: --eval, 2: a bake. */
static int parse(int argc, char **argv, dyn_run *d)
{
    const cli_bake_str strs[] = {{"regions", &d->regions}, {"eval", &d->eval}, {"at", &d->at},
                                 {"normal", &d->normal},   {"sh", &d->sh},     {NULL, NULL}};
    const cli_bake_cmd cmd = {.name = "bake-dynamic", .out_hint = "MODEL.json",
                              .table = &cli_dyn_table, .params = &d->desc.params,
                              .strs = strs, .option = dyn_option, .user = d};
    if (!cli_bake_parse(&cmd, argc, argv, &d->a))
        return 0;
    if (d->eval)
        return 1;
    cli_bake_check(&cmd, &d->a);
    if (d->a.shards && d->paths)
        cli_die_usage("bake-dynamic", "--shard writes a part, not a model: --paths goes with --merge");
    obs_dyn_params_resolve(&d->desc.params, &d->p);
    return 2;
}

/* --shard I/N: one part of the points' trace into a part file. */
static int run_shard(dyn_run *d)
{
    const cli_bake_args *a = &d->a;
    obs_dyn_stats st;
    obs_status s = obs_dyn_bake_shard(&a->sc, &d->desc, a->shard, a->shards, a->out, &st, d->err);
    int rc = s == OBS_OK ? EXIT_OK : cli_fail(s, a->in, d->err);
    if (rc == EXIT_OK && st.decorator_warning[0])
        fprintf(stderr, "obscura: bake-dynamic: warning: %s\n", st.decorator_warning);
    if (rc == EXIT_OK && a->report && !write_report(a->report, a->in, &d->p, &st, NULL, a->load_s))
        rc = EXIT_FAIL;
    if (rc == EXIT_OK && !a->quiet)
        fprintf(stderr, "obscura: bake-dynamic: shard %d/%d: %zu points (%zu dropped by the "
                "back-face rule), %llu rays in %.1f s; wrote %s\n", a->shard, a->shards,
                st.points_valid + st.points_backface, st.points_backface,
                (unsigned long long)st.rays, st.seconds[OBS_DYN_STAGE_trace], a->out);
    return rc;
}

static void print_summary(const obs_dyn_stats *st, const char *out)
{
    fprintf(stderr,
            "obscura: bake-dynamic: %zu regions (%zu absorbed, %zu models), %zu of %zu grid "
            "points valid (%zu inside, %zu behind a wall, %zu back faces), %llu rays in "
            "%.1f s; wrote %s\n",
            st->regions, st->regions_absorbed, st->models, st->points_valid, st->grid_points,
            st->points_inside, st->points_hidden, st->points_backface,
            (unsigned long long)st->rays, st->seconds[OBS_DYN_STAGE_trace], out);
}

/* After the fit: --paths measured, the model, the report, the summary. */
static int finish_model(dyn_run *d, const obs_dyn_result *r)
{
    const cli_bake_args *a = &d->a;
    const obs_dyn_stats *st = &r->stats;
    int rc = EXIT_OK;
    obs_status s;
    obs_dyn_path_stats ps;
    if (d->paths > 0 &&
        (s = obs_dyn_measure_paths(&a->sc, r, &d->p, d->desc.decorators_json, d->paths,
                                   d->path_steps, d->path_rays, d->tau, &ps, d->err)) != OBS_OK)
        rc = cli_fail(s, a->in, d->err);
    if (rc == EXIT_OK && (s = obs_dyn_model_write(a->out, &r->model, d->err)) != OBS_OK)
        rc = cli_fail(s, a->out, d->err);
    if (rc == EXIT_OK && a->report &&
        !write_report(a->report, a->in, &d->p, st, d->paths > 0 ? &ps : NULL, a->load_s))
        rc = EXIT_FAIL;
    if (rc == EXIT_OK && !st->points_valid)
        fprintf(stderr, "obscura: bake-dynamic: warning: no valid point in any region: every "
                        "region lies inside geometry or behind walls\n");
    if (rc == EXIT_OK && !a->quiet)
        print_summary(st, a->out);
    return rc;
}

/* The whole model, or the merge of --merge's parts. */
static int run_bake(dyn_run *d)
{
    const cli_bake_args *a = &d->a;
    obs_dyn_result r;
    obs_status s = a->nparts ? obs_dyn_bake_merge(&a->sc, &d->desc, a->parts, a->nparts, &r, d->err)
                             : obs_dyn_bake(&a->sc, &d->desc, &r, d->err);
    if (s != OBS_OK)
        return cli_bake_fail(a, s, d->err);
    if (r.stats.decorator_warning[0])
        fprintf(stderr, "obscura: bake-dynamic: warning: %s\n", r.stats.decorator_warning);
    if (a->nparts) /* the parts' parameters, for the paths and the report */
        obs_dyn_params_resolve(&d->desc.params, &d->p);
    int rc = finish_model(d, &r);
    obs_dyn_result_free(&r);
    return rc;
}

/* The regions file, the decorators and the level read, then the bake. */
static int run(dyn_run *d)
{
    obs_dyn_regions rg = {0};
    obs_status s;
    if (d->regions) {
        if ((s = obs_dyn_regions_read(d->regions, &rg, d->err)) != OBS_OK)
            return cli_input_fail(s, d->regions, d->err);
        d->desc.regions = &rg;
    }
    int rc = cli_bake_load(&d->a, (size_t)d->p.max_triangles, d->err);
    if (rc == EXIT_OK) {
        d->desc.decorators_json = d->a.decor_text; /* read as obscura bake reads it */
        if (cli_bake_shows_progress(&d->a)) {
            d->desc.progress = on_progress;
            d->desc.progress_user = &d->a.progress;
        }
        rc = d->a.shards ? run_shard(d) : run_bake(d);
    }
    obs_dyn_regions_free(&rg);
    return rc;
}

int cli_dynamic(int argc, char **argv)
{
    dyn_run d = {.path_steps = 64, .path_rays = 256, .tau = 4.0f};
    int how = parse(argc, argv, &d);
    int rc = how == 0   ? EXIT_OK
             : how == 1 ? eval_cmd(d.eval, d.at, d.normal, d.sh)
                        : run(&d);
    cli_bake_args_free(&d.a);
    return rc;
}
