/* The valid points of the regions and their spherical obscurance
 * (section 2.3).
 *
 * "Before the bake is launched we compute a one bit flag at 8 x 8 x 8
 * samples in the region where the bit is set if the point is valid": the
 * grid's points are the centres of grid^3 equal cells of the box.  A
 * point is valid when both hold:
 *   - it is outside geometry: at most backface_limit of 32 rays (a fixed
 *     spiral over the sphere) meet a one-sided face from behind (the
 *     bake's back-face rule of section 2.1, through Embree);
 *   - it is not behind a wall from the region's viewpoint: the segment
 *     from the viewpoint to the point meets no geometry (an Embree
 *     occlusion ray).  The viewpoint is the outside grid point nearest the
 *     box's centre; it stands in for the visibility system's "not on the
 *     other side of a diagonal wall".
 * Both tests see the opaque triangles alone: decorators are not solid
 * (a point in a tree's canopy or a shrub's box is outside geometry, and
 * no tree hides a point behind it; dyn_bake.c).
 * Then every valid point traces `rays` directions over the whole sphere
 * (equal-area Fibonacci spiral, a random rotation per point): the
 * spherical obscurance f(w) = rho(d(p, w)) T(w), rho(x) = 1 - exp(a x),
 * a = ln 0.5 / d, at both distances (section 2; a miss is rho = 1), T
 * the transmittance of the decorators' fog boxes and tree triangles up
 * to the hit (section 2.1; 1 without decorators), is
 * projected to quadratic SH and convolved with the clamped cosine (level/sh.c,
 * level/point_sh.c).
 * "We start by eliminating any points that see too many back faces": a
 * point whose rays meet back faces more often than backface_limit is
 * dropped here too (the full ray set sees more than the 32 of the flag). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dynamic/dyn_internal.h"
#include "level/kernel.h"
#include "level/rng.h"
#include "internal.h"
#include "pool.h"

#define FLAG_RAYS 32

int obs__dyn_inside(const obs__bake_bvh *bvh, const float p[3], int rays, float limit)
{
    float dirs[3 * 256], t[256];
    uint8_t back[256];
    if (rays > 256)
        rays = 256;
    obs__sphere_dirs(rays, 0, 0, dirs);
    obs__bake_bvh_cast(bvh, p, dirs, rays, INFINITY, t, back, NULL);
    int nb = 0;
    for (int k = 0; k < rays; k++)
        nb += back[k];
    return (double)nb > (double)limit * rays;
}

obs_status obs__dyn_points_alloc(obs__dyn_points *pt, size_t n, char err[OBS_ERR_LEN])
{
    const size_t bytes[] = {n * 3 * sizeof *pt->pos, n * OBS_DYN_CHANNELS * sizeof *pt->sh,
                            n * sizeof *pt->region, n, n * sizeof *pt->id, n};
    void *a[6];
    if (!obs__alloc_arrays(6, bytes, a))
        return obs__fail(err, OBS_NO_MEMORY, "%zu valid points", n);
    *pt = (obs__dyn_points){.count = n, .pos = a[0], .sh = a[1], .region = a[2], .held = a[3],
                            .id = a[4], .dropped = a[5]};
    return OBS_OK;
}

void obs__dyn_points_free(obs__dyn_points *pt)
{
    free(pt->pos); /* the block of all six arrays (obs__dyn_points_alloc) */
    memset(pt, 0, sizeof *pt);
}

typedef struct flag_job {
    const obs__bake_bvh *bvh;
    const obs_dyn_regions *rg;
    const obs_dyn_params *p;
    uint8_t *state; /* per grid point: 0 valid, 1 inside, 2 hidden */
} flag_job;

static void grid_point(const obs_dyn_box *b, int g, size_t k, float q[3])
{
    size_t ix[3] = {k % (size_t)g, k / (size_t)g % (size_t)g, k / ((size_t)g * g)};
    for (int a = 0; a < 3; a++)
        q[a] = b->lo[a] + (b->hi[a] - b->lo[a]) * ((float)ix[a] + 0.5f) / (float)g;
}

