/* obscura bake LEVEL -o OUT.(glb|ply): per-vertex ambient obscurance
 * (obscura/bake.h), flags from the bake parameter table, the report as
 * JSON. */
#include <cjson/cJSON.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "bake_common.h"
#include "bake_lod.h"
#include "cli.h"
#include "obscura/bake.h"

void cli_bake_usage(FILE *f)
{
    fprintf(f,
            "  obscura bake LEVEL -o OUT.(glb|ply) [--distances S,L] [--blend B]\n"
            "                  [--report R.json] [--ply P.ply] [--color] [--quiet] [--progress percent]\n"
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

static int on_progress(void *user, size_t done, size_t total)
{
    cli_progress *p = user;
    double t;
    if (!cli_progress_due(p, done, total, &t))
        return 0;
    fprintf(stderr, "\robscura: bake: traced %zu / %zu samples (%.0f %%), %.1f s", done, total,
            total ? 100.0 * (double)done / (double)total : 100.0, t - p->start);
    cli_progress_end(done, total);
    return 0;
}

#define COUNT(key, field) {key, offsetof(obs_bake_stats, field)}

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
    static const cli_count counts[] = {
        COUNT("meshes", instanced_meshes),       COUNT("instances", instanced_instances),
        COUNT("volume_bricks", volume_bricks),   COUNT("volume_points", volume_points),
        COUNT("volume_points_inside", volume_points_inside),
    };
    cJSON *in = cJSON_AddObjectToObject(r, "instanced");
    cli_bake_report_counts(in, st, counts, sizeof counts / sizeof *counts);
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

/* The stages' seconds, with the load and the write around them. */
static void report_seconds(cJSON *r, const obs_bake_stats *st, double load_s, double write_s)
{
    cJSON *sec = cJSON_AddObjectToObject(r, "seconds");
    double total = load_s + write_s;
    cJSON_AddNumberToObject(sec, "load", load_s);
    for (int i = 0; i < OBS_BAKE_STAGE_COUNT; i++) {
        cJSON_AddNumberToObject(sec, obs_bake_stage_name(i), st->seconds[i]);
        total += st->seconds[i];
    }
    cJSON_AddNumberToObject(sec, "write", write_s);
    cJSON_AddNumberToObject(sec, "total", total);
}

static void report_counts(cJSON *r, const obs_bake_scene *sc, const obs_bake_stats *st)
{
    static const cli_count counts[] = {
        COUNT("instances", instances),
        COUNT("triangles", triangles),
        COUNT("degenerate_triangles", degenerate_triangles),
        COUNT("faces_against_normals", faces_against_normals),
        COUNT("two_sided_triangles", two_sided_triangles),
        COUNT("vertices", vertices),
        COUNT("welded_vertices", welded_vertices),
        COUNT("interior_edges", interior_edges),
        COUNT("boundary_edges", boundary_edges),
        COUNT("nonmanifold_edges", nonmanifold_edges),
        COUNT("samples", samples),
        COUNT("samples_dropped_backface", samples_dropped_backface),
        COUNT("vertices_without_samples", vertices_without_samples),
        COUNT("vertices_isolated", vertices_isolated),
    };
    cJSON *c = cJSON_AddObjectToObject(r, "counts");
    cJSON_AddNumberToObject(c, "meshes", (double)sc->mesh_count);
    cJSON_AddNumberToObject(c, "nodes", (double)sc->node_count);
    cli_bake_report_counts(c, st, counts, sizeof counts / sizeof *counts);
    cJSON_AddNumberToObject(c, "rays", (double)st->rays);
}

/* The fit against the traced samples and its two baselines, in and out
 * of sample (holdout). */
static void report_residuals(cJSON *r, const obs_bake_params *p, const obs_bake_stats *st)
{
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
}

/* Section 2.2.1: one scalar per small decorator. */
static void report_small(cJSON *r, const obs_bake_scene *sc, const obs_bake_stats *st,
                         const obs_bake_result *result)
{
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

static int write_report(const char *path, const char *level, const obs_bake_params *p,
                        const obs_bake_scene *sc, const obs_bake_stats *st,
                        const obs_bake_result *result, double load_s, double write_s)
{
    cJSON *r = cli_bake_report_new(level, &cli_bake_table, p);
    report_seconds(r, st, load_s, write_s);
    report_counts(r, sc, st);
    cli_bake_report_decorators(r, st->decorator_nodes);
    double ts = st->seconds[OBS_BAKE_STAGE_trace];
    cJSON_AddNumberToObject(r, "rays_per_second", ts > 0.0 ? (double)st->rays / ts : 0.0);
    report_residuals(r, p, st);
    if (st->lod_levels)
        cli_bake_lod_report(r, p, st);
    report_instanced(r, sc, st, result);
    if (st->small_decorators)
        report_small(r, sc, st, result);
    cJSON *ao = cJSON_AddObjectToObject(r, "ao");
    cJSON_AddNumberToObject(ao, "mean", st->ao_mean);
    cJSON_AddNumberToObject(ao, "min", st->ao_min);
    cJSON_AddNumberToObject(ao, "max", st->ao_max);
    return cli_bake_report_write("bake", path, r);
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

/* What the steps of one obscura bake share. */
typedef struct bake_run {
    cli_bake_args a;
    const char *ply;
    int color, out_ply;
    obs_bake_desc desc;
    obs_bake_params p; /* resolved */
    char err[OBS_ERR_LEN];
} bake_run;

/* --distances SHORT,LONG: the two distance rows at once. */
static int bake_option(void *user, const char *key, const char *val)
{
    obs_bake_params *params = user;
    if (strcmp(key, "distances"))
        return 0;
    char s[64], l[64], err[OBS_ERR_LEN] = "";
    const char *comma = strchr(val, ',');
    if (!comma || strchr(comma + 1, ','))
        cli_die_usage("bake", "--distances '%s': expected SHORT,LONG (e.g. 2,300)", val);
    snprintf(s, sizeof s, "%.*s", (int)(comma - val), val);
    snprintf(l, sizeof l, "%s", comma + 1);
    if (obs_bake_param_set(params, "distance_short", s, err) != OBS_OK ||
        obs_bake_param_set(params, "distance_long", l, err) != OBS_OK)
        cli_die_usage("bake", "--distances: %s", err);
    return 1;
}

/* The flags, then the checks that need them all.  0: --params listed. */
static int parse(int argc, char **argv, bake_run *b)
{
    static const char *const flags[] = {"color", NULL};
    const cli_bake_str strs[] = {{"ply", &b->ply}, {NULL, NULL}};
    const cli_bake_cmd cmd = {.name = "bake", .out_hint = "OUT.glb or OUT.ply",
                              .table = &cli_bake_table, .params = &b->desc.params,
                              .flags = flags, .flag_vals = &b->color, .strs = strs,
                              .option = bake_option, .user = &b->desc.params};
    if (!cli_bake_parse(&cmd, argc, argv, &b->a))
        return 0;
    const cli_bake_args *a = &b->a;
    cli_bake_check(&cmd, a);
    if (a->shards && (b->ply || b->color))
        cli_die_usage("bake", "--shard writes a part, not a model: --ply and --color go with --merge");
    b->out_ply = ends_with(a->out, ".ply");
    if (!a->shards && !b->out_ply && !ends_with(a->out, ".glb"))
        cli_die_usage("bake", "cannot tell the format of '%s': use .glb or .ply", a->out);
    obs_bake_params_resolve(&b->desc.params, &b->p);
    if (b->p.lods && !a->shards && (b->out_ply || b->ply))
        cli_die_usage("bake", "--lods writes its levels into the .glb (MSFT_lod); a .ply has "
                              "no LODs: drop --ply or --lods");
    return 1;
}

/* --shard I/N: one part of the trace into a part file. */
static int run_shard(bake_run *b)
{
    const cli_bake_args *a = &b->a;
    obs_bake_stats st;
    obs_status s = obs_bake_shard(&a->sc, &b->desc, a->shard, a->shards, a->out, &st, b->err);
    int rc = s == OBS_OK ? EXIT_OK : cli_fail(s, a->in, b->err);
    if (rc == EXIT_OK && a->report &&
        !write_report(a->report, a->in, &b->p, &a->sc, &st, NULL, a->load_s, 0.0))
        rc = EXIT_FAIL;
    if (rc == EXIT_OK && !a->quiet)
        fprintf(stderr, "obscura: bake: shard %d/%d: %zu samples (%zu dropped by the back-face "
                "rule), %llu rays in %.1f s; wrote %s\n", a->shard, a->shards, st.samples,
                st.samples_dropped_backface, (unsigned long long)st.rays,
                st.seconds[OBS_BAKE_STAGE_trace], a->out);
    return rc;
}

/* The model (and --ply's copy); *write_s their time. */
static obs_status write_model(bake_run *b, const obs_bake_result *r, double *write_s)
{
    const cli_bake_args *a = &b->a;
    double t1 = cli_now_s();
    obs_status s = b->out_ply ? obs_bake_write_ply(a->out, &a->sc, r, b->err)
                              : obs_bake_write_glb(a->out, &a->sc, r, b->color, b->err);
    if (s == OBS_OK && b->ply)
        s = obs_bake_write_ply(b->ply, &a->sc, r, b->err);
    *write_s = cli_now_s() - t1;
    return s;
}

static void print_summary(const obs_bake_stats *st, const char *out)
{
    fprintf(stderr,
            "obscura: bake: %zu instances, %zu triangles, %zu samples (%zu dropped by the "
            "back-face rule), %llu rays in %.1f s; mean _AO %.3f; wrote %s\n",
            st->instances, st->triangles, st->samples, st->samples_dropped_backface,
            (unsigned long long)st->rays, st->seconds[OBS_BAKE_STAGE_trace], st->ao_mean, out);
    for (size_t k = 0; k < st->lod_levels && k < OBS_BAKE_MAX_LODS; k++)
        fprintf(stderr, "obscura: bake: LOD %zu: %zu triangles (%.0f %%), %zu samples "
                "resampled and fitted\n", k + 1, st->lod_triangles[k],
                st->triangles ? 100.0 * (double)st->lod_triangles[k] / (double)st->triangles : 0.0,
                st->lod_samples[k]);
}

/* The whole bake, or the merge of --merge's parts: the model, the
 * report, the summary. */
static int run_bake(bake_run *b)
{
    const cli_bake_args *a = &b->a;
    obs_bake_result r;
    obs_status s = a->nparts ? obs_bake_merge(&a->sc, &b->desc, a->parts, a->nparts, &r, b->err)
                             : obs_bake_run(&a->sc, &b->desc, &r, b->err);
    if (s != OBS_OK)
        return cli_bake_fail(a, s, b->err);
    if (a->nparts) /* the parts' trace parameters, for the report */
        obs_bake_params_resolve(&b->desc.params, &b->p);
    warn(a->in, &r.stats);
    double write_s;
    s = write_model(b, &r, &write_s);
    int rc = s == OBS_OK ? EXIT_OK : cli_fail(s, a->out, b->err);
    if (rc == EXIT_OK && a->report &&
        !write_report(a->report, a->in, &b->p, &a->sc, &r.stats, &r, a->load_s, write_s))
        rc = EXIT_FAIL;
    if (rc == EXIT_OK && !a->quiet)
        print_summary(&r.stats, a->out);
    obs_bake_result_free(&r);
    return rc;
}

int cli_bake(int argc, char **argv)
{
    bake_run b = {0};
    if (!parse(argc, argv, &b))
        return EXIT_OK;
    int rc = cli_bake_load(&b.a, (size_t)b.p.max_triangles, b.err);
    if (rc == EXIT_OK) {
        b.desc.decorators_json = b.a.decor_text;
        if (cli_bake_shows_progress(&b.a)) {
            b.desc.progress = on_progress;
            b.desc.progress_user = &b.a.progress;
        }
        rc = b.a.shards ? run_shard(&b) : run_bake(&b);
    }
    cli_bake_args_free(&b.a);
    return rc;
}
