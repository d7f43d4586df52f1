/* The baked channels of a level with dynamic objects in it (scene.h,
 * obs_raster_baked_dynamic; obscura gbuffer --dynamic): the static
 * meshes keep their interpolated vertex _AO (raster_baked.c's way: the
 * baked triple rasterised in the albedo's place), and the pixels of the
 * dynamic meshes take the region model of obscura bake-dynamic
 * (dynamic.h, obs_dyn_eval) at the pixel's world position and normal,
 * as an engine evaluates it per pixel or per vertex for an object
 * (section 2.3 of the paper).  The dynamic meshes' vertices carry a
 * value no baked AO has (-1) through the same rasteriser, so that the
 * pixels they cover are known from the same triangles as the G-buffer's
 * position and normal. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "ground/raster_internal.h"
#include "obscura/scene.h"

#define DYNAMIC_MARK -1.0f

/* Static triangles' count and box against the level the model records. */
obs_status obs_scene_check_dynamic_level(const obs_scene *s, const obs_dyn_model *m,
                                         char err[OBS_ERR_LEN])
{
    size_t nt = 0;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t k = 0; k < s->mesh_count; k++) {
        const obs_scene_mesh *me = &s->meshes[k];
        if (me->dynamic)
            continue;
        nt += me->triangle_count;
        for (size_t t = me->first_triangle; t < me->first_triangle + me->triangle_count; t++)
            for (int c = 0; c < 3; c++) {
                const float *p = s->positions + 3 * (size_t)s->indices[3 * t + c];
                for (int a = 0; a < 3; a++)
                    lo[a] = fminf(lo[a], p[a]), hi[a] = fmaxf(hi[a], p[a]);
            }
    }
    const obs_dyn_level *l = &m->level;
    double diag = 0.0;
    for (int a = 0; a < 3; a++)
        diag += (double)(l->hi[a] - l->lo[a]) * (l->hi[a] - l->lo[a]);
    /* the same level through another loader: its floats may round apart */
    double tol = 1e-4 * sqrt(diag) + 1e-6, off = 0.0;
    for (int a = 0; a < 3 && nt; a++)
        off = fmax(off, fmax(fabs((double)lo[a] - l->lo[a]), fabs((double)hi[a] - l->hi[a])));
    if (nt != l->triangles || off > tol)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "the region model was baked from another level (%llu triangles in "
                         "[%g %g %g] .. [%g %g %g]); the scene's static nodes have %zu triangles "
                         "in [%g %g %g] .. [%g %g %g] (a dynamic object left unmarked, or baked "
                         "into the level?)",
                         (unsigned long long)l->triangles, l->lo[0], l->lo[1], l->lo[2], l->hi[0],
                         l->hi[1], l->hi[2], nt, nt ? lo[0] : 0.0f, nt ? lo[1] : 0.0f,
                         nt ? lo[2] : 0.0f, nt ? hi[0] : 0.0f, nt ? hi[1] : 0.0f,
                         nt ? hi[2] : 0.0f);
    return OBS_OK;
}

obs_status obs_raster_baked_dynamic(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam,
                                    int width, int height, const obs_raster *g,
                                    const obs_dyn_model *m, int quadratic, obs_image *out,
                                    size_t *dynamic_pixels, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    if (dynamic_pixels)
        *dynamic_pixels = 0;
    if (!scene || !scene->baked)
        return obs__fail(err, OBS_MISSING_CHANNEL,
                         "the scene has no baked _AO values (load a baked level)");
    if (!g || g->position.width != width || g->position.height != height ||
        g->normal.width != width || g->normal.height != height || !g->position.data ||
        !g->normal.data)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "the G-buffer's positions and normals are "
                                                    "not %dx%d", width, height);
    size_t nv = scene->vertex_count, bytes;
    if (obs__size_mul3(nv ? nv : 1, 3, sizeof(float), &bytes))
        return obs__fail(err, OBS_TOO_LARGE, "%zu vertices", nv);
    float *mark = malloc(bytes);
    if (!mark)
        return obs__fail(err, OBS_NO_MEMORY, "%zu vertices", nv);
    memcpy(mark, scene->baked, nv * 3 * sizeof(float));
    for (size_t k = 0; k < scene->mesh_count; k++) {
        const obs_scene_mesh *me = &scene->meshes[k];
        for (size_t t = me->first_triangle; me->dynamic && t < me->first_triangle + me->triangle_count; t++)
            for (int c = 0; c < 3; c++)
                for (int a = 0; a < 3; a++)
                    mark[3 * (size_t)scene->indices[3 * t + c] + a] = DYNAMIC_MARK;
    }
    obs_raster r;
    obs_status s = obs__raster_values(ctx, scene, mark, cam, width, height, 3, &r, out, err);
    free(mark);
    if (s != OBS_OK)
        return s;
    size_t n = (size_t)width * height, dyn = 0;
    obs_dyn_sh_order order = quadratic ? OBS_DYN_QUADRATIC : OBS_DYN_LINEAR;
    for (size_t i = 0; i < n; i++) {
        const float *c = r.color.data + 4 * i;
        float *o = out->data + 3 * i;
        if (!(c[3] > 0.0f)) { /* coverage 0: open */
            o[0] = o[1] = o[2] = 1.0f;
        } else if (c[0] < 0.5f * DYNAMIC_MARK) {
            float ao[3]; /* short, long, blended */
            obs_dyn_eval(m, g->position.data + 3 * i, g->normal.data + 3 * i, order, ao);
            o[0] = ao[2], o[1] = ao[0], o[2] = ao[1];
            dyn++;
        } else {
            memcpy(o, c, 3 * sizeof *o);
        }
    }
    if (dynamic_pixels)
        *dynamic_pixels = dyn;
    obs_raster_free(&r);
    return OBS_OK;
}
