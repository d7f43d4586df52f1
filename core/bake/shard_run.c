/* obs_bake_shard and obs_bake_merge (obscura/bake.h): level/part.h's
 * drivers over bake.c's steps with shard.c's step in place of the trace
 * and shard.c's part format; a merge takes the parts' trace parameters,
 * all alike, unless given, when they must agree.  (Apart from shard.c,
 * which bake.c calls: no two files call each other.) */
#include <stdlib.h>
#include <string.h>

#include "bake/shard.h"
#include "internal.h"

OBS__PART_DRIVERS(obs_bake_shard, obs_bake_merge, obs_bake_desc, obs_bake_result, obs_bake_stats,
                  obs__bake_run_job, obs_bake_result_free, obs__bake_part_format, NULL)
