/* obs_bake_shard and obs_bake_merge (obscura/bake.h): the checks of a
 * merge's parts against each other and its parameters, then bake.c's
 * steps with shard.c's step in place of the trace.  (Apart from shard.c,
 * which bake.c calls: no two files call each other.) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/shard.h"
#include "internal.h"

obs_status obs_bake_shard(const obs_bake_scene *scene, const obs_bake_desc *desc, int index,
                          int count, const char *path, obs_bake_stats *st, char err[OBS_ERR_LEN])
{
    if (st)
        memset(st, 0, sizeof *st);
    obs_status rc = obs__shard_check(index, count, path, err);
    if (rc != OBS_OK)
        return rc;
    obs__bake_shard sh = {.index = index, .count = count, .path = path};
    obs_bake_params_resolve(desc ? &desc->params : NULL, &sh.params);
    obs_bake_result r;
    rc = obs__bake_run_shard(scene, desc, &sh, &r, err);
    if (st)
        *st = r.stats;
    obs_bake_result_free(&r);
    return rc;
}

/* The trace parameters a part carries: name, and whether it agrees. */
#define TRACE_PARAMS(X)                                                         \
    X(rays, rays_per_sample, INT)                                               \
    X(seed, seed, INT)                                                          \
    X(max_samples_per_face, max_samples_per_face, INT)                          \
    X(samples_per_face, samples_per_face, FLOAT)                                \
    X(distance_short, distance_short, FLOAT)                                    \
    X(distance_long, distance_long, FLOAT)                                      \
    X(backface_limit, backface_limit, FLOAT)

static int row_of(const char *name)
{
    const obs_bake_param_info *pi = obs_bake_param_find(name);
    return pi ? (int)(pi - obs_bake_param_at(0)) : -1;
}

/* The merge's parameters: those of the trace the parts' (all alike),
 * unless given, when they must agree. */
static obs_status adopt(obs_bake_params *p, const obs__bake_part *parts, size_t n, char err[OBS_ERR_LEN])
{
    const obs__bake_part *a = &parts[0];
    for (size_t i = 1; i < n; i++) {
        const obs__bake_part *b = &parts[i];
#define SAME(name, field, type) OBS__PART_SAME(a, b, name, field)
        TRACE_PARAMS(SAME)
#undef SAME
    }
#define TAKE(name, field, type) OBS__PART_TAKE(p, a, row_of(#name), name, field)
    TRACE_PARAMS(TAKE)
#undef TAKE
    return OBS_OK;
}

/* A part's header (level/part.h reads every part through it). */
static obs_status read_header(const char *path, void *h, char err[OBS_ERR_LEN])
{
    return obs__bake_part_read_header(path, h, err);
}

obs_status obs_bake_merge(const obs_bake_scene *scene, obs_bake_desc *desc,
                          const char *const *paths, size_t n, obs_bake_result *out,
                          char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    void *parts = NULL;
    obs_status rc = obs__bake_parts_read(paths, n, sizeof(obs__bake_part), read_header, &parts,
                                         err);
    obs__bake_part *ordered = parts;
    obs_bake_desc d = desc ? *desc : (obs_bake_desc){0};
    if (rc == OBS_OK)
        rc = adopt(&d.params, ordered, n, err);
    if (rc == OBS_OK) {
        obs__bake_shard sh = {.index = 0, .count = (int)n, .parts = ordered};
        obs_bake_params_resolve(&d.params, &sh.params);
        rc = obs__bake_run_shard(scene, &d, &sh, out, err);
        if (desc)
            desc->params = d.params;
    }
    free(ordered);
    return rc;
}
