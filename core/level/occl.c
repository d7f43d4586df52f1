/* What the rays of eq 1 meet (section 2.1 of the paper): "shoot the
 * opaque ray first, then shoot a ray from the origin to the intersection
 * location where we intersect a second BVH of just the bounding boxes of
 * these objects.  Each object has a density and exponential attenuation
 * is used to modify the obscurance multiplicatively"; trees "are treated
 * as semi-transparent objects, where each intersection attenuates
 * visibility by 50 %, and are in the same BVH as the shrubs".
 *
 * Here: the opaque BVH holds the triangles of class none; the second BVH
 * (Embree too) holds every shrub's world box as a user primitive and the
 * trees' triangles.  A ray of the second BVH never reports a hit: the box
 * callback adds -density * (length of the ray inside the box, up to the
 * opaque hit) to the ray's log-visibility, the trees' filter callback adds
 * ln(1 - tree_attenuation) for each triangle crossed and rejects it, so
 * traversal goes on to the end of the segment.  The second scene is built
 * without spatial splits (build quality medium), so that each primitive is
 * met once per ray. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "level/occl.h"
#include "level/sweep.h"
#include "internal.h"
#include "pool.h"

/* The ray context the callbacks see: Embree's, then the sums, one per
 * ray of a packet of 8, by the ray's id (Embree may hand a callback the
 * packet or one ray of it). */
typedef struct fog_ctx {
    struct RTCIntersectContext ctx;
    const obs__bake_occl *o;
    double log_vis[8]; /* ln of the visibility left */
} fog_ctx;

/* Field k of ray i of a packet of N, structure of arrays (Embree's RTCRayN
 * layout; its accessors are C++ only): org xyz 0-2, tnear 3, dir xyz 4-6,
 * time 7, tfar 8, mask 9, id 10, flags 11. */
#define RAYF(ray, N, k, i) (((const float *)(ray))[(k) * (N) + (i)])
#define RAY_ID(ray, N, i) (((const unsigned *)(ray))[10 * (N) + (i)] & 7u)

static void device_error(void *user, enum RTCError code, const char *msg)
{
    char *buf = user;
    if (!buf[0])
        snprintf(buf, OBS_ERR_LEN, "Embree error %d: %s", (int)code, msg ? msg : "");
}

void obs__bake_occl_free(obs__bake_occl *o)
{
    if (!o)
        return;
    if (o->opaque)
        rtcReleaseScene(o->opaque);
    if (o->fog)
        rtcReleaseScene(o->fog);
    if (o->dev)
        rtcReleaseDevice(o->dev);
    free(o->opaque_tri);
    free(o->box);
    free(o->density);
    free(o->box_node);
    free(o);
}

/* ---- the overlap pre-pass (section 2.1) ---------------------------------
 * "In a pre-processing step we compute the amount of overlap between a
 * bounding box and the rest of the shrubbery bounding boxes, reducing the
 * density so that visibility does not darken too much where bounding
 * boxes overlap."  The paper gives no formula; ours: with V_i the volume
 * of box i and O_i = sum over j != i of vol(B_i ∩ B_j),
 *   density_i <- density_i * V_i / (V_i + O_i),
 * so a box lying wholly inside k - 1 others of its size (O_i = (k - 1) V)
 * keeps 1/k of its density: k coincident boxes attenuate as one.  Pairs
 * by a sweep over the boxes sorted by min x (sweep.c). */
static double volume(const float *b)
{
    double v = 1.0;
    for (int k = 0; k < 3; k++)
        v *= fmax(0.0, (double)b[3 + k] - b[k]);
    return v;
}

void obs__bake_fog_overlap(const float *box, size_t n, float *density)
{
    uint32_t *o = obs__sweep_order(box, 6 * sizeof *box, n);
    double *ov = calloc(n ? n : 1, sizeof *ov);
    if (!o || !ov) { /* no memory: the densities stay as given */
        free(o);
        free(ov);
        return;
    }
    for (size_t a = 0; a < n; a++) {
        const float *p = box + 6 * (size_t)o[a];
        for (size_t b = a + 1; b < n && box[6 * (size_t)o[b]] < p[3]; b++) {
            const float *q = box + 6 * (size_t)o[b];
            double v = 1.0;
            for (int k = 0; k < 3; k++)
                v *= fmax(0.0, fmin((double)p[3 + k], q[3 + k]) - fmax((double)p[k], q[k]));
            ov[o[a]] += v;
            ov[o[b]] += v;
        }
    }
    for (size_t i = 0; i < n; i++) {
        double v = volume(box + 6 * i);
        if (v + ov[i] > 0.0)
            density[i] = (float)(density[i] * (v / (v + ov[i])));
    }
    free(o);
    free(ov);
}

