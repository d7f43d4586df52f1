/* The sparse volume of spherical visibility around the large instanced
 * decorators (section 2.2): "We sampled the regions around all of the
 * trees volumetrically with a fixed target sampling density and used
 * tri-linear interpolation to generate AO at the vertices.  A two level
 * sparse volume texture was created which guarantees that any sample
 * inside any tree instance bounding box would have all 8 samples used in
 * tri-linear interpolation present.  Each valid voxel has a spherical
 * visibility function that represents AO at two distances using
 * quadratic spherical harmonics (SH)."
 *
 * The grid is the integer multiples of the spacing h (volume.h); the
 * top level a hash of bricks of OBS__VOL_BRICK^3 points, the second each
 * brick's table of its points.  A point's spherical obscurance is traced
 * and projected as the dynamic-object bake's points are (level/point_sh.c,
 * level/sh.c); SH are linear in the function, so interpolating the
 * coefficients and evaluating them at a normal is interpolating the AO. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "level/level.h"
#include "bake/volume.h"
#include "internal.h"
#include "pool.h"

#define B OBS__VOL_BRICK
#define B3 (B * B * B)
#define NONE UINT32_MAX

void obs__vol_free(obs__vol *v)
{
    if (!v)
        return;
    free(v->slot_key);
    free(v->slot_brick);
    free(v->brick_point);
    free(v->ijk);
    free(v->sh);
    free(v->inside);
    memset(v, 0, sizeof *v);
}

/* floor(i / B) and i - B floor(i / B) for negative i too. */
static int32_t brick_of(int32_t i) { return i >= 0 ? i / B : -((-i + B - 1) / B); }
static int local_of(int32_t i) { return (int)(i - brick_of(i) * B); }

static uint64_t hash3(int32_t a, int32_t b, int32_t c)
{
    uint64_t h = (uint64_t)(uint32_t)a * 0x9e3779b97f4a7c15ULL;
    h ^= (uint64_t)(uint32_t)b * 0xc2b2ae3d27d4eb4fULL + (h << 6) + (h >> 2);
    h ^= (uint64_t)(uint32_t)c * 0x165667b19e3779f9ULL + (h << 6) + (h >> 2);
    return h ^ (h >> 29);
}

/* The slot of brick (a, b, c): its own, or the empty one it would take. */
static size_t slot_of(const obs__vol *v, int32_t a, int32_t b, int32_t c)
{
    size_t m = v->slots - 1, s = (size_t)hash3(a, b, c) & m;
    while (v->slot_brick[s] != NONE) {
        const int32_t *k = v->slot_key + 3 * s;
        if (k[0] == a && k[1] == b && k[2] == c)
            return s;
        s = (s + 1) & m;
    }
    return s;
}

static int rehash(obs__vol *v, size_t slots)
{
    int32_t *key = malloc(slots * 3 * sizeof *key);
    uint32_t *br = malloc(slots * sizeof *br);
    if (!key || !br) {
        free(key);
        free(br);
        return 0;
    }
    for (size_t s = 0; s < slots; s++)
        br[s] = NONE;
    obs__vol old = *v;
    v->slot_key = key;
    v->slot_brick = br;
    v->slots = slots;
    for (size_t s = 0; s < old.slots; s++) {
        if (old.slot_brick[s] == NONE)
            continue;
        const int32_t *k = old.slot_key + 3 * s;
        size_t t = slot_of(v, k[0], k[1], k[2]);
        memcpy(v->slot_key + 3 * t, k, 3 * sizeof *k);
        v->slot_brick[t] = old.slot_brick[s];
    }
    free(old.slot_key);
    free(old.slot_brick);
    return 1;
}

int64_t obs__vol_find(const obs__vol *v, int32_t i, int32_t j, int32_t k)
{
    if (!v->slots)
        return -1;
    size_t s = slot_of(v, brick_of(i), brick_of(j), brick_of(k));
    if (v->slot_brick[s] == NONE)
        return -1;
    uint32_t p = v->brick_point[(size_t)v->slot_brick[s] * B3 +
                                (size_t)((local_of(k) * B + local_of(j)) * B + local_of(i))];
    return p == NONE ? -1 : (int64_t)p;
}

