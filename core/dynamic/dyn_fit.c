/* The region models of section 2.3: eq 4 per region, the neighbour
 * regularisation, tiny regions absorbed (section 3).
 *
 * Eq 4:  AO_dynamic(p) = v_mean + sum_{i=0..2} (p - c)_i v_{2i+s_i},
 * s_i = 0 or 1 by the sign of (p - c)_i, the v_j ordered +x, -x, +y, -y,
 * +z, -z.  For a fixed centre c the seven terms are linear: least squares
 * over the region's valid points, one system for all 18 channels ("The
 * system is solved once and applied for each of the 18 channels").  The
 * candidate centres are "the center of mass of the valid samples in the
 * region and the center of the region"; the one with the smaller sum of
 * squared residuals is kept.
 *
 * The regularisation minimises
 *   E = sum_i ||M_i - M_orig,i||^2 + beta sum_{ij} w_ij (M_i(b_ij) - M_j(b_ij))^2
 * with ||M_i - M_orig,i||^2 measured where it matters, over the region's
 * own points: (x - x0)^T A_i (x - x0), A_i = X_i^T X_i / n_i (the mean
 * squared difference of the two models at the points), each edge once,
 * w_ij the shared boundary area divided by the mean over the edges (so
 * beta does not depend on the level's units), b_ij the centre of the
 * shared face (boundary_points > 1: a grid of points over the face, the
 * weight shared among them; not the paper's).  "Instead of solving a global linear system, we simply use a
 * variant of block coordinate descent": each sweep minimises E over one
 * model at a time, the others fixed (a 7 x 7 system with 18 right-hand
 * sides); E never grows.
 *
 * Section 3: "very small regions are absorbed into the most compatible
 * neighbor": a region with fewer than absorb_points valid points takes
 * the model of the neighbour that predicts its points best (the smallest
 * squared error; with no points, the neighbour with the largest shared
 * face). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dynamic/dyn_internal.h"
#include "internal.h"

#define T OBS_DYN_TERMS
#define C OBS_DYN_CHANNELS

void obs__dyn_eq4_row(const float q[3], double row[T])
{
    row[0] = 1.0;
    for (int i = 0; i < 3; i++) {
        row[1 + 2 * i] = q[i] >= 0.0f ? q[i] : 0.0; /* v_2i,   s_i = 0 */
        row[2 + 2 * i] = q[i] < 0.0f ? q[i] : 0.0;  /* v_2i+1, s_i = 1 */
    }
}

/* The columns of a kind: eq 4's 7, the constant's 1, the gradient's 4
 * (1, q_x, q_y, q_z). */
static int kind_row(obs__dyn_kind kind, const float q[3], double row[T])
{
    if (kind == OBS__DYN_EQ4) {
        obs__dyn_eq4_row(q, row);
        return T;
    }
    row[0] = 1.0;
    if (kind == OBS__DYN_CONSTANT)
        return 1;
    for (int i = 0; i < 3; i++)
        row[1 + i] = q[i];
    return 4;
}

/* Solves H x = B in place (H m x m symmetric positive definite after a
 * small ridge, B m x C); returns 0 when the factorisation fails. */
static int chol_solve(double *H, double *B, int m)
{
    double tr = 0.0;
    for (int i = 0; i < m; i++)
        tr += H[i * m + i];
    double ridge = 1e-12 * (tr > 0.0 ? tr : 1.0);
    for (int i = 0; i < m; i++)
        H[i * m + i] += ridge;
    for (int j = 0; j < m; j++) {
        double d = H[j * m + j];
        for (int k = 0; k < j; k++)
            d -= H[j * m + k] * H[j * m + k];
        if (!(d > 0.0))
            return 0;
        d = sqrt(d);
        H[j * m + j] = d;
        for (int i = j + 1; i < m; i++) {
            double s = H[i * m + j];
            for (int k = 0; k < j; k++)
                s -= H[i * m + k] * H[j * m + k];
            H[i * m + j] = s / d;
        }
    }
    for (int c = 0; c < C; c++) {
        for (int i = 0; i < m; i++) {
            double s = B[i * C + c];
            for (int k = 0; k < i; k++)
                s -= H[i * m + k] * B[k * C + c];
            B[i * C + c] = s / H[i * m + i];
        }
        for (int i = m - 1; i >= 0; i--) {
            double s = B[i * C + c];
            for (int k = i + 1; k < m; k++)
                s -= H[k * m + i] * B[k * C + c];
            B[i * C + c] = s / H[i * m + i];
        }
    }
    return 1;
}

