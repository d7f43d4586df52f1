/* Large instanced decorators (section 2.2 of "Baked ambient obscurance on
 * the vertices of game levels"): trees.
 *
 * "For every individual tree model, we compute a 'local AO' signal by
 * simply baking the tree in isolation [...].  We then complement this
 * per-model signal with per-instance AO representation, the 'global AO',
 * which takes into account the AO contribution due to the placement of
 * this instance in the scene.  [...] we use a 3D linear function (four
 * scalar coefficients).  These per-instance coefficients are determined
 * by a least squares fit of the residual between the actual AO signal and
 * local AO times the function" (eq 3):
 *
 *   min_y  sum_i ( f(s_i) - G_y(s_i) L(T_j s_i) )^2
 *
 * Here:
 *   - L, per distinct mesh (not per instance): the bake's steps 2-4
 *     (samples, trace, fit) on the mesh alone in its own space, through
 *     obs_bake_run on a scene of that one mesh (bake.c's local_ao, handed
 *     in);
 *   - f, the "actual AO signal" at the instance's vertices, from the
 *     sparse volume of spherical visibility traced in the whole level
 *     around the instances (volume.c), trilinear, evaluated at the
 *     vertex's normal ("This volume data is only used by the tool to
 *     reconstruct values at vertices");
 *   - the points s_i of eq 3 are the instance's vertices, and G_y is a
 *     function of the vertex's position q = T_j s_i in the mesh's space,
 *     G_y(q) = y0 + y1 qx + y2 qy + y3 qz, so an engine evaluates it on
 *     the instanced mesh's own POSITION;
 *   - the vertex's AO is "local AO times the function", L(q) G_y(q)
 *     (section 2.2, Figure 2), at each distance and for the blend (_AO).
 * The instances' own faces take no surface samples in the level: their
 * vertices are this model's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/instanced.h"
#include "bake/volume.h"
#include "internal.h"

/* A volume this large would take hours to trace: refused, naming the
 * parameter that shrinks it. */
#define MAX_VOLUME_POINTS ((size_t)4 << 20)

static float clamp01(double v) { return (float)(v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v); }

/* Solves the symmetric 4x4 system a y = b by Gaussian elimination with
 * partial pivoting; 0 when singular. */
static int solve4(double a[4][4], double b[4], double y[4])
{
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c]))
                piv = r;
        if (!(fabs(a[piv][c]) > 1e-300))
            return 0;
        if (piv != c) {
            for (int k = 0; k < 4; k++) {
                double t = a[c][k];
                a[c][k] = a[piv][k];
                a[piv][k] = t;
            }
            double t = b[c];
            b[c] = b[piv];
            b[piv] = t;
        }
        for (int r = c + 1; r < 4; r++) {
            double m = a[r][c] / a[c][c];
            for (int k = c; k < 4; k++)
                a[r][k] -= m * a[c][k];
            b[r] -= m * b[c];
        }
    }
    for (int r = 3; r >= 0; r--) {
        double s = b[r];
        for (int k = r + 1; k < 4; k++)
            s -= a[r][k] * y[k];
        y[r] = s / a[r][r];
    }
    return 1;
}

