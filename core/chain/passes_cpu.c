/* The CPU kernel of each pass (passes_cpu.h): the twins of the GL passes
 * (passes_gl.c), pixel by pixel.  The order and whether a pass runs are
 * the table's (passes.c); the driver is run_cpu.c. */
#include <string.h>
#include <time.h>

#include "chain/bands_cpu.h"
#include "chain/multibounce.h"
#include "chain/passes_cpu.h"
#include "chain/prep_cpu.h"
#include "chain/vao_cpu.h"

/* GLSL: composite.frag.glsl.  Section 5: "applied to resulting image
 * simply by multiplication by occlusion values": colour x AO, and x the
 * bleed term (section 4.7) when bleeding is on; grey AO when there is no
 * colour; with multibounce, the AO of each channel through the fit of
 * the colour as albedo (obs__multibounce). */
static void composite_pixel(const float *color, float ao, const float *bleed, int multibounce,
                            float out[4])
{
    if (!color) {
        out[0] = out[1] = out[2] = ao;
        out[3] = 1.0f;
        return;
    }
    float occ[3] = {ao, ao, ao};
    if (multibounce) {
        float rho[3];
        for (int k = 0; k < 3; k++)
            rho[k] = color[k] > 0.0f ? (color[k] < 1.0f ? color[k] : 1.0f) : 0.0f;
        obs__multibounce(ao, rho, occ);
    }
    for (int k = 0; k < 3; k++)
        out[k] = bleed ? color[k] * occ[k] * bleed[k] : color[k] * occ[k];
    out[3] = color[3];
}

#ifndef AO_TILE_W
#define AO_TILE_W 64
#define AO_TILE_H 16
#endif

/* OBS_OUTPUT_BENT of the VAO estimator at pixel i, which took n samples
 * (0: culled greedily or background): the scalar estimator's sum of the
 * same samples (obs__vao_estimate_bent), the view normal where nothing is
 * open or nothing was sampled on the geometry, 0 on the background.  The
 * AO stays the SIMD form's. */
static void vao_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y, int n,
                     int culled, float bent[3])
{
    size_t i = (size_t)y * f->width + x;
    bent[0] = bent[1] = bent[2] = 0.0f;
    if (!(pos[4 * i + 3] > 0.0f))
        return;
    if (n > 0) {
        const float *xy = f->adaptive || culled ? f->sample_table + 2 * (n - 2) : f->sample_xy;
        obs__vao_estimate_bent(f, pos, nrm, x, y, pos + 4 * i, nrm + 3 * i, n, xy, bent);
    }
    if (bent[0] == 0.0f && bent[1] == 0.0f && bent[2] == 0.0f)
        for (int k = 0; k < 3; k++)
            bent[k] = nrm[3 * i + k];
}

/* The clock against the run's deadline, and the caller's cancel, read
 * between the passes and the AO pass's tiles: past it (or cancelled), the
 * rest of the pass's tiles are skipped (the run then fails with
 * OBS_DEADLINE or OBS_CANCELLED, run_cpu.c). */
