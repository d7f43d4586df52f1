/* obscura bake LEVEL -o OUT.(glb|ply): per-vertex ambient obscurance
 * (obscura/bake.h), flags from the bake parameter table, the report as
 * JSON. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bake.h"
#include "cli.h"
#include "obscura/bake.h"

void cli_bake_usage(FILE *f)
{
    fprintf(f,
            "  obscura bake LEVEL -o OUT.(glb|ply) [--distances S,L] [--blend B]\n"
            "                  [--report R.json] [--ply P.ply] [--color] [--quiet]\n"
            "                  [--decorators D.json]\n"
            "                  [--PARAM VALUE]...  ambient obscurance baked onto the vertices\n"
            "                  of a level (glTF/GLB, AC3D, anything assimp reads; node graph\n"
            "                  and instances kept): _AO, _AO_SHORT, _AO_LONG per vertex;\n"
            "                  'obscura bake --params' lists the parameters\n"
            "  obscura bake LEVEL --shard I/N -o PART [--PARAM VALUE]...\n"
            "                  trace shard I (0 .. N-1) of the level's samples into a part file\n"
            "  obscura bake LEVEL --merge PART... -o OUT.(glb|ply) [...]\n"
            "                  every shard's part read back and fitted: the unsharded bake\n");
}

/* The parameter table: plain text, or README's markdown table. */
static void list_params(int markdown)
{
    obs_bake_params p;
    obs_bake_params_resolve(NULL, &p);
    if (markdown)
        printf("| flag | default | range | meaning |\n| --- | --- | --- | --- |\n");
    for (int i = 0; i < obs_bake_param_count(); i++) {
        const obs_bake_param_info *pi = obs_bake_param_at(i);
        char def[64];
        obs_bake_param_format(&p, pi, def, sizeof def);
        cli_param_row(pi, def, markdown);
    }
}

typedef struct progress {
    double start, last;
} progress;

static int on_progress(void *user, size_t done, size_t total)
{
    progress *p = user;
    double t = cli_now_s();
    if (t - p->last < 0.5 && done < total)
        return 0;
    p->last = t;
    fprintf(stderr, "\robscura: bake: traced %zu / %zu samples (%.0f %%), %.1f s", done, total,
            total ? 100.0 * (double)done / (double)total : 100.0, t - p->start);
    if (done >= total)
        fprintf(stderr, "\n");
    return 0;
}

static cJSON *pair(const double v[2])
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "short", v[0]);
    cJSON_AddNumberToObject(o, "long", v[1]);
    return o;
}

/* The instanced decorators (section 2.2): counts, the volume, eq 3's
 * residual and every instance's coefficients (README's bake section). */
static void report_instanced(cJSON *r, const obs_bake_scene *sc, const obs_bake_stats *st,
                             const obs_bake_result *res)
{
    cJSON *in = cJSON_AddObjectToObject(r, "instanced");
    cJSON_AddNumberToObject(in, "meshes", (double)st->instanced_meshes);
    cJSON_AddNumberToObject(in, "instances", (double)st->instanced_instances);
    cJSON_AddNumberToObject(in, "volume_bricks", (double)st->volume_bricks);
    cJSON_AddNumberToObject(in, "volume_points", (double)st->volume_points);
    cJSON_AddNumberToObject(in, "volume_points_inside", (double)st->volume_points_inside);
    cJSON_AddNumberToObject(in, "volume_rays", (double)st->volume_rays);
    cJSON_AddNumberToObject(in, "eq3_residual_rms", st->instanced_residual);
    cJSON *list = cJSON_AddArrayToObject(in, "list");
    static const char *const keys[3] = {"global_ao", "global_ao_short", "global_ao_long"};
    for (size_t i = 0; res && i < res->instance_count; i++) {
        const obs_bake_instance *b = &res->instances[i];
        if (!b->ao_local)
            continue;
        cJSON *e = cJSON_CreateObject();
        cJSON_AddStringToObject(e, "node", sc->nodes[b->node].name ? sc->nodes[b->node].name : "");
        cJSON_AddStringToObject(e, "mesh", sc->meshes[b->mesh].name ? sc->meshes[b->mesh].name : "");
        for (int c = 0; c < 3; c++)
            cJSON_AddItemToObject(e, keys[c], cJSON_CreateFloatArray(b->global[c], 4));
        cJSON_AddItemToArray(list, e);
    }
}

