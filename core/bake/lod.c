/* The lod stage (paper 2.2.1, Table 1's "resample LOD geometry" and
 * "least squares solve LOD"): the full-detail bake carried onto lower
 * levels of detail without tracing again.  For each level l = 1 .. lods:
 *   simplify.c  every mesh's level l (meshoptimizer), in its own space;
 *   flatten.c   the scene with every mesh at level l: instance i of that
 *               world is instance i of the full-detail one;
 *   samples.c   the LOD's surface samples, placed as the bake places its
 *               own (area-proportional, capped, the same seed);
 *   resample    each sample takes the full-detail vertex values
 *               interpolated at the nearest point of the same instance's
 *               full-detail surface (closest.c) -- where the paper shoots
 *               rays from a small sphere's boundary, we take the nearest
 *               point, a sphere shrunk to it;
 *   weld.c, fit.c  eq 2 onto the LOD's vertices, with the bake's alpha,
 *               mass and ridge: a signal linear over the surface comes
 *               back exactly (mass = samples).
 * The baseline is "sampling at the LOD's vertices": each LOD vertex takes
 * the value at its own nearest full-detail point.  With lod_check the
 * LOD's samples are also traced on the LOD geometry (eq 1, the bake's
 * rays) and fitted (eq 2): the bake made directly on the LOD, which both
 * are compared with over the LOD's samples; and both are compared with
 * the resampled values at held-out positions (never fitted). */
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bake/closest.h"
#include "bake/lod.h"
#include "bake/simplify.h"
#include "internal.h"
#include "pool.h"


void obs__bake_lods_free(obs_bake_result *out)
{
    size_t levels = out->lod_levels;
    for (size_t i = 0; out->lod_instances && i < levels * out->instance_count; i++) {
        free(out->lod_instances[i].ao);
        free(out->lod_instances[i].ao_short);
        free(out->lod_instances[i].ao_long);
    }
    free(out->lod_instances);
    out->lod_instances = NULL;
    /* lod_meshes holds levels x mesh_count meshes; the count is not kept
     * beside it, so the array ends with an all-zero mesh */
    for (obs_bake_mesh *m = out->lod_meshes; m && (m->name || m->positions); m++)
        obs__bake_mesh_free(m);
    free(out->lod_meshes);
    out->lod_meshes = NULL;
    out->lod_levels = 0;
}

/* The work of the resampling: instances taken one at a time by each
 * thread (each writes only its own instance's samples and vertices). */
typedef struct job {
    const obs__bake_world *full, *lw;
    const obs__bake_weld *fwd;
    const double *x;
    obs__bake_samples *ls;
    double *vertex;
    atomic_int failed; /* out of memory for a nearest-point search */
} job;

static size_t end_of(const obs__bake_world *w, size_t i, int tri)
{
    if (i + 1 < w->instance_count)
        return tri ? w->inst[i + 1].first_triangle : w->inst[i + 1].first_vertex;
    return tri ? w->triangle_count : w->vertex_count;
}

/* The full-detail signal at the nearest point of c's triangles to p. */
static void value_at(const job *j, const obs__bake_closest *c, const float p[3], double out[2])
{
    float b[3];
    int64_t ft;
    obs__bake_closest_query(c, p, &ft, b);
    for (int ch = 0; ch < 2; ch++) {
        double g = ft >= 0 ? 0.0 : 1.0; /* an instance of degenerate faces only */
        for (int k = 0; k < 3 && ft >= 0; k++)
            g += b[k] * j->x[2 * j->fwd->of[j->full->tri[3 * (size_t)ft + k]] + ch];
        out[ch] = g;
    }
}

static void resample_instance(job *j, size_t i)
{
    const obs__bake_inst *fi = &j->full->inst[i], *li = &j->lw->inst[i];
    size_t lend = end_of(j->lw, i, 1), vend = end_of(j->lw, i, 0);
    if (lend == li->first_triangle && vend == li->first_vertex)
        return;
    obs__bake_closest *c;
    char err[OBS_ERR_LEN];
    if (obs__bake_closest_new(j->full, fi->first_triangle,
                              end_of(j->full, i, 1) - fi->first_triangle, &c, err) != OBS_OK) {
        atomic_store(&j->failed, 1);
        return;
    }
    obs__bake_samples *ls = j->ls;
    for (size_t t = li->first_triangle; t < lend; t++)
        for (size_t k = ls->first[t]; k < ls->first[t + 1]; k++) {
            float p[3];
            double g[2];
            obs__bake_sample_pos(j->lw, ls, k, p);
            value_at(j, c, p, g);
            ls->valid[k] = 1;
            ls->ao[2 * k] = (float)g[0];
            ls->ao[2 * k + 1] = (float)g[1];
        }
    for (size_t v = li->first_vertex; j->vertex && v < vend; v++)
        value_at(j, c, j->lw->pos + 3 * v, j->vertex + 2 * v);
    obs__bake_closest_free(c);
}