void obs__cpu_arm(obs__cpu_run *c, const obs_cpu_options *opt)
{
    c->deadline_ms = 0.0;
    c->cancel = NULL;
    c->cancel_user = NULL;
    if (opt && opt->deadline > 0.0) {
        struct timespec ts;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        c->deadline_ms = (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6 + opt->deadline * 1e3;
    }
    if (opt) {
        c->cancel = opt->cancel;
        c->cancel_user = opt->cancel_user;
    }
    atomic_init(&c->stopped, 0);
}

int obs__cpu_stop_now(obs__cpu_run *c)
{
    if (atomic_load_explicit(&c->stopped, memory_order_relaxed))
        return 1;
    int why = 0, none = 0;
    if (c->cancel && c->cancel(c->cancel_user)) {
        why = OBS__CPU_CANCELLED;
    } else if (c->deadline_ms > 0.0) {
        struct timespec ts;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        if ((double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6 > c->deadline_ms)
            why = OBS__CPU_PAST_DEADLINE;
    }
    if (!why)
        return 0;
    atomic_compare_exchange_strong(&c->stopped, &none, why); /* the first reason stays */
    return 1;
}

obs_status obs__cpu_stopped_fail(obs__cpu_run *c, const char *where, obs_pass p, char err[OBS_ERR_LEN])
{
    if (atomic_load(&c->stopped) == OBS__CPU_CANCELLED)
        return obs__fail(err, OBS_CANCELLED, "the frame was cancelled (%s the %s pass)", where,
                         obs_pass_name(p));
    return obs__fail(err, OBS_DEADLINE, "the frame ran past its deadline (%s the %s pass)", where,
                     obs_pass_name(p));
}

/* ao_tile() for the VAO estimator without colour bleeding and without
 * object masks: the tile's pixels sorted by the sample set they take,
 * each set's pixels run in SIMD lanes (obs__vao_estimate_pixels), the
 * same results as pixel by pixel. */
static void ao_tile_lanes(obs__cpu_run *c, const unsigned char *cand, int x0, int x1, int y0,
                          int y1)
{
    const obs__frame *f = c->pl->af;
    const float *pos = c->apos, *nrm = c->anrm;
    float *ao = c->aao, *bleed = c->ableed;
    const int bleed_read = c->pl->f.bleed_step || c->out->bleed.data;
    float *count = c->out->sample_count.data, *mask = c->out->cull_mask.data;
    int px[AO_TILE_W * AO_TILE_H], ns[AO_TILE_W * AO_TILE_H], set[AO_TILE_W * AO_TILE_H];
    unsigned char culled[AO_TILE_W * AO_TILE_H];
    int m = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            const size_t i = (size_t)y * f->width + x;
            const size_t t = (size_t)(y - y0) * (size_t)(x1 - x0) + (size_t)(x - x0);
            ao[i] = 1.0f;
            if (bleed_read)
                bleed[3 * i] = bleed[3 * i + 1] = bleed[3 * i + 2] = 1.0f;
            if (count)
                count[i] = 0.0f;
            if (mask)
                mask[i] = 0.0f;
            if (!(pos[4 * i + 3] > 0.0f))
                continue;
            /* Section 4.2: a culling candidate gets AO 1 (greedy) or at
             * most the 4-sample set (careful). */
            const int cull = f->culling && cand[t];
            if (mask)
                mask[i] = (float)cull;
            if (cull && f->culling != 2)
                continue;
            culled[m] = (unsigned char)cull;
            px[m++] = (int)i;
        }
    if (m > 0) /* section 4.1: the set of each pixel's count */
        obs__vao_counts(f, pos, nrm, px, m, ns);
    for (int j = 0; j < m; j++) {
        ns[j] = culled[j] && ns[j] > OBS_CULL_CAREFUL ? OBS_CULL_CAREFUL : ns[j];
        if (count)
            count[px[j]] = (float)ns[j];
    }
    /* each set (the count's set of the table, or the samples parameter's
     * own set), its pixels in lanes */
    int done = 0;
    unsigned char taken[AO_TILE_W * AO_TILE_H];
    memset(taken, 0, sizeof taken);
    while (done < m) {
        int first = 0;
        while (taken[first])
            first++;
        const int n = ns[first];
        const int table = f->adaptive || culled[first];
        int k = 0;
        for (int j = first; j < m; j++)
            if (!taken[j] && ns[j] == n && (f->adaptive || culled[j]) == table) {
                taken[j] = 1;
                set[k++] = px[j];
            }
        done += k;
        const float *xy = table ? f->sample_table + 2 * (n - 2) : f->sample_xy;
        obs__vao_estimate_pixels(f, pos, nrm, c->dnz, set, k, n, xy, ao);
    }
    if (c->out->bent.data)
        for (int j = 0, y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) {
                const size_t i = (size_t)y * f->width + x;
                int n = 0, cull = 0;
                if (j < m && px[j] == (int)i) {
                    n = ns[j];
                    cull = culled[j];
                    j++;
                }
                vao_bent(f, pos, nrm, x, y, n, cull, c->out->bent.data + 3 * i);
            }
}

/* ao_tile() for a comparison method without the bent normal: the
 * tile's pixels with geometry in SIMD lanes (obs__method_pixels); 0 (the
 * tile untouched) where the method has no lanes. */
static int ao_tile_method(obs__cpu_run *c, int x0, int x1, int y0, int y1)
{
    const obs__frame *f = c->pl->af;
    const float *pos = c->apos, *nrm = c->anrm;
    float *count = c->out->sample_count.data;
    int px[AO_TILE_W * AO_TILE_H], m = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            const size_t i = (size_t)y * f->width + x;
            if (pos[4 * i + 3] > 0.0f)
                px[m++] = (int)i;
        }
    if (m > 0 && !obs__method_pixels(f, pos, nrm, px, m, c->aao, count))
        return 0;
    const int bleed_read = c->pl->f.bleed_step || c->out->bleed.data;
    float *mask = c->out->cull_mask.data;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            const size_t i = (size_t)y * f->width + x;
            if (bleed_read)
                c->ableed[3 * i] = c->ableed[3 * i + 1] = c->ableed[3 * i + 2] = 1.0f;
            if (mask)
                mask[i] = 0.0f;
            if (pos[4 * i + 3] > 0.0f)
                continue;
            c->aao[i] = 1.0f; /* background */
            if (count)
                count[i] = 0.0f;
        }
    return 1;
}

