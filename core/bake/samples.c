/* Surface samples per face (paper 2.1): a budget spread over the faces in
 * proportion to their area, at least one per face and at most a cap per
 * face, so that large coarse distant faces do not take the budget of the
 * detailed playable area; each sample weighs w = A_t / n_t, so that the
 * samples of a face integrate over it whatever their number (the finite
 * element weighting of Kavan et al. 2011). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake/bake_internal.h"
#include "level/rng.h"
#include "internal.h"

/* The golden ratio's fractional part: the second coordinate of a rank-1
 * lattice (the Fibonacci lattice). */
#define PHI_FRAC 0.6180339887498949

void obs__bake_samples_free(obs__bake_samples *s)
{
    if (!s)
        return;
    free(s->tri); /* the block of all six arrays (obs__alloc_arrays) */
    memset(s, 0, sizeof *s);
}

static size_t face_count(double lambda, float area, int cap)
{
    if (!(area > 0.0f))
        return 0;
    double n = floor(lambda * area + 0.5);
    return n < 1.0 ? 1 : n > cap ? (size_t)cap : (size_t)n;
}

static size_t total(const obs__bake_world *w, double lambda, int cap)
{
    size_t n = 0;
    for (size_t t = 0; t < w->triangle_count; t++)
        n += face_count(lambda, w->area[t], cap);
    return n;
}

void obs__bake_sample_pos(const obs__bake_world *w, const obs__bake_samples *s, size_t i,
                          float p[3])
{
    const uint32_t *v = w->tri + 3 * s->tri[i];
    const float *b = s->bary + 3 * i;
    for (int k = 0; k < 3; k++)
        p[k] = b[0] * w->pos[3 * v[0] + k] + b[1] * w->pos[3 * v[1] + k] +
               b[2] * w->pos[3 * v[2] + k];
}

obs_status obs__bake_samples_make(const obs__bake_world *w, double per_face, int max_face,
                                  uint64_t seed, obs__bake_samples *s, char err[OBS_ERR_LEN])
{
    memset(s, 0, sizeof *s);
    size_t faces = w->triangle_count - w->degenerate;
    double area = 0.0;
    for (size_t t = 0; t < w->triangle_count; t++)
        area += w->area[t];
    double budget = per_face * (double)faces;
    /* lambda (samples per unit area) such that the capped counts add up
     * to the budget: the total grows with lambda, so bisect. */
    double lo = 0.0, hi = budget / area;
    while (total(w, hi, max_face) < budget && hi < 1e30 &&
           total(w, hi, max_face) < faces * (size_t)max_face)
        hi *= 2.0;
    for (int it = 0; it < 60; it++) {
        double mid = 0.5 * (lo + hi);
        if ((double)total(w, mid, max_face) < budget)
            lo = mid;
        else
            hi = mid;
    }
    size_t n = total(w, hi, max_face);
    if (n > UINT32_MAX)
        return obs__fail(err, OBS_TOO_LARGE, "%zu samples; at most %u", n, (unsigned)UINT32_MAX);
    const size_t bytes[] = {n * sizeof *s->tri, n * 3 * sizeof *s->bary, n * sizeof *s->weight,
                            n * 2 * sizeof *s->ao, n, (w->triangle_count + 1) * sizeof *s->first};
    void *a[6];
    if (!obs__alloc_arrays(6, bytes, a))
        return obs__fail(err, OBS_NO_MEMORY, "%zu samples", n);
    *s = (obs__bake_samples){.tri = a[0], .bary = a[1], .weight = a[2], .ao = a[3], .valid = a[4],
                             .first = a[5]};
    size_t i = 0;
    for (size_t t = 0; t < w->triangle_count; t++) {
        size_t nt = face_count(hi, w->area[t], max_face);
        s->first[t] = (uint32_t)i;
        /* A rank-1 lattice over the unit square, shifted by a random
         * offset per face (Cranley-Patterson rotation: every point is
         * uniform, the set stratified), mapped onto the triangle with
         * the area-preserving square-root warp. */
        obs__bake_rng r = obs__bake_rng_stream(seed, t, 1);
        double o1 = obs__bake_rng_unit(&r), o2 = obs__bake_rng_unit(&r);
        for (size_t k = 0; k < nt; k++, i++) {
            double u = fmod((k + 0.5) / (double)nt + o1, 1.0);
            double v = fmod((double)k * PHI_FRAC + o2, 1.0);
            double su = sqrt(u);
            s->tri[i] = (uint32_t)t;
            s->bary[3 * i] = (float)(1.0 - su);
            s->bary[3 * i + 1] = (float)(su * (1.0 - v));
            s->bary[3 * i + 2] = (float)(su * v);
            s->weight[i] = w->area[t] / (float)nt;
        }
    }
    s->first[w->triangle_count] = (uint32_t)i;
    s->count = n;
    return OBS_OK;
}
