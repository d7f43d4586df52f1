/* The info a reader fills beside a G-buffer: the renderer the header
 * names (presets.c), the conventions of the channel match, and the camera
 * with its source, cross-check and warnings (decided in core/camera/exr.c).
 * Shared by the flat reader (exr_read.c) and obscura inspect
 * (exr_describe.c). */
#include <stdio.h>

#include "io/exr_internal.h"
#include "internal.h"

void obs__exr_describe(exr_const_context_t ctx, int part, const obs__channel_match *m,
                       obs_gbuffer *gb, obs_exr_info *info)
{
    const char *renderer = obs__preset_detect(ctx, part, info->renderer_why,
                                              sizeof info->renderer_why);
    snprintf(info->renderer, sizeof info->renderer, "%s", renderer ? renderer : "");
    info->depth_mode = m->depth_mode;
    info->normal_space = m->normal_space;
    obs__camera_read_header(ctx, part, renderer, &gb->camera, info);
}
