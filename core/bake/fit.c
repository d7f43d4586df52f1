/* The least-squares vertex fit of Kavan, Bargteil and Sloan 2011, "Least
 * Squares Vertex Baking", as the paper uses it (eq 2):
 *
 *   E(x) = integral over S of (f(p) - g_x(p))^2 dp + alpha integral of R_edge(p)^2 dp
 *
 * g_x the piecewise-linear signal of the vertex values x (hat basis
 * phi_i), f the traced obscurance.  dE/dx = 0 gives (M + alpha R) x = b:
 *   M_ij = sum over samples of w phi_i phi_j (mass = samples), or the hat
 *          basis integrated exactly, A/12 [[2,1,1],[1,2,1],[1,1,2]] per
 *          face, scaled by its share of valid samples (mass = analytic);
 *   b_i  = sum over samples of w phi_i f, w = A_t / n_t;
 *   R    = for each interior edge (two faces, the edge shared in the
 *          welded mesh), the squared difference of the two faces' linear
 *          functions, each extended over the other with the two faces
 *          unfolded into one plane, integrated over both faces: the jump J
 *          of the derivative across the edge times the distance to the
 *          edge, so integral = J^2 (A1 h1^2 + A2 h2^2) / 6
 *          (obs__bake_edge_jump).  It is zero for a signal linear over the
 *          unfolded pair.
 * Plus ridge * D (x - x0), D the lumped area, x0 each vertex's own sample
 * mean (its neighbours' where it has none): keeps the system definite
 * where a vertex has no valid sample.  One CHOLMOD factorisation, both
 * distances solved with it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <suitesparse/cholmod.h>
#include <time.h>

#include "bake/bake_internal.h"
#include "internal.h"

double obs__bake_edge_jump(const float a[3], const float b[3], const float c[3],
                           const float d[3], double j[4])
{
    double e[3], len = 0.0;
    for (int k = 0; k < 3; k++) {
        e[k] = (double)b[k] - a[k];
        len += e[k] * e[k];
    }
    len = sqrt(len);
    if (!(len > 0.0))
        return -1.0;
    for (int k = 0; k < 3; k++)
        e[k] /= len;
    const float *apex[2] = {c, d};
    double s[2], h[2];
    for (int t = 0; t < 2; t++) {
        double q[3], along = 0.0, perp = 0.0;
        for (int k = 0; k < 3; k++) {
            q[k] = (double)apex[t][k] - a[k];
            along += q[k] * e[k];
        }
        for (int k = 0; k < 3; k++) {
            double r = q[k] - along * e[k];
            perp += r * r;
        }
        h[t] = sqrt(perp);
        s[t] = along / len;
        if (!(h[t] > 1e-9 * len))
            return -1.0;
    }
    /* Face t's derivative away from the edge towards its apex: (x_apex -
     * g(foot)) / h, g(foot) = (1 - s) x_a + s x_b.  Unfolded, the two
     * directions are opposite, so the jump is the sum of the two. */
    j[0] = -(1.0 - s[0]) / h[0] - (1.0 - s[1]) / h[1];
    j[1] = -s[0] / h[0] - s[1] / h[1];
    j[2] = 1.0 / h[0];
    j[3] = 1.0 / h[1];
    double area0 = 0.5 * len * h[0], area1 = 0.5 * len * h[1];
    return (area0 * h[0] * h[0] + area1 * h[1] * h[1]) / 6.0;
}

typedef struct edge {
    uint32_t u, v; /* welded, u < v */
    uint32_t face;
    uint8_t corner; /* the face's corner opposite the edge */
} edge;

static int edge_cmp(const void *pa, const void *pb)
{
    const edge *a = pa, *b = pb;
    if (a->u != b->u)
        return a->u < b->u ? -1 : 1;
    if (a->v != b->v)
        return a->v < b->v ? -1 : 1;
    return a->face < b->face ? -1 : a->face > b->face;
}

/* Triplets of the upper triangle; a pair of corners that welded into one
 * vertex adds both halves to the diagonal. */
typedef struct trip {
    cholmod_triplet *t;
} trip;

static void put(trip *tr, uint32_t i, uint32_t j, double v)
{
    cholmod_triplet *t = tr->t;
    if (v == 0.0)
        return;
    int *ri = t->i, *ci = t->j;
    double *x = t->x;
    ri[t->nnz] = (int)(i < j ? i : j);
    ci[t->nnz] = (int)(i < j ? j : i);
    x[t->nnz] = v;
    t->nnz++;
}