static void flag_region(void *ctx, size_t r)
{
    flag_job *j = ctx;
    int g = j->p->grid;
    size_t n = (size_t)g * g * g;
    uint8_t *s = j->state + r * n;
    const obs_dyn_box *b = &j->rg->box[r];
    float c[3], view[3], best = INFINITY;
    int have = 0;
    for (int a = 0; a < 3; a++)
        c[a] = 0.5f * (b->lo[a] + b->hi[a]);
    for (size_t k = 0; k < n; k++) {
        float q[3];
        grid_point(b, g, k, q);
        s[k] = obs__dyn_inside(j->bvh, q, FLAG_RAYS, j->p->backface_limit) ? 1 : 0;
        float d = (q[0] - c[0]) * (q[0] - c[0]) + (q[1] - c[1]) * (q[1] - c[1]) +
                  (q[2] - c[2]) * (q[2] - c[2]);
        if (!s[k] && d < best)
            best = d, memcpy(view, q, sizeof view), have = 1;
    }
    for (size_t k = 0; have && k < n; k++) {
        float q[3];
        grid_point(b, g, k, q);
        if (!s[k] && obs__bake_bvh_occluded(j->bvh, view, q))
            s[k] = 2;
    }
}

typedef struct sph_job {
    const obs__bake_bvh *bvh;
    const obs_dyn_params *p;
    obs__dyn_points *pt;
    size_t first;
    void (*progress)(void *, size_t, size_t);
    void *user;
} sph_job;

static void trace_point(void *ctx, size_t i)
{
    sph_job *j = ctx;
    obs__dyn_points *pt = j->pt;
    size_t k = j->first + i;
    int dropped = 0;
    if (!obs__point_sh(j->bvh, pt->pos + 3 * k, j->p, pt->id[k],
                           pt->sh + (size_t)OBS_DYN_CHANNELS * k, &dropped))
        dropped = 2; /* no memory: reported by the caller */
    pt->dropped[k] = (uint8_t)dropped;
}

static int trace_points(void *ctx, void *local, size_t i0, size_t i1)
{
    (void)local;
    for (size_t i = i0; i < i1; i++)
        trace_point(ctx, i);
    return 0;
}

/* The shard's progress never cancels. */
static int report(void *ctx, size_t done, size_t total)
{
    const sph_job *j = ctx;
    j->progress(j->user, done, total);
    return 0;
}

obs_status obs__dyn_points_flag(const obs__bake_bvh *bvh, const obs_dyn_regions *rg,
                                const obs_dyn_params *p, obs__dyn_points *out,
                                char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    size_t per = (size_t)p->grid * p->grid * p->grid;
    if (rg->count > SIZE_MAX / per / 2)
        return obs__fail(err, OBS_TOO_LARGE, "%zu regions", rg->count);
    size_t total = rg->count * per, nv = 0;
    uint8_t *state = calloc(total ? total : 1, 1);
    if (!state)
        return obs__fail(err, OBS_NO_MEMORY, "valid flags of %zu points", total);
    flag_job fj = {bvh, rg, p, state};
    obs__pool_each(rg->count, 1, p->threads, flag_region, &fj);
    size_t inside = 0, hidden = 0;
    for (size_t k = 0; k < total; k++) {
        inside += state[k] == 1;
        hidden += state[k] == 2;
        nv += state[k] == 0;
    }
    obs_status rc = obs__dyn_points_alloc(out, nv, err);
    if (rc != OBS_OK) {
        free(state);
        return rc;
    }
    out->grid = total;
    out->inside = inside;
    out->hidden = hidden;
    size_t i = 0;
    for (size_t k = 0; k < total; k++) {
        if (state[k])
            continue;
        grid_point(&rg->box[k / per], p->grid, k % per, out->pos + 3 * i);
        out->region[i] = (uint32_t)(k / per);
        out->id[i] = k;
        obs__bake_rng r = obs__bake_rng_stream((uint64_t)p->seed, k, 11);
        out->held[i] = obs__bake_rng_unit(&r) < p->holdout;
        i++;
    }
    free(state);
    return OBS_OK;
}

