/* Multi-bounce AO (parameter multibounce, OBS_OUTPUT_MULTIBOUNCE): the
 * AO through the albedo-driven cubic fit of Jimenez, Wu, Pesce and
 * Jarabo, "Practical Realtime Strategies for Accurate Indirect
 * Occlusion" (Activision tech report ATVI-TR-16-01, 2016; SIGGRAPH 2016
 * course), section 5, eq 10: the ambient light that bounces off the
 * occluders back into the occluded part of the hemisphere, fitted
 * against ray-traced multi-bounce references as
 *
 *     A' = f(A, rho) = max(A, ((a A + b) A + c) A),
 *     a = 2.0404 rho - 0.3324, b = -4.7951 rho + 0.6417,
 *     c = 2.7552 rho + 0.6903,
 *
 * rho the albedo, per colour channel (the occluders are taken to have the
 * shaded point's albedo).  The max keeps A' >= A where the fit dips below
 * the single-bounce AO (rho near 0).  XeGTAO (vaShared.hlsl's
 * GTAOMultiBounce) and HDRP apply it the same way.  GLSL twin:
 * obs_multibounce in composite.frag.glsl. */
#include <string.h>

#include "chain/multibounce.h"

void obs__multibounce(float ao, const float albedo[3], float out[3])
{
    for (int k = 0; k < 3; k++) {
        float rho = albedo[k];
        float a = 2.0404f * rho - 0.3324f;
        float b = -4.7951f * rho + 0.6417f;
        float c = 2.7552f * rho + 0.6903f;
        float m = ((a * ao + b) * ao + c) * ao;
        out[k] = m > ao ? m : ao;
    }
}

/* The clamp of the albedo the fit was made for: [0, 1] (a colour plane may
 * hold HDR values or negatives from a filter's ringing). */
static float unit(float v)
{
    return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
}

void obs__multibounce_image(const obs_gbuffer *gb, const obs_image *ao, obs_image *out)
{
    const int w = ao->width, h = ao->height;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            const float *c = obs__plane_px(&gb->color, w, x, y);
            float rho[3] = {unit(c[0]), unit(c[1]), unit(c[2])};
            obs__multibounce(ao->data[i], rho, out->data + 3 * i);
        }
}

int obs__multibounce_wanted(const obs_gbuffer *gb, const obs_params *p, unsigned outputs)
{
    if (!gb->color.data)
        return 0;
    return (outputs & OBS_OUTPUT_MULTIBOUNCE) ||
           (p->multibounce == OBS_ON && (outputs & (OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE)));
}

obs_status obs__multibounce_finish(const obs_gbuffer *gb, int made, unsigned asked, obs_result *out,
                                   char err[OBS_ERR_LEN])
{
    if (!made)
        return OBS_OK;
    obs_status s = obs__image_alloc(&out->multibounce, out->ao.width, out->ao.height, 3, err);
    if (s != OBS_OK)
        return s;
    obs__multibounce_image(gb, &out->ao, &out->multibounce);
    /* the AO was read back for the fit only */
    if (!(asked & OBS_OUTPUT_AO))
        obs_image_free(&out->ao);
    return OBS_OK;
}
