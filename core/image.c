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

/* Every image of a result, its place and channels: those with an output
 * are the ones obs__alloc_result makes when it is asked for (in this
 * order), the others (0) are made by their passes; obs_result_free frees
 * them all. */
static const struct {
    unsigned output;
    size_t at;
    int channels;
} result_images[] = {
    {OBS_OUTPUT_AO, offsetof(obs_result, ao), 1},
    {OBS_OUTPUT_COMPOSITE, offsetof(obs_result, composite), 4},
    {OBS_OUTPUT_SAMPLE_COUNT, offsetof(obs_result, sample_count), 1},
    {OBS_OUTPUT_CULL_MASK, offsetof(obs_result, cull_mask), 1},
    {OBS_OUTPUT_LUMINANCE, offsetof(obs_result, luminance), 1},
    {OBS_OUTPUT_BLEED, offsetof(obs_result, bleed), 3},
    {OBS_OUTPUT_BENT, offsetof(obs_result, bent), 3},
    {0, offsetof(obs_result, multibounce), 3},
    {0, offsetof(obs_result, ao_screen), 1},
    {0, offsetof(obs_result, ao_baked), 1},
};
#define RESULT_IMAGES (sizeof result_images / sizeof result_images[0])

obs_status obs__alloc_result(obs_result *out, int w, int h, unsigned outputs, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    obs_status s = OBS_OK;
    for (size_t i = 0; s == OBS_OK && i < RESULT_IMAGES; i++)
        if (outputs & result_images[i].output)
            s = obs__image_alloc((obs_image *)((char *)out + result_images[i].at), w, h,
                                 result_images[i].channels, err);
    if (s != OBS_OK)
        obs_result_free(out);
    return s;
}

void obs_result_free(obs_result *r)
{
    for (size_t i = 0; r && i < RESULT_IMAGES; i++)
        obs_image_free((obs_image *)((char *)r + result_images[i].at));
}