static int write_report(const char *path, const char *level, const obs_bake_params *p,
                        const obs_bake_scene *sc, const obs_bake_stats *st,
                        const obs_bake_result *result, double load_s, double write_s)
{
    cJSON *r = cJSON_CreateObject();
    cJSON_AddStringToObject(r, "level", level);
    cJSON *par = cJSON_AddObjectToObject(r, "params");
    for (int i = 0; i < obs_bake_param_count(); i++) {
        const obs_bake_param_info *pi = obs_bake_param_at(i);
        char v[64];
        obs_bake_param_format(p, pi, v, sizeof v);
        if (pi->type == OBS_BAKE_PARAM_ENUM)
            cJSON_AddStringToObject(par, pi->name, v);
        else
            cJSON_AddNumberToObject(par, pi->name, strtod(v, NULL));
    }
    cJSON *sec = cJSON_AddObjectToObject(r, "seconds");
    double total = load_s + write_s;
    cJSON_AddNumberToObject(sec, "load", load_s);
    for (int i = 0; i < OBS_BAKE_STAGE_COUNT; i++) {
        cJSON_AddNumberToObject(sec, obs_bake_stage_name(i), st->seconds[i]);
        total += st->seconds[i];
    }
    cJSON_AddNumberToObject(sec, "write", write_s);
    cJSON_AddNumberToObject(sec, "total", total);
    cJSON *c = cJSON_AddObjectToObject(r, "counts");
    cJSON_AddNumberToObject(c, "meshes", (double)sc->mesh_count);
    cJSON_AddNumberToObject(c, "nodes", (double)sc->node_count);
    cJSON_AddNumberToObject(c, "instances", (double)st->instances);
    cJSON_AddNumberToObject(c, "triangles", (double)st->triangles);
    cJSON_AddNumberToObject(c, "degenerate_triangles", (double)st->degenerate_triangles);
    cJSON_AddNumberToObject(c, "faces_against_normals", (double)st->faces_against_normals);
    cJSON_AddNumberToObject(c, "two_sided_triangles", (double)st->two_sided_triangles);
    cJSON_AddNumberToObject(c, "vertices", (double)st->vertices);
    cJSON_AddNumberToObject(c, "welded_vertices", (double)st->welded_vertices);
    cJSON_AddNumberToObject(c, "interior_edges", (double)st->interior_edges);
    cJSON_AddNumberToObject(c, "boundary_edges", (double)st->boundary_edges);
    cJSON_AddNumberToObject(c, "nonmanifold_edges", (double)st->nonmanifold_edges);
    cJSON_AddNumberToObject(c, "samples", (double)st->samples);
    cJSON_AddNumberToObject(c, "samples_dropped_backface", (double)st->samples_dropped_backface);
    cJSON_AddNumberToObject(c, "vertices_without_samples", (double)st->vertices_without_samples);
    cJSON_AddNumberToObject(c, "vertices_isolated", (double)st->vertices_isolated);
    cJSON_AddNumberToObject(c, "rays", (double)st->rays);
    cJSON *dn = cJSON_AddObjectToObject(r, "decorator_nodes");
    static const char *const dnames[4] = {"none", "shrub", "tree", "small"};
    for (int k = 0; k < 4; k++)
        cJSON_AddNumberToObject(dn, dnames[k], (double)st->decorator_nodes[k]);
    double ts = st->seconds[OBS_BAKE_STAGE_trace];
    cJSON_AddNumberToObject(r, "rays_per_second", ts > 0.0 ? (double)st->rays / ts : 0.0);
    cJSON *res = cJSON_AddObjectToObject(r, "residual_rms");
    cJSON_AddItemToObject(res, "least_squares", pair(st->residual_fit));
    cJSON_AddItemToObject(res, "face_mean", pair(st->residual_face_mean));
    cJSON_AddItemToObject(res, "point_sample", pair(st->residual_point));
    cJSON_AddItemToObject(r, "regulariser_energy", pair(st->regulariser_energy));
    if (p->holdout > 0.0f) {
        cJSON *h = cJSON_AddObjectToObject(r, "holdout_rms");
        cJSON_AddNumberToObject(h, "samples", (double)st->holdout_samples);
        cJSON_AddItemToObject(h, "least_squares", pair(st->holdout_fit));
        cJSON_AddItemToObject(h, "face_mean", pair(st->holdout_face_mean));
        cJSON_AddItemToObject(h, "point_sample", pair(st->holdout_point));
    }
    if (st->lod_levels)
        cli_bake_lod_report(r, p, st);
    report_instanced(r, sc, st, result);
    if (st->small_decorators) {
        /* section 2.2.1: one scalar per small decorator */
        cJSON *sd = cJSON_AddObjectToObject(r, "small_decorators");
        cJSON_AddNumberToObject(sd, "count", (double)st->small_decorators);
        cJSON_AddNumberToObject(sd, "unresolved", (double)st->small_unresolved);
        cJSON *arr = cJSON_AddArrayToObject(sd, "nodes");
        for (size_t n = 0; result && result->node_ao && n < result->node_count; n++) {
            const float *a = result->node_ao + 3 * n;
            if (a[0] != a[0]) /* NaN: not a small decorator, or unresolved */
                continue;
            cJSON *e = cJSON_CreateObject();
            cJSON_AddNumberToObject(e, "node", (double)n);
            cJSON_AddStringToObject(e, "name", sc->nodes[n].name);
            cJSON_AddNumberToObject(e, "_AO", a[0]);
            cJSON_AddNumberToObject(e, "_AO_SHORT", a[1]);
            cJSON_AddNumberToObject(e, "_AO_LONG", a[2]);
            cJSON_AddItemToArray(arr, e);
        }
    }
    cJSON *ao = cJSON_AddObjectToObject(r, "ao");
    cJSON_AddNumberToObject(ao, "mean", st->ao_mean);
    cJSON_AddNumberToObject(ao, "min", st->ao_min);
    cJSON_AddNumberToObject(ao, "max", st->ao_max);
    char *txt = cJSON_Print(r);
    cJSON_Delete(r);
    FILE *f = txt ? fopen(path, "w") : NULL;
    int ok = f && fputs(txt, f) >= 0 && fputc('\n', f) != EOF;
    if (f && fclose(f) != 0)
        ok = 0;
    free(txt);
    if (!ok)
        fprintf(stderr, "obscura: bake: %s: cannot write the report: %s\n", path, strerror(errno));
    return ok;
}

