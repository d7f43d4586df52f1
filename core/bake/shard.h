/* A bake spread over many machines (shard.c): the hook of bake.c's steps
 * and the pieces the tests look at. */
#ifndef OBSCURA_BAKE_SHARD_H
#define OBSCURA_BAKE_SHARD_H

#include "bake/bake_internal.h"
#include "level/part.h"

/* A part's header as read (shard.c documents the layout). */
typedef struct obs__bake_part {
    obs__part_range r;          /* level: the traced fingerprint; items: the level's samples */
    uint64_t rays, dropped;
    int32_t rays_per_sample, seed, max_samples_per_face;
    float samples_per_face, distance_short, distance_long, backface_limit;
    double bvh_seconds, trace_seconds;
    uint64_t checksum;          /* FNV-1a 64 of the payload */
} obs__bake_part;

/* bake.c: obs_bake_run's steps with a shard's or a merge's job in place
 * of the trace (sh NULL: obs_bake_run); sh->parts are obs__bake_parts.
 * level/part.h's OBS__BAKE_ENTRY. */
obs_status obs__bake_run_job(const obs_bake_scene *scene, const obs_bake_desc *desc,
                             obs__part_job *sh, obs_bake_result *out, char err[OBS_ERR_LEN]);
/* shard.c: the step (p: the bake's resolved parameters); fills st's
 * trace rows (times, rays, samples). */
obs_status obs__bake_shard_step(obs__part_job *sh, const obs__bake_world *w,
                                obs__bake_samples *s, const obs__bake_trace_desc *td,
                                const obs_bake_params *p, obs_bake_stats *st,
                                char err[OBS_ERR_LEN]);

/* The part file's layout (shard.c): its header's fields, the bake
 * parameters they carry (obs__part_header_read reads one, with its
 * checks: magic, version, sizes, the file's length against its count). */
extern const obs__part_format obs__bake_part_format;

#endif