/* The AO pass over a tile of the frame at the AO's size (GLSL:
 * vao.frag.glsl, or the method's method.frag.glsl): ao, the bleed term
 * (when the composite or the output reads it) and the debug planes (NULL:
 * not wanted) of every pixel. */
static void ao_tile(void *ctx, int x0, int x1, int y0, int y1)
{
    obs__cpu_run *c = ctx;
    if (obs__cpu_stop_now(c))
        return;
    const obs__frame *f = c->pl->af;
    const obs__method *method = c->pl->method;
    const float *pos = c->apos, *nrm = c->anrm, *col = c->col, *est = c->est;
    float *ao = c->aao, *bleed = c->ableed, unread[3];
    const int bleed_read = c->pl->f.bleed_step || c->out->bleed.data;
    float *count = c->out->sample_count.data, *mask = c->out->cull_mask.data;
    unsigned char cand[AO_TILE_W * AO_TILE_H]; /* section 4.2's test, the tile at once */
    if (f->culling && !method->pixel)
        obs__cull_candidates(f, est, x0, x1, y0, y1, cand);
    if (!method->pixel && !f->mask_on && !(col && f->bleed_step > 0)) {
        ao_tile_lanes(c, cand, x0, x1, y0, y1);
        return;
    }
    if (method->pixel && !c->out->bent.data && ao_tile_method(c, x0, x1, y0, y1))
        return;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            size_t i = (size_t)y * f->width + x;
            int n = 0, culled = 0;
            float *b = bleed_read ? bleed + 3 * i : unread;
            ao[i] = 1.0f;
            b[0] = b[1] = b[2] = 1.0f;
            if (method->pixel) {
                /* a comparison method in place of the VAO estimator */
                ao[i] = c->out->bent.data
                            ? obs__method_pixel_bent(f, pos, nrm, x, y, &n, c->out->bent.data + 3 * i)
                            : obs__method_pixel(f, pos, nrm, x, y, &n);
            } else if (pos[4 * i + 3] > 0.0f) {
                /* Section 4.2: a culling candidate gets AO 1 (greedy) or
                 * at most the 4-sample set (careful). */
                culled = f->culling && cand[(size_t)(y - y0) * (size_t)(x1 - x0) + (size_t)(x - x0)];
                if (!culled) {
                    /* section 4.1: the set of the pixel's count */
                    n = obs__vao_count(f, pos + 4 * i, nrm + 3 * i);
                    const float *xy = f->adaptive ? f->sample_table + 2 * (n - 2) : f->sample_xy;
                    ao[i] = obs__vao_estimate_dnz(f, pos, nrm, c->dnz, col, x, y, pos + 4 * i,
                                                  nrm + 3 * i, n, xy, b);
                } else if (f->culling == 2) {
                    n = obs__vao_count(f, pos + 4 * i, nrm + 3 * i);
                    n = n < OBS_CULL_CAREFUL ? n : OBS_CULL_CAREFUL;
                    const float *xy = f->sample_table + 2 * (n - 2);
                    ao[i] = obs__vao_estimate_dnz(f, pos, nrm, c->dnz, col, x, y, pos + 4 * i,
                                                  nrm + 3 * i, n, xy, b);
                }
            }
            if (c->out->bent.data && !method->pixel)
                vao_bent(f, pos, nrm, x, y, n, culled, c->out->bent.data + 3 * i);
            if (count)
                count[i] = (float)n;
            if (mask)
                mask[i] = (float)culled;
        }
}

/* The prep pass at full size, in two sweeps: view positions, then
 * normals (from the input, or derived from the positions of the
 * neighbours, which the first sweep has finished). */
static void position_rows(void *ctx, int y0, int y1)
{
    const obs__cpu_run *c = ctx;
    const obs__frame *f = &c->pl->f;
    const obs_gbuffer *gb = c->pl->gb;
    for (int y = y0; y < y1; y++) {
        const float *depth = obs__plane_px(&gb->depth, f->width, 0, y); /* the row, once */
        obs__prep_position_row(f, depth, (size_t)gb->depth.channels, y,
                               c->pos + 4 * (size_t)y * f->width);
    }
}