static void resample_one(void *ctx, size_t i)
{
    job *j = ctx;
    if (!atomic_load(&j->failed))
        resample_instance(j, i);
}

obs_status obs__bake_lod_resample(const obs__bake_world *full, const obs__bake_weld *fwd,
                                  const double *x, const obs__bake_world *lw,
                                  obs__bake_samples *ls, double *vertex, int threads,
                                  char err[OBS_ERR_LEN])
{
    if (full->instance_count != lw->instance_count)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "LOD resampling: %zu instances at full detail, %zu in the LOD",
                         full->instance_count, lw->instance_count);
    for (size_t i = 0; i < lw->instance_count; i++)
        if (full->inst[i].node != lw->inst[i].node || full->inst[i].mesh != lw->inst[i].mesh)
            return obs__fail(err, OBS_INVALID_ARGUMENT,
                             "LOD resampling: instance %zu is not the same (node, mesh)", i);
    job j = {full, lw, fwd, x, ls, vertex};
    atomic_init(&j.failed, 0);
    obs__pool_each(lw->instance_count, 1, threads, resample_one, &j);
    if (atomic_load(&j.failed))
        return obs__fail(err, OBS_NO_MEMORY, "LOD resampling: a nearest-point search");
    ls->dropped = 0;
    return OBS_OK;
}

/* The welded LOD solution onto each instance's LOD vertices, as bake.c's
 * copy_back does for the full detail. */
static obs_status copy_level(const obs__bake_world *lw, const obs__bake_weld *lwd,
                             const double *x, float blend, obs_bake_instance *dst,
                             char err[OBS_ERR_LEN])
{
    for (size_t i = 0; i < lw->instance_count; i++) {
        size_t end = i + 1 < lw->instance_count ? lw->inst[i + 1].first_vertex : lw->vertex_count;
        size_t n = end - lw->inst[i].first_vertex;
        if (obs__bake_instance_values(&dst[i], &lw->inst[i], n, lwd->of + lw->inst[i].first_vertex,
                                      x, blend) != 0)
            return obs__fail(err, OBS_NO_MEMORY, "LOD results of %zu vertices", n);
    }
    return OBS_OK;
}

/* Per welded LOD vertex, the mean of the vertex baseline of the world
 * vertices welded into it. */
static void weld_values(const obs__bake_world *lw, const obs__bake_weld *lwd, const double *vertex,
                        double *out, double *count)
{
    memset(out, 0, 2 * lwd->count * sizeof *out);
    memset(count, 0, lwd->count * sizeof *count);
    for (size_t v = 0; v < lw->vertex_count; v++) {
        uint32_t k = lwd->of[v];
        out[2 * k] += vertex[2 * v];
        out[2 * k + 1] += vertex[2 * v + 1];
        count[k] += 1.0;
    }
    for (size_t k = 0; k < lwd->count; k++)
        if (count[k] > 0.0)
            out[2 * k] /= count[k], out[2 * k + 1] /= count[k];
}

/* One level's working state: its flattened world, samples resampled
 * from the full detail, welded vertices and the solutions over them. */
typedef struct lod_level {
    obs__bake_world lw;
    obs__bake_samples s, chk;
    obs__bake_weld lwd;
    double *vert;  /* 2 per LOD vertex: the resampled solution */
    double *solve; /* one block: the arrays below, per welded vertex */
    double *vx, *vw, *face, *point; /* 2 each: fit, vertex baseline, baselines */
    double *cnt;                    /* 1: world vertices welded into it */
    double *direct;                 /* 2, with lod_check: the direct bake */
    obs_bake_params fp; /* the fit's parameters */
} lod_level;

static void level_free(lod_level *v)
{
    free(v->vert);
    free(v->solve);
    obs__bake_weld_free(&v->lwd);
    obs__bake_samples_free(&v->chk);
    obs__bake_samples_free(&v->s);
    obs__bake_world_free(&v->lw);
}

/* Flatten level l, make its samples and resample the full detail's
 * solution x onto them and onto its vertices. */
