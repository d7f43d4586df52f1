/* obs_run_cpu: the chain on the CPU, pass by pass in the order of
 * run_gl.c (prep, culling pre-pass, AO, blur, finish, composite), each
 * pass through its twin.  Links without the GL libraries. */
#include <stdlib.h>
#include <string.h>

#include "chain/frame.h"
#include "methods/methods.h"

/* GLSL: composite.frag.glsl.  Section 5: "applied to resulting image
 * simply by multiplication by occlusion values": colour x AO, and x the
 * bleed term (section 4.7) when bleeding is on; grey AO when there is no
 * colour. */
static void composite_pixel(const float *color, float ao, const float *bleed, float out[4])
{
    if (!color) {
        out[0] = out[1] = out[2] = ao;
        out[3] = 1.0f;
        return;
    }
    for (int k = 0; k < 3; k++)
        out[k] = bleed ? color[k] * ao * bleed[k] : color[k] * ao;
    out[3] = color[3];
}

/* The AO pass over frame f's planes (GLSL: vao.frag.glsl, or the method's
 * method.frag.glsl): ao, the bleed term and the debug planes (NULL: not
 * wanted) of every pixel. */
static void ao_pass(const obs__frame *f, const obs__method *method, const float *pos,
                    const float *nrm, const float *col, const float *est, float *ao, float *bleed,
                    float *count, float *mask)
{
    for (int y = 0; y < f->height; y++)
        for (int x = 0; x < f->width; x++) {
            size_t i = (size_t)y * f->width + x;
            int n = 0, culled = 0;
            float *b = bleed + 3 * i;
            ao[i] = 1.0f;
            b[0] = b[1] = b[2] = 1.0f;
            if (method->pixel) {
                /* a comparison method in place of the VAO estimator */
                ao[i] = obs__method_pixel(f, pos, nrm, x, y, &n);
            } else if (pos[4 * i + 3] > 0.0f) {
                /* Section 4.2: a culling candidate gets AO 1 (greedy) or
                 * at most the 4-sample set (careful). */
                culled = f->culling && obs__cull_candidate(f, est, x, y);
                if (!culled) {
                    /* section 4.1: the set of the pixel's count */
                    n = obs__vao_count(f, pos + 4 * i, nrm + 3 * i);
                    const float *xy = f->adaptive ? f->sample_table + 2 * (n - 2) : f->sample_xy;
                    ao[i] = obs__vao_estimate_bleed(f, pos, nrm, col, x, y, pos + 4 * i,
                                                    nrm + 3 * i, n, xy, b);
                } else if (f->culling == 2) {
                    n = obs__vao_count(f, pos + 4 * i, nrm + 3 * i);
                    n = n < OBS_CULL_CAREFUL ? n : OBS_CULL_CAREFUL;
                    const float *xy = f->sample_table + 2 * (n - 2);
                    ao[i] = obs__vao_estimate_bleed(f, pos, nrm, col, x, y, pos + 4 * i,
                                                    nrm + 3 * i, n, xy, b);
                }
            }
            if (count)
                count[i] = (float)n;
            if (mask)
                mask[i] = (float)culled;
        }
}

/* ao_resolution half (GLSL: the down, AO, blur and up passes of run_gl.c):
 * the prep planes downsampled, the culling pre-pass, AO and blur on the
 * half frame, the AO upsampled into `ao`. */
static obs_status run_half(const obs__frame *f, const obs__method *method, const float *pos,
                           const float *nrm, const float *col, float *est, float *ao,
                           char err[OBS_ERR_LEN])
{
    obs__frame hf;
    obs__frame_half(f, &hf);
    const size_t hn = (size_t)hf.width * (size_t)hf.height;
    float *hpos = malloc(hn * 4 * sizeof(float)), *hnrm = malloc(hn * 3 * sizeof(float));
    float *hao = malloc(hn * sizeof(float)), *htmp = malloc(hn * sizeof(float));
    float *hbleed = malloc(hn * 3 * sizeof(float));
    obs_status s = OBS_OK;
    if (!hpos || !hnrm || !hao || !htmp || !hbleed) {
        s = obs__fail(err, OBS_NO_MEMORY, "out of memory for a %dx%d half frame", hf.width,
                      hf.height);
        goto done;
    }
    for (int hy = 0; hy < hf.height; hy++)
        for (int hx = 0; hx < hf.width; hx++) {
            long k = obs__half_source(f, pos, hx, hy);
            if (k < 0) /* all background: the block's first pixel, background too */
                k = (long)(2 * hy) * f->width + 2 * hx;
            const size_t h = (size_t)hy * hf.width + hx;
            memcpy(hpos + 4 * h, pos + 4 * k, 4 * sizeof(float));
            memcpy(hnrm + 3 * h, nrm + 3 * k, 3 * sizeof(float));
        }
    if (hf.culling)
        obs__cull_prepass(&hf, hpos, hnrm, est);
    ao_pass(&hf, method, hpos, hnrm, col, est, hao, hbleed, NULL, NULL);
    obs__blur(&hf, hpos, hao, htmp);
    for (int y = 0; y < f->height; y++)
        for (int x = 0; x < f->width; x++)
            ao[(size_t)y * f->width + x] = obs__half_upsample(f, &hf, pos, nrm, hpos, hnrm, hao, x, y);
done:
    free(hpos);
    free(hnrm);
    free(hao);
    free(htmp);
    free(hbleed);
    return s;
}

