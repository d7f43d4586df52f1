/* The regions of the dynamic-object bake (section 2.3).  The paper takes
 * them from its visibility system [Umbra 2013]: "a set of coarse
 * visibility regions, represented as axis-aligned boxes and a graph
 * representing their connectivity".  Here they come from a JSON file
 * (obs_dyn_regions_read), or, without one, from an adaptive subdivision
 * of the level's box (obs__dyn_regions_build):
 *
 *   - start from the box of the level's vertices;
 *   - repeatedly split, at the middle of its longest side, the largest
 *     box that holds geometry (a triangle whose bounding box meets it) and
 *     whose longest side is at least twice min_region_size, until there
 *     are max_regions boxes or no box can be split: the boxes are small
 *     where the geometry is and large in open space;
 *   - drop every box without geometry whose centre lies inside solid
 *     geometry (back-face hits: more than backface_limit of 64 rays from
 *     the centre meet a one-sided face from behind, as the bake's
 *     back-face rule, section 2.1): those boxes are wholly inside (under
 *     the terrain, inside a building's closed shell);
 *   - the boxes that hold geometry stay: their grid points inside
 *     geometry are not valid (dyn_probes.c), so no region's samples lie in
 *     solid geometry;
 *   - adjacency: boxes that share a face of positive area.
 * The boxes of a subdivision never overlap. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dynamic/dyn_internal.h"
#include "level/sweep.h"
#include "internal.h"

void obs_dyn_regions_free(obs_dyn_regions *r)
{
    if (!r)
        return;
    free(r->box);
    free(r->edge);
    memset(r, 0, sizeof *r);
}

static double box_size(const obs_dyn_box *b)
{
    return fmax(b->hi[0] - b->lo[0], fmax(b->hi[1] - b->lo[1], b->hi[2] - b->lo[2]));
}

static double tol_of(const obs_dyn_box *a, const obs_dyn_box *b)
{
    return 1e-5 * fmax(box_size(a), box_size(b));
}

double obs__dyn_shared_face(const obs_dyn_box *a, const obs_dyn_box *b, float centre[3])
{
    double tol = tol_of(a, b);
    for (int ax = 0; ax < 3; ax++) {
        double plane;
        if (fabs(a->hi[ax] - b->lo[ax]) <= tol)
            plane = a->hi[ax];
        else if (fabs(b->hi[ax] - a->lo[ax]) <= tol)
            plane = a->lo[ax];
        else
            continue;
        double area = 1.0;
        float c[3];
        c[ax] = (float)plane;
        for (int k = 1; k < 3; k++) {
            int o = (ax + k) % 3;
            double lo = fmax(a->lo[o], b->lo[o]), hi = fmin(a->hi[o], b->hi[o]);
            if (hi - lo <= tol)
                return 0.0;
            area *= hi - lo;
            c[o] = (float)(0.5 * (lo + hi));
        }
        if (centre)
            memcpy(centre, c, sizeof c);
        return area;
    }
    return 0.0;
}

static int overlap(const obs_dyn_box *a, const obs_dyn_box *b)
{
    double tol = tol_of(a, b);
    for (int ax = 0; ax < 3; ax++)
        if (fmin(a->hi[ax], b->hi[ax]) - fmax(a->lo[ax], b->lo[ax]) <= tol)
            return 0;
    return 1;
}

static int push_edge(obs_dyn_regions *r, size_t *cap, uint32_t i, uint32_t j)
{
    if (r->edge_count == *cap) {
        size_t nc = *cap ? 2 * *cap : 64;
        uint32_t *e = realloc(r->edge, 2 * nc * sizeof *e);
        if (!e)
            return 0;
        r->edge = e;
        *cap = nc;
    }
    r->edge[2 * r->edge_count] = i < j ? i : j;
    r->edge[2 * r->edge_count + 1] = i < j ? j : i;
    r->edge_count++;
    return 1;
}

/* Calls visit(i, j, user) for each pair of regions that can touch or
 * overlap, found by a sweep over them ordered by their lower x
 * (level/sweep.h): j after i with lo_x(j) <= hi_x(i) + slack, until it
 * returns nonzero.  Returns what it returned, 0 when no call did, -1 when
 * out of memory. */
static int each_near_pair(const obs_dyn_regions *r,
                          int (*visit)(uint32_t i, uint32_t j, void *user), void *user)
{
    double big = 0.0;
    for (size_t i = 0; i < r->count; i++)
        big = fmax(big, box_size(&r->box[i]));
    double slack = 2e-5 * big;
    uint32_t *o = obs__sweep_order(r->count ? r->box[0].lo : NULL, sizeof *r->box, r->count);
    if (!o)
        return -1;
    int stop = 0;
    for (size_t a = 0; a < r->count && !stop; a++)
        for (size_t b = a + 1; b < r->count && !stop; b++) {
            uint32_t i = o[a], j = o[b];
            if (r->box[j].lo[0] > r->box[i].hi[0] + slack)
                break;
            stop = visit(i, j, user);
        }
    free(o);
    return stop;
}