static void normal_rows(void *ctx, int y0, int y1)
{
    const obs__cpu_run *c = ctx;
    const obs__frame *f = &c->pl->f;
    const obs_gbuffer *gb = c->pl->gb;
    for (int y = y0; y < y1; y++) {
        const float *row = gb->normal.data ? obs__plane_px(&gb->normal, f->width, 0, y) : NULL;
        const size_t r0 = (size_t)y * f->width;
        if (row && !f->reconstruct_normals) { /* the input's normals: the row in lanes */
            obs__prep_normal_row(f, c->pos + 4 * r0, row, (size_t)gb->normal.channels,
                                 c->nrm + 3 * r0, f->half ? NULL : c->dnz + 2 * r0);
            continue;
        }
        for (int x = 0; x < f->width; x++) {
            const float *in = row ? row + (size_t)gb->normal.channels * (size_t)x : NULL;
            const size_t i = (size_t)y * f->width + x;
            obs__prep_normal(f, c->pos, in, x, y, c->nrm + 3 * i);
            if (!f->half) {
                c->dnz[2 * i] = c->pos[4 * i + 3];
                c->dnz[2 * i + 1] = c->nrm[3 * i + 2];
            }
        }
    }
}

static void prep_full(obs__cpu_run *c)
{
    obs__cpu_rows(c->pl->f.height, 0, position_rows, c);
    obs__cpu_rows(c->pl->f.height, 0, normal_rows, c);
}

/* The colour, packed, for sections 4.3 and 4.7. */
static void color_rows(void *ctx, int y0, int y1)
{
    const obs__cpu_run *c = ctx;
    const obs__frame *f = &c->pl->f;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < f->width; x++)
            memcpy(c->col + 4 * ((size_t)y * f->width + x),
                   obs__plane_px(&c->pl->gb->color, f->width, x, y), 4 * sizeof(float));
}

static obs_status cpu_upload(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    (void)err;
    if (c->col)
        obs__cpu_rows(c->pl->f.height, 0, color_rows, c);
    return OBS_OK;
}

static obs_status cpu_prep(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    (void)err;
    prep_full(c);
    return OBS_OK;
}

/* ao_resolution half: each half pixel takes the planes of the pixel
 * obs__half_source picks (GLSL: prep.frag.glsl with OBS_HALF, straight
 * from the raw planes). */
static void half_rows(void *ctx, int y0, int y1)
{
    const obs__cpu_run *c = ctx;
    const obs__frame *f = &c->pl->f, *hf = c->pl->af;
    for (int hy = y0; hy < y1; hy++)
        for (int hx = 0; hx < hf->width; hx++) {
            long k = obs__half_source(f, c->pos, hx, hy);
            if (k < 0) /* all background: the block's first pixel, background too */
                k = (long)(2 * hy) * f->width + 2 * hx;
            const size_t h = (size_t)hy * hf->width + hx;
            memcpy(c->hpos + 4 * h, c->pos + 4 * k, 4 * sizeof(float));
            memcpy(c->hnrm + 3 * h, c->nrm + 3 * k, 3 * sizeof(float));
            obs__half_masks(f, k, h, c->hmask_w, c->hmask_id); /* object masks */
            c->dnz[2 * h] = c->hpos[4 * h + 3];
            c->dnz[2 * h + 1] = c->hnrm[3 * h + 2];
        }
}

/* ao_resolution half: the full prep (the upsample reads it), then the
 * half planes. */
static obs_status cpu_downsample(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    (void)err;
    prep_full(c);
    obs__cpu_rows(c->pl->af->height, 0, half_rows, c);
    return OBS_OK;
}

/* Section 4.2: the culling pre-pass. */
static obs_status cpu_cull(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    (void)err;
    obs__cull_prepass_dnz(c->pl->af, c->apos, c->anrm, c->dnz, c->est);
    return OBS_OK;
}

static obs_status cpu_ao(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    (void)err;
    const obs__frame *af = c->pl->af;
    obs__cpu_tiles(af->width, af->height, AO_TILE_W, AO_TILE_H, ao_tile, c);
    return OBS_OK;
}

/* ao_definition rays (not linear: applied to the filtered estimate). */
static void rays_rows(void *ctx, int y0, int y1)
{
    const obs__cpu_run *c = ctx;
    const size_t w = (size_t)c->pl->f.width;
    obs__rays_rows(c->ao + (size_t)y0 * w, (size_t)(y1 - y0) * w);
}

static void rays(obs__cpu_run *c)
{
    obs__cpu_rows(c->pl->f.height, 0, rays_rows, c);
}

/* Section 4.6, the low-pass filter; the conversion of ao_definition rays
 * in its vertical pass's sweep, as GL's vertical pass does. */
