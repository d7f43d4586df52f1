/* The one weight of the object masks at a sample site (parameters
 * occluders and self_only, core/mask.c): what a method multiplies a
 * sample's occlusion by.  GLSL twins: occluder_weight() in common.glsl
 * (the flat chain), node_weight() in deep.frag.glsl (deep input's
 * nodes).  Not installed. */
#ifndef OBSCURA_MASK_WEIGHT_H
#define OBSCURA_MASK_WEIGHT_H

#include <string.h>

#include "chain/frame.h"

/* The weight of node sk at pixel (sx, sy) as an occluder of node ck at
 * pixel (cx, cy): the occluders coverage of that surface (1 without the
 * mask), times 0 where self_only's object there is not the receiver's.
 * The flat chain has one node a pixel (f->mask_plane 0: every k reads
 * the one plane); deep input one weight and one object per kept node
 * (core/deep).  A sample off the image reads the nearest pixel on it
 * (the border continues that surface, border_cpu.c).  1 without masks. */
static inline float obs__occluder_weight_node(const obs__frame *f, int cx, int cy, int ck, int sx,
                                              int sy, int sk)
{
    if (!f->mask_on)
        return 1.0f;
    sx = sx < 0 ? 0 : sx >= f->width ? f->width - 1 : sx;
    sy = sy < 0 ? 0 : sy >= f->height ? f->height - 1 : sy;
    size_t s = (size_t)sk * f->mask_plane + (size_t)sy * (size_t)f->width + (size_t)sx;
    float w = f->mask_occl ? f->mask_occl[s] : 1.0f;
    if (f->mask_id) {
        size_t c = (size_t)ck * f->mask_plane + (size_t)cy * (size_t)f->width + (size_t)cx;
        /* IDs compared as bits: a Cryptomatte ID is a hash stored as a float */
        if (memcmp(&f->mask_id[s], &f->mask_id[c], sizeof(float)) != 0)
            w = 0.0f;
    }
    return w;
}

/* The flat chain's: the surface seen at pixel (sx, sy) as an occluder of
 * the pixel (cx, cy). */
static inline float obs__occluder_weight(const obs__frame *f, int cx, int cy, int sx, int sy)
{
    return obs__occluder_weight_node(f, cx, cy, 0, sx, sy, 0);
}

#endif