/* What the bake noticed about its input and could not decide for the
 * user: printed even with --quiet. */
static int ends_with(const char *s, const char *tail);

static void warn(const char *level, const obs_bake_stats *st)
{
    if (st->decorator_warning[0])
        fprintf(stderr, "obscura: bake: warning: %s\n", st->decorator_warning);
    if (st->small_unresolved)
        fprintf(stderr,
                "obscura: bake: warning: %zu of %zu small decorators met no geometry within "
                "their sphere (--small-radius): they keep their own fitted values\n",
                st->small_unresolved, st->small_decorators);
    /* assimp 5.2's AC3D reader drops the surfaces' double-sided flag
     * (SURF 0x20); the loader reads it from the file, unless the file's
     * objects and assimp's nodes disagree. */
    if ((ends_with(level, ".ac") || ends_with(level, ".acc")) && !st->two_sided_triangles)
        fprintf(stderr,
                "obscura: bake: warning: %s: no double-sided AC3D surface found (or its "
                "objects did not match assimp's nodes): every face counts as one-sided for "
                "the back-face rule\n",
                level);
    if (st->faces_against_normals)
        fprintf(stderr,
                "obscura: bake: warning: %zu of %zu faces wind against their vertex normals; "
                "their winding decides the side that is traced\n",
                st->faces_against_normals, st->triangles);
    if (st->degenerate_triangles)
        fprintf(stderr, "obscura: bake: warning: %zu degenerate (zero-area) faces skipped\n",
                st->degenerate_triangles);
    if (st->samples && st->samples_dropped_backface * 10 > st->samples)
        fprintf(stderr,
                "obscura: bake: warning: %zu of %zu samples (%.0f %%) dropped by the back-face "
                "rule: inside geometry, or one-sided faces seen from behind\n",
                st->samples_dropped_backface, st->samples,
                100.0 * (double)st->samples_dropped_backface / (double)st->samples);
    if (st->vertices_isolated)
        fprintf(stderr,
                "obscura: bake: warning: %zu vertices have no valid sample and no neighbour "
                "with one: they take the mean of the level's samples\n",
                st->vertices_isolated);
}

