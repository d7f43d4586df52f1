/* Ambient obscurance (eq 1 of "Baked ambient obscurance on the vertices
 * of game levels", section 2) at one point of the reference: the kernel,
 * the ray set and the random shifts are the bake's own (bake/kernel.h,
 * bake/rng.h), so that the per-pixel reference and the baked vertices
 * estimate one quantity the same way.  Closest hits in packets of 8, the
 * lanes summed in ray order, as core/bake/trace.c does.  With the bake's
 * occluders (obs_reference_desc.occluders) the rays meet what the bake's
 * meet: its opaque BVH, and each ray's rho times the transmittance of the
 * shrubs' fog and the trees up to the hit (section 2.1, core/level/occl.c). */
#include <embree3/rtcore.h>
#include <math.h>

#include "level/kernel.h"
#include "level/occl.h"
#include "level/rng.h"
#include "ground/reference_internal.h"

#define PACKET 8
/* The salt of the bake's ray shifts (core/bake/trace.c). */
#define RAY_SALT 2

void obs__obscurance_init(obs__obscurance *o, const float distance[2], int rays, uint64_t seed,
                          const struct obs__bake_occl *occl)
{
    o->occl = occl;
    for (int c = 0; c < 2; c++)
        o->a[c] = obs__bake_kernel_a(distance[c]);
    o->tfar = OBS__BAKE_RAY_LENGTH_FACTOR * fmaxf(distance[0], distance[1]);
    o->rays = rays;
    o->seed = seed;
}

void obs__obscurance_at(RTCScene rtc, struct RTCIntersectContext *ctx, const obs__obscurance *o,
                        uint64_t stream, const float p[3], const float n[3], float out[2])
{
    const int nr = o->rays;
    float tg[3], bt[3], org[3];
    float m = fmaxf(1.0f, fmaxf(fabsf(p[0]), fmaxf(fabsf(p[1]), fabsf(p[2]))));
    for (int k = 0; k < 3; k++)
        org[k] = p[k] + n[k] * 1e-4f * m; /* off the surface: float spacing */
    obs__bake_frame(n, tg, bt);
    obs__bake_rng r = obs__bake_rng_stream(o->seed, stream, RAY_SALT);
    double o1 = obs__bake_rng_unit(&r), o2 = obs__bake_rng_unit(&r);
    double acc[2] = {0.0, 0.0};
    for (int k0 = 0; k0 < nr; k0 += PACKET) {
        RTC_ALIGN(32) struct RTCRayHit8 rh;
        RTC_ALIGN(32) int valid[PACKET];
        for (int l = 0; l < PACKET; l++) {
            int k = k0 + l;
            float d[3];
            valid[l] = k < nr ? -1 : 0;
            obs__bake_lattice_dir(k, nr, o1, o2, n, tg, bt, d);
            obs__bake_ray8_lane(&rh, l, org, d, o->tfar);
        }
        rtcIntersect8(valid, o->occl ? o->occl->opaque : rtc, ctx, &rh);
        double tr[PACKET] = {1, 1, 1, 1, 1, 1, 1, 1}; /* shrubs and trees, section 2.1 */
        if (o->occl)
            obs__bake_occl_transmittance8(o->occl, valid, &rh, tr);
        for (int l = 0; l < PACKET && k0 + l < nr; l++)
            for (int c = 0; c < 2; c++)
                acc[c] += (rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID
                               ? 1.0
                               : obs__bake_rho(o->a[c], rh.ray.tfar[l])) *
                          tr[l];
    }
    out[0] = (float)(acc[0] / nr);
    out[1] = (float)(acc[1] / nr);
}
