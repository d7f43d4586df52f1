#ifndef OBSCURA_BAKE_VOLUME_H
#define OBSCURA_BAKE_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include "bake/bake_internal.h"

/* The two-level sparse grid of spherical visibility around the large
 * instanced decorators (section 2.2; volume.c; instanced.c reads it).
 *
 * Points lie at integer multiples of the spacing h: point (i, j, k) is at
 * (i h, j h, k h).  The points are grouped in bricks of OBS__VOL_BRICK^3;
 * the top level is a hash of the bricks that hold a point, the second a
 * brick's table of its points (an index, or none).  A box needs the
 * points floor(lo / h) .. floor(hi / h) + 1 on each axis, so that the cell
 * of any p inside it, floor(p / h) .. floor(p / h) + 1, has its 8 corners
 * ("a two level sparse volume texture [...] which guarantees that any
 * sample inside any tree instance bounding box would have all 8 samples
 * used in tri-linear interpolation present", section 2.2). */
#define OBS__VOL_BRICK 4
#define OBS__VOL_CHANNELS 18 /* quadratic SH (9) at the two distances */

typedef struct obs__vol {
    float h;
    size_t brick_count, slots; /* the hash: slots a power of 2 */
    int32_t *slot_key;         /* 3 per slot: the brick's coordinates */
    uint32_t *slot_brick;      /* per slot: the brick, UINT32_MAX empty */
    uint32_t *brick_point;     /* OBS__VOL_BRICK^3 per brick: a point or UINT32_MAX */
    size_t count;              /* points */
    int32_t *ijk;              /* 3 per point */
    double *sh;                /* OBS__VOL_CHANNELS per point (convolved, sh.c) */
    uint8_t *inside;           /* per point: its rays met too many back faces */
    size_t inside_count;
    uint64_t rays;
} obs__vol;

/* The points the n boxes (6 floats each: lo xyz, hi xyz) need, sh zero.
 * Refuses a non-finite box and a grid of more than max_points points. */
obs_status obs__vol_build(obs__vol *v, float h, const float *boxes, size_t n, size_t max_points,
                          char err[OBS_ERR_LEN]);
void obs__vol_free(obs__vol *v);
/* The point (i, j, k), or -1 when the grid does not hold it. */
int64_t obs__vol_find(const obs__vol *v, int32_t i, int32_t j, int32_t k);
/* The 8 corners of p's cell and their trilinear weights, in the order
 * (dx, dy, dz) = bit 0, 1, 2 of the corner's number; returns how many are
 * present (idx -1 for those that are not). */
int obs__vol_corners(const obs__vol *v, const float p[3], int64_t idx[8], double wt[8]);
/* Traces every point: `rays` directions over the sphere, spherical
 * obscurance at both distances projected to quadratic SH and convolved
 * with the clamped cosine (level/sh.c, as the dynamic-object bake's points). */
/* stop (may be NULL) is called, serialised, every few hundred points;
 * nonzero: the trace stops with OBS_CANCELLED. */
obs_status obs__vol_trace(obs__vol *v, const obs__bake_bvh *bvh, int rays, const float dist[2],
                          float backface_limit, uint64_t seed, int threads,
                          int (*stop)(void *), void *user, char err[OBS_ERR_LEN]);
/* Eq 1 at p for the unit normal n from the volume: the corners' SH
 * interpolated trilinearly (those inside geometry left out, the weights
 * renormalised, unless all are) and evaluated at n (bands 0..2); n NULL:
 * band 0 alone.  ao[0] short, ao[1] long; 0 when p's cell has a corner
 * missing. */
int obs__vol_eval(const obs__vol *v, const float p[3], const float *n, double ao[2]);

#endif