static obs_status level_resample(const obs_bake_scene *scene, const obs__bake_world *w,
                                 const obs__bake_weld *wd, const double *x,
                                 const obs_bake_params *p, int l, obs_bake_result *out,
                                 lod_level *v, char err[OBS_ERR_LEN])
{
    obs_bake_scene ls = *scene;
    ls.meshes = out->lod_meshes + (size_t)(l - 1) * scene->mesh_count;
    obs_status rc;
    if ((rc = obs__bake_flatten(&ls, &v->lw, err)) != OBS_OK)
        return rc;
    if ((rc = obs__bake_samples_make(&v->lw, p->samples_per_face, p->max_samples_per_face,
                                     (uint64_t)p->seed, &v->s, err)) != OBS_OK)
        return rc;
    v->vert = malloc(2 * (v->lw.vertex_count ? v->lw.vertex_count : 1) * sizeof *v->vert);
    if (!v->vert)
        return obs__fail(err, OBS_NO_MEMORY, "%zu vertices", v->lw.vertex_count);
    return obs__bake_lod_resample(w, wd, x, &v->lw, &v->s, v->vert, p->threads, err);
}

/* Weld level l, fit the resampled samples (eq 2) and measure the fit and
 * the vertex baseline against them (stats row l - 1). */
static obs_status level_fit(const obs_bake_params *p, int l, lod_level *v, obs_bake_stats *st,
                            char err[OBS_ERR_LEN])
{
    obs_status rc = obs__bake_weld_make(&v->lw, p->weld_tolerance, p->weld_angle, &v->lwd, err);
    if (rc != OBS_OK)
        return rc;
    size_t n = v->lwd.count ? v->lwd.count : 1;
    v->solve = malloc((p->lod_check ? 11 : 9) * n * sizeof *v->solve);
    if (!v->solve)
        return obs__fail(err, OBS_NO_MEMORY, "solution of %zu vertices", v->lwd.count);
    v->vx = v->solve;
    v->vw = v->vx + 2 * n;
    v->face = v->vw + 2 * n;
    v->point = v->face + 2 * n;
    v->cnt = v->point + 2 * n;
    v->direct = p->lod_check ? v->cnt + n : NULL;
    v->fp = *p;
    v->fp.values = OBS_BAKE_VALUES_FIT; /* the fit itself, whatever the full detail writes */
    obs_bake_stats fst = {0};
    if ((rc = obs__bake_fit(&v->lw, &v->lwd, &v->s, &v->fp, v->vx, v->face, v->point, &fst,
                            err)) != OBS_OK)
        return rc;
    weld_values(&v->lw, &v->lwd, v->vert, v->vw, v->cnt);
    int k = l - 1;
    st->lod_triangles[k] = v->lw.triangle_count;
    st->lod_vertices[k] = v->lw.vertex_count;
    st->lod_welded[k] = v->lwd.count;
    st->lod_samples[k] = v->s.count;
    memcpy(st->lod_fit[k], fst.residual_fit, sizeof st->lod_fit[k]);
    obs__bake_residual(&v->lw, &v->lwd, &v->s, v->vw, st->lod_vertex[k]);
    return OBS_OK;
}

/* The fit and the baseline against held-out samples: other positions
 * (the holdout's seed), resampled, never fitted. */
static obs_status check_holdout(const obs__bake_world *w, const obs__bake_weld *wd,
                                const double *x, const obs_bake_params *p, int k, lod_level *v,
                                obs_bake_stats *st, char err[OBS_ERR_LEN])
{
    obs__bake_samples h;
    uint64_t hseed = (uint64_t)p->seed ^ 0x5bd1e995u;
    obs_status rc = obs__bake_samples_make(&v->lw, p->samples_per_face, p->max_samples_per_face,
                                           hseed, &h, err);
    if (rc != OBS_OK)
        return rc;
    if ((rc = obs__bake_lod_resample(w, wd, x, &v->lw, &h, NULL, p->threads, err)) == OBS_OK) {
        obs__bake_residual(&v->lw, &v->lwd, &h, v->vx, st->lod_holdout_fit[k]);
        obs__bake_residual(&v->lw, &v->lwd, &h, v->vw, st->lod_holdout_vertex[k]);
    }
    obs__bake_samples_free(&h);
    return rc;
}

/* The comparisons over the LOD's samples, against the direct bake's
 * signal: the resampled fit, the vertex baseline, and the resampled
 * values themselves. */
