/* The one allocator of images and results: sizes overflow-checked before
 * anything is allocated. */
#include <stdlib.h>
#include <string.h>

#include "internal.h"

obs_status obs__image_alloc(obs_image *img, int w, int h, int channels, char err[OBS_ERR_LEN])
{
    size_t n;
    if (obs__size_mul3((size_t)w, (size_t)h, (size_t)channels * sizeof(float), &n) != 0)
        return obs__fail(err, OBS_TOO_LARGE, "image %dx%dx%d overflows", w, h, channels);
    img->data = malloc(n);
    if (!img->data)
        return obs__fail(err, OBS_NO_MEMORY, "out of memory for a %dx%d image", w, h);
    img->width = w;
    img->height = h;
    img->channels = channels;
    return OBS_OK;
}

void obs_image_free(obs_image *img)
{
    if (!img)
        return;
    free(img->data);
    memset(img, 0, sizeof *img);
}

obs_status obs__alloc_result(obs_result *out, int w, int h, unsigned outputs, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    obs_status s = OBS_OK;
    if (outputs & OBS_OUTPUT_AO)
        s = obs__image_alloc(&out->ao, w, h, 1, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_COMPOSITE))
        s = obs__image_alloc(&out->composite, w, h, 4, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_SAMPLE_COUNT))
        s = obs__image_alloc(&out->sample_count, w, h, 1, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_CULL_MASK))
        s = obs__image_alloc(&out->cull_mask, w, h, 1, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_LUMINANCE))
        s = obs__image_alloc(&out->luminance, w, h, 1, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_BLEED))
        s = obs__image_alloc(&out->bleed, w, h, 3, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_BENT))
        s = obs__image_alloc(&out->bent, w, h, 3, err);
    if (s != OBS_OK)
        obs_result_free(out);
    return s;
}

void obs_result_free(obs_result *r)
{
    if (!r)
        return;
    obs_image_free(&r->ao);
    obs_image_free(&r->composite);
    obs_image_free(&r->sample_count);
    obs_image_free(&r->cull_mask);
    obs_image_free(&r->luminance);
    obs_image_free(&r->bleed);
    obs_image_free(&r->multibounce);
    obs_image_free(&r->bent);
    obs_image_free(&r->ao_screen);
    obs_image_free(&r->ao_baked);
}