static int cmp_edge(const void *a, const void *b);

/* The adjacency's pairs: those sharing a face of positive area. */
typedef struct edges {
    obs_dyn_regions *r;
    size_t cap;
} edges;

static int add_edge(uint32_t i, uint32_t j, void *user)
{
    edges *e = user;
    return obs__dyn_shared_face(&e->r->box[i], &e->r->box[j], NULL) > 0.0 &&
           !push_edge(e->r, &e->cap, i, j);
}

obs_status obs__dyn_adjacency(obs_dyn_regions *r, char err[OBS_ERR_LEN])
{
    free(r->edge);
    r->edge = NULL;
    r->edge_count = 0;
    edges e = {r, 0};
    if (each_near_pair(r, add_edge, &e) != 0)
        return obs__fail(err, OBS_NO_MEMORY, "adjacency of %zu regions", r->count);
    if (r->edge_count)
        qsort(r->edge, r->edge_count, 2 * sizeof *r->edge, cmp_edge);
    return OBS_OK;
}

/* The first pair of regions that overlap. */
typedef struct overlapping {
    const obs_dyn_regions *r;
    uint32_t i, j;
} overlapping;

static int find_overlap(uint32_t i, uint32_t j, void *user)
{
    overlapping *o = user;
    if (!overlap(&o->r->box[i], &o->r->box[j]))
        return 0;
    o->i = i;
    o->j = j;
    return 1;
}

/* Boxes non-empty and finite, no two overlapping. */
static obs_status check_boxes(const obs_dyn_regions *r, char err[OBS_ERR_LEN])
{
    static const char axis[3] = {'x', 'y', 'z'};
    for (size_t i = 0; i < r->count; i++)
        for (int ax = 0; ax < 3; ax++) {
            const obs_dyn_box *b = &r->box[i];
            if (!isfinite(b->lo[ax]) || !isfinite(b->hi[ax]))
                return obs__fail(err, OBS_INVALID_ARGUMENT, "region %zu: coordinates not finite",
                                 i);
            if (!(b->hi[ax] > b->lo[ax]))
                return obs__fail(err, OBS_INVALID_ARGUMENT,
                                 "region %zu is empty: max %c %g is not above min %c %g", i,
                                 axis[ax], b->hi[ax], axis[ax], b->lo[ax]);
        }
    overlapping o = {r, 0, 0};
    int stop = each_near_pair(r, find_overlap, &o);
    if (stop < 0)
        return obs__fail(err, OBS_NO_MEMORY, "%zu regions", r->count);
    if (stop)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "regions %u and %u overlap (boxes may share faces, not volume)",
                         o.i < o.j ? o.i : o.j, o.i < o.j ? o.j : o.i);
    return OBS_OK;
}

static int read_vec3(const cJSON *a, float v[3])
{
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != 3)
        return 0;
    for (int k = 0; k < 3; k++) {
        const cJSON *e = cJSON_GetArrayItem(a, k);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
            return 0;
        v[k] = (float)e->valuedouble;
    }
    return 1;
}

static int cmp_edge(const void *a, const void *b)
{
    const uint32_t *x = a, *y = b;
    return x[0] != y[0] ? (x[0] < y[0] ? -1 : 1) : x[1] != y[1] ? (x[1] < y[1] ? -1 : 1) : 0;
}