int obs__bake_eq3_fit(const float *q, const double *f, const double *L, size_t n, double y[4])
{
    y[0] = 1.0, y[1] = y[2] = y[3] = 0.0;
    if (n == 0)
        return 0;
    /* Centred on the points' mean c: G(q) = z0 + z . (q - c), then
     * y0 = z0 - z . c; keeps the normal equations well conditioned far
     * from the origin. */
    double c[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++)
            c[a] += q[3 * i + a] / (double)n;
    /* Eq 3's normal equations: row r_i = L_i (1, q - c), A = sum r r^T,
     * b = sum r f_i. */
    double A[4][4] = {{0}}, b[4] = {0}, z[4] = {1.0, 0.0, 0.0, 0.0};
    for (size_t i = 0; i < n; i++) {
        double l = L ? L[i] : 1.0;
        double r[4] = {l, l * (q[3 * i] - c[0]), l * (q[3 * i + 1] - c[1]),
                       l * (q[3 * i + 2] - c[2])};
        for (int u = 0; u < 4; u++) {
            b[u] += r[u] * f[i];
            for (int v = 0; v < 4; v++)
                A[u][v] += r[u] * r[v];
        }
    }
    if (!(A[0][0] > 0.0))
        return 0;
    /* A tiny ridge on the gradient, relative to the system's scale: a
     * flat card (or a single point) leaves directions free. */
    double tr = A[0][0] + A[1][1] + A[2][2] + A[3][3];
    for (int u = 1; u < 4; u++)
        A[u][u] += 1e-9 * tr + 1e-300;
    if (!solve4(A, b, z))
        return 0;
    y[0] = z[0] - z[1] * c[0] - z[2] * c[1] - z[3] * c[2];
    y[1] = z[1], y[2] = z[2], y[3] = z[3];
    return 1;
}

static double eval_g(const double y[4], const float q[3])
{
    return y[0] + y[1] * q[0] + y[2] * q[1] + y[3] * q[2];
}

static size_t tri_end(const obs__bake_world *w, size_t i)
{
    return i + 1 < w->instance_count ? w->inst[i + 1].first_triangle : w->triangle_count;
}

size_t obs__bake_instanced_select(const obs_bake_scene *s, const obs__bake_world *w,
                                  const obs__bake_decor *dc, const obs_bake_params *p,
                                  uint8_t *sel)
{
    memset(sel, 0, w->instance_count);
    if (p->instanced != OBS_BAKE_INSTANCED_TREES || !dc->node_class)
        return 0;
    size_t *uses = calloc(s->mesh_count ? s->mesh_count : 1, sizeof *uses), n = 0;
    if (!uses)
        return 0; /* no memory: nothing instanced, everything traced in place */
    for (size_t i = 0; i < w->instance_count; i++)
        if (dc->node_class[w->inst[i].node] == OBS__DECOR_TREE)
            uses[w->inst[i].mesh]++;
    for (size_t i = 0; i < w->instance_count; i++) {
        const obs__bake_inst *in = &w->inst[i];
        /* a mesh of degenerate faces only has nothing to bake alone: it
         * stays in place (the level's warnings name such faces) */
        int area = 0;
        for (size_t t = in->first_triangle; t < tri_end(w, i) && !area; t++)
            area = w->area[t] > 0.0f;
        sel[i] = dc->node_class[in->node] == OBS__DECOR_TREE &&
                 uses[in->mesh] >= (size_t)p->instanced_min && area;
        n += sel[i];
    }
    free(uses);
    return n;
}

void obs__bake_instanced_mask(obs__bake_world *w, const uint8_t *sel)
{
    /* Counted with the degenerate faces from here on (the report took
     * its count before), so that the sample budget, a mean per face with
     * area (samples.c), is the rest of the level's alone. */
    for (size_t i = 0; i < w->instance_count; i++)
        if (sel[i])
            for (size_t t = w->inst[i].first_triangle; t < tri_end(w, i); t++) {
                w->degenerate += w->area[t] > 0.0f;
                w->area[t] = 0.0f;
            }
}

void obs__bake_instanced_uncount(const obs__bake_world *w, const obs__bake_weld *wd,
                                 const uint8_t *sel, obs_bake_stats *st)
{
    /* bit 0: held by a selected instance, bit 1: by another */
    uint8_t *by = calloc(wd->count ? wd->count : 1, 1);
    if (!by)
        return; /* the counts stay as the fit made them */
    for (size_t i = 0; i < w->instance_count; i++) {
        size_t v1 = i + 1 < w->instance_count ? w->inst[i + 1].first_vertex : w->vertex_count;
        for (size_t v = w->inst[i].first_vertex; v < v1; v++)
            by[wd->of[v]] |= sel[i] ? 1 : 2;
    }
    size_t n = 0;
    for (size_t k = 0; k < wd->count; k++)
        n += by[k] == 1;
    free(by);
    st->vertices_without_samples -= n < st->vertices_without_samples ? n : st->vertices_without_samples;
    st->vertices_isolated -= n < st->vertices_isolated ? n : st->vertices_isolated;
}

