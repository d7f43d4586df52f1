/* Colour bleeding, VAO++ section 4.7, eq 5 (GLSL: bleed_weight() in
 * vao.glsl).  The estimator (obs__vao_estimate_bleed in vao_cpu.c) calls
 * it for every bleed_step-th sample. */
#include <math.h>

#include "chain/frame.h"

/* Eq 5: c(x) = max(0, (x - p).n / |x - p|) (1 - |x - p| / radius)^2.
 * x is the view-space point the depth buffer holds at the sample's pixel
 * (the paper uses the samples "regardless of whether they lie on the
 * surface": the visible surface there, which may be in front of or far
 * behind the sample).  As printed, (1 - |x-p|/radius)^2 grows again past
 * 2 radius, so a far background would bleed more than a near wall; the
 * falloff is clamped at 0 from |x - p| = radius on.  x = p gives 0. */
float obs__bleed_weight(const float x[3], const float p[3], const float n[3], float R)
{
    float dx = x[0] - p[0], dy = x[1] - p[1], dz = x[2] - p[2];
    float len = sqrtf(dx * dx + dy * dy + dz * dz);
    if (!(len > 0.0f))
        return 0.0f;
    float cosv = (dx * n[0] + dy * n[1] + dz * n[2]) / len;
    float fall = fmaxf(0.0f, 1.0f - len / R);
    return fmaxf(0.0f, cosv) * fall * fall;
}
