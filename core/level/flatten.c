/* Instances to world space: every (node, mesh) pair of the graph becomes
 * its own run of world-space vertices and triangles, the input of the
 * samples, the BVH and the fit. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "level/level.h"
#include "obscura/scene.h"
#include "internal.h"

void obs__bake_world_free(obs__bake_world *w)
{
    if (!w)
        return;
    free(w->pos); /* the block of all seven arrays (obs__alloc_arrays) */
    memset(w, 0, sizeof *w);
}

static void xform_point(const float m[16], const float p[3], float out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
}

/* The normal matrix: the inverse transpose of m's 3x3 part, as the
 * cofactors (the determinant's scale drops out when normalising). */
static float normal_matrix(const float m[16], float c[9])
{
    float a = m[0], b = m[1], cc = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9],
          i = m[10];
    c[0] = e * i - f * h;
    c[1] = -(d * i - f * g);
    c[2] = d * h - e * g;
    c[3] = -(b * i - cc * h);
    c[4] = a * i - cc * g;
    c[5] = -(a * h - b * g);
    c[6] = b * f - cc * e;
    c[7] = -(a * f - cc * d);
    c[8] = a * e - b * d;
    return a * c[0] + b * c[1] + cc * c[2];
}

static void face(obs__bake_world *w, size_t t)
{
    const uint32_t *v = w->tri + 3 * t;
    const float *p0 = w->pos + 3 * v[0], *p1 = w->pos + 3 * v[1], *p2 = w->pos + 3 * v[2];
    float n[3];
    double len = obs__tri_normal(p0, p1, p2, n);
    if (len == 0.0) {
        w->area[t] = 0.0f;
        memset(w->fn + 3 * t, 0, 3 * sizeof(float));
        w->degenerate++;
        return;
    }
    w->area[t] = (float)(0.5 * len);
    float sn[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) {
        w->fn[3 * t + k] = (float)(n[k] / len);
        sn[k] = w->nrm[3 * v[0] + k] + w->nrm[3 * v[1] + k] + w->nrm[3 * v[2] + k];
    }
    if (sn[0] * n[0] + sn[1] * n[1] + sn[2] * n[2] < 0.0f)
        w->against_normals++;
}

