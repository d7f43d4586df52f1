/* LODs of the bake (paper 2.2.1): the pieces lod.c puts together, apart
 * for the tests.  simplify.c makes a level of a mesh with meshoptimizer;
 * closest.c finds the nearest point of an instance's full-detail surface;
 * lod.c resamples the full-detail bake there and fits the LOD's vertices
 * (eq 2). */
#ifndef OBSCURA_BAKE_LOD_H
#define OBSCURA_BAKE_LOD_H

#include "bake/bake_internal.h"

/* Level `level` (>= 1) of mesh m: m welded with the bake's own weld
 * (tolerance and angle as the weld_* parameters, within the mesh), then
 * meshopt_simplify towards ratio^level of its triangles with the error
 * bound level x error (relative to the mesh's extent; lock_border: the
 * vertices of the welded mesh's open border stay), then compacted to
 * the vertices it uses (each the first of its weld group: position and
 * normal unchanged).  out->name is m's with "_LOD<level>"; never empty
 * when m has a triangle of nonzero area.  Free with obs__bake_mesh_free
 * (level.h). */
obs_status obs__bake_simplify(const obs_bake_mesh *m, int level, float ratio, float error,
                              int lock_border, float weld_tolerance, float weld_angle,
                              obs_bake_mesh *out, char err[OBS_ERR_LEN]);

/* The triangles [first, first + count) of a world, for nearest-point
 * queries (closest.c; a bounding-volume hierarchy of its own: Embree's
 * rtcPointQuery would need the same point-triangle routine as a
 * callback, and a scene per instance). */
typedef struct obs__bake_closest obs__bake_closest;
obs_status obs__bake_closest_new(const obs__bake_world *w, size_t first, size_t count,
                                 obs__bake_closest **out, char err[OBS_ERR_LEN]);
void obs__bake_closest_free(obs__bake_closest *c);
/* The nearest point of those triangles (degenerate ones skipped) to p:
 * its triangle (-1 when every triangle is degenerate) and barycentric
 * weights; returns the squared distance. */
double obs__bake_closest_query(const obs__bake_closest *c, const float p[3], int64_t *tri,
                               float bary[3]);
/* The nearest point of triangle (a, b, c) to p as barycentric weights
 * (a = bary[0] ...); returns the squared distance. */
double obs__bake_closest_tri(const float p[3], const float a[3], const float b[3],
                             const float c[3], float bary[3]);

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
