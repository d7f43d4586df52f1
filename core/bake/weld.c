/* Triangle soup welded for the fit (paper 2.1: the levels are triangle
 * soup; Kavan et al.'s regulariser needs the shared edges).  Our own pass,
 * not meshoptimizer's meshopt_generateVertexRemap: that welds only
 * byte-identical vertices, and the split by normal below needs a pass of
 * its own anyway.  Vertices whose positions quantise to the same cell of
 * size tolerance x (the level's box diagonal) are
 * one vertex, unless their normals are weld_angle or more apart: the two
 * sides of a back-to-back pair of faces stay two vertices.  The weld spans
 * the whole level, not one instance at a time: a soup level such as a
 * TORCS track cuts one surface into many objects, whose shared edges the
 * regulariser must see too.  The cells are found by sorting the quantised
 * keys (deterministic, O(n log n)). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake/bake_internal.h"
#include "internal.h"

typedef struct key {
    int64_t q[3];
    uint32_t v;
} key;

static int key_cmp(const void *pa, const void *pb)
{
    const key *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->q[k] != b->q[k])
            return a->q[k] < b->q[k] ? -1 : 1;
    return a->v < b->v ? -1 : a->v > b->v;
}

void obs__bake_weld_free(obs__bake_weld *wd)
{
    if (!wd)
        return;
    free(wd->of);
    memset(wd, 0, sizeof *wd);
}

static int64_t quantise(float x, double cell)
{
    if (cell <= 0.0) {
        int32_t bits;
        float z = x == 0.0f ? 0.0f : x; /* -0 and 0 are one position */
        memcpy(&bits, &z, sizeof bits);
        return bits;
    }
    return (int64_t)floor((double)x / cell);
}

obs_status obs__bake_weld_make(const obs__bake_world *w, float tolerance, float angle_deg,
                          obs__bake_weld *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    out->of = malloc(w->vertex_count * sizeof *out->of);
    size_t n = w->vertex_count;
    key *keys = malloc((n ? n : 1) * sizeof *keys);
    uint32_t *rep = malloc((n ? n : 1) * sizeof *rep);
    if (!out->of || !keys || !rep) {
        free(keys);
        free(rep);
        obs__bake_weld_free(out);
        return obs__fail(err, OBS_NO_MEMORY, "welding %zu vertices", w->vertex_count);
    }
    const float cos_max = cosf(angle_deg * 3.14159265f / 180.0f);
    size_t next = 0;
    {
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t v = 0; v < n; v++)
            for (int k = 0; k < 3; k++) {
                lo[k] = fminf(lo[k], w->pos[3 * v + k]);
                hi[k] = fmaxf(hi[k], w->pos[3 * v + k]);
            }
        double diag = 0.0;
        for (int k = 0; k < 3 && n; k++)
            diag += (double)(hi[k] - lo[k]) * (hi[k] - lo[k]);
        double cell = tolerance * sqrt(diag);
        for (size_t v = 0; v < n; v++) {
            key *kk = &keys[v];
            for (int k = 0; k < 3; k++)
                kk->q[k] = quantise(w->pos[3 * v + k], cell);
            kk->v = (uint32_t)v;
        }
        qsort(keys, n, sizeof *keys, key_cmp);
        for (size_t a = 0; a < n;) {
            size_t b = a + 1;
            while (b < n && !memcmp(keys[b].q, keys[a].q, sizeof keys[a].q))
                b++;
            /* One cell: each vertex joins the first earlier group whose
             * first vertex's normal is close enough, else starts one. */
            size_t groups = 0;
            for (size_t c = a; c < b; c++) {
                uint32_t v = keys[c].v;
                const float *nv = w->nrm + 3 * (size_t)v;
                size_t g = 0;
                for (; g < groups; g++) {
                    const float *ng = w->nrm + 3 * (size_t)rep[g];
                    float dn = nv[0] * ng[0] + nv[1] * ng[1] + nv[2] * ng[2];
                    int none = (nv[0] == 0 && nv[1] == 0 && nv[2] == 0) ||
                               (ng[0] == 0 && ng[1] == 0 && ng[2] == 0);
                    if (none || dn > cos_max || angle_deg >= 180.0f)
                        break;
                }
                if (g == groups)
                    rep[groups++] = v;
                out->of[v] = g == groups - 1 && rep[g] == v ? (uint32_t)next++ : out->of[rep[g]];
            }
            a = b;
        }
    }
    free(keys);
    free(rep);
    out->count = next;
    return OBS_OK;
}

static float clamp01(double v) { return (float)(v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v); }

int obs__bake_instance_values(obs_bake_instance *r, const obs__bake_inst *in, size_t n,
                              const uint32_t *of, const double *x, float blend)
{
    r->node = in->node;
    r->mesh = in->mesh;
    r->ao = malloc((n ? n : 1) * sizeof(float));
    r->ao_short = malloc((n ? n : 1) * sizeof(float));
    r->ao_long = malloc((n ? n : 1) * sizeof(float));
    if (!r->ao || !r->ao_short || !r->ao_long)
        return -1;
    for (size_t v = 0; v < n; v++) {
        uint32_t k = of[v];
        r->ao_short[v] = clamp01(x[2 * k]);
        r->ao_long[v] = clamp01(x[2 * k + 1]);
        /* _AO, the artists' blend (section 2) */
        r->ao[v] = clamp01(blend * r->ao_short[v] + (1.0f - blend) * r->ao_long[v]);
    }
    return 0;
}
