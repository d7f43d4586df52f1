/* The obscurance kernel of the bake and the ray set it is estimated with,
 * as inline functions, so that the per-pixel reference of the same
 * quantity (core/ground/obscurance.c) evaluates eq 1 of the paper exactly
 * as the bake's samples do (core/bake/trace.c):
 *
 *   AO(p) = 1/pi  integral over the hemisphere of rho(d(p, w)) cos(theta) dw,
 *   rho(x) = 1 - exp(a x),  a = ln(0.5) / d   (section 2)
 *
 * d(p, w) the distance to the closest hit; a miss counts rho = 1.  The
 * directions are cosine-weighted (pdf cos(theta) / pi), so AO is the mean
 * of rho over the rays. */
#ifndef OBSCURA_BAKE_KERNEL_H
#define OBSCURA_BAKE_KERNEL_H

#include <math.h>

/* Rays stop at this many long distances: rho is within 2^-16 of 1. */
#define OBS__BAKE_RAY_LENGTH_FACTOR 16.0f

/* a = ln(0.5) / d: the kernel halves visibility at distance d. */
static inline float obs__bake_kernel_a(float d)
{
    return logf(0.5f) / d;
}

/* rho(x) = 1 - exp(a x) of a hit at distance x (eq 1, section 2). */
static inline double obs__bake_rho(float a, float x)
{
    return 1.0 - exp((double)a * x);
}

/* An orthonormal tangent frame around unit n (Frisvad 2012, with the
 * n.z = -1 case handled by symmetry). */
static inline void obs__bake_frame(const float n[3], float t[3], float b[3])
{
    if (n[2] < -0.9999999f) {
        t[0] = 0.0f, t[1] = -1.0f, t[2] = 0.0f;
        b[0] = -1.0f, b[1] = 0.0f, b[2] = 0.0f;
        return;
    }
    float a = 1.0f / (1.0f + n[2]), c = -n[0] * n[1] * a;
    t[0] = 1.0f - n[0] * n[0] * a, t[1] = c, t[2] = -n[0];
    b[0] = c, b[1] = 1.0f - n[1] * n[1] * a, b[2] = -n[1];
}

/* Ray k of nr around n (frame t, b): a rank-1 lattice shifted by
 * (o1, o2), both in [0, 1), lifted to the hemisphere by Malley's method
 * (a point of the unit disk): each direction has the cosine density, the
 * set is stratified. */
static inline void obs__bake_lattice_dir(int k, int nr, double o1, double o2, const float n[3],
                                         const float t[3], const float b[3], float d[3])
{
    double u1 = fmod((k + 0.5) / nr + o1, 1.0), u2 = fmod(k * 0.6180339887498949 + o2, 1.0);
    double rad = sqrt(u1), phi = 2.0 * 3.14159265358979323846 * u2;
    float x = (float)(rad * cos(phi)), y = (float)(rad * sin(phi)),
          z = (float)sqrt(fmax(0.0, 1.0 - u1));
    for (int c = 0; c < 3; c++)
        d[c] = x * t[c] + y * b[c] + z * n[c];
}

#endif
