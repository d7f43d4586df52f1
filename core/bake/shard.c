/* A bake spread over many machines (paper, section 4: the bakes ran on a
 * farm).  The level's surface samples, numbered as the unsharded bake
 * numbers them, are split into count contiguous ranges; shard i traces
 * the samples [i n / count, (i + 1) n / count) with the rays of the
 * unsharded bake (each sample's random numbers are keyed by its index
 * and the seed alone, rng.h) and writes them as a part.  The merge makes
 * the same samples again, reads every part into them and fits: the
 * merged bake is the unsharded one, value for value.
 *
 * A part file, every field little-endian:
 *
 *   offset size  field
 *     0     8    magic "OBSSHARD"
 *     8     4    u32 version (1)
 *    12     4    u32 header size in bytes (128)
 *    16     8    u64 level fingerprint: FNV-1a 64 of the flattened level
 *                (vertex and triangle counts, positions' float bits,
 *                triangles, double-sidedness; with decorators, each
 *                instance's class and density and tree_attenuation too)
 *    24     4    u32 shard index I (0 .. N-1)
 *    28     4    u32 shard count N
 *    32     8    u64 samples of the whole level
 *    40     8    u64 first sample of this shard
 *    48     8    u64 samples of this shard (n)
 *    56     8    u64 rays traced
 *    64     8    u64 samples dropped by the back-face rule
 *    72     4    i32 rays            76  4  i32 seed
 *    80     4    i32 max_samples_per_face
 *    84     4    f32 samples_per_face   88  4  f32 distance_short
 *    92     4    f32 distance_long      96  4  f32 backface_limit
 *   100     4    u32 reserved (0)
 *   104     8    f64 seconds of the BVH build
 *   112     8    f64 seconds of the trace
 *   120     8    u64 FNV-1a 64 of the payload
 *   128  8 n     payload: per sample f32 obscurance at the short
 *                distance, f32 at the long one
 *   128+8n  n    per sample u8: 1 valid, 0 dropped by the back-face rule
 *
 * The file is exactly 128 + 9 n bytes.  The trace parameters (rays,
 * seed, the sample budget, the distances, the back-face limit) are the
 * ones that decide the samples' values; the merge takes those it is not
 * given from the parts and refuses parts that disagree with it or each
 * other.  A shard writes its part under PATH.tmp and renames it, so a
 * killed shard leaves no part that looks whole. */
#include <errno.h>
#include <stddef.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "level/decor.h"
#include "bake/shard.h"
#include "internal.h"

#define MAGIC "OBSSHARD"
#define VERSION 1u
#define HEADER 128u
#define FNV_OFFSET OBS__BAKE_FNV_OFFSET
#define FNV_PRIME 0x100000001b3ULL

/* The header's fields after the range: offset, type, member, and the
 * bake parameter it carries (shard_run.c's merge checks those). */
#define FIELD(at, type, member, param) {at, OBS__PART_##type, offsetof(obs__bake_part, member), param}
static const obs__part_field fields[] = {
    FIELD(56, U64, rays, NULL),
    FIELD(64, U64, dropped, NULL),
    FIELD(72, I32, rays_per_sample, "rays"),
    FIELD(76, I32, seed, "seed"),
    FIELD(80, I32, max_samples_per_face, "max_samples_per_face"),
    FIELD(84, F32, samples_per_face, "samples_per_face"),
    FIELD(88, F32, distance_short, "distance_short"),
    FIELD(92, F32, distance_long, "distance_long"),
    FIELD(96, F32, backface_limit, "backface_limit"),
    FIELD(104, F64, bvh_seconds, NULL),
    FIELD(112, F64, trace_seconds, NULL),
    FIELD(120, U64, checksum, NULL),
};
#undef FIELD
_Static_assert(HEADER <= OBS__PART_HEAD_MAX, "a part's header fits obs__part_write's buffer");

const obs__part_format obs__bake_part_format = {
    .magic = MAGIC, .what = "bake part", .writer = "obscura bake --shard I/N", .kind = "part",
    .items = "samples", .version = VERSION, .head_len = HEADER, .max_total = UINT32_MAX,
    .item_bytes = 9, .part_size = sizeof(obs__bake_part), .fields = fields,
    .field_count = sizeof fields / sizeof fields[0], .param_find = obs_bake_param_find,
    .param_at = obs_bake_param_at, .params_given = offsetof(obs_bake_params, set)};

static uint64_t traced_fingerprint(const obs__bake_world *w, const obs__bake_trace_desc *td)
{
    return td ? obs__bake_traced_fingerprint(w, td->decor, td->tree_attenuation)
              : obs__bake_level_fingerprint(w);
}

/* ---- writing a part ----------------------------------------------------- */

/* The payload of samples [first, first + n) as the file holds it. */
static unsigned char *payload_bytes(const obs__bake_samples *s, size_t first, size_t n)
{
    unsigned char *p = malloc(n * 9 + 1);
    if (!p)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        obs__le_put32(p + 8 * i, obs__le_fbits(s->ao[2 * (first + i)]));
        obs__le_put32(p + 8 * i + 4, obs__le_fbits(s->ao[2 * (first + i) + 1]));
        p[8 * n + i] = s->valid[first + i] ? 1 : 0;
    }
    return p;
}

