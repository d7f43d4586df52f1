/* bake-dynamic spread over many machines (obscura bake-dynamic --shard
 * I/N, --merge).  The expensive step is the spherical obscurance of the
 * regions' valid points (dyn_probes.c); every shard builds the same regions
 * and flags the same grid points (cheap: 32 rays a point), then traces
 * its contiguous range [i n / count, (i + 1) n / count) of the n valid
 * points, each with the directions of the unsharded bake (keyed by the
 * seed and the point's grid index alone), and writes them as a part.
 * The merge flags the points again, reads every part into them, and fits:
 * the merged model is the unsharded one, byte for byte.  The part file
 * follows the bake's parts (bake/shard.c) and uses their pieces (level/part.h).
 *
 * A part file, every field little-endian:
 *
 *   offset size  field
 *     0     8    magic "OBSDYNPT"
 *     8     4    u32 version (1)
 *    12     4    u32 header size in bytes (128)
 *    16     8    u64 level fingerprint (level/part.c's, of the flattened level
 *                with its decorators folded in: obs__bake_traced_fingerprint)
 *    24     4    u32 shard index I (0 .. N-1)
 *    28     4    u32 shard count N
 *    32     8    u64 valid points of the whole level (before the back-face
 *                rule of the full ray set)
 *    40     8    u64 first point of this shard
 *    48     8    u64 points of this shard (n)
 *    56     8    u64 fingerprint of the regions (boxes) and the valid
 *                points (their grid indices)
 *    64     4    i32 rays           68  4  i32 seed
 *    72     4    i32 grid           76  4  i32 max_regions
 *    80     4    f32 distance_short 84  4  f32 distance_long
 *    88     4    f32 backface_limit 92  4  f32 min_region_size
 *    96     4    u32 regions        100 4  u32 reserved (0)
 *   104     8    f64 seconds before the trace (flatten, BVH, regions,
 *                valid points: every shard spends them)
 *   112     8    f64 seconds of the trace
 *   120     8    u64 FNV-1a 64 of the payload
 *   128  144 n   payload: per point its 18 channels (dynamic.h), f64
 *   128+144n n   per point u8: 1 dropped by the back-face rule, else 0
 *
 * The file is exactly 128 + 145 n bytes.  The parameters in the header
 * decide the points and their values (grid, max_regions and
 * min_region_size the regions and points; rays, seed, the distances and
 * the back-face limit the channels); the merge takes those it is not
 * given from the parts and refuses parts that disagree with it or each
 * other (dyn_shard_run.c). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dynamic/dyn_internal.h"
#include "level/part.h"
#include "internal.h"

#define MAGIC "OBSDYNPT"
#define VERSION 1u
#define HEADER 128u
#define POINT_BYTES (8u * OBS_DYN_CHANNELS)

/* The header's fields after the range: offset, type, member, and the
 * parameter it carries (dyn_shard_run.c's merge checks those). */
#define FIELD(at, type, member, param) {at, OBS__PART_##type, offsetof(obs__dyn_part, member), param}
static const obs__part_field fields[] = {
    FIELD(56, U64, points, NULL),
    FIELD(64, I32, rays, "rays"),
    FIELD(68, I32, seed, "seed"),
    FIELD(72, I32, grid, "grid"),
    FIELD(76, I32, max_regions, "max_regions"),
    FIELD(80, F32, distance_short, "distance_short"),
    FIELD(84, F32, distance_long, "distance_long"),
    FIELD(88, F32, backface_limit, "backface_limit"),
    FIELD(92, F32, min_region_size, "min_region_size"),
    FIELD(96, U32, regions, NULL),
    FIELD(104, F64, prep_seconds, NULL),
    FIELD(112, F64, trace_seconds, NULL),
    FIELD(120, U64, checksum, NULL),
};
#undef FIELD
_Static_assert(HEADER <= OBS__PART_HEAD_MAX, "a part's header fits obs__part_write's buffer");

