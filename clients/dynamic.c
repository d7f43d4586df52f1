/* obscura bake-dynamic LEVEL -o MODEL.json: the region model of baked
 * obscurance for dynamic objects (obscura/dynamic.h), flags from its own
 * parameter table; --eval MODEL.json --at X,Y,Z --normal X,Y,Z prints the
 * AO there. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "dynamic.h"
#include "obscura/dynamic.h"

void cli_dynamic_usage(FILE *f)
{
    fprintf(f,
            "  obscura bake-dynamic LEVEL -o MODEL.json [--regions R.json] [--report R.json]\n"
            "                  [--paths N] [--decorators D.json] [--PARAM VALUE]...  obscurance\n"
            "                  for dynamic objects: regions, valid points, SH at two distances,\n"
            "                  eq 4 per region, regularised (section 2.3), through the decorators\n"
            "                  as obscura bake traces them; 'obscura bake-dynamic --params'\n"
            "  obscura bake-dynamic LEVEL --shard I/N -o PART [--regions R.json] [--PARAM VALUE]...\n"
            "                  trace shard I (0 .. N-1) of the valid points into a part file\n"
            "  obscura bake-dynamic LEVEL --merge PART... -o MODEL.json [...]\n"
            "                  every shard's part read back and fitted: the unsharded model\n"
            "  obscura bake-dynamic --eval MODEL.json --at X,Y,Z --normal X,Y,Z\n"
            "                  [--sh linear|quadratic]  prints short, long and blended AO\n");
}

static void list_params(int markdown)
{
    obs_dyn_params p;
    obs_dyn_params_resolve(NULL, &p);
    if (markdown)
        printf("| flag | default | range | meaning |\n| --- | --- | --- | --- |\n");
    for (int i = 0; i < obs_dyn_param_count(); i++) {
        const obs_bake_param_info *pi = obs_dyn_param_at(i);
        char def[64];
        obs_dyn_param_format(&p, pi, def, sizeof def);
        cli_param_row(pi, def, markdown);
    }
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

static int write_report(const char *path, const char *level, const obs_dyn_params *p,
                        const obs_dyn_stats *st, const obs_dyn_path_stats *ps, double load_s)
{
    cJSON *r = cJSON_CreateObject();
    cJSON_AddStringToObject(r, "level", level);
    cJSON *par = cJSON_AddObjectToObject(r, "params");
    for (int i = 0; i < obs_dyn_param_count(); i++) {
        const obs_bake_param_info *pi = obs_dyn_param_at(i);
        char v[64];
        obs_dyn_param_format(p, pi, v, sizeof v);
        if (pi->type == OBS_BAKE_PARAM_ENUM)
            cJSON_AddStringToObject(par, pi->name, v);
        else
            cJSON_AddNumberToObject(par, pi->name, strtod(v, NULL));
    }
    cJSON *dn = cJSON_AddObjectToObject(r, "decorator_nodes"); /* as obscura bake's report */
    const char *dnames[4] = {"none", "shrub", "tree", "small"};
    for (int k = 0; k < 4; k++)
        cJSON_AddNumberToObject(dn, dnames[k], (double)st->decorator_nodes[k]);
    cJSON *sec = cJSON_AddObjectToObject(r, "seconds");
    cJSON_AddNumberToObject(sec, "load", load_s);
    for (int i = 0; i < OBS_DYN_STAGE_COUNT; i++)
        cJSON_AddNumberToObject(sec, obs_dyn_stage_name(i), st->seconds[i]);
    cJSON *c = cJSON_AddObjectToObject(r, "counts");
    cJSON_AddNumberToObject(c, "regions", (double)st->regions);
    cJSON_AddNumberToObject(c, "edges", (double)st->edges);
    cJSON_AddNumberToObject(c, "models", (double)st->models);
    cJSON_AddNumberToObject(c, "regions_absorbed", (double)st->regions_absorbed);
    cJSON_AddNumberToObject(c, "regions_without_points", (double)st->regions_without_points);
    cJSON_AddNumberToObject(c, "grid_points", (double)st->grid_points);
    cJSON_AddNumberToObject(c, "points_inside", (double)st->points_inside);
    cJSON_AddNumberToObject(c, "points_hidden", (double)st->points_hidden);
    cJSON_AddNumberToObject(c, "points_backface", (double)st->points_backface);
    cJSON_AddNumberToObject(c, "points_valid", (double)st->points_valid);
    cJSON_AddNumberToObject(c, "centre_of_mass_kept", (double)st->centre_of_mass_kept);
    cJSON_AddNumberToObject(c, "rays", (double)st->rays);
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
    if (ps) {
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
    char *txt = cJSON_Print(r);
    cJSON_Delete(r);
    FILE *fp = txt ? fopen(path, "w") : NULL;
    int ok = fp && fputs(txt, fp) >= 0 && fputc('\n', fp) != EOF;
    if (fp && fclose(fp) != 0)
        ok = 0;
    free(txt);
    if (!ok)
        fprintf(stderr, "obscura: bake-dynamic: %s: cannot write the report: %s\n", path,
                strerror(errno));
    return ok;
}