/* A symmetric local matrix m (n x n) over the vertices idx. */
static void put_local(trip *tr, const uint32_t *idx, int n, const double *m)
{
    for (int a = 0; a < n; a++) {
        put(tr, idx[a], idx[a], m[a * n + a]);
        for (int b = a + 1; b < n; b++)
            put(tr, idx[a], idx[b], idx[a] == idx[b] ? 2.0 * m[a * n + b] : m[a * n + b]);
    }
}

typedef struct sys {
    size_t n;
    edge *edges;   /* every face's three edges, sorted */
    size_t nedges;
    double *cover; /* sum of w phi_i over valid samples */
    double *b;     /* 2 per vertex */
    double *x0;    /* 2 per vertex */
    double *lump;  /* lumped area */
    size_t *interior; /* the first record of each interior edge's pair */
    size_t ninterior;
} sys;

static void sys_free(sys *y)
{
    free(y->edges);
    free(y->cover);
    free(y->b);
    free(y->x0);
    free(y->lump);
    free(y->interior);
}

static double wsum_valid(const obs__bake_samples *s)
{
    double w = 0.0;
    for (size_t i = 0; i < s->count; i++)
        w += s->valid[i] ? s->weight[i] : 0.0;
    return w;
}

/* x0: a vertex's own sample mean; where it has none, the mean of its
 * neighbours' values, front by front; where no neighbour has one, the
 * mean of every valid sample (1 with none at all). */
static void initial_values(const obs__bake_samples *s, sys *y, obs_bake_stats *st)
{
    size_t n = y->n;
    double all[2] = {0, 0}, wsum = 0.0;
    for (size_t i = 0; i < s->count; i++)
        if (s->valid[i]) {
            all[0] += s->weight[i] * s->ao[2 * i];
            all[1] += s->weight[i] * s->ao[2 * i + 1];
            wsum += s->weight[i];
        }
    for (int c = 0; c < 2; c++)
        all[c] = wsum > 0.0 ? all[c] / wsum : 1.0;
    uint8_t *have = calloc(n, 1);
    double *acc = calloc(3 * n, sizeof *acc);
    size_t missing = 0;
    for (size_t v = 0; v < n; v++) {
        if (y->cover[v] > 0.0) {
            if (have)
                have[v] = 1;
            y->x0[2 * v] = y->b[2 * v] / y->cover[v];
            y->x0[2 * v + 1] = y->b[2 * v + 1] / y->cover[v];
        } else {
            missing++;
        }
    }
    st->vertices_without_samples = missing;
    while (missing && have && acc) {
        memset(acc, 0, 3 * n * sizeof *acc);
        for (size_t e = 0; e < y->nedges; e++) {
            uint32_t u = y->edges[e].u, v = y->edges[e].v;
            if (have[u] && !have[v]) {
                acc[3 * v] += y->x0[2 * u], acc[3 * v + 1] += y->x0[2 * u + 1], acc[3 * v + 2]++;
            } else if (have[v] && !have[u]) {
                acc[3 * u] += y->x0[2 * v], acc[3 * u + 1] += y->x0[2 * v + 1], acc[3 * u + 2]++;
            }
        }
        size_t got = 0;
        for (size_t v = 0; v < n; v++)
            if (!have[v] && acc[3 * v + 2] > 0.0) {
                y->x0[2 * v] = acc[3 * v] / acc[3 * v + 2];
                y->x0[2 * v + 1] = acc[3 * v + 1] / acc[3 * v + 2];
                have[v] = 2; /* set after the front is done */
                got++;
            }
        for (size_t v = 0; v < n; v++)
            have[v] = have[v] ? 1 : 0;
        missing -= got;
        if (!got)
            break;
    }
    st->vertices_isolated = 0;
    for (size_t v = 0; v < n; v++)
        if (!have || !have[v]) {
            y->x0[2 * v] = all[0];
            y->x0[2 * v + 1] = all[1];
            st->vertices_isolated++;
        }
    free(have);
    free(acc);
}

/* The welded vertex at corner k of sample i's face. */
static uint32_t corner_vertex(const obs__bake_world *w, const obs__bake_weld *wd,
                              const obs__bake_samples *s, size_t i, int k)
{
    return wd->of[w->tri[3 * (size_t)s->tri[i] + k]];
}