/* ---- the second BVH's callbacks ----------------------------------------- */

static void box_bounds(const struct RTCBoundsFunctionArguments *args)
{
    const obs__bake_occl *o = args->geometryUserPtr;
    const float *b = o->box + 6 * (size_t)args->primID;
    struct RTCBounds *r = args->bounds_o;
    r->lower_x = b[0], r->lower_y = b[1], r->lower_z = b[2];
    r->upper_x = b[3], r->upper_y = b[4], r->upper_z = b[5];
}

/* The ray's segment inside the box (slabs), clipped to [tnear, tfar]:
 * tfar is the opaque hit, as no hit of this BVH is ever reported. */
static void box_intersect(const struct RTCIntersectFunctionNArguments *args)
{
    const obs__bake_occl *o = args->geometryUserPtr;
    fog_ctx *c = (fog_ctx *)args->context;
    const float *b = o->box + 6 * (size_t)args->primID;
    const void *ray = args->rayhit; /* the RTCRayN part comes first */
    const unsigned N = args->N;
    for (unsigned i = 0; i < N; i++) {
        if (args->valid[i] != -1)
            continue;
        float org[3] = {RAYF(ray, N, 0, i), RAYF(ray, N, 1, i), RAYF(ray, N, 2, i)};
        float dir[3] = {RAYF(ray, N, 4, i), RAYF(ray, N, 5, i), RAYF(ray, N, 6, i)};
        double t0 = RAYF(ray, N, 3, i), t1 = RAYF(ray, N, 8, i); /* tnear, tfar */
        for (int k = 0; k < 3 && t0 < t1; k++) {
            if (dir[k] == 0.0f) {
                if (org[k] < b[k] || org[k] > b[3 + k])
                    t1 = t0; /* parallel to the slab, outside it */
                continue;
            }
            double inv = 1.0 / dir[k], ta = (b[k] - org[k]) * inv, tb = (b[3 + k] - org[k]) * inv;
            t0 = fmax(t0, fmin(ta, tb));
            t1 = fmin(t1, fmax(ta, tb));
        }
        if (t1 > t0) /* exp(-density len) */
            c->log_vis[RAY_ID(ray, N, i)] -= (double)o->density[args->primID] * (t1 - t0);
    }
}

static void box_occluded(const struct RTCOccludedFunctionNArguments *args)
{
    (void)args; /* fog never blocks a shadow ray outright */
}

static void tree_filter(const struct RTCFilterFunctionNArguments *args)
{
    fog_ctx *c = (fog_ctx *)args->context;
    for (unsigned i = 0; i < args->N; i++) {
        if (args->valid[i] == 0)
            continue;
        /* one crossing keeps 1 - tree_attenuation */
        c->log_vis[RAY_ID(args->ray, args->N, i)] += c->o->log_keep;
        args->valid[i] = 0; /* rejected: traversal goes on */
    }
}

void obs__bake_occl_transmittance8(const obs__bake_occl *o, const int *valid,
                                   const struct RTCRayHit8 *opaque, double tr[8])
{
    for (int l = 0; l < 8; l++)
        tr[l] = 1.0;
    if (!o->fog)
        return;
    fog_ctx c;
    rtcInitIntersectContext(&c.ctx);
    c.o = o;
    RTC_ALIGN(32) struct RTCRayHit8 rh;
    RTC_ALIGN(32) int v[8];
    for (int l = 0; l < 8; l++) {
        c.log_vis[l] = 0.0;
        v[l] = valid[l];
        rh.ray.org_x[l] = opaque->ray.org_x[l];
        rh.ray.org_y[l] = opaque->ray.org_y[l];
        rh.ray.org_z[l] = opaque->ray.org_z[l];
        rh.ray.dir_x[l] = opaque->ray.dir_x[l];
        rh.ray.dir_y[l] = opaque->ray.dir_y[l];
        rh.ray.dir_z[l] = opaque->ray.dir_z[l];
        rh.ray.tnear[l] = 0.0f;
        rh.ray.tfar[l] = opaque->ray.tfar[l]; /* up to the opaque hit */
        rh.ray.time[l] = 0.0f;
        rh.ray.mask[l] = 0xffffffffu;
        rh.ray.id[l] = (unsigned)l; /* the callbacks' lane */
        rh.ray.flags[l] = 0;
        rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(v, o->fog, &c.ctx, &rh);
    for (int l = 0; l < 8; l++)
        if (valid[l])
            tr[l] = exp(c.log_vis[l]);
}

/* ---- building ----------------------------------------------------------- */

/* A triangle geometry of the world's triangles listed in tri (n). */
static obs_status add_triangles(obs__bake_occl *o, RTCScene sc, const obs__bake_world *w,
                                const uint32_t *tri, size_t n, RTCFilterFunctionN filter,
                                const char *dev_err, char err[OBS_ERR_LEN])
{
    if (n == 0)
        return OBS_OK;
    RTCGeometry g = rtcNewGeometry(o->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    /* Copies: Embree reads vertex buffers in 16-byte loads and wants them
     * padded. */
    float *v = g ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                           3 * sizeof(float), w->vertex_count)
                 : NULL;
    unsigned *ix = g ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                               3 * sizeof(unsigned), n)
                     : NULL;
    if (!v || !ix) {
        if (g)
            rtcReleaseGeometry(g);
        return obs__fail(err, OBS_NO_MEMORY, "Embree scene of %zu triangles: %s", n,
                         dev_err[0] ? dev_err : "out of memory");
    }
    memcpy(v, w->pos, w->vertex_count * 3 * sizeof(float));
    if (!tri)
        memcpy(ix, w->tri, n * 3 * sizeof(unsigned));
    else
        for (size_t k = 0; k < n; k++)
            memcpy(ix + 3 * k, w->tri + 3 * (size_t)tri[k], 3 * sizeof(unsigned));
    if (filter) {
        rtcSetGeometryIntersectFilterFunction(g, filter);
        rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_MEDIUM);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(sc, g);
    rtcReleaseGeometry(g);
    return OBS_OK;
}

