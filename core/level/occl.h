/* What the rays of eq 1 meet (core/level/occl.c): the opaque BVH of the
 * level's non-decorator triangles, and a second BVH of the shrubs' world
 * boxes (fog) and the trees' triangles (semi-transparent), section 2.1 of
 * the paper.  The bake's trace (trace.c) and the per-pixel reference's
 * obscurance (core/ground/obscurance.c) both trace through it. */
#ifndef OBSCURA_BAKE_OCCL_H
#define OBSCURA_BAKE_OCCL_H

#include <embree3/rtcore.h>
#include <stddef.h>
#include <stdint.h>

#include "level/level.h"
#include "level/decor.h"

typedef struct obs__bake_occl {
    RTCDevice dev;
    RTCScene opaque;       /* the closest hits: triangles of class none */
    uint32_t *opaque_tri;  /* world triangle of each opaque primitive */
    size_t opaque_count;
    RTCScene fog;          /* shrub boxes and tree triangles; NULL when none */
    size_t box_count, tree_count;
    float *box;            /* 6 per shrub box: min xyz, max xyz (world) */
    float *density;        /* per box, after the overlap pre-pass (1/m) */
    uint32_t *box_node;    /* the node of each box */
    double log_keep;       /* ln(1 - tree_attenuation): one tree crossing */
} obs__bake_occl;

/* One ray org + t dir, 0 <= t <= tfar, ready for rtcIntersect1. */
static inline void obs__bake_ray1(struct RTCRayHit *rh, const float org[3], const float dir[3],
                                  float tfar)
{
    rh->ray.org_x = org[0], rh->ray.org_y = org[1], rh->ray.org_z = org[2];
    rh->ray.dir_x = dir[0], rh->ray.dir_y = dir[1], rh->ray.dir_z = dir[2];
    rh->ray.tnear = 0.0f;
    rh->ray.tfar = tfar;
    rh->ray.time = 0.0f;
    rh->ray.mask = 0xffffffffu;
    rh->ray.id = 0;
    rh->ray.flags = 0;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/* The two BVHs of world w; d NULL (or no decorators): every triangle
 * opaque, no second BVH.  Small decorators (section 2.2.1) are neither:
 * they occlude nothing.  Free with obs__bake_occl_free(). */
obs_status obs__bake_occl_new(const obs__bake_world *w, const obs__bake_decor *d,
                              float tree_attenuation, obs__bake_occl **out,
                              char err[OBS_ERR_LEN]);
void obs__bake_occl_free(obs__bake_occl *o);

/* The fraction of visibility left along each ray of a packet of 8 that
 * the opaque BVH has answered (opaque: its rays with tfar at the hit, or
 * the ray's end; valid: -1 for the lanes in use): exp(-sum density_i
 * len_i) over the shrub boxes times (1 - tree_attenuation) per tree
 * triangle crossed, on [0, tfar] (section 2.1).  1 where there is no
 * second BVH, and in unused lanes.  Thread-safe. */
void obs__bake_occl_transmittance8(const obs__bake_occl *o, const int *valid,
                                   const struct RTCRayHit8 *opaque, double tr[8]);

/* The two BVHs of the public wrapper (obs_bake_occluders_new); NULL for
 * NULL. */
const obs__bake_occl *obs__bake_occluders_occl(const obs_bake_occluders *o);

/* The overlap pre-pass of section 2.1 on n boxes (6 floats each):
 * density[i] *= V_i / (V_i + O_i), O_i the summed volume of box i's
 * intersections with the other boxes. */
void obs__bake_fog_overlap(const float *box, size_t n, float *density);

/* Lane l of an 8-ray packet: origin o, unit direction d, [0, tfar], no
 * hit yet (the bake's samples, the points' rays, the reference's
 * obscurance fill their packets alike). */
static inline void obs__bake_ray8_lane(struct RTCRayHit8 *rh, int l, const float o[3],
                                       const float d[3], float tfar)
{
    rh->ray.org_x[l] = o[0], rh->ray.org_y[l] = o[1], rh->ray.org_z[l] = o[2];
    rh->ray.dir_x[l] = d[0], rh->ray.dir_y[l] = d[1], rh->ray.dir_z[l] = d[2];
    rh->ray.tnear[l] = 0.0f;
    rh->ray.tfar[l] = tfar;
    rh->ray.time[l] = 0.0f;
    rh->ray.mask[l] = 0xffffffffu;
    rh->ray.id[l] = 0;
    rh->ray.flags[l] = 0;
    rh->hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
}

#endif
