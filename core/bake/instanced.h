/* Large instanced decorators (section 2.2 of "Baked ambient obscurance on
 * the vertices of game levels"): the sparse volume of spherical
 * visibility around them (volume.c) and the per-instance model, a local
 * AO per mesh times a linear global AO fitted by eq 3 (instanced.c). */
#ifndef OBSCURA_BAKE_INSTANCED_H
#define OBSCURA_BAKE_INSTANCED_H

#include <stddef.h>
#include <stdint.h>

#include "bake/bake_internal.h"
#include "level/decor.h"

/* ---- volume.c: the two-level sparse grid -------------------------------
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

/* ---- instanced.c -------------------------------------------------------- */

/* Eq 3 for one instance: y minimising sum_i (f_i - G_y(q_i) L_i)^2 with
 * G_y(q) = y0 + y1 qx + y2 qy + y3 qz, over n points q (3 each), f and L
 * (L NULL: 1).  Centred on the points' mean, with a tiny ridge on the
 * gradient (a flat card leaves its normal direction free).  Returns 0
 * when the system is empty (y = (1, 0, 0, 0)). */
int obs__bake_eq3_fit(const float *q, const double *f, const double *L, size_t n, double y[4]);

/* Which instances of w take the instanced path (parameters instanced,
 * instanced_min; classes from dc): sel[i] 1 for those.  Returns their
 * count. */
size_t obs__bake_instanced_select(const obs_bake_scene *s, const obs__bake_world *w,
                                  const obs__bake_decor *dc, const obs_bake_params *p,
                                  uint8_t *sel);
/* Their faces get no surface samples in the level (area 0: samples.c
 * gives none, fit.c pins their vertices) nor a share of the sample
 * budget (counted in w->degenerate); the BVH keeps them. */
void obs__bake_instanced_mask(obs__bake_world *w, const uint8_t *sel);
/* The fit's counts of vertices without samples and isolated ones (st)
 * less the welded vertices that only selected instances hold: those have
 * no samples by design (obs__bake_instanced_mask), not by accident. */
void obs__bake_instanced_uncount(const obs__bake_world *w, const obs__bake_weld *wd,
                                 const uint8_t *sel, obs_bake_stats *st);
/* The local AO of mesh m of s baked alone in its own space, the steps of
 * the pipeline on a scene of that one mesh (bake.c, which hands it in so
 * that the pipeline and this step do not call each other): 2 values per
 * vertex, short and long, into out. */
typedef obs_status (*obs__bake_alone_fn)(const obs_bake_scene *s, uint32_t m,
                                         const obs_bake_params *p, double *out,
                                         char err[OBS_ERR_LEN]);

/* The model of section 2.2 for the selected instances: the local AO of
 * each of their meshes baked alone (samples, trace, fit), the volume
 * around them traced in the whole level, eq 3 per instance; their
 * results in out replaced (ao, ao_short, ao_long, ao_local, global) and
 * the stats filled; local_ao bakes each mesh alone.  desc's progress
 * callback (may be NULL) is called with (samples, samples) between the
 * meshes and during the volume's trace; nonzero stops the bake with
 * OBS_CANCELLED. */
obs_status obs__bake_instanced_run(const obs_bake_scene *s, const obs__bake_world *w,
                                   const uint8_t *sel, const obs_bake_params *p,
                                   const obs_bake_desc *desc, size_t samples,
                                   const obs__bake_decor *dc, obs__bake_alone_fn local_ao,
                                   obs_bake_result *out, char err[OBS_ERR_LEN]);

#endif