void obs__bake_residual(const obs__bake_world *w, const obs__bake_weld *wd,
                        const obs__bake_samples *s, const double *val, double out[2])
{
    double e[2] = {0, 0}, ws = 0.0;
    for (size_t i = 0; i < s->count; i++) {
        if (!s->valid[i])
            continue;
        const uint32_t *t = w->tri + 3 * s->tri[i];
        const float *b = s->bary + 3 * i;
        for (int c = 0; c < 2; c++) {
            double g = 0.0;
            for (int k = 0; k < 3; k++)
                g += b[k] * val[2 * wd->of[t[k]] + c];
            double r = g - s->ao[2 * i + c];
            e[c] += s->weight[i] * r * r;
        }
        ws += s->weight[i];
    }
    for (int c = 0; c < 2; c++)
        out[c] = ws > 0.0 ? sqrt(e[c] / ws) : 0.0;
}

/* The two baselines from the same samples (obs_bake_stats): per-face
 * averaging (the area-weighted mean of the samples of the vertex's faces)
 * and point sampling (the sample nearest the vertex, by its barycentric
 * weight, among those faces). */
static void baselines(const obs__bake_world *w, const obs__bake_weld *wd,
                      const obs__bake_samples *s, const sys *y, double *face, double *point,
                      obs_bake_stats *st)
{
    size_t n = y->n;
    double *mean = calloc(3 * n, sizeof *mean);
    float *best = malloc(n * sizeof *best);
    if (!mean || !best)
        goto done;
    for (size_t v = 0; v < n; v++) {
        best[v] = -1.0f;
        memcpy(face + 2 * v, y->x0 + 2 * v, 2 * sizeof *face);
        memcpy(point + 2 * v, y->x0 + 2 * v, 2 * sizeof *point);
    }
    for (size_t i = 0; i < s->count; i++) {
        if (!s->valid[i])
            continue;
        for (int k = 0; k < 3; k++) {
            uint32_t v = corner_vertex(w, wd, s, i, k);
            mean[3 * v] += s->weight[i] * s->ao[2 * i];
            mean[3 * v + 1] += s->weight[i] * s->ao[2 * i + 1];
            mean[3 * v + 2] += s->weight[i];
            if (s->bary[3 * i + k] > best[v]) {
                best[v] = s->bary[3 * i + k];
                point[2 * v] = s->ao[2 * i];
                point[2 * v + 1] = s->ao[2 * i + 1];
            }
        }
    }
    for (size_t v = 0; v < n; v++)
        if (mean[3 * v + 2] > 0.0) {
            face[2 * v] = mean[3 * v] / mean[3 * v + 2];
            face[2 * v + 1] = mean[3 * v + 1] / mean[3 * v + 2];
        }
    obs__bake_residual(w, wd, s, face, st->residual_face_mean);
    obs__bake_residual(w, wd, s, point, st->residual_point);
done:
    free(mean);
    free(best);
}

/* The regulariser's row of an interior edge (its two faces' records):
 * the welded vertices a, b (the edge), c, d (the apexes) in idx, the jump's
 * weights in j; returns the weight of its square, <= 0 to skip it. */
static double edge_row(const obs__bake_world *w, const obs__bake_weld *wd, const edge *e1,
                       const edge *e2, uint32_t idx[4], double j[4])
{
    const uint32_t *t1 = w->tri + 3 * (size_t)e1->face, *t2 = w->tri + 3 * (size_t)e2->face;
    uint32_t c[4] = {t1[(e1->corner + 1) % 3], t1[(e1->corner + 2) % 3], t1[e1->corner],
                     t2[e2->corner]};
    for (int k = 0; k < 4; k++)
        idx[k] = wd->of[c[k]];
    return obs__bake_edge_jump(w->pos + 3 * (size_t)c[0], w->pos + 3 * (size_t)c[1],
                               w->pos + 3 * (size_t)c[2], w->pos + 3 * (size_t)c[3], j);
}

/* The faces' edges in the welded mesh, sorted so that the faces of one
 * edge are neighbours. */
