/* The nearest point of one instance's full-detail surface (the LOD
 * resampling of paper 2.2.1 takes the bake's value there).  A bounding
 * volume hierarchy of our own over the instance's triangles: boxes split
 * at the median centroid of their longest axis, leaves of up to 4
 * triangles; a query visits the nearer child first and skips a box
 * farther than the best point so far.  Embree's rtcPointQuery was the
 * other way: it needs this point-triangle routine as its callback anyway,
 * and a scene per instance. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake/closest.h"
#include "internal.h"

#define LEAF 4

typedef struct node {
    float lo[3], hi[3];
    uint32_t left;  /* inner: the first child (the second follows it); leaf: first item */
    uint32_t count; /* 0 for an inner node */
} node;

/* One allocation holds the struct, its items and its nodes. */
struct obs__bake_closest {
    const obs__bake_world *w;
    uint32_t *items; /* world triangle indices */
    size_t nitems;
    node *nodes;
    size_t nnodes;
    float *cen; /* 3 per item, for the build */
};

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

double obs__bake_closest_tri(const float p[3], const float a[3], const float b[3],
                             const float c[3], float bary[3])
{
    /* The nearest point lies in one of the triangle's seven regions
     * (three corners, three edges, the face); each is told by the signs
     * of dot products of p - corner with the edges. */
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int k = 0; k < 3; k++) {
        ab[k] = (double)b[k] - a[k];
        ac[k] = (double)c[k] - a[k];
        ap[k] = (double)p[k] - a[k];
        bp[k] = (double)p[k] - b[k];
        cp[k] = (double)p[k] - c[k];
    }
    double u = 1.0, v = 0.0, t = 0.0; /* weights of a, b, c */
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d1 <= 0.0 && d2 <= 0.0) {
        u = 1.0, v = 0.0, t = 0.0; /* corner a */
    } else if (d3 >= 0.0 && d4 <= d3) {
        u = 0.0, v = 1.0, t = 0.0; /* corner b */
    } else if (d6 >= 0.0 && d5 <= d6) {
        u = 0.0, v = 0.0, t = 1.0; /* corner c */
    } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        v = d1 / (d1 - d3), u = 1.0 - v, t = 0.0; /* edge ab */
    } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        t = d2 / (d2 - d6), u = 1.0 - t, v = 0.0; /* edge ac */
    } else if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6)), v = 1.0 - t, u = 0.0; /* edge bc */
    } else {
        double den = va + vb + vc; /* the face: the areas of the sub-triangles */
        v = vb / den, t = vc / den, u = 1.0 - v - t;
    }
    double e = 0.0;
    for (int k = 0; k < 3; k++) {
        double q = u * a[k] + v * b[k] + t * c[k] - p[k];
        e += q * q;
    }
    bary[0] = (float)u, bary[1] = (float)v, bary[2] = (float)t;
    return e;
}

static void bounds(const obs__bake_closest *c, size_t first, size_t count, node *n)
{
    for (int k = 0; k < 3; k++) {
        n->lo[k] = INFINITY;
        n->hi[k] = -INFINITY;
    }
    for (size_t i = first; i < first + count; i++) {
        const uint32_t *t = c->w->tri + 3 * (size_t)c->items[i];
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++) {
                float x = c->w->pos[3 * (size_t)t[j] + k];
                n->lo[k] = fminf(n->lo[k], x);
                n->hi[k] = fmaxf(n->hi[k], x);
            }
    }
}

/* Partly sorts items [lo, hi) so that the one of rank mid along axis is
 * at mid, smaller ones before it (quickselect on the centroids). */
static void select_mid(obs__bake_closest *c, size_t lo, size_t hi, size_t mid, int axis)
{
    while (hi - lo > 1) {
        float pivot = c->cen[3 * (lo + (hi - lo) / 2) + axis];
        size_t i = lo, j = hi - 1;
        while (i <= j) {
            while (c->cen[3 * i + axis] < pivot)
                i++;
            while (c->cen[3 * j + axis] > pivot)
                j--;
            if (i <= j) {
                uint32_t ti = c->items[i];
                c->items[i] = c->items[j];
                c->items[j] = ti;
                float tc[3];
                memcpy(tc, c->cen + 3 * i, sizeof tc);
                memcpy(c->cen + 3 * i, c->cen + 3 * j, sizeof tc);
                memcpy(c->cen + 3 * j, tc, sizeof tc);
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (mid <= j)
            hi = j + 1;
        else if (mid >= i)
            lo = i;
        else
            return;
    }
}

/* Node k over items [first, first + count). */
static void build(obs__bake_closest *c, size_t k, size_t first, size_t count)
{
    node *n = &c->nodes[k];
    bounds(c, first, count, n);
    if (count <= LEAF) {
        n->left = (uint32_t)first;
        n->count = (uint32_t)count;
        return;
    }
    float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = first; i < first + count; i++)
        for (int a = 0; a < 3; a++) {
            clo[a] = fminf(clo[a], c->cen[3 * i + a]);
            chi[a] = fmaxf(chi[a], c->cen[3 * i + a]);
        }
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[axis] - clo[axis])
            axis = a;
    size_t half = count / 2;
    select_mid(c, first, first + count, first + half, axis);
    size_t child = c->nnodes;
    c->nnodes += 2;
    n->left = (uint32_t)child;
    n->count = 0;
    build(c, child, first, half);
    build(c, child + 1, first + half, count - half);
}