/* total at most 2^40: a size the payload's bytes cannot overflow */
const obs__part_format obs__dyn_part_format = {
    .magic = MAGIC, .what = "bake-dynamic part", .writer = "obscura bake-dynamic --shard I/N",
    .kind = "bake-dynamic part", .items = "points", .version = VERSION, .head_len = HEADER,
    .max_total = (uint64_t)1 << 40, .item_bytes = POINT_BYTES + 1,
    .part_size = sizeof(obs__dyn_part), .fields = fields,
    .field_count = sizeof fields / sizeof fields[0], .param_find = obs_dyn_param_find,
    .param_at = obs_dyn_param_at, .params_given = offsetof(obs_dyn_params, set)};

obs_dyn_level obs__dyn_level_of(const obs__bake_world *w)
{
    obs_dyn_level l = {.fingerprint = obs__bake_level_fingerprint(w),
                       .triangles = w->triangle_count};
    for (int a = 0; a < 3; a++)
        l.lo[a] = INFINITY, l.hi[a] = -INFINITY;
    for (size_t i = 0; i < w->vertex_count; i++)
        for (int a = 0; a < 3; a++) {
            l.lo[a] = fminf(l.lo[a], w->pos[3 * i + a]);
            l.hi[a] = fmaxf(l.hi[a], w->pos[3 * i + a]);
        }
    return l;
}

uint64_t obs__dyn_points_fingerprint(const obs_dyn_regions *rg, const obs__dyn_points *pt)
{
    unsigned char b[8];
    uint64_t h = obs__bake_fnv(OBS__BAKE_FNV_OFFSET, "obscura dyn points 1", 20);
    obs__le_put64(b, rg->count);
    h = obs__bake_fnv(h, b, 8);
    for (size_t r = 0; r < rg->count; r++)
        for (int a = 0; a < 6; a++) {
            obs__le_put32(b, obs__le_fbits(a < 3 ? rg->box[r].lo[a] : rg->box[r].hi[a - 3]));
            h = obs__bake_fnv(h, b, 4);
        }
    obs__le_put64(b, pt->count);
    h = obs__bake_fnv(h, b, 8);
    for (size_t i = 0; i < pt->count; i++) {
        obs__le_put64(b, pt->id[i]);
        h = obs__bake_fnv(h, b, 8);
    }
    return h;
}

/* ---- writing a part ------------------------------------------------------ */

static obs_status trace_shard(obs__part_job *sh, const obs_dyn_desc *desc, uint64_t level,
                              const obs_dyn_regions *rg, const obs_dyn_params *p,
                              const obs__bake_bvh *bvh, obs__dyn_points *pt, obs_dyn_stats *st,
                              char err[OBS_ERR_LEN])
{
    obs__dyn_part h = {
        .r = obs__part_range_of(VERSION, level, sh->index, sh->count, pt->count),
        .points = obs__dyn_points_fingerprint(rg, pt),
        .rays = p->rays,
        .seed = p->seed,
        .grid = p->grid,
        .max_regions = p->max_regions,
        .distance_short = p->distance_short,
        .distance_long = p->distance_long,
        .backface_limit = p->backface_limit,
        .min_region_size = p->min_region_size,
        .regions = (uint32_t)rg->count,
    };
    for (int k = 0; k < OBS_DYN_STAGE_trace; k++)
        h.prep_seconds += st->seconds[k];
    double t = obs__bake_now();
    pt->rays = 0;
    size_t n = (size_t)h.r.n, first = (size_t)h.r.first, dropped = 0;
    obs__dyn_points_trace(bvh, p, pt, first, first + n, desc ? desc->progress : NULL,
                          desc ? desc->progress_user : NULL);
    h.trace_seconds = obs__bake_now() - t;
    unsigned char *payload = malloc(n * (POINT_BYTES + 1) + 1);
    if (!payload)
        return obs__fail(err, OBS_NO_MEMORY, "the part of %zu points", n);
    for (size_t i = 0; i < n; i++) {
        const double *c = pt->sh + (size_t)OBS_DYN_CHANNELS * (first + i);
        for (int k = 0; k < OBS_DYN_CHANNELS; k++)
            obs__le_put64(payload + POINT_BYTES * i + 8 * (size_t)k, obs__le_dbits(c[k]));
        if (pt->dropped[first + i] == 2) {
            free(payload);
            return obs__fail(err, OBS_NO_MEMORY, "rays of one point");
        }
        payload[POINT_BYTES * n + i] = pt->dropped[first + i];
        dropped += pt->dropped[first + i];
    }
    h.checksum = obs__bake_fnv(OBS__BAKE_FNV_OFFSET, payload, n * (POINT_BYTES + 1));
    obs_status rc = obs__part_write(sh->path, &obs__dyn_part_format, &h, payload,
                                    n * (POINT_BYTES + 1), err);
    free(payload);
    st->seconds[OBS_DYN_STAGE_trace] = h.trace_seconds;
    st->grid_points = pt->grid;
    st->points_inside = pt->inside;
    st->points_hidden = pt->hidden;
    st->points_valid = n - dropped;
    st->points_backface = dropped;
    st->rays = pt->rays;
    sh->stop = 1;
    return rc;
}