static void part_params(obs__bake_part *h, const obs__bake_trace_desc *td, const obs_bake_params *p)
{
    h->rays_per_sample = td->rays;
    h->seed = (int32_t)td->seed;
    h->distance_short = td->distance[0];
    h->distance_long = td->distance[1];
    h->backface_limit = td->backface_limit;
    if (p) {
        h->samples_per_face = p->samples_per_face;
        h->max_samples_per_face = p->max_samples_per_face;
    }
}

static obs_status trace_shard(obs__part_job *sh, const obs__bake_world *w, obs__bake_samples *s,
                              const obs__bake_trace_desc *td, const obs_bake_params *p,
                              obs_bake_stats *st, char err[OBS_ERR_LEN])
{
    obs__bake_part h = {
        .r = obs__part_range_of(VERSION, traced_fingerprint(w, td), sh->index, sh->count, s->count)};
    part_params(&h, td, p);
    double t = obs__bake_now(), bvh = 0.0;
    obs_status rc = OBS_OK;
    s->rays = 0;
    s->dropped = 0;
    size_t n = (size_t)h.r.n, first = (size_t)h.r.first;
    if (n) { /* an empty shard builds no BVH */
        obs__bake_trace_desc d = *td;
        d.first = first;
        d.end = first + n;
        if ((rc = obs__bake_trace(w, s, &d, &bvh, err)) != OBS_OK)
            return rc;
    }
    h.bvh_seconds = bvh;
    h.trace_seconds = obs__bake_now() - t - bvh;
    h.rays = s->rays;
    h.dropped = s->dropped;
    unsigned char *payload = payload_bytes(s, first, n);
    if (!payload)
        return obs__fail(err, OBS_NO_MEMORY, "the part of %zu samples", n);
    h.checksum = obs__bake_fnv(FNV_OFFSET, payload, n * 9);
    rc = obs__part_write(sh->path, &obs__bake_part_format, &h, payload, n * 9, err);
    free(payload);
    st->seconds[OBS_BAKE_STAGE_bvh] = h.bvh_seconds;
    st->seconds[OBS_BAKE_STAGE_trace] = h.trace_seconds;
    st->samples = n;
    sh->stop = 1;
    return rc;
}

/* ---- reading parts ------------------------------------------------------- */

static obs_status read_payload(const obs__bake_part *h, obs__bake_samples *s, char err[OBS_ERR_LEN])
{
    size_t n = (size_t)h->r.n, first = (size_t)h->r.first;
    unsigned char *p;
    obs_status rc = obs__bake_part_payload(h->r.path, HEADER, 9 * n, h->checksum, &p, err);
    if (rc != OBS_OK)
        return rc;
    for (size_t i = 0; i < n; i++) {
        s->ao[2 * (first + i)] = obs__le_bitsf(obs__le_get32(p + 8 * i));
        s->ao[2 * (first + i) + 1] = obs__le_bitsf(obs__le_get32(p + 8 * i + 4));
        s->valid[first + i] = p[8 * n + i] != 0;
    }
    free(p);
    return OBS_OK;
}

static obs_status read_shards(obs__part_job *sh, const obs__bake_world *w, obs__bake_samples *s,
                              const obs__bake_trace_desc *td, obs_bake_stats *st,
                              char err[OBS_ERR_LEN])
{
    uint64_t level = traced_fingerprint(w, td);
    const obs__bake_part *parts = sh->parts;
    const obs__part_range *p0 = &parts[0].r;
    obs_status rc = obs__part_check_level(p0->path, p0->level, level, err);
    if (rc != OBS_OK)
        return rc;
    if (p0->total != s->count)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: the parts split %llu samples; this level "
                         "and these parameters make %zu", p0->path, (unsigned long long)p0->total,
                         s->count);
    double t = obs__bake_now();
    s->rays = 0;
    s->dropped = 0;
    for (int i = 0; i < sh->count; i++) {
        rc = read_payload(&parts[i], s, err);
        if (rc != OBS_OK)
            return rc;
        s->rays += parts[i].rays;
        s->dropped += (size_t)parts[i].dropped;
        /* the parts' times, summed: the farm's machine time */
        st->seconds[OBS_BAKE_STAGE_bvh] += parts[i].bvh_seconds;
        st->seconds[OBS_BAKE_STAGE_trace] += parts[i].trace_seconds;
    }
    st->seconds[OBS_BAKE_STAGE_trace] += obs__bake_now() - t;
    return OBS_OK;
}

obs_status obs__bake_shard_step(obs__part_job *sh, const obs__bake_world *w,
                                obs__bake_samples *s, const obs__bake_trace_desc *td,
                                const obs_bake_params *p, obs_bake_stats *st,
                                char err[OBS_ERR_LEN])
{
    return sh->parts ? read_shards(sh, w, s, td, st, err) : trace_shard(sh, w, s, td, p, st, err);
}

