/* obs_dyn_bake_shard and obs_dyn_bake_merge (obscura/dynamic.h): the
 * checks of a merge's parts against each other and its parameters, then
 * dynamic.c's steps with dyn_shard.c's step in place of the trace. */
#include <stdlib.h>
#include <string.h>

#include "dynamic/dyn_internal.h"
#include "level/part.h"
#include "internal.h"

obs_status obs_dyn_bake_shard(const obs_bake_scene *scene, const obs_dyn_desc *desc, int index,
                              int count, const char *path, obs_dyn_stats *st,
                              char err[OBS_ERR_LEN])
{
    if (st)
        memset(st, 0, sizeof *st);
    obs_status rc = obs__shard_check(index, count, path, err);
    if (rc != OBS_OK)
        return rc;
    obs__dyn_shard sh = {.index = index, .count = count, .path = path,
                         .progress = desc ? desc->progress : NULL,
                         .progress_user = desc ? desc->progress_user : NULL};
    obs_dyn_result r;
    rc = obs__dyn_bake_run(scene, desc, &sh, &r, err);
    if (st)
        *st = r.stats;
    obs_dyn_result_free(&r);
    return rc;
}

/* Parts of one bake also split the same valid points of the same regions. */
static obs_status same_points(const void *pa, const void *pb, char err[OBS_ERR_LEN])
{
    const obs__dyn_part *a = pa, *b = pb;
    if (a->points != b->points || a->r.total != b->r.total)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s and %s were traced over different "
                         "regions or valid points (%llu and %llu points): they are not parts "
                         "of one bake", a->r.path, b->r.path, (unsigned long long)a->r.total,
                         (unsigned long long)b->r.total);
    return OBS_OK;
}

obs_status obs_dyn_bake_merge(const obs_bake_scene *scene, obs_dyn_desc *desc,
                              const char *const *paths, size_t n, obs_dyn_result *out,
                              char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    void *parts = NULL;
    obs_status rc = obs__bake_parts_read(paths, n, &obs__dyn_part_format, &parts, err);
    obs__dyn_part *ordered = parts;
    obs_dyn_desc d = desc ? *desc : (obs_dyn_desc){0};
    /* the parameters: the parts' (all alike), unless given, when they must agree */
    if (rc == OBS_OK)
        rc = obs__part_adopt(&obs__dyn_part_format, ordered, n, &d.params, same_points, err);
    if (rc == OBS_OK) {
        obs__dyn_shard sh = {.index = 0, .count = (int)n, .parts = ordered};
        rc = obs__dyn_bake_run(scene, &d, &sh, out, err);
        if (desc)
            desc->params = d.params;
    }
    free(ordered);
    return rc;
}
