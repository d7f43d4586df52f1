/* The CPU device's kernels in SIMD lanes: the VAO estimator (vao_cpu.c),
 * the prep pass's rows (prep_cpu.c) and the comparison methods
 * (methods_cpu.c).  No GL.  Not installed. */
#ifndef OBSCURA_VAO_CPU_H
#define OBSCURA_VAO_CPU_H

#include <math.h>

#include "chain/frame.h"

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

/* obs__vao_estimate_bleed (the same arithmetic, the same result) reading
 * each sample's depth and view normal z from dnz, the two packed per
 * pixel (dnz[2 k] = pos[4 k + 3], dnz[2 k + 1] = nrm[3 k + 2]): a sample
 * then touches one cache line instead of two, from a plane of 8 bytes a
 * pixel instead of 28.  pos and nrm are read for colour bleeding and for
 * the samples off the planes (the surface continued past the border). */
float obs__vao_estimate_dnz(const obs__frame *f, const float *pos, const float *nrm,
                            const float *dnz, const float *col, int x, int y, const float p[3],
                            const float n[3], int ns, const float *xy, float bleed[3]);

/* obs__vao_count of each of the m pixels px[] (indices into the planes)
 * into n[], the pixels in SIMD lanes (the same counts). */
void obs__vao_counts(const obs__frame *f, const float *pos, const float *nrm, const int *px, int m,
                     int *n);

/* ao[px[j]] = obs__vao_estimate_dnz's AO of each of the m pixels px[]
 * (indices into the planes), all taking the ns samples at xy, without
 * colour bleeding and without object masks (the caller's to rule out):
 * the same results, bit for bit, the pixels in SIMD lanes over the
 * sample set (a tile's pixels at once). */
void obs__vao_estimate_pixels(const obs__frame *f, const float *pos, const float *nrm,
                              const float *dnz, const int *px, int m, int ns, const float *xy,
                              float *ao);

/* obs__cull_prepass (the same result) with the estimator above. */
void obs__cull_prepass_dnz(const obs__frame *f, const float *pos, const float *nrm,
                           const float *dnz, float *est);

/* obs__rays_from_volume of each of the n values at ao, in place, in lanes
 * by polynomials: within 1e-6 of it (3.0e-7 measured over 2^24 inputs),
 * exactly its value at 1 and where it leaves the value unchanged. */
void obs__rays_rows(float *ao, size_t n);

/* obs__blur (the same result, bit for bit) with the depths from dnz;
 * with rays, each row of the vertical pass then converted by
 * obs__rays_from_volume (ao_definition rays, as GL's vertical pass does),
 * in the same sweep.  The two passes fused in bands (blur_cpu.c): the
 * result goes to tmp, not in place; returns the plane that holds it (tmp,
 * or ao where there was no memory for the bands' scratch). */
float *obs__blur_dnz(const obs__frame *f, const float *pos, const float *dnz, float *ao,
                     float *tmp, int rays);

/* The prep pass's rows in lanes (prep_cpu.c), the twins' floats:
 * obs__prep_position of row y's pixels, their raw depths at depth[dc x],
 * into out[4 x]; obs__prep_normal of a row's pixels from the input
 * normals in[nc x] (not for reconstruct_normals) into out[3 x], and,
 * where dnz is not NULL, the packed plane's row from pos (the row's
 * positions) and those normals. */
void obs__prep_position_row(const obs__frame *f, const float *depth, size_t dc, int y, float *out);
void obs__prep_normal_row(const obs__frame *f, const float *pos, const float *in, size_t nc,
                          float *out, float *dnz);

/* The comparison method's AO (obs__method_pixel) of each of the m pixels
 * px[] (indices into the planes, each with geometry) into ao[px[j]], and
 * its sample count into count[px[j]] (count NULL: not wanted), the pixels
 * in SIMD lanes (methods_cpu.c), the same results bit for bit; the flat
 * chain without object masks.  0 (nothing written) where the method has
 * no lanes: the caller then takes obs__method_pixel. */
int obs__method_pixels(const obs__frame *f, const float *pos, const float *nrm, const int *px,
                       int m, float *ao, float *count);

#endif
