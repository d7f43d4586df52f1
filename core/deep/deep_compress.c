/* List compression, OITAO (Bauer et al.) section III-B.
 *
 * Each pixel's fragment list is inserted into a fixed array of m nodes
 * sorted by depth; when more than m were inserted, the node j minimising
 *     a[j].alpha * (1 - a[j].z)                      (eq 5)
 * is eliminated: opaque nodes and near nodes are kept, transparent and
 * distant ones dropped.  Optionally the search runs over the back half of
 * the array only, preserving the front nodes (section V-A, Fig. 6 column
 * C).
 *
 * z in eq 5 is a normalised depth, and the paper says over what: its
 * array "is initialized with depth values of 1" (III-B), the far end of
 * the camera's [0, 1] depth range, the far clip plane, and eq 5 prefers
 * "fragments with low depth ... opposed to those resident in greater
 * distance", fragments close to the camera; the depth it stores is
 * linear (III-A: "it is usually enough to store solely the linear depth
 * value of the fragment").  So z is the planar depth normalised over the
 * view frustum, z = (Z - near) / (far - near) with the camera's clip
 * range, not over the image's own depths nor the pixel's own list: over
 * those the farthest fragment (the image's, or each pixel's) would score
 * a (1 - z) = 0 and go first whatever its opacity, where the paper drops
 * it only for being transparent or distant.  The clip range is that of
 * the camera's projection (perspective or orthographic), as the chain
 * resolves it (a deep EXR without clip attributes: 0.1 .. 1000, the
 * reader's default; parameters near and far with a field of view); a
 * camera without a projection falls back to the default clip range of
 * those parameters.
 *
 * With intervals (deep_intervals, obs__deep_intervals) a front face and
 * its matching back face bound a solid: the chain reads the depth between
 * them as occupied and the depth behind the back face as free, and a
 * front face whose back face the list lacks as solid behind it to
 * infinity.  Eq 5 scores single nodes, so on its own it can keep a front
 * face and drop its back face (opaque nodes: the farther one), turning a
 * thin object into an infinitely deep one.  The unit eq 5 eliminates is
 * then a closed interval's two ends: when the node it chooses is one end
 * of a matched pair (facing +1 and -1 matched as parentheses, front to
 * back, as obs__deep_intervals matches them), its partner goes with it.
 * Removing a matched pair leaves every other pair matched (and makes no
 * unmatched node matched), so no kept front face loses its back face to
 * compression; a node of no pair (a surface seen from one side, facing
 * unknown) is dropped alone, as without intervals.  The partner may lie
 * in the front half that front_half preserves: the pair goes whole. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "obscura/deep.h"
#include "deep/deep_internal.h"
#include "internal.h"

/* Normalised depth of eq 5 (see above), clamped to [0, 1]; 0 for a
 * degenerate range. */
static float norm_z(float z, float zmin, float zmax)
{
    if (!(zmax > zmin) || !isfinite(z))
        return isfinite(z) ? 0.0f : 1.0f;
    float t = (z - zmin) / (zmax - zmin);
    return t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
}

/* A sample's depth and index, sorted by depth, ties by index (a NaN
 * depth last, as the deep reader sorts them). */
typedef struct depth_ix {
    float z;
    int s;
} depth_ix;

static int by_depth(const void *a, const void *b)
{
    const depth_ix *p = a, *q = b;
    return p->z < q->z ? -1 : p->z > q->z ? 1 : p->s - q->s;
}

/* The intervals of a whole list (n samples): pair[s] = the sample matched
 * with sample s by the facing flags, front to back by depth (ties in
 * insertion order) as parentheses: a front face (+1) opens, the next back
 * face (-1) closes the innermost open one, as obs__deep_intervals matches
 * a kept list; -1 for a sample in no pair (facing 0, a back face with
 * nothing open, a front face whose back face the list lacks).  order, open:
 * scratch of n each. */
static void match_list(const float *samples, int n, int *pair, depth_ix *order, int *open)
{
    for (int s = 0; s < n; s++) {
        const float z = samples[(size_t)s * OBS_DEEP_CH + OBS_DEEP_Z];
        order[s] = (depth_ix){isnan(z) ? INFINITY : z, s};
        pair[s] = -1;
    }
    qsort(order, (size_t)n, sizeof *order, by_depth);
    int depth = 0; /* the open front faces, innermost last */
    for (int k = 0; k < n; k++) {
        int s = order[k].s;
        float fc = samples[(size_t)s * OBS_DEEP_CH + OBS_DEEP_FACING];
        if (fc > 0.0f) {
            open[depth++] = s;
        } else if (fc < 0.0f && depth > 0) {
            int o = open[--depth];
            pair[o] = s;
            pair[s] = o;
        }
    }
}

/* Removes node j of the count nodes of a and ix; returns count - 1. */
static int remove_node(float *a, int *ix, int count, int j)
{
    memmove(a + j * OBS_DEEP_CH, a + (j + 1) * OBS_DEEP_CH,
            (size_t)(count - j - 1) * OBS_DEEP_CH * sizeof(float));
    memmove(ix + j, ix + j + 1, (size_t)(count - j - 1) * sizeof *ix);
    return count - 1;
}