static obs_status collect_edges(const obs__bake_world *w, const obs__bake_weld *wd, sys *y,
                                char err[OBS_ERR_LEN])
{
    y->edges = malloc(3 * w->triangle_count * sizeof *y->edges);
    if (!y->edges)
        return obs__fail(err, OBS_NO_MEMORY, "edges of %zu faces", w->triangle_count);
    for (size_t t = 0; t < w->triangle_count; t++) {
        if (!(w->area[t] > 0.0f))
            continue;
        for (int k = 0; k < 3; k++) {
            uint32_t u = wd->of[w->tri[3 * t + (k + 1) % 3]], v = wd->of[w->tri[3 * t + (k + 2) % 3]];
            if (u == v)
                continue;
            edge *e = &y->edges[y->nedges++];
            e->u = u < v ? u : v;
            e->v = u < v ? v : u;
            e->face = (uint32_t)t;
            e->corner = (uint8_t)k;
        }
    }
    qsort(y->edges, y->nedges, sizeof *y->edges, edge_cmp);
    return OBS_OK;
}

/* Each welded vertex's share of the samples (cover, b = sum w_i B_i f_i)
 * and of the area around it (lump: a third of each face's). */
static void gather_samples(const obs__bake_world *w, const obs__bake_weld *wd,
                           const obs__bake_samples *s, sys *y)
{
    for (size_t i = 0; i < s->count; i++) {
        if (!s->valid[i])
            continue;
        for (int k = 0; k < 3; k++) {
            uint32_t v = corner_vertex(w, wd, s, i, k);
            double wp = (double)s->weight[i] * s->bary[3 * i + k];
            y->cover[v] += wp;
            y->b[2 * v] += wp * s->ao[2 * i];
            y->b[2 * v + 1] += wp * s->ao[2 * i + 1];
        }
    }
    for (size_t t = 0; t < w->triangle_count; t++)
        for (int k = 0; k < 3; k++)
            y->lump[wd->of[w->tri[3 * t + k]]] += w->area[t] / 3.0;
}

/* Interior edges: exactly two faces on the welded edge. */
static obs_status interior_edges(sys *y, obs_bake_stats *st, char err[OBS_ERR_LEN])
{
    st->boundary_edges = st->nonmanifold_edges = 0;
    if (!(y->interior = malloc((y->nedges ? y->nedges : 1) * sizeof *y->interior)))
        return obs__fail(err, OBS_NO_MEMORY, "%zu edges", y->nedges);
    for (size_t e = 0; e < y->nedges;) {
        size_t f = e + 1;
        while (f < y->nedges && y->edges[f].u == y->edges[e].u && y->edges[f].v == y->edges[e].v)
            f++;
        if (f - e == 1)
            st->boundary_edges++;
        else if (f - e == 2)
            y->interior[y->ninterior++] = e;
        else
            st->nonmanifold_edges++;
        e = f;
    }
    st->interior_edges = y->ninterior;
    return OBS_OK;
}

/* Without the ridge only samples make the system definite (R is zero on
 * linear signals): refuse rather than solve a singular system. */
static obs_status check_definite(const obs__bake_samples *s, const obs_bake_params *p,
                                 const obs_bake_stats *st, char err[OBS_ERR_LEN])
{
    if (!(wsum_valid(s) > 0.0))
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "no valid sample in the level: all %zu dropped by the back-face rule "
                         "(backface_limit %g)",
                         s->count, (double)p->backface_limit);
    if (p->ridge <= 0.0f && st->vertices_without_samples)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "ridge 0 leaves the system singular: %zu vertices have no valid sample "
                         "(a ridge above 0 gives them their neighbours' value)",
                         st->vertices_without_samples);
    return OBS_OK;
}

/* M, face by face: sum w_i B_i B_i^T over the face's valid samples, or
 * the analytic mass matrix scaled by their share. */
static void assemble_mass(const obs__bake_world *w, const obs__bake_weld *wd,
                          const obs__bake_samples *s, const obs_bake_params *p, trip *tr)
{
    for (size_t t = 0; t < w->triangle_count; t++) {
        if (!(w->area[t] > 0.0f))
            continue;
        uint32_t idx[3];
        double m[9] = {0};
        for (int k = 0; k < 3; k++)
            idx[k] = wd->of[w->tri[3 * t + k]];
        size_t valid = 0, n_t = s->first[t + 1] - s->first[t];
        for (size_t i = s->first[t]; i < s->first[t + 1]; i++) {
            if (!s->valid[i])
                continue;
            valid++;
            const float *b = s->bary + 3 * i;
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 3; c++)
                    m[3 * a + c] += (double)s->weight[i] * b[a] * b[c];
        }
        if (p->mass == OBS_BAKE_MASS_ANALYTIC) {
            double share = n_t ? w->area[t] * (double)valid / (double)n_t / 12.0 : 0.0;
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 3; c++)
                    m[3 * a + c] = share * (a == c ? 2.0 : 1.0);
        }
        put_local(tr, idx, 3, m);
    }
}