static void check_traced(lod_level *v, int k, obs_bake_stats *st)
{
    obs__bake_samples *chk = &v->chk;
    for (size_t i = 0; i < chk->count; i++) {
        const uint32_t *tv = v->lw.tri + 3 * chk->tri[i];
        const float *b = chk->bary + 3 * i;
        for (int c = 0; c < 2; c++) {
            double g = 0.0;
            for (int j = 0; j < 3; j++)
                g += b[j] * v->direct[2 * v->lwd.of[tv[j]] + c];
            chk->ao[2 * i + c] = (float)g;
        }
        chk->valid[i] = 1;
    }
    obs__bake_residual(&v->lw, &v->lwd, chk, v->vx, st->lod_traced_fit[k]);
    obs__bake_residual(&v->lw, &v->lwd, chk, v->vw, st->lod_traced_vertex[k]);
    double e[2] = {0, 0}, ws = 0.0;
    for (size_t i = 0; i < chk->count; i++) {
        for (int c = 0; c < 2; c++) {
            double r = (double)v->s.ao[2 * i + c] - chk->ao[2 * i + c];
            e[c] += chk->weight[i] * r * r;
        }
        ws += chk->weight[i];
    }
    for (int c = 0; c < 2; c++)
        st->lod_traced_resampled[k][c] = ws > 0.0 ? sqrt(e[c] / ws) : 0.0;
    st->lod_traced_samples[k] = chk->count - chk->dropped;
}

/* lod_check: level l's resampled bake against held-out samples and
 * against a bake traced directly on the LOD geometry. */
static obs_status level_check(const obs__bake_world *w, const obs__bake_weld *wd,
                              const double *x, const obs_bake_params *p, int l, lod_level *v,
                              obs_bake_stats *st, char err[OBS_ERR_LEN])
{
    int k = l - 1;
    obs_status rc;
    if ((rc = check_holdout(w, wd, x, p, k, v, st, err)) != OBS_OK)
        return rc;
    /* the same samples (same seed), traced on the LOD geometry */
    if ((rc = obs__bake_samples_make(&v->lw, p->samples_per_face, p->max_samples_per_face,
                                     (uint64_t)p->seed, &v->chk, err)) != OBS_OK)
        return rc;
    obs__bake_trace_desc td = {{p->distance_short, p->distance_long}, p->rays, p->threads,
                               p->backface_limit, (uint64_t)p->seed, NULL, NULL};
    double bvh;
    if ((rc = obs__bake_trace(&v->lw, &v->chk, &td, &bvh, err)) != OBS_OK)
        return rc;
    /* the direct bake: the traced samples fitted (eq 2) */
    obs_bake_stats dst = {0};
    if ((rc = obs__bake_fit(&v->lw, &v->lwd, &v->chk, &v->fp, v->direct, v->face, v->point, &dst,
                            err)) != OBS_OK)
        return rc;
    memcpy(st->lod_direct_residual[k], dst.residual_fit, sizeof st->lod_direct_residual[k]);
    check_traced(v, k, st);
    return OBS_OK;
}

/* One level: flatten, samples, resample, weld, fit, (check), values. */
static obs_status level(const obs_bake_scene *scene, const obs__bake_world *w,
                        const obs__bake_weld *wd, const double *x, const obs_bake_params *p,
                        int l, obs_bake_result *out, char err[OBS_ERR_LEN])
{
    obs_bake_stats *st = &out->stats;
    lod_level v = {0};
    double t = obs__bake_now();
    obs_status rc = level_resample(scene, w, wd, x, p, l, out, &v, err);
    if (rc != OBS_OK)
        goto done;
    st->lod_seconds[1] += obs__bake_now() - t;
    t = obs__bake_now();
    if ((rc = level_fit(p, l, &v, st, err)) != OBS_OK)
        goto done;
    st->lod_seconds[2] += obs__bake_now() - t;
    if (p->lod_check) {
        t = obs__bake_now();
        if ((rc = level_check(w, wd, x, p, l, &v, st, err)) != OBS_OK)
            goto done;
        st->lod_seconds[3] += obs__bake_now() - t;
    }
    rc = copy_level(&v.lw, &v.lwd, v.vx, p->blend,
                    out->lod_instances + (size_t)(l - 1) * out->instance_count, err);
done:
    level_free(&v);
    return rc;
}