/* FNV-1a of a triangle's three positions, in order, and its sidedness. */
static uint64_t tri_hash(const obs__bake_world *w, uint32_t t)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    for (int c = 0; c < 3; c++) {
        const unsigned char *b = (const unsigned char *)(w->pos + 3 * (size_t)w->tri[3 * t + c]);
        for (size_t k = 0; k < 3 * sizeof(float); k++)
            h = (h ^ b[k]) * 0x100000001b3ULL;
    }
    return (h ^ w->two_sided[t]) * 0x100000001b3ULL;
}

static int tri_same(const obs__bake_world *w, uint32_t a, uint32_t b)
{
    if (w->two_sided[a] != w->two_sided[b])
        return 0;
    for (int c = 0; c < 3; c++)
        if (memcmp(w->pos + 3 * (size_t)w->tri[3 * a + c], w->pos + 3 * (size_t)w->tri[3 * b + c],
                   3 * sizeof(float)))
            return 0;
    return 1;
}

size_t obs__bake_drop_copies(const obs__bake_world *w, uint32_t *list, size_t n)
{
    size_t cap = 16;
    while (cap < 2 * n)
        cap *= 2;
    uint32_t *slot = malloc(cap * sizeof *slot);
    if (!slot)
        return SIZE_MAX;
    memset(slot, 0xff, cap * sizeof *slot);
    size_t kept = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t t = list[i];
        size_t s = (size_t)tri_hash(w, t) & (cap - 1);
        while (slot[s] != UINT32_MAX && !tri_same(w, slot[s], t))
            s = (s + 1) & (cap - 1);
        if (slot[s] != UINT32_MAX)
            continue; /* a copy */
        slot[s] = t;
        list[kept++] = t;
    }
    free(slot);
    return kept;
}

/* The world boxes of the shrub nodes (one per node: the union of its
 * instances), their densities through the overlap pre-pass. */