/* alpha R, interior edge by interior edge. */
static void assemble_regulariser(const obs__bake_world *w, const obs__bake_weld *wd,
                                 const sys *y, const obs_bake_params *p, trip *tr)
{
    for (size_t k = 0; k < y->ninterior && p->alpha > 0.0f; k++) {
        uint32_t idx[4];
        double j[4], m[16];
        double om = edge_row(w, wd, &y->edges[y->interior[k]], &y->edges[y->interior[k] + 1], idx, j);
        if (!(om > 0.0))
            continue;
        for (int a = 0; a < 4; a++)
            for (int c = 0; c < 4; c++)
                m[4 * a + c] = p->alpha * om * j[a] * j[c];
        put_local(tr, idx, 4, m);
    }
}

/* The ridge D on the diagonal, and the right-hand side b + D x0 (bx: the
 * two channels one after the other). */
static void assemble_ridge(const sys *y, const obs_bake_params *p, trip *tr, double *bx)
{
    double lump_mean = 0.0;
    for (size_t v = 0; v < y->n; v++)
        lump_mean += y->lump[v] / (double)y->n;
    for (size_t v = 0; v < y->n; v++) {
        /* A vertex of no face with area (unused by the mesh, or of
         * degenerate faces only) has no row otherwise: pinned to x0. */
        double r = y->lump[v] > 0.0 ? p->ridge * y->lump[v] : lump_mean;
        put(tr, (uint32_t)v, (uint32_t)v, r);
        bx[v] = y->b[2 * v] + r * y->x0[2 * v];
        bx[y->n + v] = y->b[2 * v + 1] + r * y->x0[2 * v + 1];
    }
}

/* The solution copied back, two values per welded vertex. */
static obs_status copy_back(const double *xx, size_t n, double *x, char err[OBS_ERR_LEN])
{
    for (size_t v = 0; v < n; v++) {
        x[2 * v] = xx[v];
        x[2 * v + 1] = xx[n + v];
        /* The samples lie in [0, 1]; a fit far outside is a system too
         * ill-conditioned to trust, not an answer. */
        if (!(fabs(x[2 * v]) < 1e3) || !(fabs(x[2 * v + 1]) < 1e3))
            return obs__fail(err, OBS_INVALID_ARGUMENT,
                             "the fit is %g at welded vertex %zu: the least-squares system is "
                             "ill-conditioned",
                             x[2 * v], v);
    }
    return OBS_OK;
}

/* alpha x^T R x, edge by edge. */
static void regulariser_energy(const obs__bake_world *w, const obs__bake_weld *wd, const sys *y,
                               const obs_bake_params *p, const double *x, obs_bake_stats *st)
{
    st->regulariser_energy[0] = st->regulariser_energy[1] = 0.0;
    for (size_t k = 0; k < y->ninterior; k++) {
        uint32_t idx[4];
        double j[4];
        double om = edge_row(w, wd, &y->edges[y->interior[k]], &y->edges[y->interior[k] + 1], idx, j);
        for (int ch = 0; ch < 2 && om > 0.0; ch++) {
            double jump = 0.0;
            for (int c = 0; c < 4; c++)
                jump += j[c] * x[2 * idx[c] + ch];
            st->regulariser_energy[ch] += p->alpha * om * jump * jump;
        }
    }
}

