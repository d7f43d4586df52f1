/* Large instanced decorators (section 2.2 of "Baked ambient obscurance on
 * the vertices of game levels"): the per-instance model, a local AO per
 * mesh times a linear global AO fitted by eq 3 (instanced.c), read from
 * the sparse volume of spherical visibility around them (volume.h). */
#ifndef OBSCURA_BAKE_INSTANCED_H
#define OBSCURA_BAKE_INSTANCED_H

#include <stddef.h>
#include <stdint.h>

#include "bake/bake_internal.h"
#include "level/decor.h"

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
