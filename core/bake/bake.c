/* The bake's steps in order (obscura/bake.h), each timed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bake/bake_internal.h"
#include "level/decor.h"
#include "bake/instanced.h"
#include "bake/lod.h"
#include "bake/shard.h"
#include "internal.h"

void obs_bake_result_free(obs_bake_result *r)
{
    if (!r)
        return;
    for (size_t i = 0; i < r->instance_count && r->instances; i++) {
        free(r->instances[i].ao);
        free(r->instances[i].ao_short);
        free(r->instances[i].ao_long);
        free(r->instances[i].ao_local);
    }
    free(r->instances);
    obs__bake_lods_free(r);
    free(r->node_ao);
    memset(r, 0, sizeof *r);
}

/* The welded solution copied back to every instance's own vertices. */
static obs_status copy_back(const obs_bake_scene *scene, const obs__bake_world *w,
                            const obs__bake_weld *wd, const double *x, float blend,
                            obs_bake_result *out, char err[OBS_ERR_LEN])
{
    out->instances = calloc(w->instance_count, sizeof *out->instances);
    if (!out->instances)
        return obs__fail(err, OBS_NO_MEMORY, "%zu instances", w->instance_count);
    out->instance_count = w->instance_count;
    double sum = 0.0, lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < w->instance_count; i++) {
        obs_bake_instance *r = &out->instances[i];
        const obs__bake_inst *in = &w->inst[i];
        size_t n = scene->meshes[in->mesh].vertex_count;
        if (obs__bake_instance_values(r, in, n, wd->of + in->first_vertex, x, blend) != 0)
            return obs__fail(err, OBS_NO_MEMORY, "results of %zu vertices", n);
        for (size_t v = 0; v < n; v++) {
            sum += r->ao[v];
            lo = fmin(lo, r->ao[v]);
            hi = fmax(hi, r->ao[v]);
        }
    }
    out->stats.ao_mean = w->vertex_count ? sum / (double)w->vertex_count : 0.0;
    out->stats.ao_min = lo;
    out->stats.ao_max = hi;
    return OBS_OK;
}

/* The values of the instances sel (the instanced decorators, instanced.c:
 * local x global, section 2.2; the small decorators' scalars, small.c)
 * written into the welded solution in place of the fit's, so that the
 * LODs (lod.c) resample what the .glb holds. */
static void results_into_solution(const obs_bake_scene *scene, const obs__bake_world *w,
                                    const obs__bake_weld *wd, const uint8_t *sel,
                                    const obs_bake_result *out, double *x)
{
    for (size_t i = 0; i < w->instance_count; i++) {
        if (!sel[i])
            continue;
        const obs__bake_inst *in = &w->inst[i];
        size_t n = scene->meshes[in->mesh].vertex_count;
        for (size_t v = 0; v < n; v++) {
            uint32_t k = wd->of[in->first_vertex + v];
            x[2 * k] = out->instances[i].ao_short[v];
            x[2 * k + 1] = out->instances[i].ao_long[v];
        }
    }
}

/* The local AO of mesh m, baked alone in its own space (steps 2-4 of the
 * pipeline on a scene of that one mesh, a tree): 2 per vertex, short and
 * long. */
static obs_status local_ao(const obs_bake_scene *s, uint32_t m, const obs_bake_params *p,
                           double *out, char err[OBS_ERR_LEN])
{
    obs_bake_node node = {0};
    uint32_t zero = 0;
    node.name = (char *)"local";
    node.parent = -1;
    for (int i = 0; i < 16; i++)
        node.local[i] = node.world[i] = i % 5 == 0 ? 1.0f : 0.0f;
    node.meshes = &zero;
    node.mesh_count = 1;
    obs_bake_scene one = {0};
    one.meshes = &s->meshes[m];
    one.mesh_count = 1;
    one.materials = s->materials;
    one.material_count = s->material_count;
    one.nodes = &node;
    one.node_count = 1;
    one.instance_count = 1;
    one.world_triangles = s->meshes[m].triangle_count;
    obs_bake_desc d = {0};
    d.params = *p;
    d.params.instanced = OBS_BAKE_INSTANCED_OFF;
    /* the mesh occludes itself as a tree occludes in the level (section
     * 2.1: semi-transparent), as the volume's f sees it (instanced.c) */
    d.params.decorator_source = OBS_BAKE_DECOR_FILE;
    d.decorators_json = "{\"decorators\": [{\"name\": \"local\", \"class\": \"tree\"}]}";
    d.params.holdout = 0.0f;
    d.params.set = ~(uint64_t)0; /* every field as given here */
    obs_bake_result r;
    obs_status rc = obs_bake_run(&one, &d, &r, err);
    if (rc != OBS_OK)
        return rc;
    size_t n = s->meshes[m].vertex_count;
    for (size_t v = 0; v < n; v++) {
        out[2 * v] = r.instances[0].ao_short[v];
        out[2 * v + 1] = r.instances[0].ao_long[v];
    }
    obs_bake_result_free(&r);
    return OBS_OK;
}

