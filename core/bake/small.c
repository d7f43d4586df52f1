/* Small decorators (section 2.2.1 of the paper): "For very small
 * decorators, like clumps of grass, a single scalar is sufficient.  In
 * that case, we just want to match the terrain near the decorator.  This
 * resampling is done by sampling the AO on the geometry within a small
 * sphere around the point by shooting rays from the boundary of the
 * sphere toward its center.  These values are weighted by the distance to
 * the boundary."
 *
 * Here, for each node of class small with geometry: the point is the
 * centre of the node's world box (not its origin: a triangle soup's nodes
 * all sit at the world's), the sphere's radius small_radius plus half the
 * diagonal of the box; rays start at points of the sphere
 * (a Fibonacci lattice of `rays` directions, turned by a random shift per
 * node) and go towards the centre through the opaque BVH (occl.c: the
 * decorator itself and other decorators are not in it); at the first hit
 * h inside the sphere the baked AO is read (the fitted vertex values,
 * interpolated over the hit face: the AO on the geometry), weighted by
 * w = R - |h - c|, its distance to the boundary.  Hits on the back of a
 * one-sided face are skipped.  The node's scalar is sum w AO / sum w, at
 * both distances; every vertex of its instances gets it; a node whose
 * rays meet nothing keeps the value of its own fit and is counted. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "level/occl.h"
#include "level/rng.h"
#include "internal.h"

#define RNG_SALT 3

/* The weighted resample of one node: out[0] short, out[1] long; 0 when
 * no ray met the geometry. */
static int resample(const obs__bake_occl *o, const obs__bake_world *w, const uint32_t *of,
                    const double *x, const float c[3], float radius, int rays, uint64_t seed,
                    uint64_t stream, double out[2])
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    obs__bake_rng r = obs__bake_rng_stream(seed, stream, RNG_SALT);
    double shift = obs__bake_rng_unit(&r), sum[2] = {0.0, 0.0}, wsum = 0.0;
    for (int k = 0; k < rays; k++) {
        /* the Fibonacci lattice: uniform in z, golden-angle turns */
        double z = 1.0 - 2.0 * (k + 0.5) / rays, s = sqrt(fmax(0.0, 1.0 - z * z));
        double phi = 2.0 * 3.14159265358979323846 * fmod(k * 0.6180339887498949 + shift, 1.0);
        float u[3] = {(float)(s * cos(phi)), (float)(s * sin(phi)), (float)z};
        const float org[3] = {c[0] + radius * u[0], c[1] + radius * u[1], c[2] + radius * u[2]},
                    dir[3] = {-u[0], -u[1], -u[2]};
        struct RTCRayHit rh;
        obs__bake_ray1(&rh, org, dir, 2.0f * radius); /* the chord through the centre */
        rtcIntersect1(o->opaque, &ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
            continue;
        size_t t = o->opaque_tri ? o->opaque_tri[rh.hit.primID] : rh.hit.primID;
        const float *fn = w->fn + 3 * t;
        if (!w->two_sided[t] && -(fn[0] * u[0] + fn[1] * u[1] + fn[2] * u[2]) > 0.0f)
            continue; /* the back of a one-sided face */
        float h[3];
        for (int a = 0; a < 3; a++)
            h[a] = c[a] + radius * u[a] - rh.ray.tfar * u[a];
        double dist = sqrt((double)(h[0] - c[0]) * (h[0] - c[0]) +
                           (double)(h[1] - c[1]) * (h[1] - c[1]) +
                           (double)(h[2] - c[2]) * (h[2] - c[2]));
        double wt = radius - dist; /* weighted by the distance to the boundary */
        if (!(wt > 0.0))
            continue;
        const uint32_t *v = w->tri + 3 * t;
        double b[3] = {1.0 - rh.hit.u - rh.hit.v, rh.hit.u, rh.hit.v};
        for (int d = 0; d < 2; d++) {
            double val = 0.0;
            for (int a = 0; a < 3; a++)
                val += b[a] * x[2 * (size_t)of[v[a]] + d];
            sum[d] += wt * val;
        }
        wsum += wt;
    }
    if (!(wsum > 0.0))
        return 0;
    for (int d = 0; d < 2; d++) {
        double v = sum[d] / wsum;
        out[d] = v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v;
    }
    return 1;
}

