/* Ambient obscurance at the surface samples, eq 1 of the paper:
 *
 *   AO(p) = 1/pi  integral over the hemisphere of rho(d(p, w)) cos(theta) dw
 *
 * d the distance to the closest hit in direction w, with the exponential
 * kernel rho(x) = 1 - exp(a x), a = ln(0.5) / d_half (section 2), at two
 * distances at once from the same rays.  Directions are cosine
 * importance-sampled (pdf cos(theta) / pi), so AO is the mean of rho over
 * the rays; a miss counts rho = 1.  Closest hits through Embree 3; a ray
 * that hits the back of a one-sided face counts towards the back-face
 * rule (section 2.1): a sample with more than backface_limit of its rays
 * on back faces lies inside geometry and is dropped.
 *
 * Decorators (section 2.1, core/level/occl.c): the closest hit is of the
 * opaque triangles alone; shrubs (fog boxes) and trees (semi-transparent
 * triangles) on the ray's segment up to that hit multiply the ray's
 * value by their transmittance T:  rho(d) T, a miss 1 T ("both simply
 * attenuate the current AO value for a ray"). */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bake/bake_internal.h"
#include "level/kernel.h"
#include "level/occl.h"
#include "level/rng.h"
#include "internal.h"
#include "pool.h"

#define CHUNK 64
#define PACKET 8

typedef struct job {
    const obs__bake_world *w;
    obs__bake_samples *s;
    const obs__bake_trace_desc *d;
    const obs__bake_occl *occl;
    RTCScene rtc;
    float a[2]; /* the kernels' a = ln(0.5) / d */
    size_t end; /* the range ends at end (d->first .. end) */
    uint64_t rays;
    size_t dropped;
} job;

static void trace_sample(job *j, struct RTCIntersectContext *ctx, size_t i, uint64_t *rays,
                         size_t *dropped)
{
    const obs__bake_world *w = j->w;
    obs__bake_samples *s = j->s;
    const int nr = j->d->rays;
    uint32_t t = s->tri[i];
    const float *n = w->fn + 3 * t;
    float p[3], tg[3], bt[3], o[3];
    obs__bake_sample_pos(w, s, i, p);
    float m = fmaxf(1.0f, fmaxf(fabsf(p[0]), fmaxf(fabsf(p[1]), fabsf(p[2]))));
    for (int k = 0; k < 3; k++)
        o[k] = p[k] + n[k] * 1e-4f * m; /* off the surface: float spacing */
    obs__bake_frame(n, tg, bt);
    /* Cosine-weighted directions (Malley's method: a point of the unit
     * disk lifted to the hemisphere) from a rank-1 lattice with a random
     * shift per sample: each direction has the cosine density, the set
     * is stratified. */
    obs__bake_rng r = obs__bake_rng_stream(j->d->seed, i, 2);
    double o1 = obs__bake_rng_unit(&r), o2 = obs__bake_rng_unit(&r);
    double acc[2] = {0.0, 0.0};
    int back = 0;
    float tfar = OBS__BAKE_RAY_LENGTH_FACTOR * fmaxf(j->d->distance[0], j->d->distance[1]);
    /* Packets of 8 rays (rtcIntersect8): one sample's rays share their
     * origin; lanes are summed in ray order, so the result is the
     * packet's, whatever the thread. */
    for (int k0 = 0; k0 < nr; k0 += PACKET) {
        RTC_ALIGN(32) struct RTCRayHit8 rh;
        RTC_ALIGN(32) int valid[PACKET];
        for (int l = 0; l < PACKET; l++) {
            int k = k0 + l;
            valid[l] = k < nr ? -1 : 0;
            float dir[3];
            obs__bake_lattice_dir(k, nr, o1, o2, n, tg, bt, dir);
            obs__bake_ray8_lane(&rh, l, o, dir, tfar);
        }
        rtcIntersect8(valid, j->rtc, ctx, &rh);
        double tr[PACKET]; /* shrubs and trees up to the opaque hit (section 2.1) */
        obs__bake_occl_transmittance8(j->occl, valid, &rh, tr);
        for (int l = 0; l < PACKET && k0 + l < nr; l++) {
            if (rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) {
                acc[0] += tr[l];
                acc[1] += tr[l];
                continue;
            }
            for (int c = 0; c < 2; c++)
                acc[c] += obs__bake_rho(j->a[c], rh.ray.tfar[l]) * tr[l]; /* rho(x) T */
            size_t ht = j->occl->opaque_tri ? j->occl->opaque_tri[rh.hit.primID[l]]
                                            : rh.hit.primID[l];
            const float *hn = w->fn + 3 * ht;
            if (!w->two_sided[ht] &&
                hn[0] * rh.ray.dir_x[l] + hn[1] * rh.ray.dir_y[l] + hn[2] * rh.ray.dir_z[l] > 0.0f)
                back++;
        }
    }
    *rays += (uint64_t)nr;
    s->ao[2 * i] = (float)(acc[0] / nr);
    s->ao[2 * i + 1] = (float)(acc[1] / nr);
    s->valid[i] = (double)back <= (double)j->d->backface_limit * nr;
    *dropped += !s->valid[i];
}