static obs_status mesh_copy(const obs_bake_mesh *a, obs_bake_mesh *b, char err[OBS_ERR_LEN])
{
    *b = *a;
    size_t nv = a->vertex_count, ni = 3 * a->triangle_count;
    b->name = strdup(a->name ? a->name : "");
    b->positions = malloc(3 * (nv ? nv : 1) * sizeof(float));
    b->normals = a->normals ? malloc(3 * (nv ? nv : 1) * sizeof(float)) : NULL;
    b->indices = malloc((ni ? ni : 1) * sizeof(uint32_t));
    if (!b->name || !b->positions || (a->normals && !b->normals) || !b->indices) {
        obs__bake_mesh_free(b);
        return obs__fail(err, OBS_NO_MEMORY, "LOD '%s': %zu vertices", a->name, nv);
    }
    memcpy(b->positions, a->positions, 3 * nv * sizeof(float));
    if (a->normals)
        memcpy(b->normals, a->normals, 3 * nv * sizeof(float));
    memcpy(b->indices, a->indices, ni * sizeof(uint32_t));
    return OBS_OK;
}

obs_status obs__bake_lods(const obs_bake_scene *scene, const obs__bake_world *w,
                          const obs__bake_weld *wd, const double *x, const obs_bake_params *p,
                          obs_bake_result *out, char err[OBS_ERR_LEN])
{
    int levels = p->lods;
    if (levels <= 0)
        return OBS_OK;
    if (levels > OBS_BAKE_MAX_LODS)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "lods %d: at most %d", levels,
                         OBS_BAKE_MAX_LODS);
    double t0 = obs__bake_now(), t = t0;
    size_t nm = scene->mesh_count;
    out->lod_meshes = calloc((size_t)levels * nm + 1, sizeof *out->lod_meshes);
    out->lod_instances = calloc((size_t)levels * out->instance_count + 1,
                                sizeof *out->lod_instances);
    if (!out->lod_meshes || !out->lod_instances) {
        obs__bake_lods_free(out);
        return obs__fail(err, OBS_NO_MEMORY, "%d LODs of %zu meshes", levels, nm);
    }
    out->lod_levels = (size_t)levels;
    out->stats.lod_levels = (size_t)levels;
    int from_file = p->lod_source != OBS_BAKE_LOD_SOURCE_SIMPLIFY;
    if (from_file && scene->file_lod_error) {
        obs__bake_lods_free(out);
        return obs__fail(err, OBS_BAD_FILE,
                         "%s (with lod_source simplify the file's LODs are not read)",
                         scene->file_lod_error);
    }
    obs_status rc = OBS_OK;
    for (int l = 1; l <= levels && rc == OBS_OK; l++)
        for (size_t m = 0; m < nm && rc == OBS_OK; m++) {
            size_t c = (size_t)(l - 1) * nm + m;
            const obs_bake_mesh *fl = from_file && (size_t)l <= scene->file_lod_levels
                                          ? &scene->file_lods[c]
                                          : NULL;
            if (fl && fl->triangle_count) { /* the file's own level */
                rc = mesh_copy(fl, &out->lod_meshes[c], err);
                out->stats.lod_file_meshes[l - 1]++;
            } else {
                rc = obs__bake_simplify(&scene->meshes[m], l, p->lod_ratio, p->lod_error,
                                        p->lod_lock_border, p->weld_tolerance, p->weld_angle,
                                        &out->lod_meshes[c], err);
                /* each level starts from the full mesh, so a simplifier
                 * held back (a locked border) can stop above the level
                 * before; a level never has more triangles than that one:
                 * it takes its geometry then */
                obs_bake_mesh *lm = &out->lod_meshes[c], *up = l > 1 ? lm - nm : NULL;
                if (rc == OBS_OK && up && lm->triangle_count > up->triangle_count) {
                    char *name = lm->name;
                    lm->name = NULL;
                    obs__bake_mesh_free(lm);
                    rc = mesh_copy(up, lm, err);
                    free(lm->name);
                    lm->name = name;
                }
            }
        }
    out->stats.lod_seconds[0] = obs__bake_now() - t;
    for (int l = 1; l <= levels && rc == OBS_OK; l++)
        if ((rc = level(scene, w, wd, x, p, l, out, err)) != OBS_OK) {
            char why[OBS_ERR_LEN];
            memcpy(why, err, sizeof why);
            snprintf(err, OBS_ERR_LEN, "LOD level %d: %.*s", l, OBS_ERR_LEN - 20, why);
        }
    out->stats.seconds[OBS_BAKE_STAGE_lod] = obs__bake_now() - t0;
    return rc;
}
