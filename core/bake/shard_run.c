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
    if (count < 1 || index < 0 || index >= count)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "shard %d/%d: the index is 0 .. count-1 "
                         "(count at least 1)", index, count);
    if (!path || !*path)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "shard %d/%d: no part file to write", index, count);
    obs__bake_shard sh = {.index = index, .count = count, .path = path};
    obs_bake_params_resolve(desc ? &desc->params : NULL, &sh.params);
    obs_bake_result r;
    obs_status rc = obs__bake_run_shard(scene, desc, &sh, &r, err);
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

/* parts in shard order: every shard of one split, once (shard.c). */
static obs_status order_parts(const obs__bake_part *in, size_t n, obs__bake_part *out,
                              char err[OBS_ERR_LEN])
{
    obs__bake_part_key *keys = calloc(n, sizeof *keys);
    size_t *order = calloc(in[0].count, sizeof *order);
    obs_status rc = keys && order ? OBS_OK : obs__fail(err, OBS_NO_MEMORY, "%zu parts", n);
    for (size_t i = 0; rc == OBS_OK && i < n; i++)
        keys[i] = (obs__bake_part_key){in[i].path, in[i].index, in[i].count, in[i].level};
    if (rc == OBS_OK)
        rc = obs__bake_parts_order(keys, n, order, err);
    for (uint32_t k = 0; rc == OBS_OK && k < in[0].count; k++)
        out[k] = in[order[k]];
    free(keys);
    free(order);
    return rc;
}

obs_status obs_bake_merge(const obs_bake_scene *scene, obs_bake_desc *desc,
                          const char *const *paths, size_t n, obs_bake_result *out,
                          char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    if (n == 0 || !paths)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "merge: no parts");
    obs__bake_part *heads = calloc(n, sizeof *heads), *ordered = NULL;
    obs_status rc = heads ? OBS_OK : obs__fail(err, OBS_NO_MEMORY, "%zu parts", n);
    for (size_t i = 0; rc == OBS_OK && i < n; i++)
        rc = obs__bake_part_read_header(paths[i], &heads[i], err);
    if (rc == OBS_OK && !(ordered = calloc(heads[0].count, sizeof *ordered)))
        rc = obs__fail(err, OBS_NO_MEMORY, "%u parts", heads[0].count);
    if (rc == OBS_OK)
        rc = order_parts(heads, n, ordered, err);
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
    free(heads);
    return rc;
}