static obs_status cpu_blur(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    (void)err;
    float *res = obs__blur_dnz(c->pl->af, c->apos, c->dnz, c->aao, c->atmp, c->pl->rays_in_blur);
    if (res != c->aao) { /* the result in the other plane: the two swap roles */
        c->atmp = c->aao;
        c->aao = res;
        if (c->pl->f.half) {
            c->htmp = c->atmp;
            c->hao = res;
        } else {
            c->tmp = c->atmp;
            c->ao = res;
        }
    }
    return OBS_OK;
}

/* ao_resolution half: the joint bilateral upsample (GLSL: up.frag.glsl). */
static void up_rows(void *ctx, int y0, int y1)
{
    const obs__cpu_run *c = ctx;
    const obs__frame *f = &c->pl->f, *hf = c->pl->af;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < f->width; x++)
            c->ao[(size_t)y * f->width + x] =
                obs__half_upsample(f, hf, c->pos, c->nrm, c->hpos, c->hnrm, c->hao, x, y);
}

/* ao_resolution half: the upsample, then ao_definition rays' conversion. */
static obs_status cpu_up(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    (void)err;
    obs__cpu_rows(c->pl->f.height, 0, up_rows, c);
    if (c->pl->f.rays)
        rays(c);
    return OBS_OK;
}

/* Luminance sensitivity (section 4.3, eq 3) of the rows. */
static void luminance_rows(void *ctx, int y0, int y1)
{
    const obs__cpu_run *c = ctx;
    const obs__frame *f = &c->pl->f;
    const size_t w = (size_t)f->width;
    float *lum = c->out->luminance.data;
    for (size_t i = (size_t)y0 * w; i < (size_t)y1 * w; i++) {
        if (lum)
            lum[i] = obs__luminance_factor(f, c->col + 4 * i);
        c->ao[i] = obs__luminance_ao(f, c->ao[i], c->col + 4 * i);
    }
}

/* The finishing pass (luminance.frag.glsl), after the blur: the
 * conversion of ao_definition rays when no blur did it, then luminance
 * sensitivity (section 4.3, eq 3): the blur is depth-aware only and would
 * carry a bright pixel's suppression onto its dark neighbours (and their
 * occlusion onto it). */
static obs_status cpu_finish(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    (void)err;
    if (c->pl->rays_in_finish)
        rays(c);
    if (c->pl->f.luminance)
        obs__cpu_rows(c->pl->f.height, 0, luminance_rows, c);
    return OBS_OK;
}

static void composite_rows(void *ctx, int y0, int y1)
{
    const obs__cpu_run *c = ctx;
    const obs__frame *f = &c->pl->f;
    const obs_gbuffer *gb = c->pl->gb;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < f->width; x++) {
            size_t i = (size_t)y * f->width + x;
            composite_pixel(gb->color.data ? obs__plane_px(&gb->color, f->width, x, y) : NULL,
                            c->ao[i], f->bleed_step ? c->bleed + 3 * i : NULL,
                            c->pl->multibounce, c->out->composite.data + 4 * i);
        }
}

static obs_status cpu_composite(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    (void)err;
    obs__cpu_rows(c->pl->f.height, 0, composite_rows, c);
    return OBS_OK;
}

static void fill_ones(float *dst, size_t n)
{
    for (size_t i = 0; i < n; i++)
        dst[i] = 1.0f;
}

/* The planes into the result; the parts that are off give their neutral
 * value (bleeding is refused at half resolution). */
static obs_status cpu_readback(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    obs_result *out = c->out;
    (void)err;
    if (out->ao.data)
        memcpy(out->ao.data, c->ao, c->npx * sizeof(float));
    if (out->bleed.data && c->pl->f.half)
        fill_ones(out->bleed.data, c->npx * 3);
    else if (out->bleed.data)
        memcpy(out->bleed.data, c->bleed, c->npx * 3 * sizeof(float));
    if (out->luminance.data && !c->pl->f.luminance)
        fill_ones(out->luminance.data, c->npx);
    return OBS_OK;
}

const obs__cpu_kernel obs__cpu_kernels[OBS_PASS_COUNT] = {
    [OBS_PASS_UPLOAD] = cpu_upload,       [OBS_PASS_PREP] = cpu_prep,
    [OBS_PASS_DOWNSAMPLE] = cpu_downsample, [OBS_PASS_CULL] = cpu_cull,
    [OBS_PASS_AO] = cpu_ao,               [OBS_PASS_BLUR] = cpu_blur,
    [OBS_PASS_UPSAMPLE] = cpu_up,         [OBS_PASS_FINISH] = cpu_finish,
    [OBS_PASS_COMPOSITE] = cpu_composite, [OBS_PASS_READBACK] = cpu_readback,
};