obs_status obs_run_cpu(const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                       obs_result *out, char err[OBS_ERR_LEN])
{
    obs_params p;
    obs__frame f;
    float *pos = NULL, *nrm = NULL, *ao = NULL, *tmp = NULL, *est = NULL, *col = NULL,
          *bleed = NULL;
    obs_status s;

    memset(out, 0, sizeof *out);
    if (!(outputs & OBS__OUTPUTS_ALL))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no output requested");
    obs__params_for_gbuffer(params, gb, &p);
    s = obs__frame_setup(NULL, gb, &p, &f, err);
    if (s == OBS_OK)
        s = obs__frame_check_outputs(&f, outputs, err);
    if (s != OBS_OK)
        return s;
    const obs__method *method = obs__method_get(f.method);

    size_t npx = (size_t)f.width * (size_t)f.height;
    pos = malloc(npx * 4 * sizeof(float));
    nrm = malloc(npx * 3 * sizeof(float));
    ao = malloc(npx * sizeof(float));
    tmp = malloc(npx * sizeof(float));
    est = malloc((size_t)f.cull_w * (size_t)f.cull_h * sizeof(float));
    /* colour, packed RGBA, for sections 4.3 and 4.7; the bleed term */
    if (f.luminance || f.bleed_step)
        col = malloc(npx * 4 * sizeof(float));
    bleed = malloc(npx * 3 * sizeof(float));
    if (!pos || !nrm || !ao || !tmp || !est || !bleed || ((f.luminance || f.bleed_step) && !col)) {
        s = obs__fail(err, OBS_NO_MEMORY, "out of memory for a %dx%d frame", f.width, f.height);
        goto fail;
    }
    s = obs__alloc_result(out, f.width, f.height, outputs, err);
    if (s != OBS_OK)
        goto fail;

    /* prep pass */
    for (int y = 0; y < f.height; y++)
        for (int x = 0; x < f.width; x++)
            obs__prep_position(&f, *obs__plane_px(&gb->depth, f.width, x, y), x, y,
                               pos + 4 * ((size_t)y * f.width + x));
    for (int y = 0; y < f.height; y++)
        for (int x = 0; x < f.width; x++) {
            const float *in = gb->normal.data ? obs__plane_px(&gb->normal, f.width, x, y) : NULL;
            obs__prep_normal(&f, pos, in, x, y, nrm + 3 * ((size_t)y * f.width + x));
        }
    if (col)
        for (int y = 0; y < f.height; y++)
            for (int x = 0; x < f.width; x++)
                memcpy(col + 4 * ((size_t)y * f.width + x), obs__plane_px(&gb->color, f.width, x, y),
                       4 * sizeof(float));
    /* culling pre-pass (section 4.2) */
    if (f.culling)
        obs__cull_prepass(&f, pos, nrm, est);
    if (f.half) {
        s = run_half(&f, method, pos, nrm, col, est, ao, err);
        if (s != OBS_OK)
            goto fail;
        for (size_t i = 0; i < 3 * npx; i++)
            bleed[i] = 1.0f; /* bleeding is refused at half resolution */
    } else {
        ao_pass(&f, method, pos, nrm, col, est, ao, bleed, out->sample_count.data,
                out->cull_mask.data);
        /* low-pass filter (section 4.6) */
        obs__blur(&f, pos, ao, tmp);
    }
    /* the finishing pass (luminance.frag.glsl), after the blur: the
     * conversion of ao_definition rays (not linear: applied to the
     * filtered estimate), then luminance sensitivity (section 4.3, eq 3):
     * the blur is depth-aware only and would carry a bright pixel's
     * suppression onto its dark neighbours (and their occlusion onto it) */
    if (f.rays)
        for (size_t i = 0; i < npx; i++)
            ao[i] = obs__rays_from_volume(ao[i]);
    for (size_t i = 0; out->luminance.data && i < npx; i++)
        out->luminance.data[i] = f.luminance ? obs__luminance_factor(&f, col + 4 * i) : 1.0f;
    if (f.luminance)
        for (size_t i = 0; i < npx; i++)
            ao[i] = obs__luminance_ao(&f, ao[i], col + 4 * i);
    if (out->ao.data)
        memcpy(out->ao.data, ao, npx * sizeof(float));
    if (out->bleed.data)
        memcpy(out->bleed.data, bleed, npx * 3 * sizeof(float));
    if (out->composite.data)
        for (int y = 0; y < f.height; y++)
            for (int x = 0; x < f.width; x++) {
                size_t i = (size_t)y * f.width + x;
                composite_pixel(gb->color.data ? obs__plane_px(&gb->color, f.width, x, y) : NULL,
                                ao[i], f.bleed_step ? bleed + 3 * i : NULL,
                                out->composite.data + 4 * i);
            }
    s = OBS_OK;

fail:
    free(pos);
    free(nrm);
    free(ao);
    free(tmp);
    free(est);
    free(col);
    free(bleed);
    if (s != OBS_OK)
        obs_result_free(out);
    return s;
}