/* obs_deep_compress_list that also writes, when src is not NULL, the
 * index (0 .. n - 1) of the sample each kept node came from: the nodes
 * move with their index, so the object masks of a sample reach the node
 * it became (obs_deep_layers.occluders, object_id).  pair: NULL, or the
 * list's intervals (match_list), which eq 5 then drops whole; it marks a
 * sample whose partner went -2 (the sample goes on arrival). */
static int compress_list(const float *samples, int n, int m, int front_half, int *pair,
                         float zmin, float zmax, float *out, int *src)
{
    /* m + 1 slots: the insertion that overflows is followed at once by
     * the elimination of eq 5 over the m + 1 candidates. */
    float a[(OBS_DEEP_MAX_LAYERS + 1) * OBS_DEEP_CH];
    int ix[OBS_DEEP_MAX_LAYERS + 1];
    int count = 0;
    if (m < 1)
        m = 1;
    if (m > OBS_DEEP_MAX_LAYERS)
        m = OBS_DEEP_MAX_LAYERS;
    for (int s = 0; s < n; s++) {
        if (pair && pair[s] == -2)
            continue; /* its interval was eliminated before it arrived */
        const float *f = samples + (size_t)s * OBS_DEEP_CH;
        float fz = f[OBS_DEEP_Z];
        /* "looking up the index i of a where a[i]z < fz < a[i+1]z" */
        int i = count;
        while (i > 0 && a[(i - 1) * OBS_DEEP_CH + OBS_DEEP_Z] > fz)
            i--;
        memmove(a + (i + 1) * OBS_DEEP_CH, a + i * OBS_DEEP_CH,
                (size_t)(count - i) * OBS_DEEP_CH * sizeof(float));
        memcpy(a + i * OBS_DEEP_CH, f, OBS_DEEP_CH * sizeof(float));
        memmove(ix + i + 1, ix + i, (size_t)(count - i) * sizeof *ix);
        ix[i] = s;
        count++;
        if (count <= m)
            continue;
        /* eq 5, over every node or the back half (j >= m / 2) */
        int j0 = front_half ? m / 2 : 0, drop = j0;
        float best = INFINITY;
        for (int j = j0; j < count; j++) {
            const float *nd = a + j * OBS_DEEP_CH;
            float v = nd[OBS_DEEP_A] * (1.0f - norm_z(nd[OBS_DEEP_Z], zmin, zmax));
            if (v < best) {
                best = v;
                drop = j;
            }
        }
        /* with intervals, a closed interval's two ends go together: the
         * partner now if it is in the array, on arrival if it is to come */
        int partner = pair ? pair[ix[drop]] : -1;
        count = remove_node(a, ix, count, drop);
        if (partner >= 0) {
            int k = 0;
            while (k < count && ix[k] != partner)
                k++;
            if (k < count)
                count = remove_node(a, ix, count, k);
            else
                pair[partner] = -2;
        }
    }
    memcpy(out, a, (size_t)count * OBS_DEEP_CH * sizeof(float));
    if (src)
        memcpy(src, ix, (size_t)count * sizeof *src);
    return count;
}

int obs_deep_compress_list(const float *samples, int n, int m, int front_half, float zmin,
                           float zmax, float *out)
{
    return compress_list(samples, n, m, front_half, NULL, zmin, zmax, out, NULL);
}

/* The scratch of match_list for lists of up to n samples: pair and open
 * (n ints each), order (n depth_ix); NULL when out of memory. */
static int *match_alloc(size_t n, depth_ix **order)
{
    int *pair = malloc(n * (2 * sizeof(int) + sizeof(depth_ix)));
    *order = pair ? (depth_ix *)(void *)(pair + 2 * n) : NULL;
    return pair;
}

int obs__deep_compress_list(const float *samples, int n, int m, int front_half, int intervals,
                            float zmin, float zmax, float *out)
{
    int *pair = NULL;
    depth_ix *order = NULL;
    if (intervals && n > 0) {
        if (!(pair = match_alloc((size_t)n, &order)))
            return -1;
        match_list(samples, n, pair, order, pair + n);
    }
    int c = compress_list(samples, n, m, front_half, pair, zmin, zmax, out, NULL);
    free(pair);
    return c;
}

void obs_deep_layers_free(obs_deep_layers *l)
{
    if (!l)
        return;
    free(l->node);
    free(l->count);
    free(l->occluders);
    free(l->object_id);
    memset(l, 0, sizeof *l);
}

