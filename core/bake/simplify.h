/* A LOD of a mesh (paper 2.2.1) made with meshoptimizer (simplify.c;
 * lod.c asks for it when the file has none). */
#ifndef OBSCURA_BAKE_SIMPLIFY_H
#define OBSCURA_BAKE_SIMPLIFY_H

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

#endif
