/* The chain's pass order (passes.h) and the plan every device's driver
 * walks it with. */
#include <string.h>

#include "chain/multibounce.h"
#include "chain/passes.h"

obs_status obs__plan_init(obs__plan *pl, obs_ctx *log_ctx, const obs_gbuffer *gb,
                          const obs_params *params, unsigned outputs, char err[OBS_ERR_LEN])
{
    obs_params p;
    memset(pl, 0, sizeof *pl);
    if (!(outputs & OBS__OUTPUTS_ALL))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no output requested");
    obs__params_for_gbuffer(params, gb, &p);
    obs_status s = obs__frame_setup(log_ctx, gb, &p, &pl->f, err);
    if (s == OBS_OK)
        s = obs__frame_check_outputs(&pl->f, outputs, err);
    if (s != OBS_OK)
        return s;
    const obs__frame *f = &pl->f;
    pl->gb = gb;
    pl->asked = outputs;
    pl->multibounce = obs__multibounce_wanted(gb, &p, outputs);
    /* the fit reads the AO: read back whenever it is made */
    pl->outputs = pl->multibounce ? outputs | OBS_OUTPUT_AO : outputs & ~OBS_OUTPUT_MULTIBOUNCE;
    pl->method = obs__method_get(f->method);
    /* the bent normal: every method has one (vaopp and vao: the chain's
     * estimator; the others: pixel_bent), of full-resolution frames */
    if ((pl->outputs & OBS_OUTPUT_BENT) && f->half)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "ao_resolution half has no bent normal output (use ao_resolution full)");
    /* ao_resolution half: the culling pre-pass, AO and blur run on the
     * half frame, between the downsample and the upsample; everything
     * else at full size */
    if (f->half)
        obs__frame_half(f, &pl->hf);
    pl->af = f->half ? &pl->hf : f;
    pl->has_color = gb->color.data != NULL &&
                    ((outputs & OBS_OUTPUT_COMPOSITE) || f->luminance || f->bleed_step);
    pl->rays_in_blur = f->rays && f->blur_radius > 0 && !f->half;
    pl->rays_in_finish = f->rays && !pl->rays_in_blur && !f->half;
    return OBS_OK;
}

static int always(const obs__plan *pl)
{
    (void)pl;
    return 1;
}

/* ao_resolution full: the prep pass at full size; half: the downsample
 * (the prep of one pixel of each 2x2 block, straight to half size) */
static int full_size(const obs__plan *pl) { return !pl->f.half; }
static int half_size(const obs__plan *pl) { return pl->f.half; }
/* section 4.2: 8-sample AO at 1/8 resolution */
static int culling(const obs__plan *pl) { return pl->f.culling != 0; }
/* section 4.6: the low-pass filter */
static int blur(const obs__plan *pl) { return pl->f.blur_radius > 0; }
/* after the blur: luminance sensitivity (section 4.3, eq 3), and
 * ao_definition rays' conversion when neither blur nor upsample did it */
static int finish(const obs__plan *pl) { return pl->rays_in_finish || pl->f.luminance; }
static int composite(const obs__plan *pl) { return (pl->outputs & OBS_OUTPUT_COMPOSITE) != 0; }

const obs__pass obs__passes[OBS_PASS_COUNT] = {
    {OBS_PASS_UPLOAD, "upload", always},
    {OBS_PASS_PREP, "prep", full_size},
    {OBS_PASS_DOWNSAMPLE, "downsample", half_size},
    {OBS_PASS_CULL, "cull", culling},
    {OBS_PASS_AO, "ao", always},
    {OBS_PASS_BLUR, "blur", blur},
    {OBS_PASS_UPSAMPLE, "upsample", half_size},
    {OBS_PASS_FINISH, "finish", finish},
    {OBS_PASS_COMPOSITE, "composite", composite},
    {OBS_PASS_READBACK, "readback", always},
};

const char *obs_pass_name(obs_pass p)
{
    return (unsigned)p < OBS_PASS_COUNT ? obs__passes[p].name : "unknown";
}