/* Held-out samples (parameter holdout): another seed places them and
 * draws their rays; the fit and the baselines are compared with them. */
static obs_status holdout(const obs__bake_world *w, const obs__bake_weld *wd,
                          const obs__bake_decor *dc, const obs_bake_params *p, const double *x, const double *face,
                          const double *point, obs_bake_stats *st, char err[OBS_ERR_LEN])
{
    obs__bake_samples h;
    uint64_t seed = (uint64_t)p->seed ^ 0x5bd1e995u;
    obs_status rc = obs__bake_samples_make(w, p->holdout, p->max_samples_per_face, seed, &h, err);
    if (rc != OBS_OK)
        return rc;
    obs__bake_trace_desc td = {{p->distance_short, p->distance_long}, p->rays, p->threads,
                               p->backface_limit, seed, NULL, NULL};
    td.decor = dc;
    td.tree_attenuation = p->tree_attenuation;
    double bvh;
    if ((rc = obs__bake_trace(w, &h, &td, &bvh, err)) == OBS_OK) {
        obs__bake_residual(w, wd, &h, x, st->holdout_fit);
        obs__bake_residual(w, wd, &h, face, st->holdout_face_mean);
        obs__bake_residual(w, wd, &h, point, st->holdout_point);
        st->holdout_samples = h.count - h.dropped;
    }
    obs__bake_samples_free(&h);
    return rc;
}

/* The steps; with a shard (shard.c) the trace is its step instead: one
 * shard's samples traced and written (then the bake stops there), or
 * every shard's read back. */
/* The level in world space, its stats, the decorators (section 2.2:
 * which nodes are shrubs, trees, small) and the large instanced ones
 * (instanced.c: sel, their count in *inst_n) masked out of the surface
 * samples; area_kept: the faces' areas before the mask, for the LODs
 * (NULL when not needed). */
static obs_status flatten_stage(const obs_bake_scene *scene, const obs_bake_desc *desc,
                                const obs_bake_params *p, obs__bake_world *w,
                                obs__bake_decor *dc, uint8_t **sel, size_t *inst_n,
                                float **area_kept, obs_bake_stats *st, char err[OBS_ERR_LEN])
{
    obs_status rc;
    if ((rc = obs__bake_flatten_checked(scene, p->max_triangles, "bake", w, err)) != OBS_OK)
        return rc;
    st->instances = w->instance_count;
    st->triangles = w->triangle_count;
    st->vertices = w->vertex_count;
    st->degenerate_triangles = w->degenerate;
    st->faces_against_normals = w->against_normals;
    for (size_t k = 0; k < w->triangle_count; k++)
        st->two_sided_triangles += w->two_sided[k];
    if ((rc = obs__bake_decor_classify_warn(scene, p, desc ? desc->decorators_json : NULL, dc,
                                            st->decorator_warning, err)) != OBS_OK)
        return rc;
    memcpy(st->decorator_nodes, dc->counts, sizeof dc->counts);
    /* Large instanced decorators (section 2.2, instanced.c): no surface
     * samples of their own in the level. */
    if (!(*sel = malloc(w->instance_count ? w->instance_count : 1)))
        return obs__fail(err, OBS_NO_MEMORY, "%zu instances", w->instance_count);
    if ((*inst_n = obs__bake_instanced_select(scene, w, dc, p, *sel))) {
        /* the LODs resample the instanced faces' final values at their
         * nearest points (lod.c), which needs their areas */
        if (p->lods && w->triangle_count) {
            if (!(*area_kept = malloc(w->triangle_count * sizeof **area_kept)))
                return obs__fail(err, OBS_NO_MEMORY, "%zu triangles", w->triangle_count);
            memcpy(*area_kept, w->area, w->triangle_count * sizeof **area_kept);
        }
        obs__bake_instanced_mask(w, *sel);
    }
    return OBS_OK;
}

/* Eq 1 at every sample (trace.c), or, for a shard or a merge, shard.c's
 * step in its place; t: when the stage began. */
static obs_status trace_stage(const obs_bake_desc *desc, const obs_bake_params *p,
                              const obs__bake_decor *dc, obs__part_job *sh,
                              const obs__bake_world *w, obs__bake_samples *s, double t,
                              obs_bake_stats *st, char err[OBS_ERR_LEN])
{
    obs_status rc;
    obs__bake_trace_desc td = {{p->distance_short, p->distance_long}, p->rays, p->threads,
                               p->backface_limit, (uint64_t)p->seed,
                               desc ? desc->progress : NULL, desc ? desc->progress_user : NULL};
    td.decor = dc;
    td.tree_attenuation = p->tree_attenuation;
    double bvh = 0.0;
    if (sh) {
        if ((rc = obs__bake_shard_step(sh, w, s, &td, p, st, err)) != OBS_OK)
            return rc;
    } else {
        if ((rc = obs__bake_trace(w, s, &td, &bvh, err)) != OBS_OK)
            return rc;
        st->seconds[OBS_BAKE_STAGE_bvh] = bvh;
        st->seconds[OBS_BAKE_STAGE_trace] = obs__bake_now() - t - bvh;
    }
    st->rays = s->rays;
    st->samples_dropped_backface = s->dropped;
    return OBS_OK;
}