/* Adds point (i, j, k) when the grid lacks it; 0 when out of memory. */
static int add_point(obs__vol *v, int32_t i, int32_t j, int32_t k, size_t *cap_b, size_t *cap_p)
{
    if (2 * (v->brick_count + 1) > v->slots && !rehash(v, v->slots ? 2 * v->slots : 64))
        return 0;
    int32_t a = brick_of(i), b = brick_of(j), c = brick_of(k);
    size_t s = slot_of(v, a, b, c);
    if (v->slot_brick[s] == NONE) {
        if (v->brick_count == *cap_b) {
            size_t n = *cap_b ? 2 * *cap_b : 64;
            uint32_t *bp = realloc(v->brick_point, n * B3 * sizeof *bp);
            if (!bp)
                return 0;
            v->brick_point = bp;
            *cap_b = n;
        }
        for (size_t q = 0; q < B3; q++)
            v->brick_point[v->brick_count * B3 + q] = NONE;
        v->slot_key[3 * s] = a, v->slot_key[3 * s + 1] = b, v->slot_key[3 * s + 2] = c;
        v->slot_brick[s] = (uint32_t)v->brick_count++;
    }
    uint32_t *cell = &v->brick_point[(size_t)v->slot_brick[s] * B3 +
                                     (size_t)((local_of(k) * B + local_of(j)) * B + local_of(i))];
    if (*cell != NONE)
        return 1;
    if (v->count == *cap_p) {
        size_t n = *cap_p ? 2 * *cap_p : 256;
        int32_t *q = realloc(v->ijk, n * 3 * sizeof *q);
        if (!q)
            return 0;
        v->ijk = q;
        *cap_p = n;
    }
    v->ijk[3 * v->count] = i, v->ijk[3 * v->count + 1] = j, v->ijk[3 * v->count + 2] = k;
    *cell = (uint32_t)v->count++;
    return 1;
}

/* The grid index of coordinate x: floor(x / h), the same expression for
 * the boxes and the lookups, so that lo <= p <= hi gives i(lo) <= i(p) <=
 * i(hi) (division by h > 0 and floor are monotonic). */
static double grid_coord(float x, float h) { return floor((double)x / (double)h); }

obs_status obs__vol_build(obs__vol *v, float h, const float *boxes, size_t n, size_t max_points,
                          char err[OBS_ERR_LEN])
{
    memset(v, 0, sizeof *v);
    v->h = h;
    if (!(h > 0.0f) || !isfinite(h))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "volume spacing %g", (double)h);
    size_t cap_b = 0, cap_p = 0;
    for (size_t b = 0; b < n; b++) {
        const float *bx = boxes + 6 * b;
        int32_t lo[3], hi[3];
        double pts = 1.0;
        for (int a = 0; a < 3; a++) {
            double l = grid_coord(bx[a], h), u = grid_coord(bx[3 + a], h) + 1.0;
            if (!isfinite(l) || !isfinite(u) || l > u || fabs(l) > 1e9 || fabs(u) > 1e9) {
                obs__vol_free(v);
                return obs__fail(err, OBS_INVALID_ARGUMENT,
                                 "volume: box %zu (%g .. %g on axis %d) at spacing %g", b,
                                 (double)bx[a], (double)bx[3 + a], a, (double)h);
            }
            lo[a] = (int32_t)l, hi[a] = (int32_t)u;
            pts *= u - l + 1.0;
        }
        if (pts + (double)v->count > (double)max_points) {
            obs__vol_free(v);
            return obs__fail(err, OBS_TOO_LARGE,
                             "volume: more than %zu points at spacing %g (box %zu); raise "
                             "volume_spacing",
                             max_points, (double)h, b);
        }
        for (int32_t k = lo[2]; k <= hi[2]; k++)
            for (int32_t j = lo[1]; j <= hi[1]; j++)
                for (int32_t i = lo[0]; i <= hi[0]; i++)
                    if (!add_point(v, i, j, k, &cap_b, &cap_p)) {
                        obs__vol_free(v);
                        return obs__fail(err, OBS_NO_MEMORY, "volume of %zu points", v->count);
                    }
    }
    size_t m = v->count ? v->count : 1;
    v->sh = calloc(m * OBS__VOL_CHANNELS, sizeof *v->sh);
    v->inside = calloc(m, 1);
    if (!v->sh || !v->inside) {
        obs__vol_free(v);
        return obs__fail(err, OBS_NO_MEMORY, "volume of %zu points", m);
    }
    return OBS_OK;
}

int obs__vol_corners(const obs__vol *v, const float p[3], int64_t idx[8], double wt[8])
{
    double g[3], t[3];
    for (int a = 0; a < 3; a++) {
        g[a] = grid_coord(p[a], v->h);
        t[a] = (double)p[a] / (double)v->h - g[a];
        t[a] = t[a] < 0.0 ? 0.0 : t[a] > 1.0 ? 1.0 : t[a];
    }
    int present = 0;
    for (int c = 0; c < 8; c++) {
        int dx = c & 1, dy = c >> 1 & 1, dz = c >> 2 & 1;
        idx[c] = -1;
        if (fabs(g[0]) < 1e9 && fabs(g[1]) < 1e9 && fabs(g[2]) < 1e9)
            idx[c] = obs__vol_find(v, (int32_t)g[0] + dx, (int32_t)g[1] + dy, (int32_t)g[2] + dz);
        /* trilinear weights */
        wt[c] = (dx ? t[0] : 1.0 - t[0]) * (dy ? t[1] : 1.0 - t[1]) * (dz ? t[2] : 1.0 - t[2]);
        present += idx[c] >= 0;
    }
    return present;
}

