/* The dynamic-object bake's steps in order (obscura/dynamic.h), each
 * timed: flatten, BVH, regions, valid points, spherical obscurance, the
 * fit.
 *
 * The BVH holds the static bake's occluders (section 2.1, occl.c): the
 * level's nodes are classified as obscura bake classifies them (decor.c:
 * the same parameter rows, the same --decorators file), shrubs become
 * fog boxes and trees semi-transparent triangles of the second BVH, small
 * decorators occlude nothing.  Per use:
 *   - a valid point's spherical obscurance (dyn_probes.c, obs__point_sh)
 *     and the probe paths' eq 1 reference (obs__dyn_trace_eq1): rho
 *     times each ray's transmittance, the quantity of the static bake's
 *     surface samples, so that obscura gbuffer --dynamic combines like
 *     with like;
 *   - the solid tests (obs__dyn_inside: inside geometry by back faces;
 *     obs__bake_bvh_occluded: behind a wall; the regions' test of an
 *     empty box): the opaque BVH alone.  Decorators are not solid: tree
 *     and shrub triangles are not in it, so a point in a canopy or a
 *     hedge is outside geometry and a tree hides nothing behind it.
 * decorator_source off: every triangle opaque, the bytes of the bake
 * before decorators. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "level/decor.h"
#include "dynamic/dyn_internal.h"
#include "level/part.h"
#include "internal.h"

void obs_dyn_result_free(obs_dyn_result *r)
{
    if (!r)
        return;
    obs_dyn_model_free(&r->model);
    obs_dyn_model_free(&r->original);
    memset(r, 0, sizeof *r);
}

/* The dynamic rows' values into bake parameters (the same names; set,
 * so that a given 0 stays 0). */
static void decor_params(const obs_dyn_params *p, obs_bake_params *bp)
{
    static const char *const names[] = {"decorator_source", "shrub_density",
                                        "tree_attenuation"};
    memset(bp, 0, sizeof *bp);
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        const obs_bake_param_info *b = obs_bake_param_find(names[i]),
                                  *d = obs_dyn_param_find(names[i]);
        /* both int or float fields of 4 bytes: the tables share the rows */
        memcpy((char *)bp + b->offset, (const char *)p + d->offset, 4);
        bp->set |= (uint64_t)1 << (b - obs_bake_param_at(0));
    }
}

obs_status obs__dyn_occluders(const obs_bake_scene *scene, const obs__bake_world *w,
                              const obs_dyn_params *p, const char *decorators_json,
                              obs__bake_decor *dc, obs__bake_bvh **bvh,
                              char warning[OBS_ERR_LEN], char err[OBS_ERR_LEN])
{
    obs_bake_params bp;
    decor_params(p, &bp);
    *bvh = NULL;
    obs_status rc = obs__bake_decor_classify_warn(scene, &bp, decorators_json, dc, warning, err);
    if (rc != OBS_OK)
        return rc;
    return obs__bake_bvh_new_decor(w, dc, p->tree_attenuation, bvh, err);
}

/* The steps; with a shard (dyn_shard.c) its step takes the trace's
 * place: one shard's points traced and written (the bake stops there),
 * or every shard's read back. */
static obs_status steps(const obs_bake_scene *scene, const obs_dyn_desc *desc,
                        const obs_dyn_params *p, obs__part_job *sh, obs_dyn_result *out,
                        char err[OBS_ERR_LEN])
{
    obs_dyn_stats *st = &out->stats;
    obs__bake_world w = {0};
    obs__bake_bvh *bvh = NULL;
    obs__bake_decor dc = {0};
    obs_dyn_regions own = {0};
    const obs_dyn_regions *rg = desc ? desc->regions : NULL;
    obs__dyn_points pt = {0};
    obs_status rc;
    double t = obs__bake_now();
    if ((rc = obs__bake_flatten_checked(scene, p->max_triangles, "bake-dynamic", &w, err)) != OBS_OK)
        goto done;
    st->seconds[OBS_DYN_STAGE_flatten] = obs__bake_now() - t;
    t = obs__bake_now();
    if ((rc = obs__dyn_occluders(scene, &w, p, desc ? desc->decorators_json : NULL, &dc, &bvh,
                                 st->decorator_warning, err)) != OBS_OK)
        goto done;
    memcpy(st->decorator_nodes, dc.counts, sizeof dc.counts);
    st->seconds[OBS_DYN_STAGE_bvh] = obs__bake_now() - t;
    t = obs__bake_now();
    if (!rg) {
        if ((rc = obs__dyn_regions_build(&w, bvh, p, &own, err)) != OBS_OK)
            goto done;
        rg = &own;
    }
    st->regions = rg->count;
    st->edges = rg->edge_count;
    st->seconds[OBS_DYN_STAGE_regions] = obs__bake_now() - t;
    t = obs__bake_now();
    if ((rc = obs__dyn_points_flag(bvh, rg, p, &pt, err)) != OBS_OK)
        goto done;
    st->seconds[OBS_DYN_STAGE_valid] = obs__bake_now() - t;
    t = obs__bake_now();
    if (sh) {
        if ((rc = obs__dyn_shard_step(sh, desc,
                                      obs__bake_traced_fingerprint(&w, &dc, p->tree_attenuation),
                                      rg, p, bvh, &pt, st, err)) != OBS_OK || sh->stop)
            goto done;
    } else {
        obs__dyn_points_trace(bvh, p, &pt, 0, pt.count, desc ? desc->progress : NULL,
                              desc ? desc->progress_user : NULL);
        st->seconds[OBS_DYN_STAGE_trace] = obs__bake_now() - t;
    }
    if ((rc = obs__dyn_points_compact(&pt, err)) != OBS_OK)
        goto done;
    st->grid_points = pt.grid;
    st->points_inside = pt.inside;
    st->points_hidden = pt.hidden;
    st->points_backface = pt.backface;
    st->points_valid = pt.count;
    st->rays = pt.rays;
    t = obs__bake_now();
    if ((rc = obs__dyn_fit_all(&pt, rg, p, out, err)) != OBS_OK)
        goto done;
    st->seconds[OBS_DYN_STAGE_fit] = obs__bake_now() - t;
    out->model.level = out->original.level = obs__dyn_level_of(&w);
done:
    obs__dyn_points_free(&pt);
    obs_dyn_regions_free(&own);
    obs__bake_bvh_free(bvh);
    obs__bake_decor_free(&dc);
    obs__bake_world_free(&w);
    return rc;
}

/* obs_dyn_stage_name, obs_dyn_bake and obs__dyn_run_job (the steps with
 * a shard's or a merge's job, dyn_shard_run.c's), level/part.h's. */
OBS__BAKE_ENTRY(dyn, DYN, obs_dyn_bake, steps)
