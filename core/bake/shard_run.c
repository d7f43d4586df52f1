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

obs_status obs_bake_merge(const obs_bake_scene *scene, obs_bake_desc *desc,
                          const char *const *paths, size_t n, obs_bake_result *out,
                          char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    void *parts = NULL;
    obs_status rc = obs__bake_parts_read(paths, n, &obs__bake_part_format, &parts, err);
    obs__bake_part *ordered = parts;
    obs_bake_desc d = desc ? *desc : (obs_bake_desc){0};
    /* the trace parameters: the parts' (all alike), unless given, when they must agree */
    if (rc == OBS_OK)
        rc = obs__part_adopt(&obs__bake_part_format, ordered, n, &d.params, NULL, err);
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
