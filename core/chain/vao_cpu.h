/* The CPU device's form of the VAO estimator (vao_cpu.c).  No GL.  Not
 * installed. */
#ifndef OBSCURA_VAO_CPU_H
#define OBSCURA_VAO_CPU_H

#include "chain/frame.h"

/* obs__vao_estimate_bleed (the same arithmetic, the same result) reading
 * each sample's depth and view normal z from dnz, the two packed per
 * pixel (dnz[2 k] = pos[4 k + 3], dnz[2 k + 1] = nrm[3 k + 2]): a sample
 * then touches one cache line instead of two, from a plane of 8 bytes a
 * pixel instead of 28.  pos is read for colour bleeding only. */
float obs__vao_estimate_dnz(const obs__frame *f, const float *pos, const float *dnz,
                            const float *col, int x, int y, const float p[3], const float n[3],
                            int ns, const float *xy, float bleed[3]);

/* obs__cull_prepass (the same result) with the estimator above. */
void obs__cull_prepass_dnz(const obs__frame *f, const float *pos, const float *nrm,
                           const float *dnz, float *est);

#endif
