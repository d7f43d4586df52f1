/* LODs of the bake (paper 2.2.1): lod.c takes each mesh's levels from
 * the file or from simplify.h, resamples the full-detail bake at the
 * nearest point of an instance's full-detail surface (closest.h) and fits
 * the LOD's vertices (eq 2). */
#ifndef OBSCURA_BAKE_LOD_H
#define OBSCURA_BAKE_LOD_H

#include "bake/bake_internal.h"

/* The resampling of 2.2.1: each sample of ls (on the LOD world lw, whose
 * instance i is full's instance i at a lower level) takes the full-detail
 * signal x (2 values per welded vertex of fwd, short and long) at the
 * nearest point of the same instance's full-detail surface, interpolated
 * from its vertex values; every sample valid.  vertex (may be NULL): 2
 * values per vertex of lw, the same signal at the vertex's nearest point
 * (the baseline "sampling at the LOD's vertices").  On `threads` threads
 * (0: every core), instance by instance; the result does not depend on
 * their number. */
obs_status obs__bake_lod_resample(const obs__bake_world *full, const obs__bake_weld *fwd,
                                  const double *x, const obs__bake_world *lw,
                                  obs__bake_samples *ls, double *vertex, int threads,
                                  char err[OBS_ERR_LEN]);


/* The lod stage (bake.c calls it after the full-detail fit): every level
 * of every mesh, resampled and fitted; fills out's lod_* fields and
 * stats. */
obs_status obs__bake_lods(const obs_bake_scene *scene, const obs__bake_world *w,
                          const obs__bake_weld *wd, const double *x, const obs_bake_params *p,
                          obs_bake_result *out, char err[OBS_ERR_LEN]);
/* Frees out's lod_* fields. */
void obs__bake_lods_free(obs_bake_result *out);

#endif
