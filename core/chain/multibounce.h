/* Multi-bounce AO (multibounce.c, Jimenez et al. 2016 eq 10).  Not
 * installed. */
#ifndef OBSCURA_CHAIN_MULTIBOUNCE_H
#define OBSCURA_CHAIN_MULTIBOUNCE_H

#include "internal.h"

/* The fit of the AO for an albedo in [0, 1] per channel (GLSL:
 * obs_multibounce in composite.frag.glsl). */
void obs__multibounce(float ao, const float albedo[3], float out[3]);

/* Whether a frame makes the multi-bounce image: a colour plane, and
 * OBS_OUTPUT_MULTIBOUNCE asked or parameter multibounce on with the AO or
 * the composite. */
int obs__multibounce_wanted(const obs_gbuffer *gb, const obs_params *p, unsigned outputs);

/* The image of the AO `ao` and the colour plane of gb into out (RGB, the
 * size of ao). */
void obs__multibounce_image(const obs_gbuffer *gb, const obs_image *ao, obs_image *out);

/* After the readback, by every device's driver: with `made`, the result's
 * multi-bounce image from its AO and gb's colour plane; the AO is freed
 * when `asked` (the caller's outputs) did not include it. */
obs_status obs__multibounce_finish(const obs_gbuffer *gb, int made, unsigned asked, obs_result *out,
                                   char err[OBS_ERR_LEN]);

#endif
