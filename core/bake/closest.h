/* Nearest points of an instance's full-detail surface (closest.c; lod.c
 * resamples the full-detail bake there, paper 2.2.1). */
#ifndef OBSCURA_BAKE_CLOSEST_H
#define OBSCURA_BAKE_CLOSEST_H

#include "bake/bake_internal.h"

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

#endif