void obs__dyn_points_trace(const obs__bake_bvh *bvh, const obs_dyn_params *p,
                           obs__dyn_points *pt, size_t first, size_t end,
                           void (*progress)(void *, size_t, size_t), void *user)
{
    sph_job sj = {bvh, p, pt, first, progress, user};
    obs__pool_for f = {.end = end - first, .chunk = 16, .threads = p->threads,
                       .range = trace_points, .ctx = &sj, .progress = progress ? report : NULL,
                       .progress_user = &sj};
    obs__pool_run(&f, NULL);
    pt->rays += (uint64_t)(end - first) * (uint64_t)p->rays;
}

obs_status obs__dyn_points_compact(obs__dyn_points *pt, char err[OBS_ERR_LEN])
{
    /* Drop the points that see too many back faces, keeping the order. */
    size_t m = 0;
    for (size_t k = 0; k < pt->count; k++) {
        if (pt->dropped[k] == 2)
            return obs__fail(err, OBS_NO_MEMORY, "rays of one point");
        if (pt->dropped[k]) {
            pt->backface++;
            continue;
        }
        memmove(pt->pos + 3 * m, pt->pos + 3 * k, 3 * sizeof *pt->pos);
        memmove(pt->sh + OBS_DYN_CHANNELS * m, pt->sh + OBS_DYN_CHANNELS * k,
                OBS_DYN_CHANNELS * sizeof *pt->sh);
        pt->region[m] = pt->region[k];
        pt->held[m] = pt->held[k];
        pt->id[m] = pt->id[k];
        pt->dropped[m] = 0;
        m++;
    }
    pt->count = m;
    return OBS_OK;
}

obs_status obs__dyn_points_make(const obs__bake_world *w, const obs__bake_bvh *bvh,
                                const obs_dyn_regions *rg, const obs_dyn_params *p,
                                obs__dyn_points *out, double *valid_seconds,
                                void (*progress)(void *, size_t, size_t), void *user,
                                char err[OBS_ERR_LEN])
{
    (void)w;
    double t0 = obs__now_ms() * 1e-3;
    obs_status st = obs__dyn_points_flag(bvh, rg, p, out, err);
    *valid_seconds = obs__now_ms() * 1e-3 - t0;
    if (st != OBS_OK)
        return st;
    obs__dyn_points_trace(bvh, p, out, 0, out->count, progress, user);
    if ((st = obs__dyn_points_compact(out, err)) != OBS_OK)
        obs__dyn_points_free(out);
    return st;
}

void obs__dyn_trace_eq1(const obs__bake_bvh *bvh, const float o[3], const float n[3],
                        int rays, const float distance[2], uint64_t seed, uint64_t stream,
                        double ao[2])
{
    /* Eq 1 with cosine-weighted directions (Malley's method on a rank-1
     * lattice with a random shift, as trace.c): AO is the mean of rho
     * times each ray's transmittance (section 2.1; 1 without decorators). */
    float tg[3], bt[3], dirs[3 * 8], t[8], tr[8];
    uint8_t back[8];
    obs__bake_frame(n, tg, bt);
    obs__bake_rng r = obs__bake_rng_stream(seed, stream, 13);
    double o1 = obs__bake_rng_unit(&r), o2 = obs__bake_rng_unit(&r), acc[2] = {0.0, 0.0};
    float tfar = OBS__BAKE_RAY_LENGTH_FACTOR * fmaxf(distance[0], distance[1]);
    for (int k0 = 0; k0 < rays; k0 += 8) {
        int m = rays - k0 < 8 ? rays - k0 : 8;
        for (int l = 0; l < m; l++) /* the bake's ray set (kernel.h) */
            obs__bake_lattice_dir(k0 + l, rays, o1, o2, n, tg, bt, dirs + 3 * l);
        obs__bake_bvh_cast(bvh, o, dirs, m, tfar, t, back, tr);
        for (int l = 0; l < m; l++) /* rho times the decorators' transmittance, as the points' */
            for (int c = 0; c < 2; c++)
                acc[c] += (isinf(t[l]) ? 1.0 : 1.0 - exp(log(0.5) / distance[c] * t[l])) * tr[l];
    }
    ao[0] = acc[0] / rays;
    ao[1] = acc[1] / rays;
}