obs_status obs__bake_fit(const obs__bake_world *w, const obs__bake_weld *wd,
                         const obs__bake_samples *s, const obs_bake_params *p, double *x,
                         double *face, double *point, obs_bake_stats *st, char err[OBS_ERR_LEN])
{
    sys y = {0};
    y.n = wd->count;
    obs_status rc = OBS_OK;
    cholmod_common cm;
    cholmod_triplet *T = NULL;
    cholmod_sparse *A = NULL;
    cholmod_factor *L = NULL;
    cholmod_dense *B = NULL, *X = NULL;
    int started = 0;
    double t_start = obs__bake_now(), t_solve = t_start;

    y.cover = calloc(y.n, sizeof *y.cover);
    y.b = calloc(2 * y.n, sizeof *y.b);
    y.x0 = calloc(2 * y.n, sizeof *y.x0);
    y.lump = calloc(y.n, sizeof *y.lump);
    if (!y.cover || !y.b || !y.x0 || !y.lump) {
        rc = obs__fail(err, OBS_NO_MEMORY, "least-squares system of %zu vertices", y.n);
        goto done;
    }
    if ((rc = collect_edges(w, wd, &y, err)) != OBS_OK)
        goto done;
    gather_samples(w, wd, s, &y);
    initial_values(s, &y, st);
    if ((rc = interior_edges(&y, st, err)) != OBS_OK || (rc = check_definite(s, p, st, err)) != OBS_OK)
        goto done;

    /* assemble (M + alpha R + D) x = b + D x0 */
    cholmod_start(&cm);
    started = 1;
    cm.print = 0;
    size_t faces = w->triangle_count - w->degenerate;
    size_t nnz = 6 * faces + 10 * y.ninterior + y.n;
    T = cholmod_allocate_triplet(y.n, y.n, nnz, 1, CHOLMOD_REAL, &cm);
    if (!T) {
        rc = obs__fail(err, OBS_NO_MEMORY, "least-squares system: %zu entries", nnz);
        goto done;
    }
    trip tr = {T};
    assemble_mass(w, wd, s, p, &tr);
    assemble_regulariser(w, wd, &y, p, &tr);
    B = cholmod_zeros(y.n, 2, CHOLMOD_REAL, &cm);
    if (!B) {
        rc = obs__fail(err, OBS_NO_MEMORY, "right-hand side of %zu vertices", y.n);
        goto done;
    }
    assemble_ridge(&y, p, &tr, B->x);
    A = cholmod_triplet_to_sparse(T, T->nnz, &cm);
    if (!A) {
        rc = obs__fail(err, OBS_NO_MEMORY, "sparse matrix of %zu entries", T->nnz);
        goto done;
    }
    cholmod_free_triplet(&T, &cm);
    t_solve = obs__bake_now();
    st->seconds[OBS_BAKE_STAGE_assemble] = t_solve - t_start;

    /* solve */
    L = cholmod_analyze(A, &cm);
    if (!L || !cholmod_factorize(A, L, &cm)) {
        rc = obs__fail(err, OBS_NO_MEMORY, "CHOLMOD could not factorise (status %d)", cm.status);
        goto done;
    }
    if (cm.status == CHOLMOD_NOT_POSDEF) {
        rc = obs__fail(err, OBS_INVALID_ARGUMENT,
                       "the least-squares system is singular at column %d of %zu", (int)L->minor,
                       y.n);
        goto done;
    }
    X = cholmod_solve(CHOLMOD_A, L, B, &cm);
    if (!X) {
        rc = obs__fail(err, OBS_NO_MEMORY, "CHOLMOD solve (status %d)", cm.status);
        goto done;
    }
    if ((rc = copy_back(X->x, y.n, x, err)) != OBS_OK)
        goto done;
    st->seconds[OBS_BAKE_STAGE_solve] = obs__bake_now() - t_solve;

    /* what the report says about the fit */
    obs__bake_residual(w, wd, s, x, st->residual_fit);
    baselines(w, wd, s, &y, face, point, st);
    regulariser_energy(w, wd, &y, p, x, st);
    /* parameter values: a baseline written instead of the fit */
    if (p->values == OBS_BAKE_VALUES_FACE_MEAN || p->values == OBS_BAKE_VALUES_POINT) {
        memcpy(x, p->values == OBS_BAKE_VALUES_POINT ? point : face, 2 * y.n * sizeof *x);
        obs__bake_residual(w, wd, s, x, st->residual_fit);
    }
done:
    if (started) {
        cholmod_free_triplet(&T, &cm);
        cholmod_free_sparse(&A, &cm);
        cholmod_free_factor(&L, &cm);
        cholmod_free_dense(&B, &cm);
        cholmod_free_dense(&X, &cm);
        cholmod_finish(&cm);
    }
    sys_free(&y);
    return rc;
}