static int ends_with(const char *s, const char *tail)
{
    size_t n = strlen(s), m = strlen(tail);
    return n >= m && !strcasecmp(s + n - m, tail);
}

int cli_bake(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *report = NULL, *ply = NULL, *decorators = NULL;
    int color = 0, quiet = 0, shard = -1, shards = 0, merging = 0, merge = 0;
    const char **parts = calloc((size_t)argc + 1, sizeof *parts);
    size_t nparts = 0;
    if (!parts)
        cli_die_usage("bake", "out of memory");
    obs_bake_desc desc = {0};
    char err[OBS_ERR_LEN] = "";
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
                cli_die_usage("bake", "more than one level ('%s' and '%s')", in, a);
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
        if (!strcmp(key, "params") || !strcmp(key, "params-markdown")) {
            list_params(key[6] != '\0');
            free(parts);
            return EXIT_OK;
        } else if (!strcmp(key, "color")) {
            color = 1, takes = 0;
        } else if (!strcmp(key, "quiet") || !strcmp(key, "q")) {
            quiet = 1, takes = 0;
        } else if (!strcmp(key, "merge")) {
            merging = merge = 1, takes = 0;
            if (eq && *val)
                parts[nparts++] = val;
        } else if (!val) {
            cli_die_usage("bake", "option --%s needs a value", key);
        } else if (!strcmp(key, "o") || !strcmp(key, "output")) {
            out = val;
        } else if (!strcmp(key, "shard")) {
            cli_parse_shard("bake", val, &shard, &shards);
        } else if (!strcmp(key, "report")) {
            report = val;
        } else if (!strcmp(key, "decorators")) {
            decorators = val;
        } else if (!strcmp(key, "ply")) {
            ply = val;
        } else if (!strcmp(key, "distances")) {
            char s[64], l[64];
            const char *comma = strchr(val, ',');
            if (!comma || strchr(comma + 1, ','))
                cli_die_usage("bake", "--distances '%s': expected SHORT,LONG (e.g. 2,300)", val);
            snprintf(s, sizeof s, "%.*s", (int)(comma - val), val);
            snprintf(l, sizeof l, "%s", comma + 1);
            if (obs_bake_param_set(&desc.params, "distance_short", s, err) != OBS_OK ||
                obs_bake_param_set(&desc.params, "distance_long", l, err) != OBS_OK)
                cli_die_usage("bake", "--distances: %s", err);
        } else if (obs_bake_param_find(key)) {
            if (obs_bake_param_set(&desc.params, key, val, err) != OBS_OK)
                cli_die_usage("bake", "%s", err);
        } else {
            cli_die_usage("bake", "unknown option '%s' ('obscura bake --params' lists the parameters)", a);
        }
        if (takes && !eq)
            i++;
    }
    if (!in)
        cli_die_usage("bake", "no level file");
    if (!out)
        cli_die_usage("bake", shards ? "no part file (-o PART)" : "no output file (-o OUT.glb or OUT.ply)");
    if (merge && !nparts)
        cli_die_usage("bake", "--merge needs the part files (--merge PART...)");
    if (shards && nparts)
        cli_die_usage("bake", "--shard traces a part, --merge reads them: not both");
    if (shards && (ply || color))
        cli_die_usage("bake", "--shard writes a part, not a model: --ply and --color go with --merge");
    int out_ply = ends_with(out, ".ply");
    if (!shards && !out_ply && !ends_with(out, ".glb"))
        cli_die_usage("bake", "cannot tell the format of '%s': use .glb or .ply", out);
    obs_bake_params p;
    obs_bake_params_resolve(&desc.params, &p);
    if (p.lods && !shards && (out_ply || ply))
        cli_die_usage("bake", "--lods writes its levels into the .glb (MSFT_lod); a .ply has "
                              "no LODs: drop --ply or --lods");

    char *decor_text = NULL;
    if (decorators) {
        obs_status ds = cli_read_text(decorators, &decor_text, err);
        if (ds != OBS_OK) {
            free(parts);
            return cli_input_fail(ds, decorators, err);
        }
        desc.decorators_json = decor_text;
    }
    double t0 = cli_now_s();
    obs_bake_scene sc;
    obs_status s = obs_bake_load(in, (size_t)p.max_triangles, &sc, err);
    if (s != OBS_OK) {
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
    obs_bake_result r;
    if (shards) {
        obs_bake_stats st;
        s = obs_bake_shard(&sc, &desc, shard, shards, out, &st, err);
        int rc = s == OBS_OK ? EXIT_OK : cli_fail(s, in, err);
        if (rc == EXIT_OK && report && !write_report(report, in, &p, &sc, &st, NULL, load_s, 0.0))
            rc = EXIT_FAIL;
        if (rc == EXIT_OK && !quiet)
            fprintf(stderr, "obscura: bake: shard %d/%d: %zu samples (%zu dropped by the back-face "
                    "rule), %llu rays in %.1f s; wrote %s\n", shard, shards, st.samples,
                    st.samples_dropped_backface, (unsigned long long)st.rays,
                    st.seconds[OBS_BAKE_STAGE_trace], out);
        obs_bake_scene_free(&sc);
        free(parts);
        free(decor_text);
        return rc;
    }
    s = nparts ? obs_bake_merge(&sc, &desc, parts, nparts, &r, err) : obs_bake_run(&sc, &desc, &r, err);
    free(parts);
    free(decor_text);
    if (s != OBS_OK) {
        obs_bake_scene_free(&sc);
        return nparts ? cli_input_fail(s, in, err) : cli_fail(s, in, err);
    }
    if (nparts) /* the parts' trace parameters, for the report */
        obs_bake_params_resolve(&desc.params, &p);
    warn(in, &r.stats);
    double t1 = cli_now_s();
    s = out_ply ? obs_bake_write_ply(out, &sc, &r, err)
                : obs_bake_write_glb(out, &sc, &r, color, err);
    if (s == OBS_OK && ply)
        s = obs_bake_write_ply(ply, &sc, &r, err);
    double write_s = cli_now_s() - t1;
    int rc = s == OBS_OK ? EXIT_OK : cli_fail(s, out, err);
    const obs_bake_stats *st = &r.stats;
    if (rc == EXIT_OK && report &&
        !write_report(report, in, &p, &sc, st, &r, load_s, write_s))
        rc = EXIT_FAIL;
    if (rc == EXIT_OK && !quiet)
        fprintf(stderr,
                "obscura: bake: %zu instances, %zu triangles, %zu samples (%zu dropped by the "
                "back-face rule), %llu rays in %.1f s; mean _AO %.3f; wrote %s\n",
                st->instances, st->triangles, st->samples, st->samples_dropped_backface,
                (unsigned long long)st->rays, st->seconds[OBS_BAKE_STAGE_trace], st->ao_mean, out);
    if (rc == EXIT_OK && !quiet && st->lod_levels)
        for (size_t k = 0; k < st->lod_levels && k < OBS_BAKE_MAX_LODS; k++)
            fprintf(stderr, "obscura: bake: LOD %zu: %zu triangles (%.0f %%), %zu samples "
                    "resampled and fitted\n", k + 1, st->lod_triangles[k],
                    st->triangles ? 100.0 * (double)st->lod_triangles[k] / (double)st->triangles : 0.0,
                    st->lod_samples[k]);
    obs_bake_result_free(&r);
    obs_bake_scene_free(&sc);
    return rc;
}