obs_status obs_dyn_regions_parse(const char *json, obs_dyn_regions *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    obs_status st = OBS_OK;
    cJSON *doc = cJSON_Parse(json);
    if (!doc)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "regions: not JSON (near '%.20s')",
                         cJSON_GetErrorPtr() ? cJSON_GetErrorPtr() : "");
    const cJSON *regs = cJSON_GetObjectItemCaseSensitive(doc, "regions");
    if (!cJSON_IsArray(regs) || cJSON_GetArraySize(regs) == 0) {
        st = obs__fail(err, OBS_INVALID_ARGUMENT, "regions: no \"regions\" array of boxes");
        goto done;
    }
    size_t n = (size_t)cJSON_GetArraySize(regs);
    if (n > UINT32_MAX / 2) {
        st = obs__fail(err, OBS_TOO_LARGE, "regions: %zu boxes", n);
        goto done;
    }
    out->box = calloc(n, sizeof *out->box);
    if (!out->box) {
        st = obs__fail(err, OBS_NO_MEMORY, "regions: %zu boxes", n);
        goto done;
    }
    out->count = n;
    size_t i = 0;
    const cJSON *it;
    cJSON_ArrayForEach(it, regs)
    {
        if (!read_vec3(cJSON_GetObjectItemCaseSensitive(it, "min"), out->box[i].lo) ||
            !read_vec3(cJSON_GetObjectItemCaseSensitive(it, "max"), out->box[i].hi)) {
            st = obs__fail(err, OBS_INVALID_ARGUMENT,
                           "region %zu: needs \"min\" and \"max\", each 3 finite numbers", i);
            goto done;
        }
        i++;
    }
    if ((st = check_boxes(out, err)) != OBS_OK)
        goto done;
    const cJSON *adj = cJSON_GetObjectItemCaseSensitive(doc, "adjacency");
    if (!adj) {
        st = obs__dyn_adjacency(out, err);
        goto done;
    }
    if (!cJSON_IsArray(adj)) {
        st = obs__fail(err, OBS_INVALID_ARGUMENT, "regions: \"adjacency\" is not an array");
        goto done;
    }
    size_t cap = 0, k = 0;
    cJSON_ArrayForEach(it, adj)
    {
        const cJSON *a = cJSON_GetArrayItem(it, 0), *b = cJSON_GetArrayItem(it, 1);
        if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != 2 || !cJSON_IsNumber(a) ||
            !cJSON_IsNumber(b) || a->valuedouble != floor(a->valuedouble) ||
            b->valuedouble != floor(b->valuedouble)) {
            st = obs__fail(err, OBS_INVALID_ARGUMENT,
                           "adjacency %zu: expected a pair of region indices [i, j]", k);
            goto done;
        }
        double x = a->valuedouble, y = b->valuedouble;
        if (x < 0 || y < 0 || x >= (double)n || y >= (double)n) {
            st = obs__fail(err, OBS_INVALID_ARGUMENT,
                           "adjacency %zu: [%g, %g] names a region out of 0..%zu", k, x, y,
                           n - 1);
            goto done;
        }
        if (x == y) {
            st = obs__fail(err, OBS_INVALID_ARGUMENT,
                           "adjacency %zu: region %g is listed as its own neighbour", k, x);
            goto done;
        }
        if (obs__dyn_shared_face(&out->box[(size_t)x], &out->box[(size_t)y], NULL) <= 0.0) {
            st = obs__fail(err, OBS_INVALID_ARGUMENT,
                           "adjacency %zu: regions %g and %g share no face (their boundary "
                           "area, the weight w_ij, would be 0)",
                           k, x, y);
            goto done;
        }
        if (!push_edge(out, &cap, (uint32_t)x, (uint32_t)y)) {
            st = obs__fail(err, OBS_NO_MEMORY, "adjacency");
            goto done;
        }
        k++;
    }
    if (out->edge_count) {
        qsort(out->edge, out->edge_count, 2 * sizeof *out->edge, cmp_edge);
        for (size_t e = 1; e < out->edge_count; e++)
            if (!cmp_edge(out->edge + 2 * e, out->edge + 2 * (e - 1))) {
                st = obs__fail(err, OBS_INVALID_ARGUMENT, "adjacency: [%u, %u] is given twice",
                               out->edge[2 * e], out->edge[2 * e + 1]);
                goto done;
            }
    }
done:
    cJSON_Delete(doc);
    if (st != OBS_OK)
        obs_dyn_regions_free(out);
    return st;
}

obs_status obs_dyn_regions_read(const char *path, obs_dyn_regions *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "rb");
    if (!f)
        return obs__fail(err, OBS_IO, "%s: %s", path, strerror(errno));
    char *buf = NULL;
    long len = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    if (len < 0 || len > (64L << 20) || fseek(f, 0, SEEK_SET) != 0 ||
        !(buf = malloc((size_t)len + 1)) || fread(buf, 1, (size_t)len, f) != (size_t)len) {
        fclose(f);
        free(buf);
        return obs__fail(err, len > (64L << 20) ? OBS_TOO_LARGE : OBS_IO,
                         "%s: cannot read (at most 64 MiB)", path);
    }
    fclose(f);
    buf[len] = '\0';
    obs_status st = obs_dyn_regions_parse(buf, out, err);
    free(buf);
    if (st != OBS_OK) {
        char m[OBS_ERR_LEN];
        snprintf(m, sizeof m, "%s", err);
        obs__fail(err, st, "%s: %s", path, m);
    }
    return st;
}

/* ---- the subdivision ---------------------------------------------------- */

typedef struct leaf {
    obs_dyn_box box;
    uint32_t *tri; /* triangles whose bounding boxes meet the box */
    size_t n;
} leaf;

static int meets(const float *tb, const obs_dyn_box *b)
{
    for (int k = 0; k < 3; k++)
        if (tb[k] > b->hi[k] || tb[3 + k] < b->lo[k])
            return 0;
    return 1;
}