/* The seven terms of a kind's solution (the gradient's slope on both
 * sides of its axis). */
static void to_fit(obs__dyn_kind kind, const double *x, const float c[3], obs_dyn_fit *f)
{
    memset(f, 0, sizeof *f);
    memcpy(f->c, c, sizeof f->c);
    for (int ch = 0; ch < C; ch++) {
        f->coef[ch][0] = (float)x[ch];
        for (int i = 0; kind != OBS__DYN_CONSTANT && i < 3; i++) {
            double v = kind == OBS__DYN_EQ4 ? x[(1 + 2 * i) * C + ch] : x[(1 + i) * C + ch];
            double u = kind == OBS__DYN_EQ4 ? x[(2 + 2 * i) * C + ch] : v;
            f->coef[ch][1 + 2 * i] = (float)v;
            f->coef[ch][2 + 2 * i] = (float)u;
        }
    }
}

static void fit_channels(const obs_dyn_fit *f, const float p[3], double out[C])
{
    float q[3] = {p[0] - f->c[0], p[1] - f->c[1], p[2] - f->c[2]};
    double row[T];
    obs__dyn_eq4_row(q, row);
    for (int ch = 0; ch < C; ch++) {
        double s = 0.0;
        for (int k = 0; k < T; k++)
            s += row[k] * f->coef[ch][k];
        out[ch] = s;
    }
}

static double sse_of(const obs__dyn_points *pt, const uint32_t *idx, size_t n,
                     const obs_dyn_fit *f)
{
    double e = 0.0;
    for (size_t i = 0; i < n; i++) {
        double v[C];
        fit_channels(f, pt->pos + 3 * (size_t)idx[i], v);
        const double *s = pt->sh + (size_t)C * idx[i];
        for (int ch = 0; ch < C; ch++)
            e += (v[ch] - s[ch]) * (v[ch] - s[ch]);
    }
    return e;
}

