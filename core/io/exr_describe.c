/* obs_exr_describe_camera(): the renderer and camera of any EXR part
 * (flat or deep) as the readers find them, for obscura inspect. */
#include <string.h>

#include "io/exr_internal.h"
#include "internal.h"

obs_status obs_exr_describe_camera(const char *path, int part, obs_exr_info *info,
                                   obs_camera *cam, char err[OBS_ERR_LEN])
{
    exr_context_t ctx = NULL;
    int64_t size;
    obs_gbuffer gb;
    obs__channel_match m;
    char sub[OBS_ERR_LEN] = "";
    obs_status st = obs__exr_open(path, NULL, &ctx, &size, sub);
    if (st != OBS_OK)
        return obs__fail(err, st, "%s: %s", path, sub);
    memset(&gb, 0, sizeof gb);
    memset(&m, 0, sizeof m);
    obs__exr_describe(ctx, part, &m, &gb, info);
    obs__exr_msg_reset(); /* a missing attribute is not an error */
    *cam = gb.camera;
    exr_finish(&ctx);
    return OBS_OK;
}
