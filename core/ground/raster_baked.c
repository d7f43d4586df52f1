/* The baked values of a level rasterised (scene.h, obs_raster_baked):
 * the G-buffer rasteriser run with the baked triple in the place of the
 * albedo (obs__raster_values), so that depth, normals and the baked channels come
 * from the same triangles at the same pixels. */
#include <string.h>

#include "internal.h"
#include "ground/raster_internal.h"
#include "obscura/scene.h"

obs_status obs_raster_baked(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam,
                            int width, int height, obs_image *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    if (!scene || !scene->baked)
        return obs__fail(err, OBS_MISSING_CHANNEL,
                         "the scene has no baked _AO values (load a baked level)");
    obs_raster r;
    obs_status s = obs__raster_values(ctx, scene, scene->baked, cam, width, height, 3, &r, out,
                                      err);
    if (s != OBS_OK)
        return s;
    size_t n = (size_t)width * height;
    for (size_t i = 0; i < n; i++) {
        const float *c = r.color.data + 4 * i;
        for (int k = 0; k < 3; k++)
            out->data[3 * i + k] = c[3] > 0.0f ? c[k] : 1.0f; /* coverage 0: open */
    }
    obs_raster_free(&r);
    return OBS_OK;
}
