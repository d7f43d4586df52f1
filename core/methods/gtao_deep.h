/* Method gtao on deep input with intervals (gtao_deep.c): each slice's
 * visibility over its free arcs.  Not installed. */
#ifndef OBSCURA_METHODS_GTAO_DEEP_H
#define OBSCURA_METHODS_GTAO_DEEP_H

#include <math.h>

#include "chain/frame.h"
#include "obscura/deep.h"

/* The free depth ranges of one step's column (its pixel's ray): at most
 * one before each closed interval (which takes a front face and its back
 * face). */
#define OBS__GTAO_MAX_GAPS (OBS_DEEP_MAX_LAYERS / 2 + 1)
/* The most occupied arcs one side of a slice can hold: gtao_steps'
 * largest value (32, the parameter table) times a column's closed
 * intervals and the arcs where its free ranges and the previous
 * column's cross (two sorted lists of ranges: at most 2
 * OBS__GTAO_MAX_GAPS - 1).  GLSL: GT_MAX_ARCS in gtao.glsl. */
#define OBS__GTAO_MAX_ARCS (32 * (OBS_DEEP_MAX_LAYERS / 2 + 2 * OBS__GTAO_MAX_GAPS - 1))

/* One side of a slice: its occupied arcs as angles from the view vector
 * v (0 .. pi, the side's own sign left out), sorted by their near end;
 * the free depth ranges z of the last column read, each with the cosines
 * of its ends' angles (true angles: where rays cross; cosines until an
 * arc needs them, gtao_deep.c). */
typedef struct obs__gtao_side {
    int n, gaps;
    float lo[OBS__GTAO_MAX_ARCS], hi[OBS__GTAO_MAX_ARCS];
    float z[OBS__GTAO_MAX_GAPS][2], t[OBS__GTAO_MAX_GAPS][2];
    /* the cosines of the angles where the last column's ray lies within
     * the radius; until an arc needs them (win_at 1 or 2) that column's
     * pixel wq and (win_at 2) its ray wo + s wd */
    float win[2], wo[3], wd[3];
    int win_at, wq[2];
} obs__gtao_side;

/* Starts a side at the centre c: no arcs; the centre's column is the
 * free range in front of it (planar depths z0 .. -c z), where every ray
 * leaving c starts. */
void obs__gtao_side_start(obs__gtao_side *s, const float c[3], float z0);

/* Where the free range in front of the receiver node `self` starts in
 * its own column (q, end: its pixel's nodes and interval ends, plane
 * floats apart, as obs__gtao_column reads them): the depth of the
 * nearest surface in front of it, the back face of an interval or a
 * node solid behind it; 0 for the front node. */
float obs__gtao_centre_start(const float *q, const float *end, size_t plane, int self);

/* The column of one step at pixel (qx, qy) (fw: method gtao's falloff
 * mul and add and gtao_thin, obs__gtao_state's; (x, y, self): the
 * receiver's pixel and node, for the object masks): `layers` nodes at q,
 * q + plane floats, ... (view xyz, planar depth w; w 0 empty) with their
 * interval ends at end[0], end[plane / 4], ... (obs__deep_intervals; end
 * NULL: all solid behind them).  Adds the arcs of its closed intervals
 * and those where a ray passes from a free range of the previous column
 * to one of this column without a depth in common; returns the highest
 * falloff-weighted horizon cosine of its nodes solid behind them (low:
 * none), as side_horizon in gtao.c takes it.  layers 0: a column with no
 * surface (background, or off the image with no estimate).  GLSL:
 * gtao_column in gtao.glsl. */
float obs__gtao_column(const obs__frame *f, const float fw[3], obs__gtao_side *s, const float *q,
                       const float *end, size_t plane, int layers, int x, int y, int self, int qx,
                       int qy, const float c[3], const float v[3], float low);

/* A_slice / |n_p| over the free arcs: the inner integral of Jimenez et
 * al. (the closed form gtao.c cites) over the part of [h0, h1] (the
 * horizons of the nodes solid behind them, clamped to n's hemisphere)
 * that no arc of s0 (the side of h1, dir +1) or s1 (the side of h0)
 * occupies.  With no arcs, a(h0) + a(h1) exactly (GLSL: gtao_side_free
 * in gtao.glsl). */
float obs__gtao_slice_free(const obs__gtao_side *s0, const obs__gtao_side *s1, float h0, float h1,
                           float gamma, float cos_g);

/* a(h): the closed form of a slice side's inner integral from the view
 * vector to the angle h (Jimenez et al. 2016, Algorithm 1; the header of
 * gtao.c), gamma the projected normal's angle, cos_gamma its cosine.
 * GLSL: gtao_arc() in gtao.glsl. */
static inline float obs__gtao_arc(float h, float gamma, float cos_gamma)
{
    return (cos_gamma + 2.0f * h * sinf(gamma) - cosf(2.0f * h - gamma)) / 4.0f;
}

#endif