static double volume(const obs_dyn_box *b)
{
    return ((double)b->hi[0] - b->lo[0]) * ((double)b->hi[1] - b->lo[1]) *
           ((double)b->hi[2] - b->lo[2]);
}

obs_status obs__dyn_regions_build(const obs__bake_world *w, const obs__bake_bvh *bvh,
                                  const obs_dyn_params *p, obs_dyn_regions *out,
                                  char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    obs_status st = OBS_OK;
    size_t cap = (size_t)p->max_regions, nl = 1;
    leaf *L = calloc(cap, sizeof *L);
    float *tb = malloc((w->triangle_count ? w->triangle_count : 1) * 6 * sizeof *tb);
    if (!L || !tb) {
        st = obs__fail(err, OBS_NO_MEMORY, "regions: %zu boxes", cap);
        goto done;
    }
    obs_dyn_box root = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (size_t t = 0; t < w->triangle_count; t++) {
        float *b = tb + 6 * t;
        for (int k = 0; k < 3; k++)
            b[k] = INFINITY, b[3 + k] = -INFINITY;
        for (int c = 0; c < 3; c++) {
            const float *v = w->pos + 3 * (size_t)w->tri[3 * t + c];
            for (int k = 0; k < 3; k++) {
                b[k] = fminf(b[k], v[k]);
                b[3 + k] = fmaxf(b[3 + k], v[k]);
                root.lo[k] = fminf(root.lo[k], v[k]);
                root.hi[k] = fmaxf(root.hi[k], v[k]);
            }
        }
    }
    if (!w->triangle_count) {
        st = obs__fail(err, OBS_INVALID_ARGUMENT, "regions: the level has no triangles");
        goto done;
    }
    /* A flat level still gets a box of some height. */
    double pad = 1e-3 * box_size(&root);
    for (int k = 0; k < 3; k++)
        root.lo[k] -= (float)pad, root.hi[k] += (float)pad;
    L[0].box = root;
    L[0].n = w->triangle_count;
    L[0].tri = malloc(L[0].n * sizeof *L[0].tri);
    if (!L[0].tri) {
        st = obs__fail(err, OBS_NO_MEMORY, "regions");
        goto done;
    }
    for (size_t t = 0; t < L[0].n; t++)
        L[0].tri[t] = (uint32_t)t;
    while (nl < cap) {
        size_t best = SIZE_MAX;
        double bv = 0.0;
        for (size_t i = 0; i < nl; i++)
            if (L[i].n && box_size(&L[i].box) >= 2.0 * p->min_region_size &&
                volume(&L[i].box) > bv)
                bv = volume(&L[i].box), best = i;
        if (best == SIZE_MAX)
            break;
        leaf *a = &L[best], *b = &L[nl];
        int ax = 0;
        for (int k = 1; k < 3; k++)
            if (a->box.hi[k] - a->box.lo[k] > a->box.hi[ax] - a->box.lo[ax])
                ax = k;
        float mid = 0.5f * (a->box.lo[ax] + a->box.hi[ax]);
        b->box = a->box;
        a->box.hi[ax] = mid;
        b->box.lo[ax] = mid;
        b->tri = malloc((a->n ? a->n : 1) * sizeof *b->tri);
        if (!b->tri) {
            st = obs__fail(err, OBS_NO_MEMORY, "regions");
            goto done;
        }
        size_t na = 0;
        b->n = 0;
        for (size_t i = 0; i < a->n; i++) {
            uint32_t t = a->tri[i];
            if (meets(tb + 6 * (size_t)t, &b->box))
                b->tri[b->n++] = t;
            if (meets(tb + 6 * (size_t)t, &a->box))
                a->tri[na++] = t;
        }
        a->n = na;
        nl++;
    }
    out->box = malloc(nl * sizeof *out->box);
    if (!out->box) {
        st = obs__fail(err, OBS_NO_MEMORY, "regions");
        goto done;
    }
    for (size_t i = 0; i < nl; i++) {
        float c[3];
        for (int k = 0; k < 3; k++)
            c[k] = 0.5f * (L[i].box.lo[k] + L[i].box.hi[k]);
        /* solid: the opaque triangles alone (decorators are not solid) */
        if (!L[i].n && obs__dyn_inside(bvh, c, 64, p->backface_limit))
            continue;
        out->box[out->count++] = L[i].box;
    }
    if (!out->count) {
        st = obs__fail(err, OBS_INVALID_ARGUMENT,
                       "regions: every box of the subdivision lies inside geometry");
        goto done;
    }
    st = obs__dyn_adjacency(out, err);
done:
    for (size_t i = 0; L && i < nl; i++)
        free(L[i].tri);
    free(L);
    free(tb);
    if (st != OBS_OK)
        obs_dyn_regions_free(out);
    return st;
}
