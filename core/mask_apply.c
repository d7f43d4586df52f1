/* The receivers mask (parameter receivers, core/mask.c) applied to a
 * finished result: a pixel of weight w gets 1 - w (1 - AO), so an
 * unselected one keeps AO 1 exactly and an anti-aliased edge its
 * coverage's share (Arnold's aiAmbientOcclusion applied to the selected
 * shapes only). */
#include "internal.h"
#include "mask_apply.h"

static void apply(const float *w, size_t n, float *ao)
{
    for (size_t i = 0; i < n; i++)
        ao[i] = 1.0f - w[i] * (1.0f - ao[i]);
}

void obs__receivers_apply(const obs_gbuffer *gb, obs_result *r)
{
    const float *w = gb->receivers.data;
    if (!w)
        return;
    const size_t n = (size_t)gb->width * (size_t)gb->height;
    if (r->ao.data)
        apply(w, n, r->ao.data);
    /* the multi-bounce AO (R, G, B) the same way, channel by channel */
    for (size_t i = 0; r->multibounce.data && i < n; i++)
        for (int k = 0; k < 3; k++)
            r->multibounce.data[3 * i + k] = 1.0f - w[i] * (1.0f - r->multibounce.data[3 * i + k]);
    if (!r->composite.data)
        return;
    for (int y = 0; y < gb->height; y++)
        for (int x = 0; x < gb->width; x++) {
            size_t i = (size_t)y * (size_t)gb->width + (size_t)x;
            float *o = r->composite.data + 4 * i;
            const float *c = gb->color.data ? obs__plane_px(&gb->color, gb->width, x, y) : NULL;
            for (int k = 0; k < 3; k++)
                o[k] = (1.0f - w[i]) * (c ? c[k] : 1.0f) + w[i] * o[k];
        }
}

void obs__receivers_apply_deep(const obs_deep_image *d, obs_deep_result *r)
{
    if (!d->receivers)
        return;
    const size_t n = (size_t)d->width * (size_t)d->height;
    if (r->ao_front.data)
        apply(d->receivers, n, r->ao_front.data);
    if (r->ao_blend.data)
        apply(d->receivers, n, r->ao_blend.data);
}
