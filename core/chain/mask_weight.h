/* The one weight of the object masks at a sample site (parameters
 * occluders and self_only, core/mask.c): what a method multiplies a
 * sample's occlusion by.  GLSL twin: occluder_weight() in common.glsl.
 * Not installed. */
#ifndef OBSCURA_MASK_WEIGHT_H
#define OBSCURA_MASK_WEIGHT_H

#include <string.h>

#include "chain/frame.h"

/* The weight of the surface seen at pixel (sx, sy) as an occluder of the
 * pixel (cx, cy): its occluders coverage (1 without the mask), times 0
 * where self_only's object there is not the shaded pixel's.  A sample
 * off the image reads the nearest pixel on it (the border continues that
 * surface, border_cpu.c).  1 without masks. */
static inline float obs__occluder_weight(const obs__frame *f, int cx, int cy, int sx, int sy)
{
    if (!f->mask_on)
        return 1.0f;
    sx = sx < 0 ? 0 : sx >= f->width ? f->width - 1 : sx;
    sy = sy < 0 ? 0 : sy >= f->height ? f->height - 1 : sy;
    size_t s = (size_t)sy * (size_t)f->width + (size_t)sx;
    float w = f->mask_occl ? f->mask_occl[s] : 1.0f;
    if (f->mask_id) {
        size_t c = (size_t)cy * (size_t)f->width + (size_t)cx;
        /* IDs compared as bits: a Cryptomatte ID is a hash stored as a float */
        if (memcmp(&f->mask_id[s], &f->mask_id[c], sizeof(float)) != 0)
            w = 0.0f;
    }
    return w;
}

#endif