/* One range of samples on one thread: rays and drops counted locally,
 * added to the job when the thread ends (integer sums: any order). */
typedef struct counts {
    uint64_t rays;
    size_t dropped;
} counts;

static int trace_range(void *ctx, void *local, size_t i0, size_t i1)
{
    job *j = ctx;
    counts *c = local;
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    for (size_t i = i0; i < i1; i++)
        trace_sample(j, &ictx, i, &c->rays, &c->dropped);
    return 0;
}

static void trace_end(void *ctx, void *local)
{
    job *j = ctx;
    const counts *c = local;
    j->rays += c->rays;
    j->dropped += c->dropped;
}

obs_status obs__bake_trace(const obs__bake_world *w, obs__bake_samples *s,
                           const obs__bake_trace_desc *d, double *bvh_seconds,
                           char err[OBS_ERR_LEN])
{
    obs_status st = OBS_OK;
    double t0 = obs__bake_now();
    obs__bake_occl *occl = NULL;
    if ((st = obs__bake_occl_new(w, d->decor, d->tree_attenuation, &occl, err)) != OBS_OK)
        return st;
    *bvh_seconds = obs__bake_now() - t0;

    job *j = calloc(1, sizeof *j);
    if (!j) {
        st = obs__fail(err, OBS_NO_MEMORY, "trace job");
        goto done;
    }
    j->w = w;
    j->s = s;
    j->d = d;
    j->occl = occl;
    j->rtc = occl->opaque;
    for (int c = 0; c < 2; c++)
        j->a[c] = obs__bake_kernel_a(d->distance[c]); /* a = ln(0.5) / d, section 2 */
    /* The samples [first, end): a shard of the bake (shard.c), or all. */
    j->end = d->end && d->end < s->count ? d->end : s->count;
    obs__pool_for f = {.first = d->first, .end = j->end, .chunk = CHUNK, .threads = d->threads,
                       .range = trace_range, .ctx = j, .local_size = sizeof(counts),
                       .end_thread = trace_end, .progress = d->progress,
                       .progress_user = d->progress_user};
    size_t traced = 0;
    int stopped = obs__pool_run(&f, &traced); /* the progress callback cancels between ranges */
    s->rays = j->rays;
    s->dropped = j->dropped;
    if (stopped < 0)
        st = obs__fail(err, OBS_NO_MEMORY, "trace threads");
    else if (stopped)
        st = obs__fail(err, OBS_CANCELLED, "bake cancelled after %zu of %zu samples", traced,
                       j->end - d->first);
    free(j);
done:
    obs__bake_occl_free(occl);
    return st;
}
