/* The CPU device's kernels in SIMD lanes (chain/lanes.h): the VAO
 * estimator (vao_cpu.c) and the comparison methods (methods_cpu.c).  No
 * GL.  Not installed. */
#ifndef OBSCURA_VAO_CPU_H
#define OBSCURA_VAO_CPU_H

#include "chain/frame.h"
#include "chain/lanes.h"

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

/* The comparison method's AO (obs__method_pixel) of each of the m pixels
 * px[] (indices into the planes, each with geometry) into ao[px[j]], and
 * its sample count into count[px[j]] (count NULL: not wanted), the pixels
 * in SIMD lanes (methods_cpu.c), the same results bit for bit; the flat
 * chain without object masks.  0 (nothing written) where the method has
 * no lanes: the caller then takes obs__method_pixel. */
int obs__method_pixels(const obs__frame *f, const float *pos, const float *nrm, const int *px,
                       int m, float *ao, float *count);

#endif
