/* CPU twin of luminance sensitivity (VAO++ section 4.3, eq 3; GLSL:
 * luminance.frag.glsl).  Same arithmetic in the same order as the shader;
 * tests/unit/core/test_luminance.c checks eq 3 against a table computed
 * by hand and the GL pass against this one. */
#include <math.h>

#include "chain/frame.h"

float obs__luminance_factor(const obs__frame *f, const float rgb[3])
{
    /* lum(x): Rec. 709 luminance, or "the V component of the HSV color
     * model" (max of r, g, b), "less dependent on the hue". */
    float lum = f->luminance == 2 ? fmaxf(rgb[0], fmaxf(rgb[1], rgb[2]))
                                  : 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2];
    /* Eq 3: AO_L = AO (1 - min(1, max(0, lum - threshold + width)) / (2 width))^sigma.
     * As printed, min(1, .) clamps the numerator before the division, so
     * for width < 0.5 the base turns negative above lum = threshold +
     * width, where pow is undefined; the base is clamped at 0 there (the
     * occlusion is gone), which is the only change to the printed form.
     * The AO of eq 3 is the occlusion (it vanishes for bright pixels), so
     * our AO, 1 = unoccluded, is corrected as 1 - (1 - AO) * factor. */
    float t = fminf(1.0f, fmaxf(0.0f, lum - f->lum_threshold + f->lum_width));
    float base = 1.0f - t / (2.0f * f->lum_width);
    return base > 0.0f ? powf(base, f->lum_sigma) : 0.0f;
}

float obs__luminance_ao(const obs__frame *f, float ao, const float rgb[3])
{
    return 1.0f - (1.0f - ao) * obs__luminance_factor(f, rgb);
}
