/* Method hemisphere (hemisphere.c, hemisphere.glsl): its own values in the
 * frame and its functions.  Not installed. */
#ifndef OBSCURA_METHOD_HEMISPHERE_H
#define OBSCURA_METHOD_HEMISPHERE_H

#include "chain/frame.h"

/* The kernel, unit hemisphere around +z, scaled by radius at use. */
typedef struct obs__hemisphere_state {
    int count;
    float bias; /* in depth units: hemisphere_bias * R */
    float kernel[OBS_MAX_HEMISPHERE][3];
} obs__hemisphere_state;
_Static_assert(sizeof(obs__hemisphere_state) <= OBS__METHOD_STATE_BYTES, "fits obs__frame.ms");

static inline const obs__hemisphere_state *obs__hemisphere_of(const obs__frame *f)
{
    return (const obs__hemisphere_state *)(const void *)f->ms.bytes;
}

/* Fills the frame's method values from the resolved parameters. */
void obs__hemisphere_setup(const obs_params *p, obs__frame *f);

/* The unit-hemisphere kernel of n samples (n <= OBS_MAX_HEMISPHERE),
 * 3 floats each, around +z. */
void obs__hemisphere_kernel(int n, float *out);

/* Method hemisphere's kernel (GLSL: hemisphere.glsl): the view-space
 * position s of kernel sample i for the point p with normal n at pixel
 * (x, y), the kernel's +z turned to n and rotated by the pixel's 3x3 tile
 * rotation.  obs__hemisphere_basis() gives the tangent frame t1, t2 once
 * per pixel. */
void obs__hemisphere_basis(const float n[3], float t1[3], float t2[3]);
void obs__hemisphere_sample(const obs__frame *f, int x, int y, const float p[3], const float n[3],
                            const float t1[3], const float t2[3], int i, float s[3]);

/* The nodes the hemisphere estimator tests its samples against: layers
 * planes of layer_px pixels, 4 floats each (view xyz, planar depth w; 0:
 * empty), one after the other; nrm: the same layout with alpha in w (NULL:
 * opaque); interior: OITAO eqs 2-4's back side, where a node on the
 * exterior side of p's tangent plane hides nothing; self: the receiver's
 * node at (x, y), whose object self_only compares (object masks,
 * obs__occluder_weight_node).  The flat chain's prep plane is one layer. */
typedef struct obs__hemisphere_nodes {
    const float *pos, *nrm;
    const float *end; /* NULL, or the nodes' ends (deep_internal.h): a node
                       * with end < 0 (inside a nearer node's interval)
                       * occludes nothing */
    int layers;
    size_t layer_px;
    int interior;
    int self;
} obs__hemisphere_nodes;

/* Method hemisphere's estimator, for the flat and the deep chain alike. */
float obs__hemisphere_estimate(const obs__frame *f, const obs__hemisphere_nodes *nodes, int x,
                               int y, const float p[3], const float n[3]);
/* obs__hemisphere_estimate that also sums the bent normal of its samples
 * into bent[3] (NULL: not wanted; obs__hemisphere_bent_sample, bent.c). */
float obs__hemisphere_estimate_bent(const obs__frame *f, const obs__hemisphere_nodes *nodes, int x,
                                    int y, const float p[3], const float n[3], float bent[3]);

/* Normal-oriented hemisphere SSAO of the point p (xyz; planar depth in
 * p[3] is not needed) with normal n at pixel (x, y); `pos` is the prep
 * pass's position plane (GLSL: hemisphere.glsl). */
float obs__hemisphere_pixel(const obs__frame *f, const float *pos, int x, int y, const float p[3],
                            const float n[3]);
float obs__hemisphere_pixel_bent(const obs__frame *f, const float *pos, int x, int y,
                                 const float p[3], const float n[3], float bent[3]);

#endif
