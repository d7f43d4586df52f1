/* obs_dyn_bake_shard and obs_dyn_bake_merge (obscura/dynamic.h):
 * level/part.h's drivers over dyn_bake.c's steps with dyn_shard.c's step
 * in place of the trace and dyn_shard.c's part format; a merge takes the
 * parts' parameters, all alike, unless given, when they must agree, and
 * its parts must split the same valid points. */
#include <stdlib.h>
#include <string.h>

#include "dynamic/dyn_internal.h"
#include "level/part.h"
#include "internal.h"

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

OBS__PART_DRIVERS(obs_dyn_bake_shard, obs_dyn_bake_merge, obs_dyn_desc, obs_dyn_result,
                  obs_dyn_stats, obs__dyn_run_job, obs_dyn_result_free, obs__dyn_part_format,
                  same_points)
