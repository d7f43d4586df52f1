/* A deep frame's result: its three images, through the one image
 * allocator (core/image.c). */
#include <string.h>

#include "deep/deep_internal.h"

void obs_deep_result_free(obs_deep_result *r)
{
    if (!r)
        return;
    obs_image_free(&r->ao_front);
    obs_image_free(&r->ao_blend);
    obs_image_free(&r->composite);
}

obs_status obs__deep_result_alloc(obs_deep_result *out, int w, int h, char err[OBS_ERR_LEN])
{
    obs_status s;
    memset(out, 0, sizeof *out);
    if ((s = obs__image_alloc(&out->ao_front, w, h, 1, err)) == OBS_OK &&
        (s = obs__image_alloc(&out->ao_blend, w, h, 1, err)) == OBS_OK)
        s = obs__image_alloc(&out->composite, w, h, 4, err);
    if (s != OBS_OK)
        obs_deep_result_free(out);
    return s;
}
