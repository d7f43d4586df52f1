/* Boxes in sweep order (sweep.h). */
#include <stdlib.h>

#include "level/sweep.h"

typedef struct keyed {
    float x;
    uint32_t i;
} keyed;

static int by_x(const void *a, const void *b)
{
    const keyed *p = a, *q = b;
    return p->x < q->x ? -1 : p->x > q->x ? 1 : (p->i > q->i) - (p->i < q->i);
}

uint32_t *obs__sweep_order(const float *min_x, size_t stride, size_t n)
{
    uint32_t *o = malloc((n ? n : 1) * sizeof *o);
    keyed *k = malloc((n ? n : 1) * sizeof *k);
    if (!o || !k) {
        free(o);
        free(k);
        return NULL;
    }
    for (size_t i = 0; i < n; i++)
        k[i] = (keyed){*(const float *)((const char *)min_x + i * stride), (uint32_t)i};
    qsort(k, n, sizeof *k, by_x);
    for (size_t i = 0; i < n; i++)
        o[i] = k[i].i;
    free(k);
    return o;
}
