/* A lower level of detail of one mesh (paper 2.2.1: the LOD models the
 * bake is resampled onto), made with meshoptimizer's simplifier.
 *
 * The weld first: meshopt_simplify collapses edges of an indexed mesh and
 * treats two vertices at one position as a seam it must keep, so the
 * mesh's attribute splits would hold it back.  We weld with the bake's
 * own pass (weld.c: positions quantised at weld_tolerance of the mesh's
 * box diagonal, normals within weld_angle), not meshopt_generateVertexRemap:
 * that merges only byte-identical vertices, so it keeps every normal
 * split and every near-coincident pair, and the normal test keeps the two
 * sides of a back-to-back pair of faces apart, which the simplifier must
 * not fold into one.  Each level starts again from the welded full mesh
 * (not from the level above), towards ratio^level of its triangles, with
 * level x error as meshopt_simplify's error bound (relative to the mesh's
 * extent).  With lod_lock_border the mesh's open border is locked: two
 * meshes meeting along an edge (terrain tiles, the pieces of a modular
 * wall) are simplified apart, and an unlocked border (the default, which
 * reaches lod_ratio on levels made of open meshes) loses different
 * vertices on either side, leaving T-junctions and cracks. */
#include <math.h>
#include <meshoptimizer.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/simplify.h"
#include "internal.h"

/* The welded mesh: positions of each group's first vertex, the triangles
 * that did not collapse. */
typedef struct welded {
    obs__bake_weld wd;
    uint32_t *rep; /* group -> its first vertex */
    float *pos;    /* 3 per group */
    uint32_t *idx;
    size_t ni;
} welded;

static void welded_free(welded *k)
{
    obs__bake_weld_free(&k->wd);
    free(k->rep);
    free(k->pos);
    free(k->idx);
}

static obs_status weld(const obs_bake_mesh *m, float tolerance, float angle, welded *k,
                       char err[OBS_ERR_LEN])
{
    size_t nv = m->vertex_count, nt = m->triangle_count;
    obs__bake_world w = {0};
    float *zero = NULL;
    w.vertex_count = nv;
    w.pos = m->positions;
    if (!(w.nrm = m->normals) && !(w.nrm = zero = calloc(3 * nv, sizeof *zero)))
        return obs__fail(err, OBS_NO_MEMORY, "simplify '%s': %zu vertices", m->name, nv);
    obs_status rc = obs__bake_weld_make(&w, tolerance, angle, &k->wd, err);
    free(zero);
    if (rc != OBS_OK)
        return rc;
    size_t ng = k->wd.count ? k->wd.count : 1;
    k->rep = malloc(ng * sizeof *k->rep);
    k->pos = malloc(3 * ng * sizeof *k->pos);
    k->idx = malloc(3 * nt * sizeof *k->idx);
    if (!k->rep || !k->pos || !k->idx)
        return obs__fail(err, OBS_NO_MEMORY, "simplify '%s': %zu vertices", m->name, nv);
    for (size_t v = nv; v-- > 0;)
        k->rep[k->wd.of[v]] = (uint32_t)v;
    for (size_t g = 0; g < k->wd.count; g++)
        memcpy(k->pos + 3 * g, m->positions + 3 * (size_t)k->rep[g], 3 * sizeof *k->pos);
    for (size_t t = 0; t < nt; t++) {
        uint32_t a = k->wd.of[m->indices[3 * t]], b = k->wd.of[m->indices[3 * t + 1]],
                 c = k->wd.of[m->indices[3 * t + 2]];
        if (a == b || b == c || a == c)
            continue;
        k->idx[k->ni++] = a, k->idx[k->ni++] = b, k->idx[k->ni++] = c;
    }
    return OBS_OK;
}

/* flatten.c's degenerate face (obs__tri_normal): zero area, or a sliver
 * whose normal float rounding decides. */
static int flat(const float *pos, const uint32_t t[3])
{
    float n[3];
    return obs__tri_normal(pos + 3 * (size_t)t[0], pos + 3 * (size_t)t[1], pos + 3 * (size_t)t[2],
                           n) == 0.0;
}

/* The mesh copied whole into out (its name already set): a level the
 * weld cannot simplify. */
static int copy_whole(const obs_bake_mesh *m, obs_bake_mesh *out)
{
    size_t nv = m->vertex_count, ni = 3 * m->triangle_count;
    out->positions = malloc(3 * nv * sizeof *out->positions);
    out->indices = malloc(ni * sizeof *out->indices);
    if (m->normals)
        out->normals = malloc(3 * nv * sizeof *out->normals);
    if (!out->positions || !out->indices || (m->normals && !out->normals))
        return 0;
    memcpy(out->positions, m->positions, 3 * nv * sizeof *out->positions);
    memcpy(out->indices, m->indices, ni * sizeof *out->indices);
    if (m->normals)
        memcpy(out->normals, m->normals, 3 * nv * sizeof *out->normals);
    out->vertex_count = nv;
    out->triangle_count = m->triangle_count;
    return 1;
}

