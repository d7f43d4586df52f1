/* Method angle: the angle-based paired-sample SSAO of
 * shared/papers/angle-based-ssao.txt (after the SSAO of Epic's Elemental
 * demo), with the per-pixel normal.  The CPU twin of angle.glsl.
 *
 * Samples come in pairs, two opposite points of a disk of radius R (the
 * AO distance) through the point p, perpendicular to the view axis; each
 * reads the surface point x seen at its pixel.  For a pair (left, right)
 * with theta the angle between the normal and x - p, the pair's AO is
 *   min((theta_left + theta_right) / pi, 1)
 * (a plane: both pi/2, AO 1; an occluder bends a vector towards the
 * normal).  A sample whose depth differs from p's by more than R is "too
 * far away": it is replaced by the point on the plane of p and the other
 * sample, 2p - x_other (the article's pink point), interpolated by how
 * far it is, and the pair's weight is 1 with both samples near, 0.5 with
 * one far, 0 with both far; the result is the weighted mean. */
#include <math.h>

#include "chain/mask_weight.h"
#include "methods/angle.h"
#include "methods/bent.h"

/* Radical inverse of i in base 2. */
static double radical_inverse2(unsigned i)
{
    double f = 0.5, r = 0.0;
    for (; i; i >>= 1, f *= 0.5)
        r += f * (double)(i & 1u);
    return r;
}

/* Pair i of n: direction pi i / n (the partner covers the other half of
 * the circle), distance sqrt(radical_inverse2(i) + 1/2n) of the radius
 * (uniform in area, decorrelated from the direction): "nearly uniform
 * distributed", the article's pattern, with the 3x3 tile's rotation as
 * the jitter. */
void obs__angle_pattern(int pairs, float *out)
{
    for (int i = 0; i < pairs && i < OBS_MAX_PAIRS; i++) {
        double a = M_PI * i / pairs;
        double r = sqrt(fmin(1.0, radical_inverse2((unsigned)i) + 0.5 / pairs));
        out[2 * i] = (float)(r * cos(a));
        out[2 * i + 1] = (float)(r * sin(a));
    }
}

/* GLSL: acos_mode() in angle.glsl.  The article's approximations of the
 * arc cosine: linear pi (1 - x) / 2 (maximum error 18.946 degrees) and
 * quadratic pi (1 - sign(x) x^2) / 2 (9.473 degrees). */
float obs__acos_mode(int mode, float x)
{
    x = fminf(1.0f, fmaxf(-1.0f, x));
    if (mode == OBS_ACOS_EXACT)
        return acosf(x);
    if (mode == OBS_ACOS_LINEAR)
        return (float)M_PI * (1.0f - x) * 0.5f;
    return (float)M_PI * (1.0f - (x >= 0.0f ? x * x : -x * x)) * 0.5f;
}

/* theta of the article: the angle between n and v (pi/2 for v = 0). */
static float angle_to_normal(const obs__frame *f, const float n[3], const float v[3])
{
    const obs__angle_state *an = obs__angle_of(f);
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    float c = l > 0.0f ? (n[0] * v[0] + n[1] * v[1] + n[2] * v[2]) / l : 0.0f;
    return obs__acos_mode(an->acos, c);
}

/* GLSL: angle_ao() in angle.glsl */
float obs__angle_pixel(const obs__frame *f, const float *pos, int x, int y, const float p[4],
                       const float n[3])
{
    return obs__angle_pixel_bent(f, pos, x, y, p, n, NULL);
}

float obs__angle_pixel_bent(const obs__frame *f, const float *pos, int x, int y, const float p[4],
                            const float n[3], float bent[3])
{
    const obs__angle_state *an = obs__angle_of(f);
    const float R = f->radius;
    const float *rot = f->rot[obs__tile_index(f, x, y)];
    float sum = 0.0f, wsum = 0.0f;
    for (int i = 0; i < an->pairs; i++) {
        const float *a = an->xy[i];
        float ox = R * (rot[0] * a[0] - rot[1] * a[1]), oy = R * (rot[1] * a[0] + rot[0] * a[1]);
        float v[2][3], far[2];
        for (int k = 0; k < 2; k++) {
            float sg = k == 0 ? 1.0f : -1.0f;
            const float s[3] = {p[0] + sg * ox, p[1] + sg * oy, p[2]};
            int qx, qy;
            const float *q = NULL;
            if (obs__view_to_px(f, s, &qx, &qy)) {
                q = pos + 4 * ((size_t)qy * (size_t)f->width + (size_t)qx);
                if (!(q[3] > 0.0f))
                    q = NULL;
            }
            if (!q) { /* off the image or background: far, no point */
                v[k][0] = v[k][1] = v[k][2] = 0.0f;
                far[k] = 1.0f;
                continue;
            }
            for (int j = 0; j < 3; j++)
                v[k][j] = q[j] - p[j];
            /* "too far away": a depth difference over R, fully so from 2R */
            far[k] = fminf(1.0f, fmaxf(0.0f, fabsf(q[3] - p[3]) / R - 1.0f));
            /* object masks: a surface that may not occlude counts as far */
            far[k] += (1.0f - far[k]) * (1.0f - obs__occluder_weight(f, x, y, qx, qy));
        }
        /* Pair weight 1 / 0.5 / 0 for none / one / both far (continuous
         * in between); the weights renormalise the mean. */
        float w = 1.0f - 0.5f * (far[0] + far[1]);
        if (!(w > 0.0f))
            continue;
        float th = 0.0f;
        for (int k = 0; k < 2; k++) {
            /* a far sample moves towards the coplanar point 2p - x_other:
             * the vector towards -v_other */
            float u[3];
            for (int j = 0; j < 3; j++)
                u[j] = v[k][j] + far[k] * (-v[1 - k][j] - v[k][j]);
            float thk = angle_to_normal(f, n, u);
            th += thk;
            if (bent) /* OBS_OUTPUT_BENT: the open arc on u's side */
                obs__angle_bent_side(n, u, thk, w, bent);
        }
        sum += w * fminf(th / (float)M_PI, 1.0f); /* min((theta_l + theta_r) / pi, 1) */
        wsum += w;
    }
    return wsum > 0.0f ? sum / wsum : 1.0f;
}

void obs__angle_setup(const obs_params *p, obs__frame *f)
{
    obs__angle_state *s = (obs__angle_state *)(void *)f->ms.bytes;
    s->pairs = p->angle_pairs;
    obs__angle_pattern(s->pairs, &s->xy[0][0]);
    s->acos = p->angle_acos;
}