static obs_status shrub_boxes(obs__bake_occl *o, const obs__bake_world *w,
                              const obs__bake_decor *d, char err[OBS_ERR_LEN])
{
    int64_t *of = malloc((d->node_count ? d->node_count : 1) * sizeof *of);
    size_t n = 0;
    if (!of)
        return obs__fail(err, OBS_NO_MEMORY, "shrub boxes");
    for (size_t i = 0; i < d->node_count; i++)
        of[i] = -1;
    for (size_t i = 0; i < w->instance_count; i++) {
        uint32_t nd = w->inst[i].node;
        if (nd < d->node_count && d->node_class[nd] == OBS__DECOR_SHRUB && of[nd] < 0)
            of[nd] = (int64_t)n++;
    }
    o->box = malloc((n ? n : 1) * 6 * sizeof *o->box);
    o->density = malloc((n ? n : 1) * sizeof *o->density);
    o->box_node = malloc((n ? n : 1) * sizeof *o->box_node);
    if (!o->box || !o->density || !o->box_node) {
        free(of);
        return obs__fail(err, OBS_NO_MEMORY, "%zu shrub boxes", n);
    }
    o->box_count = n;
    for (size_t b = 0; b < n; b++)
        for (int k = 0; k < 3; k++)
            o->box[6 * b + k] = INFINITY, o->box[6 * b + 3 + k] = -INFINITY;
    for (size_t nd = 0; nd < d->node_count; nd++)
        if (of[nd] >= 0) {
            o->density[of[nd]] = d->density[nd];
            o->box_node[of[nd]] = (uint32_t)nd;
        }
    for (size_t i = 0; i < w->instance_count; i++) {
        const obs__bake_inst *in = &w->inst[i];
        if (in->node >= d->node_count || of[in->node] < 0)
            continue;
        size_t end = i + 1 < w->instance_count ? w->inst[i + 1].first_vertex : w->vertex_count;
        float *b = o->box + 6 * (size_t)of[in->node];
        for (size_t v = in->first_vertex; v < end; v++)
            for (int k = 0; k < 3; k++) {
                b[k] = fminf(b[k], w->pos[3 * v + k]);
                b[3 + k] = fmaxf(b[3 + k], w->pos[3 * v + k]);
            }
    }
    free(of);
    for (size_t b = 0; b < n; b++) /* a shrub without vertices: an empty box */
        if (!(o->box[6 * b] <= o->box[6 * b + 3]))
            for (int k = 0; k < 6; k++)
                o->box[6 * b + k] = 0.0f;
    obs__bake_fog_overlap(o->box, n, o->density);
    return OBS_OK;
}

obs_status obs__bake_occl_new(const obs__bake_world *w, const obs__bake_decor *d,
                              float tree_attenuation, obs__bake_occl **out,
                              char err[OBS_ERR_LEN])
{
    char dev_err[OBS_ERR_LEN] = "";
    obs_status st = OBS_OK;
    uint32_t *trees = NULL;
    *out = NULL;
    obs__bake_occl *o = calloc(1, sizeof *o);
    if (!o)
        return obs__fail(err, OBS_NO_MEMORY, "BVH");
    o->log_keep = tree_attenuation >= 1.0f ? -INFINITY : log1p(-(double)tree_attenuation);
    char embree_cfg[32];
    if (!(o->dev = rtcNewDevice(obs__pool_embree_config(embree_cfg)))) {
        free(o);
        return obs__fail(err, OBS_UNSUPPORTED, "Embree: no device (error %d)",
                         (int)rtcGetDeviceError(NULL));
    }
    rtcSetDeviceErrorFunction(o->dev, device_error, dev_err);
    const int decor = d && d->node_count &&
                      d->counts[OBS__DECOR_NONE] < d->node_count;
    /* The triangles by class: opaque ones, tree ones. */
    size_t nt = w->triangle_count, nopaque = nt, ntree = 0;
    if (decor) {
        o->opaque_tri = malloc((nt ? nt : 1) * sizeof *o->opaque_tri);
        trees = malloc((nt ? nt : 1) * sizeof *trees);
        if (!o->opaque_tri || !trees) {
            st = obs__fail(err, OBS_NO_MEMORY, "triangle classes of %zu triangles", nt);
            goto done;
        }
        nopaque = 0;
        for (size_t i = 0; i < w->instance_count; i++) {
            const obs__bake_inst *in = &w->inst[i];
            size_t end = i + 1 < w->instance_count ? w->inst[i + 1].first_triangle : nt;
            int c = in->node < d->node_count ? d->node_class[in->node] : OBS__DECOR_NONE;
            for (size_t t = in->first_triangle; t < end; t++) {
                if (c == OBS__DECOR_NONE)
                    o->opaque_tri[nopaque++] = (uint32_t)t;
                else if (c == OBS__DECOR_TREE)
                    trees[ntree++] = (uint32_t)t;
            }
        }
    }
    /* Exact copies left out (obs__bake_drop_copies): a level without any
     * keeps every triangle and no list. */
    uint32_t *all = o->opaque_tri;
    if (!all && !(all = malloc((nt ? nt : 1) * sizeof *all))) {
        st = obs__fail(err, OBS_NO_MEMORY, "the copies among %zu triangles", nt);
        goto done;
    }
    if (!o->opaque_tri)
        for (size_t t = 0; t < nt; t++)
            all[t] = (uint32_t)t;
    size_t kept = obs__bake_drop_copies(w, all, nopaque);
    if (kept == SIZE_MAX) {
        if (all != o->opaque_tri)
            free(all);
        st = obs__fail(err, OBS_NO_MEMORY, "the copies among %zu triangles", nopaque);
        goto done;
    }
    if (kept == nopaque && all != o->opaque_tri)
        free(all);
    else
        o->opaque_tri = all;
    nopaque = kept;
    o->opaque_count = nopaque;
    o->tree_count = ntree;
    o->opaque = rtcNewScene(o->dev);
    if (!o->opaque) {
        st = obs__fail(err, OBS_NO_MEMORY, "Embree scene: %s", dev_err);
        goto done;
    }
    if ((st = add_triangles(o, o->opaque, w, o->opaque_tri, nopaque, NULL, dev_err, err)) !=
        OBS_OK)
        goto done;
    rtcSetSceneBuildQuality(o->opaque, RTC_BUILD_QUALITY_HIGH);
    rtcCommitScene(o->opaque);
    if (decor && (st = shrub_boxes(o, w, d, err)) != OBS_OK)
        goto done;
    if (o->box_count || ntree) {
        o->fog = rtcNewScene(o->dev);
        if (!o->fog) {
            st = obs__fail(err, OBS_NO_MEMORY, "Embree scene: %s", dev_err);
            goto done;
        }
        /* no spatial splits: a primitive in one leaf, met once per ray */
        rtcSetSceneBuildQuality(o->fog, RTC_BUILD_QUALITY_MEDIUM);
        if ((st = add_triangles(o, o->fog, w, trees, ntree, tree_filter, dev_err, err)) != OBS_OK)
            goto done;
        if (o->box_count) {
            RTCGeometry g = rtcNewGeometry(o->dev, RTC_GEOMETRY_TYPE_USER);
            if (!g) {
                st = obs__fail(err, OBS_NO_MEMORY, "Embree: %zu shrub boxes: %s", o->box_count,
                               dev_err);
                goto done;
            }
            rtcSetGeometryUserPrimitiveCount(g, (unsigned)o->box_count);
            rtcSetGeometryUserData(g, o);
            rtcSetGeometryBoundsFunction(g, box_bounds, o);
            rtcSetGeometryIntersectFunction(g, box_intersect);
            rtcSetGeometryOccludedFunction(g, box_occluded);
            rtcCommitGeometry(g);
            rtcAttachGeometry(o->fog, g);
            rtcReleaseGeometry(g);
        }
        rtcCommitScene(o->fog);
    }
    if (dev_err[0])
        st = obs__fail(err, OBS_NO_MEMORY, "Embree scene: %s", dev_err);
done:
    free(trees);
    if (o->dev)
        rtcSetDeviceErrorFunction(o->dev, NULL, NULL);
    if (st != OBS_OK) {
        obs__bake_occl_free(o);
        return st;
    }
    *out = o;
    return OBS_OK;
}

