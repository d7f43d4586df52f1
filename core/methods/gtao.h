/* Method gtao (gtao.c, gtao.glsl): its own values in the frame and its
 * functions.  Not installed. */
#ifndef OBSCURA_METHOD_GTAO_H
#define OBSCURA_METHOD_GTAO_H

#include "chain/frame.h"

/* XeGTAO_MainPass's constants (XeGTAO.hlsli, XeGTAO.h) that the CPU
 * device's lanes share (methods_cpu.c); the others are in gtao.c */
#define GTAO_TOO_CLOSE 1.3f        /* pixelTooCloseThreshold: first sample this far, in pixels */
#define GTAO_CENTRE_SCALE 0.99999f /* viewspaceZ *= 0.99999 (FP32 depths) */
#define GTAO_R1 0.6180339887498948482f /* the steps' R1 sequence */
#define GTAO_SLOPE_FUDGE 0.05f     /* projectedNormalVecLength = lerp(len, 1, 0.05) */

/* Slices, steps per side, XeGTAO's heuristics (1: on); the search radius
 * gtao_multiplier * D in depth units; the falloff's weight =
 * saturate(r * mul + add); the thin-occluder compensation and the final
 * power. */
typedef struct obs__gtao_state {
    int slices, steps, heuristics;
    float radius;
    float falloff[2];    /* mul, add */
    float thin_power[2]; /* gtao_thin, gtao_power */
} obs__gtao_state;
_Static_assert(sizeof(obs__gtao_state) <= OBS__METHOD_STATE_BYTES, "fits obs__frame.ms");

static inline const obs__gtao_state *obs__gtao_of(const obs__frame *f)
{
    return (const obs__gtao_state *)(const void *)f->ms.bytes;
}

/* Fills the frame's method values from the resolved parameters. */
void obs__gtao_setup(const obs_params *p, obs__frame *f);

/* Ground-truth-based AO (Jimenez et al., as XeGTAO implements it) of the
 * point p with normal n at pixel (x, y) (GLSL: gtao.glsl); `nrm` is the
 * prep pass's view normal plane (read past the border).  The count of
 * depth samples read inside the image goes to *count when count is not
 * NULL. */
float obs__gtao_pixel(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                      const float p[3], const float n[3], int *count);

/* obs__gtao_pixel_bent over `layers` planes of positions (pos, then
 * pos + 4 w h, ...: deep input's nodes, core/deep): each step's horizon
 * is the largest over the nodes at its pixel (OITAO Algorithm 1, as its
 * multi-layer HBAO, Fig. 9); a step past the border reads the first
 * plane's surface continued, with nrm its normals (3 floats a pixel).
 * self: the receiver's node at (x, y), whose object self_only compares
 * (object masks, obs__occluder_weight_node; the flat chain's: 0).  end
 * (NULL: every node solid behind it): `layers` planes of the nodes'
 * interval ends (obs__deep_intervals, deep_intervals on): each slice's
 * visibility is then that of its free arcs (methods/gtao_deep.c). */
float obs__gtao_pixel_nodes(const obs__frame *f, const float *pos, const float *nrm, int layers,
                            int self, const float *end, int x, int y, const float p[3],
                            const float n[3], int *count, float bent[3]);

/* The noise of the 3x3 tile's pixel `tile` (obs__tile_index): XeGTAO's R2
 * sequence, fract(0.5 + k (0.754877666, 0.569840291)), k = tile;
 * out[0] offsets the slices, out[1] the steps (GLSL: gtao_noise()). */
void obs__gtao_noise(int tile, float out[2]);

/* Parts of obs__gtao_pixel_nodes that the CPU device's lanes share
 * (methods_cpu.c): the slice's screen direction (cos, sin of its angle)
 * from its index and the pixel's noise out[0] (obs__gtao_noise). */
void obs__gtao_slice_dir(const obs__gtao_state *g, int sl, float noise0, float cs[2]);
/* A step of a slice's side at pixel (qx, qy) off the planes, for the
 * pixel (x, y) (its node self on deep input, else 0; centre c, view
 * direction v, the side's start low): the
 * surface continued past the border (border_cpu.c), its horizon cosine
 * into *hc (the larger), *taken counted where it reads a point.  The
 * point (view xyz, planar depth) in ext, returned; NULL where it is
 * background or there is no estimate. */
const float *obs__gtao_border_step(const obs__frame *f, const float *pos, const float *nrm,
                                   int self, int x, int y, int qx, int qy, const float c[3],
                                   const float v[3], float low, float *hc, int *taken,
                                   float ext[4]);

/* The visibility's start (XeGTAO's heuristic for a small radius in pixels)
 * and its end from the slices' sum. */
float obs__gtao_vis0(const obs__gtao_state *g, float rpx);
float obs__gtao_finish(const obs__gtao_state *g, float vis);

/* obs__gtao_pixel that also sums the bent normal of every slice into
 * bent[3] (NULL: not wanted): Jimenez et al.'s Algorithm 2 extension as
 * XeGTAO computes it (obs__gtao_bent_slice, methods/bent.c). */
float obs__gtao_pixel_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                           const float p[3], const float n[3], int *count, float bent[3]);

#endif