/* The bake's progress callback with every sample done: nonzero stops. */
typedef struct stop_ctx {
    const obs_bake_desc *desc;
    size_t samples;
} stop_ctx;

static int stop_asked(void *user)
{
    const stop_ctx *c = user;
    return c->desc && c->desc->progress &&
           c->desc->progress(c->desc->progress_user, c->samples, c->samples);
}

/* The local AO, once per distinct mesh of the selected instances (the
 * pipeline on that mesh alone); max_v: the most vertices of one. */
static obs_status local_aos(const obs_bake_scene *s, const obs__bake_world *w, const uint8_t *sel,
                            const obs_bake_params *p, obs__bake_alone_fn local_ao, stop_ctx *sc,
                            double **local, size_t *max_v, obs_bake_stats *st,
                            char err[OBS_ERR_LEN])
{
    obs_status rc;
    for (size_t i = 0; i < w->instance_count; i++) {
        if (!sel[i])
            continue;
        uint32_t m = w->inst[i].mesh;
        size_t nv = s->meshes[m].vertex_count;
        *max_v = nv > *max_v ? nv : *max_v;
        if (local[m])
            continue;
        if (stop_asked(sc))
            return obs__fail(err, OBS_CANCELLED, "bake cancelled in the instanced trees' local AO");
        if (!(local[m] = malloc((nv ? nv : 1) * 2 * sizeof **local)))
            return obs__fail(err, OBS_NO_MEMORY, "local AO of %zu vertices", nv);
        if ((rc = local_ao(s, m, p, local[m], err)) != OBS_OK) {
            char why[OBS_ERR_LEN];
            snprintf(why, sizeof why, "%s", err);
            return obs__fail(err, rc, "local AO of mesh '%s': %s",
                             s->meshes[m].name ? s->meshes[m].name : "?", why);
        }
        st->instanced_meshes++;
    }
    return OBS_OK;
}

/* The selected instances' world boxes (6 floats each: lo, hi); returns
 * their count. */
static size_t instance_boxes(const obs_bake_scene *s, const obs__bake_world *w, const uint8_t *sel,
                             float *boxes)
{
    size_t nbox = 0;
    for (size_t i = 0; i < w->instance_count; i++) {
        if (!sel[i])
            continue;
        float *bx = boxes + 6 * nbox++;
        size_t v0 = w->inst[i].first_vertex, nv = s->meshes[w->inst[i].mesh].vertex_count;
        for (int a = 0; a < 3; a++)
            bx[a] = INFINITY, bx[3 + a] = -INFINITY;
        for (size_t v = v0; v < v0 + nv; v++)
            for (int a = 0; a < 3; a++) {
                bx[a] = fminf(bx[a], w->pos[3 * v + a]);
                bx[3 + a] = fmaxf(bx[3 + a], w->pos[3 * v + a]);
            }
    }
    return nbox;
}

/* Eq 3 for instance i, at each distance and for the blend: f (the
 * volume's AO) and L (the mesh's local AO) gathered at its vertices into
 * the scratch arrays (3 x the most vertices), the model's values written
 * over the instance's; sq, nsq: the blend's squared residuals. */