obs_status obs__bake_closest_new(const obs__bake_world *w, size_t first, size_t count,
                                 obs__bake_closest **out, char err[OBS_ERR_LEN])
{
    *out = NULL;
    obs__bake_closest *c;
    /* a binary tree over n leaves of >= 1 item: fewer than 2n nodes */
    const size_t bytes[] = {sizeof *c, count * sizeof *c->items, 2 * count * sizeof *c->nodes};
    void *a[3];
    float *cen = malloc(3 * (count ? count : 1) * sizeof *cen);
    if (!cen || !(c = obs__alloc_arrays(3, bytes, a))) {
        free(cen);
        return obs__fail(err, OBS_NO_MEMORY, "nearest-point search over %zu triangles", count);
    }
    *c = (obs__bake_closest){.w = w, .items = a[1], .nodes = a[2], .cen = cen};
    for (size_t t = first; t < first + count; t++)
        if (w->area[t] > 0.0f)
            c->items[c->nitems++] = (uint32_t)t;
    /* exact copies left out: each query near them measured every copy */
    size_t kept = obs__bake_drop_copies(w, c->items, c->nitems);
    if (kept == SIZE_MAX) {
        free(cen);
        free(c);
        return obs__fail(err, OBS_NO_MEMORY, "nearest-point search over %zu triangles", count);
    }
    c->nitems = kept;
    for (size_t i = 0; i < c->nitems; i++) {
        const uint32_t *v = w->tri + 3 * (size_t)c->items[i];
        float *ce = c->cen + 3 * i;
        for (int k = 0; k < 3; k++)
            ce[k] = (w->pos[3 * (size_t)v[0] + k] + w->pos[3 * (size_t)v[1] + k] +
                     w->pos[3 * (size_t)v[2] + k]) / 3.0f;
    }
    if (c->nitems) {
        c->nnodes = 1;
        build(c, 0, 0, c->nitems);
    }
    free(c->cen);
    c->cen = NULL;
    *out = c;
    return OBS_OK;
}

void obs__bake_closest_free(obs__bake_closest *c)
{
    free(c); /* with its items and nodes; cen went with the build */
}

static double box_dist2(const node *n, const float p[3])
{
    double d = 0.0;
    for (int k = 0; k < 3; k++) {
        double e = p[k] < n->lo[k] ? (double)n->lo[k] - p[k]
                   : p[k] > n->hi[k] ? (double)p[k] - n->hi[k] : 0.0;
        d += e * e;
    }
    return d;
}

double obs__bake_closest_query(const obs__bake_closest *c, const float p[3], int64_t *tri,
                               float bary[3])
{
    double best = INFINITY;
    *tri = -1;
    bary[0] = 1.0f, bary[1] = bary[2] = 0.0f;
    if (!c->nnodes)
        return best;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const node *n = &c->nodes[stack[--top]];
        if (box_dist2(n, p) >= best)
            continue;
        if (n->count) {
            for (uint32_t i = n->left; i < n->left + n->count; i++) {
                const uint32_t *v = c->w->tri + 3 * (size_t)c->items[i];
                float b[3];
                double d = obs__bake_closest_tri(p, c->w->pos + 3 * (size_t)v[0],
                                                 c->w->pos + 3 * (size_t)v[1],
                                                 c->w->pos + 3 * (size_t)v[2], b);
                if (d < best) {
                    best = d;
                    *tri = c->items[i];
                    memcpy(bary, b, sizeof b);
                }
            }
            continue;
        }
        /* the nearer child last on the stack: visited first */
        uint32_t a = n->left, b = n->left + 1;
        double da = box_dist2(&c->nodes[a], p), db = box_dist2(&c->nodes[b], p);
        if (top + 2 > (int)(sizeof stack / sizeof *stack)) {
            /* cannot happen: the median split keeps the depth at log2 n */
            continue;
        }
        if (da < db) {
            stack[top++] = b;
            stack[top++] = a;
        } else {
            stack[top++] = a;
            stack[top++] = b;
        }
    }
    return best;
}
