/* What the CPU device's SIMD kernels share (vao_cpu.c, prep_cpu.c,
 * methods_cpu.c, blur_cpu.c, cull_cpu.c): the build of each kernel for
 * three instruction sets, and the lanes' forms of fminf, fmaxf, floorf and
 * of the arc sine, arc cosine, sine and cosine (fminf, fmaxf and floorf
 * also for gtao's scalar steps and free arcs, methods/gtao.c and
 * gtao_deep.c, where gcc calls libm for them).  Macros and inline
 * functions only.  No GL.  Not installed. */
#ifndef OBSCURA_LANES_H
#define OBSCURA_LANES_H

#include <math.h>

/* The kernels whose samples or pixels run in SIMD lanes (#pragma omp
 * simd) are built three times, for the baseline (SSE2), AVX2 with FMA
 * (x86-64-v3: gathers, 8 lanes) and AVX-512 (x86-64-v4: 16 lanes), the
 * best the processor has chosen when the library loads (gcc's
 * target_clones, an ifunc).  The same operations in every build (no
 * contraction into FMA: -std=c11 means -ffp-contract=off), so the same
 * results. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define OBS__LANES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define OBS__LANES
#endif

/* fmaxf and fminf as glibc computes them (the other argument when one is
 * NaN, the first when they are equal, so also for +0 and -0), inline:
 * the lanes call them per sample, and gcc calls libm for them. */
static inline __attribute__((always_inline)) float max_f(float a, float b) { return (a >= b) | (b != b) ? a : b; }
static inline __attribute__((always_inline)) float min_f(float a, float b) { return (a <= b) | (b != b) ? a : b; }

/* min_f and max_f of two numbers (neither NaN): the same value, without
 * the NaN test, which nested in a clamp can keep gcc from vectorising */
static inline __attribute__((always_inline)) float min_num(float a, float b)
{
    return a <= b ? a : b;
}
static inline __attribute__((always_inline)) float max_num(float a, float b)
{
    return a >= b ? a : b;
}

/* floorf(v) where the caller needs only its comparisons and its int:
 * through the int conversion, which the lanes have (floorf has no SSE2
 * form); the same value for |v| < 2^23, v itself above (already an
 * integer), NaN kept (it fails every comparison, as floorf's does). */
static inline __attribute__((always_inline)) float floor_lane(float v)
{
    const float t = (float)(int)v; /* garbage for |v| >= 2^31: not selected */
    const float fl = t > v ? t - 1.0f : t;
    return fabsf(v) < 8388608.0f ? fl : v;
}

/* asin(x) for x in [-1, 1], in lanes: Cephes' asinf (S. L. Moshier), its
 * polynomial on [0, 1/2] and asin(x) = pi/2 - 2 asin(sqrt((1 - x) / 2))
 * above; relative error about 2.5e-7 (Cephes' bound).  libm's asinf and
 * acosf are calls, which the lanes cannot make. */
static inline __attribute__((always_inline)) float asin_lane(float x)
{
    const float a = fabsf(x);
    const int big = a > 0.5f;
    const float z = big ? 0.5f * (1.0f - a) : a * a;
    const float s = big ? sqrtf(z) : a;
    const float P = (((4.2163199048e-2f * z + 2.4181311049e-2f) * z + 4.5470025998e-2f) * z +
                     7.4953002686e-2f) * z + 1.6666752422e-1f;
    const float t = s + s * z * P;
    const float r = big ? 1.57079632679489662f - 2.0f * t : t;
    return x < 0.0f ? -r : r;
}

/* acos(x) for x in [-1, 1] in lanes, by asin_lane: 2 asin(sqrt((1 - |x|) /
 * 2)) (or pi less it) for |x| > 1/2, pi/2 - asin(x) below; absolute
 * error about 2e-7. */
static inline __attribute__((always_inline)) float acos_lane(float x)
{
    const float a = fabsf(x);
    const float t = 2.0f * asin_lane(sqrtf(0.5f * (1.0f - a)));
    const float big = x < 0.0f ? 3.14159265358979f - t : t;
    return a > 0.5f ? big : 1.57079632679489662f - asin_lane(x);
}

/* sin(x) (cosine 0) or cos(x) (cosine 1) for |x| < 2^13 in lanes: Cephes'
 * sinf / cosf (S. L. Moshier), x reduced by the multiple k of pi/2
 * nearest it in three parts (DP1 + DP2 + DP3 = pi/2), the quadrant from
 * k, polynomials on [-pi/4, pi/4]; absolute error about 1e-7. */
static inline __attribute__((always_inline)) float sincos_lane(float x, int cosine)
{
    const float kf = x * 0.63661977236758134f;
    const int k = (int)(kf >= 0.0f ? kf + 0.5f : kf - 0.5f);
    const float fk = (float)k;
    const float r = ((x - fk * 1.5703125f) - fk * 4.837512969970703125e-4f) -
                    fk * 7.54978995489188216e-8f;
    const float z = r * r;
    const float sr = r + r * z * ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z -
                                  1.6666654611e-1f);
    const float cr = 1.0f - 0.5f * z +
                     z * z * ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z +
                              4.166664568298827e-2f);
    const int q = (k + cosine) & 3; /* cos x = sin(x + pi/2) */
    const float v = q & 1 ? cr : sr;
    return q & 2 ? -v : v;
}

#endif