int obs__vol_eval(const obs__vol *v, const float p[3], const float *n, double ao[2])
{
    int64_t idx[8];
    double wt[8], c[OBS__VOL_CHANNELS] = {0}, sum = 0.0;
    ao[0] = ao[1] = 0.0;
    if (obs__vol_corners(v, p, idx, wt) < 8)
        return 0;
    for (int k = 0; k < 8; k++)
        sum += v->inside[idx[k]] ? 0.0 : wt[k];
    /* Points inside geometry (the back-face rule) are left out, the
     * others' weights renormalised; all inside: all kept. */
    int all = !(sum > 1e-12);
    if (all)
        sum = 1.0;
    for (int k = 0; k < 8; k++) {
        double w = all || !v->inside[idx[k]] ? wt[k] / sum : 0.0;
        const double *s = v->sh + (size_t)idx[k] * OBS__VOL_CHANNELS;
        for (int q = 0; q < OBS__VOL_CHANNELS; q++)
            c[q] += w * s[q];
    }
    static const float up[3] = {0.0f, 0.0f, 1.0f};
    for (int d = 0; d < 2; d++)
        ao[d] = obs__sh_eval(c + OBS_DYN_SH * d, n ? n : up, n ? 2 : 0);
    return 1;
}

typedef struct vol_job {
    obs__vol *v;
    const obs__bake_bvh *bvh;
    obs_dyn_params dp;
    atomic_int failed, stopped;
    int (*stop)(void *);
    void *user;
    pthread_mutex_t lock;
} vol_job;

#define STOP_EVERY 256 /* points between two calls of the stop callback */

static void vol_point(void *ctx, size_t i)
{
    vol_job *j = ctx;
    obs__vol *v = j->v;
    if (j->stop && i % STOP_EVERY == 0) {
        pthread_mutex_lock(&j->lock);
        if (!atomic_load(&j->stopped) && j->stop(j->user))
            atomic_store(&j->stopped, 1);
        pthread_mutex_unlock(&j->lock);
    }
    if (atomic_load(&j->stopped))
        return;
    const int32_t *q = v->ijk + 3 * i;
    float o[3] = {(float)((double)q[0] * v->h), (float)((double)q[1] * v->h),
                  (float)((double)q[2] * v->h)};
    /* the point's rays keyed by its grid index, not its place in the
     * list: the same point gets the same rays in any level */
    uint64_t stream = hash3(q[0], q[1], q[2]);
    int dropped = 0;
    if (!obs__point_sh(j->bvh, o, &j->dp, stream, v->sh + i * OBS__VOL_CHANNELS, &dropped))
        atomic_store(&j->failed, 1);
    v->inside[i] = (uint8_t)(dropped != 0);
}

obs_status obs__vol_trace(obs__vol *v, const obs__bake_bvh *bvh, int rays, const float dist[2],
                          float backface_limit, uint64_t seed, int threads,
                          int (*stop)(void *), void *user, char err[OBS_ERR_LEN])
{
    vol_job *j = calloc(1, sizeof *j);
    if (!j)
        return obs__fail(err, OBS_NO_MEMORY, "volume trace");
    j->v = v;
    j->bvh = bvh;
    j->dp.rays = rays;
    j->dp.seed = (int)(seed & 0x7fffffff);
    j->dp.distance_short = dist[0];
    j->dp.distance_long = dist[1];
    j->dp.backface_limit = backface_limit;
    atomic_init(&j->failed, 0);
    atomic_init(&j->stopped, 0);
    j->stop = stop;
    j->user = user;
    pthread_mutex_init(&j->lock, NULL);
    obs__pool_each(v->count, 16, threads, vol_point, j);
    pthread_mutex_destroy(&j->lock);
    int failed = atomic_load(&j->failed), stopped = atomic_load(&j->stopped);
    free(j);
    if (stopped)
        return obs__fail(err, OBS_CANCELLED, "bake cancelled in the instanced trees' volume");
    if (failed)
        return obs__fail(err, OBS_NO_MEMORY, "rays of a volume point");
    v->inside_count = 0;
    for (size_t i = 0; i < v->count; i++)
        v->inside_count += v->inside[i];
    v->rays = (uint64_t)v->count * (uint64_t)rays;
    return OBS_OK;
}
