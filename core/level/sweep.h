/* Boxes in sweep order (sweep.c), for the passes that look at the pairs
 * of boxes that can touch or overlap: the fog boxes' overlap (occl.c) and
 * the dynamic regions' adjacency and checks (dynamic/dyn_regions.c). */
#ifndef OBSCURA_LEVEL_SWEEP_H
#define OBSCURA_LEVEL_SWEEP_H

#include <stddef.h>
#include <stdint.h>

/* The n boxes' indices ordered by their min x (ties by index), read at
 * min_x, min_x + stride bytes, ...: a pair (i, j) with j after i can only
 * meet while min x of j is not past max x of i.  Caller frees; NULL when
 * out of memory. */
uint32_t *obs__sweep_order(const float *min_x, size_t stride, size_t n);

#endif