double obs__dyn_fit_centre(const obs__dyn_points *pt, const uint32_t *idx, size_t n,
                           const float c[3], obs__dyn_kind kind, obs_dyn_fit *f)
{
    double H[T * T] = {0}, B[T * C] = {0}, row[T];
    int m = 1;
    for (size_t i = 0; i < n; i++) {
        const float *p = pt->pos + 3 * (size_t)idx[i];
        float q[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
        m = kind_row(kind, q, row);
        const double *s = pt->sh + (size_t)C * idx[i];
        for (int a = 0; a < m; a++) {
            for (int b = 0; b < m; b++)
                H[a * m + b] += row[a] * row[b];
            for (int ch = 0; ch < C; ch++)
                B[a * C + ch] += row[a] * s[ch];
        }
    }
    if (!n)
        m = kind == OBS__DYN_EQ4 ? T : kind == OBS__DYN_CONSTANT ? 1 : 4;
    if (!n || !chol_solve(H, B, m))
        memset(B, 0, sizeof B);
    to_fit(kind, B, c, f);
    return sse_of(pt, idx, n, f);
}

double obs__dyn_blend_ao(const double *sh, const float n[3], float blend, int order)
{
    double s = obs__sh_eval(sh, n, order), l = obs__sh_eval(sh + OBS_DYN_SH, n, order);
    return blend * s + (1.0 - blend) * l;
}

static const float axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

/* Sum over the points idx and the 6 axis normals of the squared blended
 * AO error of f (quadratic SH). */
static double ao_sse(const obs__dyn_points *pt, const uint32_t *idx, size_t n,
                     const obs_dyn_fit *f, float blend)
{
    double e = 0.0;
    for (size_t i = 0; i < n; i++) {
        double v[C];
        fit_channels(f, pt->pos + 3 * (size_t)idx[i], v);
        const double *s = pt->sh + (size_t)C * idx[i];
        for (int a = 0; a < 6; a++) {
            double d = obs__dyn_blend_ao(v, axes[a], blend, 2) - obs__dyn_blend_ao(s, axes[a], blend, 2);
            e += d * d;
        }
    }
    return e;
}

static void fits_to_model(obs_dyn_model *dst, const obs_dyn_model *shape, const obs_dyn_fit *f)
{
    memcpy(dst->models, f, shape->model_count * sizeof *f);
}

/* The regularisation's energy (see the top). */
static double energy(const obs_dyn_fit *x, const obs_dyn_fit *x0, const double *A, size_t nm,
                     const uint32_t *em, const float *eb, const double *ew, size_t ne,
                     double beta)
{
    double e = 0.0;
    for (size_t m = 0; m < nm; m++)
        for (int ch = 0; ch < C; ch++) {
            double d[T];
            for (int k = 0; k < T; k++)
                d[k] = (double)x[m].coef[ch][k] - x0[m].coef[ch][k];
            for (int a = 0; a < T; a++)
                for (int b = 0; b < T; b++)
                    e += d[a] * A[m * T * T + a * T + b] * d[b];
        }
    for (size_t k = 0; k < ne; k++) {
        double u[C], v[C];
        fit_channels(&x[em[2 * k]], eb + 3 * k, u);
        fit_channels(&x[em[2 * k + 1]], eb + 3 * k, v);
        for (int ch = 0; ch < C; ch++)
            e += beta * ew[k] * (u[ch] - v[ch]) * (u[ch] - v[ch]);
    }
    return e;
}

/* As the runtime sees it: each distance clamped to [0, 1], then blended
 * (obs_dyn_eval). */
static double clamped_ao(const double *ch, const float n[3], float blend)
{
    double s = fmin(fmax(obs__sh_eval(ch, n, 2), 0.0), 1.0);
    double l = fmin(fmax(obs__sh_eval(ch + OBS_DYN_SH, n, 2), 0.0), 1.0);
    return blend * s + (1.0 - blend) * l;
}

static void jumps(const obs_dyn_fit *x, const uint32_t *em, const float *eb, size_t ne,
                  float blend, double *mean, double *max)
{
    double s = 0.0, mx = 0.0;
    for (size_t k = 0; k < ne; k++) {
        double u[C], v[C];
        fit_channels(&x[em[2 * k]], eb + 3 * k, u);
        fit_channels(&x[em[2 * k + 1]], eb + 3 * k, v);
        for (int a = 0; a < 6; a++) {
            double d = fabs(clamped_ao(u, axes[a], blend) - clamped_ao(v, axes[a], blend));
            s += d;
            mx = fmax(mx, d);
        }
    }
    *mean = ne ? s / (6.0 * ne) : 0.0;
    *max = mx;
}

/* For each of n nodes, the pairs (index k of pairs[2k], pairs[2k+1]) it
 * is in: items[first[i] .. first[i+1]).  0 when out of memory. */
static int csr_build(size_t n, const uint32_t *pairs, size_t np, size_t **first,
                     uint32_t **items)
{
    *first = calloc(n + 1, sizeof **first);
    *items = malloc((np ? 2 * np : 1) * sizeof **items);
    size_t *fill = calloc(n ? n : 1, sizeof *fill);
    if (!*first || !*items || !fill) {
        free(fill);
        return 0;
    }
    for (size_t k = 0; k < 2 * np; k++)
        (*first)[pairs[k] + 1]++;
    for (size_t i = 0; i < n; i++)
        (*first)[i + 1] += (*first)[i];
    for (size_t k = 0; k < 2 * np; k++)
        (*items)[(*first)[pairs[k]] + fill[pairs[k]]++] = (uint32_t)(k / 2);
    free(fill);
    return 1;
}

static obs_status copy_shape(obs_dyn_model *dst, const obs_dyn_model *src, char err[OBS_ERR_LEN])
{
    *dst = *src;
    dst->regions = malloc((src->region_count ? src->region_count : 1) * sizeof *dst->regions);
    dst->models = malloc((src->model_count ? src->model_count : 1) * sizeof *dst->models);
    dst->edge = malloc((src->edge_count ? 2 * src->edge_count : 1) * sizeof *dst->edge);
    if (!dst->regions || !dst->models || !dst->edge)
        return obs__fail(err, OBS_NO_MEMORY, "model of %zu regions", src->region_count);
    memcpy(dst->regions, src->regions, src->region_count * sizeof *dst->regions);
    memcpy(dst->models, src->models, src->model_count * sizeof *dst->models);
    memcpy(dst->edge, src->edge, 2 * src->edge_count * sizeof *dst->edge);
    return OBS_OK;
}

/* What the steps of obs__dyn_fit_all hand each other; every array freed
 * by fit_work_free. */
typedef struct fit_work {
    size_t nr, ne;
    size_t *first, *hfirst;   /* nr + 1: each region's fitted and held-back points */
    uint32_t *idx, *hidx;     /* the points, region by region */
    obs_dyn_fit *own;         /* nr: each region's own eq 4 */
    int32_t *model_of;        /* nr: the region whose model it takes, -1 none */
    int32_t *absorbed;        /* nr: 1 when it took a neighbour's */
    size_t *nfirst;           /* the region adjacency (csr_build) */
    uint32_t *nitem;
    size_t nm;                /* models */
    double *A;                /* nm x T x T: X^T X / n of each model's points */
    size_t me;                /* edges between different models */
    uint32_t *em;             /* 2 per edge: its models */
    float *eb;                /* 3 per edge: b_ij */
    double *ew;               /* per edge: w_ij */
    size_t mp;                /* boundary points, boundary_points^2 per edge */
    uint32_t *pm;
    float *pb;
    double *pw;
    size_t *mfirst;           /* the models' boundary points (csr_build) */
    uint32_t *mitem;
    obs_dyn_fit *x, *x0;      /* nm: the regularised and the original models */
} fit_work;

static void fit_work_free(fit_work *w)
{
    free(w->first);
    free(w->hfirst);
    free(w->idx);
    free(w->hidx);
    free(w->own);
    free(w->model_of);
    free(w->absorbed);
    free(w->em);
    free(w->eb);
    free(w->ew);
    free(w->pm);
    free(w->pb);
    free(w->pw);
    free(w->nfirst);
    free(w->nitem);
    free(w->mfirst);
    free(w->mitem);
    free(w->A);
    free(w->x);
    free(w->x0);
}

/* Each region's fitted and held-back points (counting sort). */
static obs_status group_points(const obs__dyn_points *pt, fit_work *w, char err[OBS_ERR_LEN])
{
    size_t nr = w->nr;
    for (size_t i = 0; i < pt->count; i++)
        (pt->held[i] ? w->hfirst : w->first)[pt->region[i] + 1]++;
    for (size_t k = 0; k < nr; k++)
        w->first[k + 1] += w->first[k], w->hfirst[k + 1] += w->hfirst[k];
    size_t *fa = calloc(nr ? nr : 1, sizeof *fa), *fh = calloc(nr ? nr : 1, sizeof *fh);
    if (!fa || !fh) {
        free(fa);
        free(fh);
        return obs__fail(err, OBS_NO_MEMORY, "fit");
    }
    for (size_t i = 0; i < pt->count; i++) {
        uint32_t g = pt->region[i];
        if (pt->held[i])
            w->hidx[w->hfirst[g] + fh[g]++] = (uint32_t)i;
        else
            w->idx[w->first[g] + fa[g]++] = (uint32_t)i;
    }
    free(fa);
    free(fh);
    return OBS_OK;
}

/* Eq 4 per region, the better of the two candidate centres; the
 * held-back points' errors against eq 4, a constant and one gradient. */
static void fit_regions(const obs__dyn_points *pt, const obs_dyn_regions *rg,
                        const obs_dyn_params *p, fit_work *w, obs_dyn_stats *ss)
{
    double hs[3] = {0, 0, 0};
    for (size_t g = 0; g < w->nr; g++) {
        const uint32_t *ix = w->idx + w->first[g];
        size_t n = w->first[g + 1] - w->first[g];
        const obs_dyn_box *b = &rg->box[g];
        float cb[3], cm[3] = {0, 0, 0};
        for (int a = 0; a < 3; a++)
            cb[a] = 0.5f * (b->lo[a] + b->hi[a]);
        for (size_t i = 0; i < n; i++)
            for (int a = 0; a < 3; a++)
                cm[a] += pt->pos[3 * (size_t)ix[i] + a] / (float)n;
        if (!n)
            memcpy(cm, cb, sizeof cm);
        obs_dyn_fit fb;
        double em_ = obs__dyn_fit_centre(pt, ix, n, cm, OBS__DYN_EQ4, &w->own[g]);
        double eb_ = obs__dyn_fit_centre(pt, ix, n, cb, OBS__DYN_EQ4, &fb);
        if (eb_ < em_)
            w->own[g] = fb;
        else
            ss->centre_of_mass_kept += n > 0;
        size_t nh = w->hfirst[g + 1] - w->hfirst[g];
        if (nh && n >= (size_t)(p->absorb_points > 1 ? p->absorb_points : 1)) {
            obs_dyn_fit fc, fg;
            const uint32_t *hx = w->hidx + w->hfirst[g];
            obs__dyn_fit_centre(pt, ix, n, w->own[g].c, OBS__DYN_CONSTANT, &fc);
            obs__dyn_fit_centre(pt, ix, n, w->own[g].c, OBS__DYN_GRADIENT, &fg);
            hs[0] += ao_sse(pt, hx, nh, &w->own[g], p->blend);
            hs[1] += ao_sse(pt, hx, nh, &fc, p->blend);
            hs[2] += ao_sse(pt, hx, nh, &fg, p->blend);
            ss->holdout_points += nh;
        }
    }
    if (ss->holdout_points) {
        ss->holdout_eq4 = sqrt(hs[0] / (6.0 * ss->holdout_points));
        ss->holdout_constant = sqrt(hs[1] / (6.0 * ss->holdout_points));
        ss->holdout_gradient = sqrt(hs[2] / (6.0 * ss->holdout_points));
    }
}

/* Tiny regions absorbed (section 3); passes until nothing changes, so a
 * tiny region between tiny ones takes a model passed along.  A tiny
 * region no neighbour could give a model keeps its own. */
static obs_status absorb_tiny(const obs__dyn_points *pt, const obs_dyn_regions *rg,
                              const obs_dyn_params *p, fit_work *w, obs_dyn_stats *ss,
                              char err[OBS_ERR_LEN])
{
    size_t nr = w->nr, *first = w->first;
    int32_t *model_of = w->model_of;
    for (size_t g = 0; g < nr; g++) {
        size_t n = first[g + 1] - first[g];
        model_of[g] = n && n >= (size_t)p->absorb_points ? (int32_t)g : -1;
        ss->regions_without_points += n == 0;
    }
    if (!csr_build(nr, rg->edge, w->ne, &w->nfirst, &w->nitem))
        return obs__fail(err, OBS_NO_MEMORY, "adjacency of %zu regions", nr);
    for (int changed = 1; changed;) {
        changed = 0;
        for (size_t g = 0; g < nr; g++) {
            if (model_of[g] >= 0)
                continue;
            size_t n = first[g + 1] - first[g];
            int32_t best = -1;
            double be = INFINITY;
            for (size_t q = w->nfirst[g]; q < w->nfirst[g + 1]; q++) {
                size_t k = w->nitem[q];
                uint32_t a = rg->edge[2 * k], b = rg->edge[2 * k + 1];
                uint32_t nb = a == g ? b : a;
                if (model_of[nb] < 0)
                    continue;
                double e = n ? sse_of(pt, w->idx + first[g], n, &w->own[model_of[nb]])
                             : -obs__dyn_shared_face(&rg->box[g], &rg->box[nb], NULL);
                if (e < be)
                    be = e, best = model_of[nb];
            }
            if (best >= 0) {
                model_of[g] = best;
                w->absorbed[g] = 1;
                changed = 1;
            }
        }
    }
    for (size_t g = 0; g < nr; g++)
        if (model_of[g] < 0 && first[g + 1] > first[g])
            model_of[g] = (int32_t)g;
    return OBS_OK;
}

/* The models numbered, the original model o (regions, models, edges)
 * and each model's A = X^T X / n over its region's own points (eq 4's
 * columns). */
static obs_status number_models(const obs__dyn_points *pt, const obs_dyn_regions *rg,
                                const obs_dyn_params *p, fit_work *w, obs_dyn_model *o,
                                obs_dyn_stats *ss, char err[OBS_ERR_LEN])
{
    size_t nr = w->nr, ne = w->ne;
    int32_t *slot = malloc((nr ? nr : 1) * sizeof *slot);
    if (!slot)
        return obs__fail(err, OBS_NO_MEMORY, "fit");
    size_t nm = 0;
    for (size_t g = 0; g < nr; g++)
        slot[g] = w->model_of[g] == (int32_t)g ? (int32_t)nm++ : -1;
    o->region_count = nr;
    o->model_count = nm;
    o->edge_count = ne;
    o->distance[0] = p->distance_short;
    o->distance[1] = p->distance_long;
    o->blend = p->blend;
    o->regions = calloc(nr ? nr : 1, sizeof *o->regions);
    o->models = calloc(nm ? nm : 1, sizeof *o->models);
    o->edge = malloc((ne ? 2 * ne : 1) * sizeof *o->edge);
    w->A = calloc((nm ? nm : 1) * T * T, sizeof *w->A);
    if (!o->regions || !o->models || !o->edge || !w->A) {
        free(slot);
        return obs__fail(err, OBS_NO_MEMORY, "model of %zu regions", nr);
    }
    if (ne)
        memcpy(o->edge, rg->edge, 2 * ne * sizeof *o->edge);
    for (size_t g = 0; g < nr; g++) {
        obs_dyn_model_region *mr = &o->regions[g];
        mr->box = rg->box[g];
        mr->model = w->model_of[g] >= 0 ? slot[w->model_of[g]] : -1;
        mr->absorbed = w->absorbed[g];
        mr->points = (uint32_t)(w->first[g + 1] - w->first[g]);
        ss->regions_absorbed += (size_t)w->absorbed[g];
        if (slot[g] < 0)
            continue;
        const obs_dyn_fit *own = &w->own[g];
        o->models[slot[g]] = *own;
        double *Am = w->A + (size_t)slot[g] * T * T;
        size_t n = w->first[g + 1] - w->first[g];
        for (size_t i = 0; i < n; i++) {
            const float *pp = pt->pos + 3 * (size_t)w->idx[w->first[g] + i];
            float q[3] = {pp[0] - own->c[0], pp[1] - own->c[1], pp[2] - own->c[2]};
            double row[T];
            obs__dyn_eq4_row(q, row);
            for (int a = 0; a < T; a++)
                for (int b = 0; b < T; b++)
                    Am[a * T + b] += row[a] * row[b] / (double)n;
        }
    }
    free(slot);
    w->nm = nm;
    ss->models = nm;
    return OBS_OK;
}

/* The edges between different models, their weights w_ij and centres
 * b_ij, and the points where the neighbours are compared: the paper's
 * b_ij (boundary_points 1), or a bp x bp grid of the shared face sharing
 * w_ij, so that the models agree over the face and not only at its
 * centre. */
static obs_status boundary_points(const obs_dyn_regions *rg, const obs_dyn_params *p,
                                  const obs_dyn_model *o, fit_work *w, char err[OBS_ERR_LEN])
{
    size_t ne = w->ne;
    w->em = malloc((ne ? 2 * ne : 1) * sizeof *w->em);
    w->eb = malloc((ne ? 3 * ne : 1) * sizeof *w->eb);
    w->ew = malloc((ne ? ne : 1) * sizeof *w->ew);
    if (!w->em || !w->eb || !w->ew)
        return obs__fail(err, OBS_NO_MEMORY, "regularisation");
    size_t me = 0;
    double wsum = 0.0;
    for (size_t k = 0; k < ne; k++) {
        uint32_t a = rg->edge[2 * k], b = rg->edge[2 * k + 1];
        int32_t ma = o->regions[a].model, mb = o->regions[b].model;
        if (ma < 0 || mb < 0 || ma == mb)
            continue;
        w->ew[me] = obs__dyn_shared_face(&rg->box[a], &rg->box[b], w->eb + 3 * me); /* w_ij, b_ij */
        w->em[2 * me] = (uint32_t)ma;
        w->em[2 * me + 1] = (uint32_t)mb;
        wsum += w->ew[me];
        me++;
    }
    for (size_t k = 0; k < me; k++)
        w->ew[k] /= wsum / (double)me;
    w->me = me;
    int bp = p->boundary_points;
    size_t mp = me * (size_t)bp * (size_t)bp;
    w->mp = mp;
    w->pm = malloc((mp ? 2 * mp : 1) * sizeof *w->pm);
    w->pb = malloc((mp ? 3 * mp : 1) * sizeof *w->pb);
    w->pw = malloc((mp ? mp : 1) * sizeof *w->pw);
    if (!w->pm || !w->pb || !w->pw)
        return obs__fail(err, OBS_NO_MEMORY, "regularisation");
    const float *eb = w->eb;
    for (size_t k = 0, e = 0, q = 0; k < ne; k++) {
        uint32_t a = rg->edge[2 * k], b = rg->edge[2 * k + 1];
        int32_t ma = o->regions[a].model, mb = o->regions[b].model;
        if (ma < 0 || mb < 0 || ma == mb)
            continue;
        const obs_dyn_box *A_ = &rg->box[a], *B_ = &rg->box[b];
        float lo[3], hi[3];
        for (int c = 0; c < 3; c++)
            lo[c] = fmaxf(A_->lo[c], B_->lo[c]), hi[c] = fminf(A_->hi[c], B_->hi[c]);
        int ax = 0; /* the face's normal axis: where the overlap is thinnest */
        for (int c = 1; c < 3; c++)
            if (hi[c] - lo[c] < hi[ax] - lo[ax])
                ax = c;
        int u = (ax + 1) % 3, v = (ax + 2) % 3;
        for (int i = 0; i < bp; i++)
            for (int j = 0; j < bp; j++, q++) {
                float *pt3 = w->pb + 3 * q;
                pt3[ax] = eb[3 * e + ax];
                pt3[u] = bp == 1 ? eb[3 * e + u] : lo[u] + (hi[u] - lo[u]) * ((float)i + 0.5f) / (float)bp;
                pt3[v] = bp == 1 ? eb[3 * e + v] : lo[v] + (hi[v] - lo[v]) * ((float)j + 0.5f) / (float)bp;
                w->pm[2 * q] = w->em[2 * e];
                w->pm[2 * q + 1] = w->em[2 * e + 1];
                w->pw[q] = w->ew[e] / (double)(bp * bp);
            }
        e++;
    }
    return OBS_OK;
}

/* Block coordinate descent: one model at a time, the others fixed; E
 * (the file's comment) before and after in the stats. */
static obs_status regularise(const obs_dyn_params *p, const obs_dyn_model *o, fit_work *w,
                             obs_dyn_stats *ss, char err[OBS_ERR_LEN])
{
    size_t nm = w->nm, mp = w->mp;
    w->x = malloc((nm ? nm : 1) * sizeof *w->x);
    w->x0 = malloc((nm ? nm : 1) * sizeof *w->x0);
    if (!w->x || !w->x0)
        return obs__fail(err, OBS_NO_MEMORY, "regularisation");
    obs_dyn_fit *x = w->x, *x0 = w->x0;
    const uint32_t *pm = w->pm;
    const float *pb = w->pb;
    const double *pw = w->pw, *A = w->A;
    memcpy(x, o->models, nm * sizeof *x);
    memcpy(x0, o->models, nm * sizeof *x0);
    double beta = p->beta;
    ss->energy[0] = energy(x, x0, A, nm, pm, pb, pw, mp, beta);
    jumps(x, w->em, w->eb, w->me, p->blend, &ss->jump_mean[0], &ss->jump_max[0]);
    if (!csr_build(nm, pm, mp, &w->mfirst, &w->mitem))
        return obs__fail(err, OBS_NO_MEMORY, "regularisation");
    for (int it = 0; beta > 0.0 && mp && it < p->iterations; it++)
        for (size_t m = 0; m < nm; m++) {
            double H[T * T], B[T * C] = {0};
            memcpy(H, A + m * T * T, sizeof H);
            for (int a = 0; a < T; a++)
                for (int ch = 0; ch < C; ch++)
                    for (int b = 0; b < T; b++)
                        B[a * C + ch] += H[a * T + b] * x0[m].coef[ch][b];
            int any = 0;
            for (size_t e = w->mfirst[m]; e < w->mfirst[m + 1]; e++) {
                size_t k = w->mitem[e];
                uint32_t other = pm[2 * k] == m ? pm[2 * k + 1] : pm[2 * k];
                any = 1;
                const float *bpt = pb + 3 * k;
                float q[3] = {bpt[0] - x[m].c[0], bpt[1] - x[m].c[1], bpt[2] - x[m].c[2]};
                double row[T], y[C];
                obs__dyn_eq4_row(q, row);
                fit_channels(&x[other], bpt, y);
                for (int a = 0; a < T; a++) {
                    for (int b = 0; b < T; b++)
                        H[a * T + b] += beta * pw[k] * row[a] * row[b];
                    for (int ch = 0; ch < C; ch++)
                        B[a * C + ch] += beta * pw[k] * row[a] * y[ch];
                }
            }
            if (!any || !chol_solve(H, B, T))
                continue;
            for (int ch = 0; ch < C; ch++)
                for (int k = 0; k < T; k++)
                    x[m].coef[ch][k] = (float)B[k * C + ch];
        }
    ss->energy[1] = energy(x, x0, A, nm, pm, pb, pw, mp, beta);
    jumps(x, w->em, w->eb, w->me, p->blend, &ss->jump_mean[1], &ss->jump_max[1]);
    return OBS_OK;
}

/* The fit's residuals at the fitted points, before and after. */
static void residuals(const obs__dyn_points *pt, const obs_dyn_params *p, const fit_work *w,
                      const obs_dyn_model *o, const obs_dyn_model *reg, obs_dyn_stats *ss)
{
    double e0 = 0.0, e1 = 0.0;
    size_t np = 0;
    for (size_t g = 0; g < w->nr; g++) {
        int32_t m = o->regions[g].model;
        size_t n = w->first[g + 1] - w->first[g];
        if (m < 0 || !n)
            continue;
        e0 += ao_sse(pt, w->idx + w->first[g], n, &o->models[m], p->blend);
        e1 += ao_sse(pt, w->idx + w->first[g], n, &reg->models[m], p->blend);
        np += n;
    }
    ss->fit_rms = np ? sqrt(e0 / (6.0 * np)) : 0.0;
    ss->fit_rms_regularised = np ? sqrt(e1 / (6.0 * np)) : 0.0;
}

obs_status obs__dyn_fit_all(const obs__dyn_points *pt, const obs_dyn_regions *rg,
                            const obs_dyn_params *p, obs_dyn_result *r, char err[OBS_ERR_LEN])
{
    obs_status st;
    obs_dyn_stats *ss = &r->stats;
    size_t nr = rg->count;
    fit_work w = {0};
    w.nr = nr;
    w.ne = rg->edge_count;
    w.first = calloc(nr + 1, sizeof *w.first);
    w.hfirst = calloc(nr + 1, sizeof *w.hfirst);
    w.idx = malloc((pt->count ? pt->count : 1) * sizeof *w.idx);
    w.hidx = malloc((pt->count ? pt->count : 1) * sizeof *w.hidx);
    w.own = calloc(nr ? nr : 1, sizeof *w.own);
    w.model_of = malloc((nr ? nr : 1) * sizeof *w.model_of);
    w.absorbed = calloc(nr ? nr : 1, sizeof *w.absorbed);
    obs_dyn_model *o = &r->original;
    memset(o, 0, sizeof *o);
    if (!w.first || !w.hfirst || !w.idx || !w.hidx || !w.own || !w.model_of || !w.absorbed) {
        st = obs__fail(err, OBS_NO_MEMORY, "fit of %zu regions", nr);
        goto done;
    }
    if ((st = group_points(pt, &w, err)) != OBS_OK)
        goto done;
    fit_regions(pt, rg, p, &w, ss);
    if ((st = absorb_tiny(pt, rg, p, &w, ss, err)) != OBS_OK ||
        (st = number_models(pt, rg, p, &w, o, ss, err)) != OBS_OK ||
        (st = boundary_points(rg, p, o, &w, err)) != OBS_OK ||
        (st = regularise(p, o, &w, ss, err)) != OBS_OK ||
        (st = copy_shape(&r->model, o, err)) != OBS_OK)
        goto done;
    fits_to_model(&r->model, o, w.x);
    residuals(pt, p, &w, o, &r->model, ss);
done:
    fit_work_free(&w);
    return st;
}