obs_status obs__bake_simplify(const obs_bake_mesh *m, int level, float ratio, float error,
                              int lock_border, float weld_tolerance, float weld_angle,
                              obs_bake_mesh *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    const char *name = m->name ? m->name : "";
    if (level < 1 || level > OBS_BAKE_MAX_LODS || !(ratio > 0.0f && ratio < 1.0f) ||
        !(error >= 0.0f && error <= 1.0f))
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "simplify '%s': level %d (1 .. %d), ratio %g (0 .. 1), error %g "
                         "(0 .. 1)",
                         name, level, OBS_BAKE_MAX_LODS, (double)ratio, (double)error);
    obs_status rc = OBS_OK;
    welded k = {0};
    uint32_t *dst = NULL, *map = NULL;
    out->material = m->material;
    out->two_sided = m->two_sided;
    size_t len = strlen(name) + 16;
    if (!(out->name = malloc(len)))
        goto nomem;
    snprintf(out->name, len, "%s_LOD%d", name, level);
    if (m->triangle_count == 0 || m->vertex_count == 0)
        return OBS_OK;
    if ((rc = weld(m, weld_tolerance, weld_angle, &k, err)) != OBS_OK)
        goto done;
    if (k.ni == 0) {
        /* Every triangle collapsed: an empty level for a mesh without
         * area; a mesh with some (faces much smaller than the weld's
         * tolerance, a fraction of its box: a small part beside long
         * slivers) is kept whole, as the bake keeps it, rather than left
         * empty (a level of such meshes alone had no triangle at all). */
        for (size_t t = 0; t < m->triangle_count; t++)
            if (!flat(m->positions, m->indices + 3 * t)) {
                if (!copy_whole(m, out))
                    goto nomem;
                break;
            }
        goto done;
    }
    if (!(dst = malloc(k.ni * sizeof *dst)))
        goto nomem;
    size_t tris = k.ni / 3;
    size_t target = (size_t)floor((double)tris * pow((double)ratio, level) + 0.5);
    target = 3 * (target < 1 ? 1 : target);
    /* LockBorder: an open edge's vertices (an edge of one triangle; the
     * weld's remaining normal splits are seams to meshoptimizer, which it
     * keeps matched without the option) do not move, so a neighbouring
     * mesh's border, locked too, still meets this one at every level */
    size_t nd = meshopt_simplify(dst, k.idx, k.ni, k.pos, k.wd.count, 3 * sizeof(float), target,
                                 (float)level * error,
                                 lock_border ? (unsigned)meshopt_SimplifyLockBorder : 0u, NULL);
    /* Zero-area triangles the collapses left along straight borders are
     * dropped (flatten.c's test: the bake would skip them anyway, and a
     * vertex of only such triangles would have no sample). */
    size_t keep = 0;
    for (size_t i = 0; i < nd; i += 3)
        if (!flat(k.pos, dst + i)) {
            memmove(dst + keep, dst + i, 3 * sizeof *dst);
            keep += 3;
        }
    nd = keep;
    if (nd == 0) { /* only for a surface without area: kept whole */
        memcpy(dst, k.idx, k.ni * sizeof *dst);
        nd = k.ni;
    }
    /* compacted: the groups the level uses, in order of first use */
    if (!(map = malloc(k.wd.count * sizeof *map)))
        goto nomem;
    for (size_t g = 0; g < k.wd.count; g++)
        map[g] = UINT32_MAX;
    size_t used = 0;
    for (size_t i = 0; i < nd; i++)
        if (map[dst[i]] == UINT32_MAX)
            map[dst[i]] = (uint32_t)used++;
    out->positions = malloc(3 * used * sizeof *out->positions);
    out->indices = malloc(nd * sizeof *out->indices);
    if (m->normals)
        out->normals = malloc(3 * used * sizeof *out->normals);
    if (!out->positions || !out->indices || (m->normals && !out->normals))
        goto nomem;
    for (size_t g = 0; g < k.wd.count; g++) {
        if (map[g] == UINT32_MAX)
            continue;
        memcpy(out->positions + 3 * (size_t)map[g], k.pos + 3 * g, 3 * sizeof(float));
        if (m->normals)
            memcpy(out->normals + 3 * (size_t)map[g], m->normals + 3 * (size_t)k.rep[g],
                   3 * sizeof(float));
    }
    for (size_t i = 0; i < nd; i++)
        out->indices[i] = map[dst[i]];
    out->vertex_count = used;
    out->triangle_count = nd / 3;
    goto done;
nomem:
    rc = obs__fail(err, OBS_NO_MEMORY, "simplify '%s': %zu vertices, %zu triangles", name,
                   m->vertex_count, m->triangle_count);
done:
    free(dst);
    free(map);
    welded_free(&k);
    if (rc != OBS_OK)
        obs__bake_mesh_free(out);
    return rc;
}
