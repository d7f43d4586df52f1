/* The bent normal of method gtao's slices (OBS_OUTPUT_BENT): the
 * cosine-weighted mean of the unoccluded directions between a slice's
 * horizons, in closed form: Jimenez et al. 2016, "Practical real-time
 * strategies for accurate indirect occlusion", Algorithm 2 ("extension
 * that computes bent normals b"), as XeGTAO computes it (XeGTAO.hlsli,
 * XeGTAO_MainPass under XE_GTAO_COMPUTE_BENT_NORMALS):
 *
 *   t0 = (6 sin(h0 - g) - sin(3 h0 - g) + 6 sin(h1 - g) - sin(3 h1 - g)
 *         + 16 sin g - 3 (sin(h0 + g) + sin(h1 + g))) / 12
 *   t1 = (-cos(3 h0 - g) - cos(3 h1 - g) + 8 cos g
 *         - 3 (cos(h0 + g) + cos(h1 + g))) / 12
 *
 * g the projected normal's angle from v, the slice's bent normal
 * |n_p| (t0 od + t1 v), od the slice's unit direction orthogonal to v:
 * XeGTAO writes (dir t0, -t1) and rotates -z onto v, which for its
 * camera is the same frame; ours looks down -Z with v towards the
 * camera, so the frame is written out.  Summed over the slices, then
 * normalised by the caller.  GLSL twin: gtao_bent_slice in method.glsl. */
#include <math.h>

#include "methods/bent.h"

void obs__gtao_bent_slice(float h0, float h1, float gamma, float np_len, const float od[3],
                          const float v[3], float acc[3])
{
    float t0 = (6.0f * sinf(h0 - gamma) - sinf(3.0f * h0 - gamma) + 6.0f * sinf(h1 - gamma) -
                sinf(3.0f * h1 - gamma) + 16.0f * sinf(gamma) -
                3.0f * (sinf(h0 + gamma) + sinf(h1 + gamma))) / 12.0f;
    float t1 = (-cosf(3.0f * h0 - gamma) - cosf(3.0f * h1 - gamma) + 8.0f * cosf(gamma) -
                3.0f * (cosf(h0 + gamma) + cosf(h1 + gamma))) / 12.0f;
    float l = sqrtf(od[0] * od[0] + od[1] * od[1] + od[2] * od[2]);
    float s = l > 0.0f ? 1.0f / l : 0.0f;
    for (int k = 0; k < 3; k++)
        acc[k] += np_len * (t0 * od[k] * s + t1 * v[k]);
}
