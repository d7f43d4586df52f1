/* Object IDs rasterised (scene.h, obs_raster_ids): the G-buffer
 * rasteriser run with each vertex's "albedo" the index + 1 of the mesh it
 * belongs to, a constant over every triangle, so the ID channel comes from
 * the same triangles at the same pixels as depth and normals (one sample
 * per pixel: no anti-aliased edges, an integer ID per pixel). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "ground/raster_internal.h"
#include "obscura/scene.h"

obs_status obs_raster_ids(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam, int width,
                          int height, obs_image *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    if (!scene || !scene->mesh_count)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "the scene has no meshes to number");
    size_t n3;
    if (obs__size_mul(scene->vertex_count, 3 * sizeof(float), &n3))
        return obs__fail(err, OBS_NO_MEMORY, "IDs of %zu vertices", scene->vertex_count);
    float *ids = calloc(1, n3 ? n3 : 1);
    if (!ids)
        return obs__fail(err, OBS_NO_MEMORY, "IDs of %zu vertices", scene->vertex_count);
    for (size_t m = 0; m < scene->mesh_count; m++) {
        const obs_scene_mesh *sm = &scene->meshes[m];
        for (size_t t = sm->first_triangle;
             t < sm->first_triangle + sm->triangle_count && t < scene->triangle_count; t++)
            for (int k = 0; k < 3; k++)
                ids[3 * (size_t)scene->indices[3 * t + k]] = (float)(m + 1);
    }
    obs_raster r;
    obs_status s = obs__raster_values(ctx, scene, ids, cam, width, height, 1, &r, out, err);
    free(ids);
    if (s != OBS_OK)
        return s;
    size_t n = (size_t)width * height;
    /* the interpolated constant, rounded back to its integer; 0: no geometry */
    for (size_t i = 0; i < n; i++)
        out->data[i] = r.color.data[4 * i + 3] > 0.0f ? floorf(r.color.data[4 * i] + 0.5f) : 0.0f;
    obs_raster_free(&r);
    return OBS_OK;
}