obs_status obs__bake_flatten(const obs_bake_scene *s, obs__bake_world *w, char err[OBS_ERR_LEN])
{
    memset(w, 0, sizeof *w);
    size_t nv = 0, nt = 0, ni = 0;
    for (size_t n = 0; n < s->node_count; n++)
        for (uint32_t k = 0; k < s->nodes[n].mesh_count; k++) {
            const obs_bake_mesh *m = &s->meshes[s->nodes[n].meshes[k]];
            nv += m->vertex_count;
            nt += m->triangle_count;
            ni++;
        }
    if (nt == 0)
        return obs__fail(err, OBS_BAD_FILE, "no triangles under the scene's nodes");
    if (nv > UINT32_MAX)
        return obs__fail(err, OBS_TOO_LARGE, "%zu vertices once instances are flattened; at most %u",
                         nv, (unsigned)UINT32_MAX);
    size_t b3;
    if (obs__size_mul(nv, 3 * sizeof(float), &b3) || obs__size_mul(nt, 3 * sizeof(float), &b3))
        return obs__fail(err, OBS_TOO_LARGE, "%zu vertices, %zu triangles", nv, nt);
    const size_t bytes[] = {nv * 3 * sizeof(float), nv * 3 * sizeof(float), nt * 3 * sizeof(uint32_t),
                            nt * sizeof(float), nt * 3 * sizeof(float), nt, ni * sizeof *w->inst};
    void *arr[7];
    if (!obs__alloc_arrays(7, bytes, arr))
        return obs__fail(err, OBS_NO_MEMORY, "world copy of %zu vertices, %zu triangles", nv, nt);
    *w = (obs__bake_world){.pos = arr[0], .nrm = arr[1], .tri = arr[2], .area = arr[3], .fn = arr[4],
                           .two_sided = arr[5], .inst = arr[6]};
    for (size_t n = 0; n < s->node_count; n++) {
        const obs_bake_node *node = &s->nodes[n];
        float nm[9];
        float det = normal_matrix(node->world, nm);
        for (uint32_t k = 0; k < node->mesh_count; k++) {
            const obs_bake_mesh *m = &s->meshes[node->meshes[k]];
            obs__bake_inst *in = &w->inst[w->instance_count++];
            in->node = (uint32_t)n;
            in->mesh = node->meshes[k];
            in->first_vertex = w->vertex_count;
            in->first_triangle = w->triangle_count;
            for (size_t v = 0; v < m->vertex_count; v++) {
                float *p = w->pos + 3 * (w->vertex_count + v), *q = w->nrm + 3 * (w->vertex_count + v);
                xform_point(node->world, m->positions + 3 * v, p);
                /* each coordinate: their sum overflows where they do not */
                if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
                    obs__bake_world_free(w);
                    return obs__fail(err, OBS_BAD_FILE,
                                     "node '%s', mesh '%s': vertex %zu is not finite in world "
                                     "space (the node's transform overflows)",
                                     node->name, m->name, v);
                }
                if (obs_scene_coord_beyond(p)) {
                    obs__fail(err, OBS_BAD_FILE,
                              "node '%s', mesh '%s': vertex %zu at (%g, %g, %g) in world "
                              "space: " OBS_SCENE_COORD_RULE,
                              node->name, m->name, v, p[0], p[1], p[2]);
                    obs__bake_world_free(w); /* p was in it */
                    return OBS_BAD_FILE;
                }
                memset(q, 0, 3 * sizeof(float));
                if (m->normals) {
                    const float *a = m->normals + 3 * v;
                    for (int r = 0; r < 3; r++)
                        q[r] = nm[3 * r] * a[0] + nm[3 * r + 1] * a[1] + nm[3 * r + 2] * a[2];
                    float len = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                    /* cofactors = det * inverse transpose: the sign of det */
                    float sc = det < 0.0f ? -1.0f : 1.0f;
                    for (int r = 0; r < 3; r++)
                        q[r] = len > 0.0f && isfinite(len) ? sc * q[r] / len : 0.0f;
                }
            }
            for (size_t t = 0; t < m->triangle_count; t++) {
                uint32_t *o = w->tri + 3 * (w->triangle_count + t);
                const uint32_t *i = m->indices + 3 * t;
                /* A mirroring transform turns the winding over. */
                o[0] = (uint32_t)w->vertex_count + i[0];
                o[1] = (uint32_t)w->vertex_count + (det < 0.0f ? i[2] : i[1]);
                o[2] = (uint32_t)w->vertex_count + (det < 0.0f ? i[1] : i[2]);
                w->two_sided[w->triangle_count + t] = (uint8_t)(m->two_sided != 0);
            }
            w->vertex_count += m->vertex_count;
            w->triangle_count += m->triangle_count;
        }
    }
    for (size_t t = 0; t < w->triangle_count; t++)
        face(w, t);
    if (w->degenerate == w->triangle_count) {
        size_t n = w->triangle_count;
        obs__bake_world_free(w);
        return obs__fail(err, OBS_BAD_FILE, "all %zu triangles are degenerate (zero area)", n);
    }
    return OBS_OK;
}

obs_status obs__bake_flatten_checked(const obs_bake_scene *scene, int max_triangles,
                                     const char *who, obs__bake_world *w, char err[OBS_ERR_LEN])
{
    if (!scene || scene->node_count == 0)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: no scene", who);
    if (scene->world_triangles > (size_t)max_triangles)
        return obs__fail(err, OBS_TOO_LARGE, "%zu triangles once flattened; max_triangles is %d",
                         scene->world_triangles, max_triangles);
    return obs__bake_flatten(scene, w, err);
}
