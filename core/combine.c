/* Baked and screen-space AO in one frame (obscura.h,
 * obs_result_combine_baked).  The paper of the bake ("Baked ambient
 * obscurance on the vertices of game levels") bakes the distant
 * obscurance and leaves the fine detail to screen-space AO; the two are
 * visibility factors of separate scales, so the default combination is
 * their product; min is the alternative that darkens once where both see
 * the same occluder. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "obscura/params.h"

obs_status obs_result_combine_baked(obs_result *r, const obs_image *baked,
                                    const obs_params *params, char err[OBS_ERR_LEN])
{
    if (!r || !r->ao.data || r->ao.channels != 1)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "combining baked AO: the result has no AO");
    if (!baked || !baked->data || baked->channels != 1 || baked->width != r->ao.width ||
        baked->height != r->ao.height)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "combining baked AO: the baked channel is %dx%d, the AO %dx%d",
                         baked ? baked->width : 0, baked ? baked->height : 0, r->ao.width,
                         r->ao.height);
    if (r->ao_screen.data)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "combining baked AO: already combined");
    obs_params p;
    obs_params_resolve(params, &p);
    const int w = r->ao.width, h = r->ao.height;
    obs_image b = {0};
    obs_status s = obs__image_alloc(&b, w, h, 1, err);
    if (s != OBS_OK)
        return s;
    const size_t n = (size_t)w * h;
    r->ao_screen = r->ao; /* the chain's AO, kept */
    memset(&r->ao, 0, sizeof r->ao);
    if ((s = obs__image_alloc(&r->ao, w, h, 1, err)) != OBS_OK) {
        r->ao = r->ao_screen;
        memset(&r->ao_screen, 0, sizeof r->ao_screen);
        obs_image_free(&b);
        return s;
    }
    for (size_t i = 0; i < n; i++) {
        float v = baked->data[i];
        v = isfinite(v) ? fminf(fmaxf(v, 0.0f), 1.0f) : 1.0f;
        float sc = r->ao_screen.data[i];
        b.data[i] = v;
        r->ao.data[i] = p.baked_combine == OBS_BAKED_MIN ? fminf(v, sc) : v * sc;
        if (r->composite.data) {
            /* the composite is linear in the AO (composite.frag.glsl) */
            float f = sc > 0.0f ? r->ao.data[i] / sc : 0.0f;
            for (int k = 0; k < 3; k++)
                r->composite.data[4 * i + k] *= f;
        }
    }
    r->ao_baked = b;
    return OBS_OK;
}
