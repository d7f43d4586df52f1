/* The bent normals of the comparison methods (OBS_OUTPUT_BENT).  gtao's slices: the
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

/* Method hemisphere's bent normal: the estimator counts every kernel
 * sample alike (AO = 1 - mean occlusion; the kernel's directions are
 * uniform in solid angle around n, obs__hemisphere_kernel), so the mean
 * unoccluded direction is the sum of the samples' unit directions
 * (s - p) / |s - p|, each times its open part 1 - occlusion (a sample the
 * AO leaves out, off the planes, counts as open, as in the AO's mean).
 * An open plane: the hemisphere's mean direction, n.  GLSL twin:
 * hemisphere_bent_sample in hemisphere.glsl. */
void obs__hemisphere_bent_sample(const float p[3], const float s[3], float open, float acc[3])
{
    float d[3] = {s[0] - p[0], s[1] - p[1], s[2] - p[2]};
    float l = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(l > 0.0f))
        return;
    for (int k = 0; k < 3; k++)
        acc[k] += open * d[k] / l;
}

/* Method angle's bent normal: a pair's AO is its open angle over pi,
 * (theta_l + theta_r) / pi, the arc of the pair's plane from each
 * sample's vector u over the normal, each angle counted alike (uniform in
 * angle).  The arc from n to u's side, theta long, has the angle-weighted
 * direction sum
 *   Int_0^theta (cos a n + sin a t) da = sin theta n + (1 - cos theta) t,
 * t the unit vector of u orthogonal to n (0 where u lies along n or is
 * 0); the pair adds both sides' times its weight w.  An open plane: theta
 * = pi/2 on both sides, t_l = -t_r, so 2 w n.  theta is the method's own
 * (its arc cosine mode).  GLSL twin: angle_bent_side in angle.glsl. */
void obs__angle_bent_side(const float n[3], const float u[3], float theta, float w, float acc[3])
{
    float un = u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
    float t[3] = {u[0] - un * n[0], u[1] - un * n[1], u[2] - un * n[2]};
    float l = sqrtf(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    float s = l > 0.0f ? (1.0f - cosf(theta)) / l : 0.0f;
    for (int k = 0; k < 3; k++)
        acc[k] += w * (sinf(theta) * n[k] + s * t[k]);
}

/* Method hbao's bent normal.  HBAO's integral, 1/(2 pi) Int Int W cos a
 * da dtheta over the elevations a from the tangent t(theta) to the
 * horizon h(theta), is a solid-angle integral (cos a da dtheta is the
 * solid angle around the view axis): each direction counts alike.  The
 * open directions of direction e (view xy, unit) are the elevations from
 * t to pi/2 less the occluded steps, each step from h_(i-1) to h_i
 * counting W(r_i) occluded, as in the AO's sum.  The direction of (e, a)
 * is cos a e + sin a z (z: view +z, the axis HBAO measures elevation
 * from), and its solid-angle sum over a in [a0, a1] is
 *   Int cos a (cos a e + sin a z) da
 *     = ((a1 - a0) / 2 + (sin 2 a1 - sin 2 a0) / 4) e + (sin^2 a1 - sin^2 a0) / 2 z,
 * added here times w (1 for the open span t..pi/2, -W(r_i) for a step).
 * The elevations come as sines (HBAO's sin h).  An open surface: the
 * hemisphere above its tangent plane, whose mean direction is n.  GLSL
 * twin: hbao_bent_span in hbao.glsl. */
void obs__hbao_bent_span(float dx, float dy, float sin0, float sin1, float w, float acc[3])
{
    float a0 = asinf(fminf(1.0f, fmaxf(-1.0f, sin0))), a1 = asinf(fminf(1.0f, fmaxf(-1.0f, sin1)));
    float along = (a1 - a0) * 0.5f + (sinf(2.0f * a1) - sinf(2.0f * a0)) * 0.25f;
    float up = (sin1 * sin1 - sin0 * sin0) * 0.5f;
    acc[0] += w * along * dx;
    acc[1] += w * along * dy;
    acc[2] += w * up;
}