static obs_status steps(const obs_bake_scene *scene, const obs_bake_desc *desc,
                        const obs_bake_params *p, obs__part_job *sh, obs_bake_result *out,
                        char err[OBS_ERR_LEN])
{
    obs_bake_stats *st = &out->stats;
    obs__bake_world w = {0};
    obs__bake_samples s = {0};
    obs__bake_weld wd = {0};
    obs__bake_decor dc = {0};
    double *x = NULL, *face = NULL, *point = NULL;
    uint8_t *inst_sel = NULL;
    float *area_kept = NULL; /* the faces' areas before the mask, for the LODs */
    size_t inst_n = 0;
    obs_status rc;
    double t = obs__bake_now();
    if ((rc = flatten_stage(scene, desc, p, &w, &dc, &inst_sel, &inst_n, &area_kept, st, err)) !=
        OBS_OK)
        goto done;
    st->seconds[OBS_BAKE_STAGE_flatten] = obs__bake_now() - t;

    t = obs__bake_now();
    if ((rc = obs__bake_samples_make(&w, p->samples_per_face, p->max_samples_per_face,
                                     (uint64_t)p->seed, &s, err)) != OBS_OK)
        goto done;
    st->samples = s.count;
    st->seconds[OBS_BAKE_STAGE_samples] = obs__bake_now() - t;

    t = obs__bake_now();
    if ((rc = trace_stage(desc, p, &dc, sh, &w, &s, t, st, err)) != OBS_OK)
        goto done;
    if (sh && sh->stop) /* a shard: its part is written; the merge fits */
        goto done;

    t = obs__bake_now();
    if ((rc = obs__bake_weld_make(&w, p->weld_tolerance, p->weld_angle, &wd, err)) != OBS_OK)
        goto done;
    st->welded_vertices = wd.count;
    st->seconds[OBS_BAKE_STAGE_weld] = obs__bake_now() - t;

    size_t nx = 2 * (wd.count ? wd.count : 1);
    x = malloc(nx * sizeof *x);
    face = malloc(nx * sizeof *face);
    point = malloc(nx * sizeof *point);
    if (!x || !face || !point) {
        rc = obs__fail(err, OBS_NO_MEMORY, "solution of %zu vertices", wd.count);
        goto done;
    }
    if ((rc = obs__bake_fit(&w, &wd, &s, p, x, face, point, st, err)) != OBS_OK)
        goto done;
    if (inst_n)
        obs__bake_instanced_uncount(&w, &wd, inst_sel, st);
    if (p->holdout > 0.0f && (rc = holdout(&w, &wd, &dc, p, x, face, point, st, err)) != OBS_OK)
        goto done;
    if ((rc = copy_back(scene, &w, &wd, x, p->blend, out, err)) != OBS_OK)
        goto done;
    if (inst_n) {
        rc = obs__bake_instanced_run(scene, &w, inst_sel, p, desc, s.count, &dc, local_ao, out,
                                     err);
        if (rc == OBS_OK)
            results_into_solution(scene, &w, &wd, inst_sel, out, x);
        if (area_kept)
            memcpy(w.area, area_kept, w.triangle_count * sizeof *area_kept);
        if (rc != OBS_OK)
            goto done;
    }
    if ((rc = obs__bake_small(scene, &w, wd.of, &dc, x, p, out, err)) != OBS_OK)
        goto done;
    if (out->node_ao && p->lods) { /* the small decorators' scalars, for the LODs too */
        for (size_t i = 0; i < w.instance_count; i++) /* NaN: not one, or unresolved */
            inst_sel[i] = !isnan(out->node_ao[3 * w.inst[i].node]);
        results_into_solution(scene, &w, &wd, inst_sel, out, x);
    }
    rc = obs__bake_lods(scene, &w, &wd, x, p, out, err); /* lod.c, paper 2.2.1 */
done:
    free(area_kept);
    free(inst_sel);
    free(x);
    free(face);
    free(point);
    obs__bake_weld_free(&wd);
    obs__bake_decor_free(&dc);
    obs__bake_samples_free(&s);
    obs__bake_world_free(&w);
    return rc;
}

/* obs_bake_stage_name, obs_bake_run and obs__bake_run_job (the steps
 * with a shard's or a merge's job, shard_run.c's), level/part.h's. */
OBS__BAKE_ENTRY(bake, BAKE, obs_bake_run, steps)