typedef struct progress {
    double start, last;
} progress;

static void on_progress(void *user, size_t done, size_t total)
{
    progress *p = user;
    double t = cli_now_s();
    if (t - p->last < 0.5 && done < total)
        return;
    p->last = t;
    fprintf(stderr, "\robscura: bake-dynamic: traced %zu / %zu points, %.1f s", done, total,
            t - p->start);
    if (done >= total)
        fprintf(stderr, "\n");
}

int cli_dynamic(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *regions = NULL, *report = NULL, *eval = NULL,
               *at = NULL, *normal = NULL, *sh = NULL, *decorators = NULL;
    int quiet = 0, paths = 0, path_steps = 64, path_rays = 256;
    int shard = -1, shards = 0, merging = 0, merge = 0;
    float tau = 4.0f;
    obs_dyn_desc desc = {0};
    char err[OBS_ERR_LEN] = "";
    const char **parts = calloc((size_t)argc + 1, sizeof *parts);
    size_t nparts = 0;
    if (!parts)
        cli_die_usage("bake-dynamic", "out of memory");
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if ((a[0] != '-' || !a[1]) && merging) {
            parts[nparts++] = a; /* --merge PART...: up to the next option */
            continue;
        }
        merging = 0;
        if (a[0] != '-' || !a[1]) {
            if (in)
                cli_die_usage("bake-dynamic", "more than one level ('%s' and '%s')", in, a);
            in = a;
            continue;
        }
        const char *name = a + (a[1] == '-' ? 2 : 1);
        char key[64];
        const char *eq = strchr(name, '=');
        snprintf(key, sizeof key, "%.*s", eq ? (int)(eq - name) : (int)strlen(name), name);
        if (eq)
            val = eq + 1;
        int takes = 1;
        char *end;
        if (!strcmp(key, "params") || !strcmp(key, "params-markdown")) {
            list_params(key[6] != '\0');
            free(parts);
            return EXIT_OK;
        } else if (!strcmp(key, "quiet") || !strcmp(key, "q")) {
            quiet = 1, takes = 0;
        } else if (!strcmp(key, "merge")) {
            merging = merge = 1, takes = 0;
            if (eq && *val)
                parts[nparts++] = val;
        } else if (!val) {
            cli_die_usage("bake-dynamic", "option --%s needs a value", key);
        } else if (!strcmp(key, "o") || !strcmp(key, "output")) {
            out = val;
        } else if (!strcmp(key, "regions")) {
            regions = val;
        } else if (!strcmp(key, "decorators")) {
            decorators = val;
        } else if (!strcmp(key, "shard")) {
            cli_parse_shard("bake-dynamic", val, &shard, &shards);
        } else if (!strcmp(key, "report")) {
            report = val;
        } else if (!strcmp(key, "eval")) {
            eval = val;
        } else if (!strcmp(key, "at")) {
            at = val;
        } else if (!strcmp(key, "normal")) {
            normal = val;
        } else if (!strcmp(key, "sh")) {
            sh = val;
        } else if (!strcmp(key, "paths") || !strcmp(key, "path-steps") ||
                   !strcmp(key, "path-rays")) {
            long v = strtol(val, &end, 10);
            if (*end || v < (key[4] ? 2 : 0) || v > 100000)
                cli_die_usage("bake-dynamic", "--%s '%s': an integer in %d..100000", key, val,
                              key[4] ? 2 : 0);
            *(!strcmp(key, "paths") ? &paths : !strcmp(key, "path-steps") ? &path_steps
                                                                            : &path_rays) = (int)v;
        } else if (!strcmp(key, "tau")) {
            double v = strtod(val, &end);
            if (*end || !(v >= 0.0) || v > 1e6)
                cli_die_usage("bake-dynamic", "--tau '%s': the blender's decay in steps, >= 0",
                              val);
            tau = (float)v;
        } else if (obs_dyn_param_find(key)) {
            if (obs_dyn_param_set(&desc.params, key, val, err) != OBS_OK)
                cli_die_usage("bake-dynamic", "%s", err);
        } else {
            cli_die_usage("bake-dynamic",
                          "unknown option '%s' ('obscura bake-dynamic --params' lists the "
                          "parameters)",
                          a);
        }
        if (takes && !eq)
            i++;
    }
    if (eval) {
        free(parts);
        return eval_cmd(eval, at, normal, sh);
    }
    if (!in)
        cli_die_usage("bake-dynamic", "no level file");
    if (!out)
        cli_die_usage("bake-dynamic", shards ? "no part file (-o PART)" : "no output file (-o MODEL.json)");
    if (merge && !nparts)
        cli_die_usage("bake-dynamic", "--merge needs the part files (--merge PART...)");
    if (shards && nparts)
        cli_die_usage("bake-dynamic", "--shard traces a part, --merge reads them: not both");
    if (shards && paths)
        cli_die_usage("bake-dynamic", "--shard writes a part, not a model: --paths goes with --merge");
    obs_dyn_params p;
    obs_dyn_params_resolve(&desc.params, &p);
    obs_dyn_regions rg = {0};
    obs_status s;
    if (regions) {
        if ((s = obs_dyn_regions_read(regions, &rg, err)) != OBS_OK) {
            free(parts);
            return cli_input_fail(s, regions, err);
        }
        desc.regions = &rg;
    }
    char *decor_text = NULL; /* read as obscura bake reads it */
    if (decorators) {
        if ((s = cli_read_text(decorators, &decor_text, err)) != OBS_OK) {
            obs_dyn_regions_free(&rg);
            free(parts);
            return cli_input_fail(s, decorators, err);
        }
        desc.decorators_json = decor_text;
    }
    double t0 = cli_now_s();
    obs_bake_scene sc;
    s = obs_bake_load(in, (size_t)p.max_triangles, &sc, err);
    if (s != OBS_OK) {
        obs_dyn_regions_free(&rg);
        free(parts);
        free(decor_text);
        return cli_input_fail(s, in, err);
    }
    double load_s = cli_now_s() - t0;
    progress pr = {cli_now_s(), 0.0};
    if (!quiet && isatty(2)) {
        desc.progress = on_progress;
        desc.progress_user = &pr;
    }
    if (shards) {
        obs_dyn_stats st;
        s = obs_dyn_bake_shard(&sc, &desc, shard, shards, out, &st, err);
        int rc = s == OBS_OK ? EXIT_OK : cli_fail(s, in, err);
        if (rc == EXIT_OK && st.decorator_warning[0])
            fprintf(stderr, "obscura: bake-dynamic: warning: %s\n", st.decorator_warning);
        if (rc == EXIT_OK && report && !write_report(report, in, &p, &st, NULL, load_s))
            rc = EXIT_FAIL;
        if (rc == EXIT_OK && !quiet)
            fprintf(stderr, "obscura: bake-dynamic: shard %d/%d: %zu points (%zu dropped by the "
                    "back-face rule), %llu rays in %.1f s; wrote %s\n", shard, shards,
                    st.points_valid + st.points_backface, st.points_backface,
                    (unsigned long long)st.rays, st.seconds[OBS_DYN_STAGE_trace], out);
        obs_dyn_regions_free(&rg);
        obs_bake_scene_free(&sc);
        free(parts);
        free(decor_text);
        return rc;
    }
    obs_dyn_result r;
    s = nparts ? obs_dyn_bake_merge(&sc, &desc, parts, nparts, &r, err)
               : obs_dyn_bake(&sc, &desc, &r, err);
    obs_dyn_regions_free(&rg);
    free(parts);
    if (s != OBS_OK) {
        obs_bake_scene_free(&sc);
        free(decor_text);
        return nparts ? cli_input_fail(s, in, err) : cli_fail(s, in, err);
    }
    if (r.stats.decorator_warning[0])
        fprintf(stderr, "obscura: bake-dynamic: warning: %s\n", r.stats.decorator_warning);
    if (nparts) /* the parts' parameters, for the paths and the report */
        obs_dyn_params_resolve(&desc.params, &p);
    int rc = EXIT_OK;
    obs_dyn_path_stats ps;
    if (paths > 0 &&
        (s = obs_dyn_measure_paths(&sc, &r, &p, desc.decorators_json, paths, path_steps,
                                   path_rays, tau, &ps, err)) != OBS_OK)
        rc = cli_fail(s, in, err);
    if (rc == EXIT_OK && (s = obs_dyn_model_write(out, &r.model, err)) != OBS_OK)
        rc = cli_fail(s, out, err);
    const obs_dyn_stats *st = &r.stats;
    if (rc == EXIT_OK && report && !write_report(report, in, &p, st, paths > 0 ? &ps : NULL, load_s))
        rc = EXIT_FAIL;
    if (rc == EXIT_OK && !st->points_valid)
        fprintf(stderr, "obscura: bake-dynamic: warning: no valid point in any region: every "
                        "region lies inside geometry or behind walls\n");
    if (rc == EXIT_OK && !quiet)
        fprintf(stderr,
                "obscura: bake-dynamic: %zu regions (%zu absorbed, %zu models), %zu of %zu grid "
                "points valid (%zu inside, %zu behind a wall, %zu back faces), %llu rays in "
                "%.1f s; wrote %s\n",
                st->regions, st->regions_absorbed, st->models, st->points_valid, st->grid_points,
                st->points_inside, st->points_hidden, st->points_backface,
                (unsigned long long)st->rays, st->seconds[OBS_DYN_STAGE_trace], out);
    obs_dyn_result_free(&r);
    obs_bake_scene_free(&sc);
    free(decor_text);
    return rc;
}