obs_status obs__bake_small(const obs_bake_scene *scene, const obs__bake_world *w,
                           const uint32_t *of, const obs__bake_decor *d, const double *x,
                           const obs_bake_params *p, obs_bake_result *out, char err[OBS_ERR_LEN])
{
    if (!d || !d->counts[OBS__DECOR_SMALL])
        return OBS_OK;
    size_t nn = scene->node_count;
    out->node_ao = malloc(3 * nn * sizeof *out->node_ao);
    float *box = malloc(6 * nn * sizeof *box);
    if (!out->node_ao || !box) {
        free(box);
        return obs__fail(err, OBS_NO_MEMORY, "small decorators of %zu nodes", nn);
    }
    out->node_count = nn;
    for (size_t n = 0; n < 3 * nn; n++)
        out->node_ao[n] = NAN;
    for (size_t n = 0; n < nn; n++)
        for (int k = 0; k < 3; k++)
            box[6 * n + k] = INFINITY, box[6 * n + 3 + k] = -INFINITY;
    for (size_t i = 0; i < w->instance_count; i++) {
        const obs__bake_inst *in = &w->inst[i];
        if (d->node_class[in->node] != OBS__DECOR_SMALL)
            continue;
        size_t end = i + 1 < w->instance_count ? w->inst[i + 1].first_vertex : w->vertex_count;
        float *b = box + 6 * (size_t)in->node;
        for (size_t v = in->first_vertex; v < end; v++)
            for (int k = 0; k < 3; k++) {
                b[k] = fminf(b[k], w->pos[3 * v + k]);
                b[3 + k] = fmaxf(b[3 + k], w->pos[3 * v + k]);
            }
    }
    obs__bake_occl *o = NULL;
    obs_status st = obs__bake_occl_new(w, d, p->tree_attenuation, &o, err);
    if (st != OBS_OK) {
        free(box);
        return st;
    }
    for (size_t n = 0; n < nn; n++) {
        const float *b = box + 6 * n;
        if (d->node_class[n] != OBS__DECOR_SMALL || !(b[0] <= b[3]))
            continue;
        const float c[3] = {0.5f * (b[0] + b[3]), 0.5f * (b[1] + b[4]), 0.5f * (b[2] + b[5])};
        double diag = sqrt((double)(b[3] - b[0]) * (b[3] - b[0]) +
                           (double)(b[4] - b[1]) * (b[4] - b[1]) +
                           (double)(b[5] - b[2]) * (b[5] - b[2]));
        float radius = p->small_radius + (float)(0.5 * diag);
        double v[2];
        out->stats.small_decorators++;
        if (!resample(o, w, of, x, c, radius, p->rays, (uint64_t)p->seed, n, v)) {
            out->stats.small_unresolved++;
            continue;
        }
        out->node_ao[3 * n + 1] = (float)v[0];
        out->node_ao[3 * n + 2] = (float)v[1];
        out->node_ao[3 * n] = (float)(p->blend * v[0] + (1.0 - p->blend) * v[1]);
    }
    obs__bake_occl_free(o);
    free(box);
    /* the scalar on every vertex of the node's instances */
    for (size_t i = 0; i < out->instance_count; i++) {
        obs_bake_instance *r = &out->instances[i];
        const float *a = out->node_ao + 3 * (size_t)r->node;
        if (isnan(a[0]))
            continue;
        for (size_t v = 0; v < scene->meshes[r->mesh].vertex_count; v++) {
            r->ao[v] = a[0];
            r->ao_short[v] = a[1];
            r->ao_long[v] = a[2];
        }
    }
    return OBS_OK;
}
