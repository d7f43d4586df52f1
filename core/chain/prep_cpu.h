/* The CPU device's prep pass rows (prep_cpu.c).  No GL.  Not installed. */
#ifndef OBSCURA_PREP_CPU_H
#define OBSCURA_PREP_CPU_H

#include <stddef.h>

#include "chain/frame.h"

/* The prep pass's rows in lanes (prep_cpu.c), the twins' floats:
 * obs__prep_position of row y's pixels, their raw depths at depth[dc x],
 * into out[4 x]; obs__prep_normal of a row's pixels from the input
 * normals in[nc x] (not for reconstruct_normals) into out[3 x], and,
 * where dnz is not NULL, the packed plane's row from pos (the row's
 * positions) and those normals. */
void obs__prep_position_row(const obs__frame *f, const float *depth, size_t dc, int y, float *out);
void obs__prep_normal_row(const obs__frame *f, const float *pos, const float *in, size_t nc,
                          float *out, float *dnz);

#endif