static obs_status eq3_instance(const obs_bake_scene *s, const obs__bake_world *w, size_t i,
                               const obs__vol *vol, double *const *local,
                               const obs_bake_params *p, double *f, double *L,
                               obs_bake_result *out, double *sq, size_t *nsq,
                               char err[OBS_ERR_LEN])
{
    const obs__bake_inst *in = &w->inst[i];
    const obs_bake_mesh *m = &s->meshes[in->mesh];
    obs_bake_instance *r = &out->instances[i];
    obs_bake_stats *st = &out->stats;
    size_t nv = m->vertex_count;
    float blend = p->blend;
    for (size_t v = 0; v < nv; v++) {
        const float *p3 = w->pos + 3 * (in->first_vertex + v),
                    *n3 = w->nrm + 3 * (in->first_vertex + v);
        double ao[2];
        int has_n = n3[0] != 0.0f || n3[1] != 0.0f || n3[2] != 0.0f;
        if (!obs__vol_eval(vol, p3, has_n ? n3 : NULL, ao))
            return obs__fail(err, OBS_INVALID_ARGUMENT,
                             "volume: a vertex of instance %zu has a corner missing", i);
        /* f: the volume's AO (eq 1 at the vertex); [c nv + v], c = 0
         * the blend (section 2's _AO), 1 short, 2 long */
        f[nv + v] = clamp01(ao[0]);
        f[2 * nv + v] = clamp01(ao[1]);
        f[v] = blend * f[nv + v] + (1.0 - blend) * f[2 * nv + v];
        L[nv + v] = local[in->mesh][2 * v];
        L[2 * nv + v] = local[in->mesh][2 * v + 1];
        L[v] = blend * L[nv + v] + (1.0 - blend) * L[2 * nv + v];
    }
    if (p->instanced_values == OBS_BAKE_IVALUES_LINEAR)
        for (size_t v = 0; v < 3 * nv; v++)
            L[v] = 1.0; /* G alone: eq 3 with L = 1 */
    free(r->ao_local);
    r->ao_local = NULL;
    if (p->instanced_values == OBS_BAKE_IVALUES_VOLUME) {
        /* no model: the volume's AO itself (the comparisons' row) */
        float *d3[3] = {r->ao, r->ao_short, r->ao_long};
        for (int c = 0; c < 3; c++)
            for (size_t v = 0; v < nv; v++)
                d3[c][v] = clamp01(f[c * nv + v]);
        st->instanced_instances++;
        return OBS_OK;
    }
    if (!(r->ao_local = malloc((nv ? nv : 1) * sizeof *r->ao_local)))
        return obs__fail(err, OBS_NO_MEMORY, "local AO of %zu vertices", nv);
    float *dst[3] = {r->ao, r->ao_short, r->ao_long};
    for (int c = 0; c < 3; c++) {
        double y[4] = {1.0, 0.0, 0.0, 0.0};
        if (p->instanced_values != OBS_BAKE_IVALUES_LOCAL)
            obs__bake_eq3_fit(m->positions, f + c * nv, L + c * nv, nv, y); /* eq 3 */
        for (int k = 0; k < 4; k++)
            r->global[c][k] = (float)y[k];
        for (size_t v = 0; v < nv; v++) {
            /* local AO times the function (section 2.2) */
            double g = eval_g(y, m->positions + 3 * v);
            dst[c][v] = clamp01(L[c * nv + v] * g);
            if (c == 0) {
                r->ao_local[v] = (float)L[v];
                double e = f[v] - dst[0][v];
                *sq += e * e;
                (*nsq)++;
            }
        }
    }
    st->instanced_instances++;
    return OBS_OK;
}

/* The level's _AO range again, the instances' values replaced. */
static void ao_range(const obs_bake_scene *s, obs_bake_result *out)
{
    double sum = 0.0, lo = INFINITY, hi = -INFINITY;
    size_t cnt = 0;
    for (size_t i = 0; i < out->instance_count; i++) {
        size_t nv = s->meshes[out->instances[i].mesh].vertex_count;
        for (size_t v = 0; v < nv; v++, cnt++) {
            float a = out->instances[i].ao[v];
            sum += a;
            lo = fmin(lo, a);
            hi = fmax(hi, a);
        }
    }
    out->stats.ao_mean = cnt ? sum / (double)cnt : 0.0;
    out->stats.ao_min = lo;
    out->stats.ao_max = hi;
}