/* ---- the public wrapper (obscura/bake.h), for the reference ------------- */

struct obs_bake_occluders {
    obs__bake_world w;
    obs__bake_occl *occl;
};

void obs_bake_occluders_free(obs_bake_occluders *o)
{
    if (!o)
        return;
    obs__bake_occl_free(o->occl);
    obs__bake_world_free(&o->w);
    free(o);
}

obs_status obs_bake_occluders_new(const obs_bake_scene *s, const obs_bake_params *params,
                                  const char *decorators_json, obs_bake_occluders **out,
                                  char warning[OBS_ERR_LEN], char err[OBS_ERR_LEN])
{
    *out = NULL;
    if (warning)
        warning[0] = 0;
    obs_bake_params p;
    obs_bake_params_resolve(params, &p);
    obs__bake_decor d;
    obs_status st = obs__bake_decor_classify(s, &p, decorators_json, &d, err);
    if (st != OBS_OK)
        return st;
    if (warning)
        snprintf(warning, OBS_ERR_LEN, "%s", err);
    err[0] = 0;
    if (d.counts[OBS__DECOR_NONE] == d.node_count) {
        obs__bake_decor_free(&d);
        return OBS_OK;
    }
    obs_bake_occluders *o = calloc(1, sizeof *o);
    if (!o) {
        obs__bake_decor_free(&d);
        return obs__fail(err, OBS_NO_MEMORY, "occluders");
    }
    /* the level is read with no limit (obs_bake_load's 0): the
     * parameter bounds what its instances flatten to */
    if ((st = obs__bake_flatten_checked(s, p.max_triangles, "occluders", &o->w, err)) == OBS_OK)
        st = obs__bake_occl_new(&o->w, &d, p.tree_attenuation, &o->occl, err);
    obs__bake_decor_free(&d);
    if (st != OBS_OK) {
        obs_bake_occluders_free(o);
        return st;
    }
    *out = o;
    return OBS_OK;
}

const obs__bake_occl *obs__bake_occluders_occl(const obs_bake_occluders *o)
{
    return o ? o->occl : NULL;
}
