/* Internal to the ray-traced reference (core/ground/): the obscurance of
 * eq 1 at one point (obscurance.c), called by reference.c's workers.  Not
 * installed. */
#ifndef OBSCURA_REFERENCE_INTERNAL_H
#define OBSCURA_REFERENCE_INTERNAL_H

#include <embree3/rtcore.h>
#include <stdint.h>

/* The kernels and rays of one render (reference.h, obscurance mode). */
typedef struct obs__obscurance {
    float a[2];   /* the kernels' a = ln(0.5) / d, short and long */
    float tfar;   /* ray length: OBS__BAKE_RAY_LENGTH_FACTOR times the longer d */
    int rays;
    uint64_t seed;
    /* the bake's occluders (core/level/occl.h), or NULL: the scene */
    const struct obs__bake_occl *occl;
} obs__obscurance;

/* occl: the bake's occluders, whose opaque BVH and fog replace the
 * caller's scene in obs__obscurance_at; NULL for none. */
void obs__obscurance_init(obs__obscurance *o, const float distance[2], int rays, uint64_t seed,
                          const struct obs__bake_occl *occl);

/* Eq 1 at p around the unit normal n at both distances (out[0] short,
 * out[1] long), with the bake's rays: the lattice shift of stream `stream`
 * (bake/rng.h, the bake's salt), so that a point and stream give the
 * value a bake sample of the same index and seed gets there. */
void obs__obscurance_at(RTCScene rtc, struct RTCIntersectContext *ctx, const obs__obscurance *o,
                        uint64_t stream, const float p[3], const float n[3], float out[2]);

#endif