void obs__deep_clip_range(const obs_camera *cam, float *near_z, float *far_z)
{
    obs_params p;
    obs_params_resolve(NULL, &p);
    *near_z = p.near;
    *far_z = p.far;
    if (!cam || !cam->has_projection)
        return;
    const float *P = cam->projection;
    double n, f;
    if (P[14] != 0.0f) { /* perspective: P10 = -(f + n) / (f - n), P11 = -2 f n / (f - n) */
        n = P[11] / (P[10] - 1.0);
        f = P[11] / (P[10] + 1.0);
    } else { /* orthographic: P10 = -2 / (f - n), P11 = -(f + n) / (f - n) */
        if (P[10] == 0.0f)
            return;
        n = (P[11] + 1.0) / P[10];
        f = (P[11] - 1.0) / P[10];
    }
    if (isfinite(n) && isfinite(f) && f > n && n >= 0.0) {
        *near_z = (float)n;
        *far_z = (float)f;
    }
}

obs_status obs_deep_compress(const obs_deep_image *d, int m, int front_half, obs_deep_layers *out,
                             char err[OBS_ERR_LEN])
{
    return obs__deep_compress(d, m, front_half, 0, out, err);
}

obs_status obs__deep_compress(const obs_deep_image *d, int m, int front_half, int intervals,
                              obs_deep_layers *out, char err[OBS_ERR_LEN])
{
    size_t npx, bytes;
    float zmin, zmax;

    memset(out, 0, sizeof *out);
    if (!d || !d->offset || d->width <= 0 || d->height <= 0)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "deep compression: no deep image");
    if (m < 0 || m > OBS_DEEP_MAX_LAYERS)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "deep compression: %d nodes (1..%d)", m,
                         OBS_DEEP_MAX_LAYERS);
    int keep_all = m == 0;
    if (keep_all)
        m = OBS_DEEP_MAX_LAYERS;
    npx = (size_t)d->width * (size_t)d->height;
    if (obs__size_mul3(npx, (size_t)m, OBS_DEEP_CH * sizeof(float), &bytes) != 0)
        return obs__fail(err, OBS_TOO_LARGE, "deep layers of %dx%dx%d", d->width, d->height, m);
    out->node = calloc(1, bytes);
    out->count = calloc(npx, sizeof *out->count);
    /* the object masks' planes: node k of pixel i at k * npx + i */
    if (d->occluders)
        out->occluders = malloc(npx * (size_t)m * sizeof *out->occluders);
    if (d->object_id)
        out->object_id = calloc(npx * (size_t)m, sizeof *out->object_id);
    if (!out->node || !out->count || (d->occluders && !out->occluders) ||
        (d->object_id && !out->object_id)) {
        obs_deep_layers_free(out);
        return obs__fail(err, OBS_NO_MEMORY, "deep layers of %dx%dx%d", d->width, d->height, m);
    }
    /* with intervals: the pairs of the longest list and their scratch */
    int *pair = NULL;
    depth_ix *order = NULL;
    if (intervals && !keep_all) {
        size_t most = 0;
        for (size_t i = 0; i < npx; i++)
            if (d->offset[i + 1] - d->offset[i] > most)
                most = (size_t)(d->offset[i + 1] - d->offset[i]);
        if (most > OBS_DEEP_MAX_PER_PIXEL)
            most = OBS_DEEP_MAX_PER_PIXEL;
        if (most && !(pair = match_alloc(most, &order))) {
            obs_deep_layers_free(out);
            return obs__fail(err, OBS_NO_MEMORY, "deep intervals of %zu samples", most);
        }
    }
    obs__deep_clip_range(&d->camera, &zmin, &zmax);
    out->width = d->width;
    out->height = d->height;
    out->m = m;
    out->zmin = zmin;
    out->zmax = zmax;
    for (size_t k = 0; out->occluders && k < npx * (size_t)m; k++)
        out->occluders[k] = 1.0f; /* empty nodes: as without the mask */
    float list[OBS_DEEP_MAX_LAYERS * OBS_DEEP_CH];
    int src[OBS_DEEP_MAX_LAYERS];
    for (size_t i = 0; i < npx; i++) {
        const float *s = d->samples + d->offset[i] * OBS_DEEP_CH;
        uint64_t n64 = d->offset[i + 1] - d->offset[i];
        int n = n64 > OBS_DEEP_MAX_PER_PIXEL ? OBS_DEEP_MAX_PER_PIXEL : (int)n64;
        int c;
        if (keep_all) { /* the front OBS_DEEP_MAX_LAYERS as they are */
            c = n < m ? n : m;
            memcpy(list, s, (size_t)c * OBS_DEEP_CH * sizeof(float));
            for (int k = 0; k < c; k++)
                src[k] = k;
        } else {
            if (pair)
                match_list(s, n, pair, order, pair + n);
            c = compress_list(s, n, m, front_half, pair, zmin, zmax, list, src);
        }
        out->count[i] = c;
        for (int k = 0; k < c; k++) {
            const size_t at = (size_t)k * npx + i;
            memcpy(out->node + at * OBS_DEEP_CH, list + k * OBS_DEEP_CH,
                   OBS_DEEP_CH * sizeof(float));
            if (out->occluders)
                out->occluders[at] = d->occluders[d->offset[i] + (uint64_t)src[k]];
            if (out->object_id)
                out->object_id[at] = d->object_id[d->offset[i] + (uint64_t)src[k]];
        }
    }
    free(pair);
    return OBS_OK;
}
