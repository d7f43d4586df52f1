/* Method hbao (hbao.c, hbao.glsl): its own values in the frame and its
 * functions.  Not installed. */
#ifndef OBSCURA_METHOD_HBAO_H
#define OBSCURA_METHOD_HBAO_H

#include "chain/frame.h"

/* Directions (unit, view xy), steps, the angle bias. */
typedef struct obs__hbao_state {
    int dirs, steps;
    float dir[OBS_MAX_DIRECTIONS][2];
    float bias_cs[2]; /* cos, sin of the angle bias */
} obs__hbao_state;
_Static_assert(sizeof(obs__hbao_state) <= OBS__METHOD_STATE_BYTES, "fits obs__frame.ms");

static inline const obs__hbao_state *obs__hbao_of(const obs__frame *f)
{
    return (const obs__hbao_state *)(const void *)f->ms.bytes;
}

/* Fills the frame's method values from the resolved parameters. */
void obs__hbao_setup(const obs_params *p, obs__frame *f);

/* Horizon-based AO of the point p with normal n at pixel (x, y), marched
 * from that pixel (GLSL: hbao.glsl).  The count of depth samples read
 * goes to *count when count is not NULL. */
float obs__hbao_pixel(const obs__frame *f, const float *pos, int x, int y, const float p[3],
                      const float n[3], int *count);
/* obs__hbao_pixel that also sums the bent normal of its directions into
 * bent[3] (NULL: not wanted; obs__hbao_bent_span, bent.c). */
float obs__hbao_pixel_bent(const obs__frame *f, const float *pos, int x, int y, const float p[3],
                           const float n[3], int *count, float bent[3]);

/* The same over `layers` planes of positions (pos, then pos + 4 w h, ...:
 * deep input's nodes, core/deep): at each step every node at its pixel,
 * front to back, raises the horizon where it lies above it (OITAO's
 * multi-layer HBAO, Fig. 9).  self: the receiver's node at (x, y), whose
 * object self_only compares (object masks, obs__occluder_weight_node). */
float obs__hbao_pixel_nodes(const obs__frame *f, const float *pos, int layers, int self, int x,
                            int y, const float p[3], const float n[3], int *count);

#endif