obs_status obs__bake_instanced_run(const obs_bake_scene *s, const obs__bake_world *w,
                                   const uint8_t *sel, const obs_bake_params *p,
                                   const obs_bake_desc *desc, size_t samples,
                                   const obs__bake_decor *dc, obs__bake_alone_fn local_ao,
                                   obs_bake_result *out, char err[OBS_ERR_LEN])
{
    stop_ctx sc = {desc, samples};
    obs_bake_stats *st = &out->stats;
    obs_status rc = OBS_OK;
    double **local = calloc(s->mesh_count ? s->mesh_count : 1, sizeof *local);
    float *boxes = malloc((w->instance_count ? w->instance_count : 1) * 6 * sizeof *boxes);
    double *f = NULL, *L = NULL;
    obs__vol vol = {0};
    obs__bake_bvh *bvh = NULL;
    size_t max_v = 0;
    if (!local || !boxes) {
        rc = obs__fail(err, OBS_NO_MEMORY, "instanced decorators of %zu instances",
                       w->instance_count);
        goto done;
    }

    double t = obs__bake_now();
    if ((rc = local_aos(s, w, sel, p, local_ao, &sc, local, &max_v, st, err)) != OBS_OK)
        goto done;
    st->seconds[OBS_BAKE_STAGE_local] = obs__bake_now() - t;

    /* The sparse volume around the instances' world boxes, traced in the
     * whole level. */
    t = obs__bake_now();
    size_t nbox = instance_boxes(s, w, sel, boxes);
    if ((rc = obs__vol_build(&vol, p->volume_spacing, boxes, nbox, MAX_VOLUME_POINTS, err)) !=
        OBS_OK)
        goto done;
    /* the level's occluders as its surface samples see them (section
     * 2.1): f is the "actual AO signal" of the bake, trees and shrubs
     * attenuating */
    if ((rc = obs__bake_bvh_new_decor(w, dc, p->tree_attenuation, &bvh, err)) != OBS_OK)
        goto done;
    float dist[2] = {p->distance_short, p->distance_long};
    if ((rc = obs__vol_trace(&vol, bvh, p->volume_rays, dist, p->backface_limit,
                             (uint64_t)p->seed, p->threads, stop_asked, &sc, err)) != OBS_OK)
        goto done;
    st->volume_bricks = vol.brick_count;
    st->volume_points = vol.count;
    st->volume_points_inside = vol.inside_count;
    st->volume_rays = vol.rays;
    st->seconds[OBS_BAKE_STAGE_volume] = obs__bake_now() - t;

    /* Eq 3 per instance. */
    t = obs__bake_now();
    f = malloc((max_v ? max_v : 1) * 3 * sizeof *f);
    L = malloc((max_v ? max_v : 1) * 3 * sizeof *L);
    if (!f || !L) {
        rc = obs__fail(err, OBS_NO_MEMORY, "eq 3 of %zu vertices", max_v);
        goto done;
    }
    double sq = 0.0;
    size_t nsq = 0;
    for (size_t i = 0; i < w->instance_count; i++)
        if (sel[i] && (rc = eq3_instance(s, w, i, &vol, local, p, f, L, out, &sq, &nsq, err)) !=
                          OBS_OK)
            goto done;
    st->instanced_residual = nsq ? sqrt(sq / (double)nsq) : 0.0;
    ao_range(s, out);
    st->seconds[OBS_BAKE_STAGE_global] = obs__bake_now() - t;
done:
    for (size_t m = 0; local && m < s->mesh_count; m++)
        free(local[m]);
    free(local);
    free(boxes);
    free(f);
    free(L);
    obs__bake_bvh_free(bvh);
    obs__vol_free(&vol);
    return rc;
}