/* ---- reading parts ------------------------------------------------------- */

static obs_status read_payload(const obs__dyn_part *h, obs__dyn_points *pt, char err[OBS_ERR_LEN])
{
    size_t n = (size_t)h->r.n, first = (size_t)h->r.first;
    unsigned char *p;
    obs_status rc = obs__bake_part_payload(h->r.path, HEADER, n * (POINT_BYTES + 1), h->checksum, &p, err);
    if (rc != OBS_OK)
        return rc;
    for (size_t i = 0; rc == OBS_OK && i < n; i++) {
        double *c = pt->sh + (size_t)OBS_DYN_CHANNELS * (first + i);
        for (int k = 0; k < OBS_DYN_CHANNELS; k++)
            c[k] = obs__le_bitsd(obs__le_get64(p + POINT_BYTES * i + 8 * (size_t)k));
        pt->dropped[first + i] = p[POINT_BYTES * n + i];
        if (p[POINT_BYTES * n + i] > 1)
            rc = obs__fail(err, OBS_BAD_FILE, "%s: damaged: point %zu's back-face flag is %u",
                           h->r.path, first + i, p[POINT_BYTES * n + i]);
    }
    free(p);
    return rc;
}

static obs_status read_shards(obs__part_job *sh, uint64_t level, const obs_dyn_regions *rg,
                              obs__dyn_points *pt, obs_dyn_stats *st, char err[OBS_ERR_LEN])
{
    const obs__dyn_part *parts = sh->parts, *p0 = &parts[0];
    obs_status rc = obs__part_check_level(p0->r.path, p0->r.level, level, err);
    if (rc != OBS_OK)
        return rc;
    if (p0->regions != rg->count || p0->r.total != pt->count ||
        p0->points != obs__dyn_points_fingerprint(rg, pt))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: the parts split %llu valid points of %u "
                         "regions; this level, these regions and parameters make %zu of %zu "
                         "(or other ones): give the merge the shards' --regions", p0->r.path,
                         (unsigned long long)p0->r.total, p0->regions, pt->count, rg->count);
    double t = obs__bake_now();
    pt->rays = 0;
    for (int i = 0; i < sh->count; i++) {
        rc = read_payload(&parts[i], pt, err);
        if (rc != OBS_OK)
            return rc;
        pt->rays += parts[i].r.n * (uint64_t)parts[i].rays;
        /* the parts' times, summed: the farm's machine time */
        st->seconds[OBS_DYN_STAGE_trace] += parts[i].trace_seconds;
    }
    st->seconds[OBS_DYN_STAGE_trace] += obs__bake_now() - t;
    return OBS_OK;
}

obs_status obs__dyn_shard_step(obs__part_job *sh, const obs_dyn_desc *desc, uint64_t level,
                               const obs_dyn_regions *rg, const obs_dyn_params *p,
                               const obs__bake_bvh *bvh, obs__dyn_points *pt, obs_dyn_stats *st,
                               char err[OBS_ERR_LEN])
{
    return sh->parts ? read_shards(sh, level, rg, pt, st, err)
                     : trace_shard(sh, desc, level, rg, p, bvh, pt, st, err);
}
