/* Frame setup: which camera, which normals, which samples. */
#include <math.h>
#include <string.h>

#include "chain/frame.h"
#include "obscura/io.h"

/* Inverse transpose of the upper 3x3 of m: the matrix that carries normals
 * the way m carries points. */
static int normal_matrix(const float m[16], float out[9])
{
    float a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9],
          i = m[10];
    float det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
    if (!isfinite(det) || fabsf(det) < 1e-12f)
        return -1;
    /* (M^-1)^T = cofactor matrix / det */
    out[0] = (e * i - f * h) / det;
    out[1] = -(d * i - f * g) / det;
    out[2] = (d * h - e * g) / det;
    out[3] = -(b * i - c * h) / det;
    out[4] = (a * i - c * g) / det;
    out[5] = -(a * h - b * g) / det;
    out[6] = (b * f - c * e) / det;
    out[7] = -(a * f - c * d) / det;
    out[8] = (a * e - b * d) / det;
    return 0;
}

obs_status obs__frame_setup_common(obs_ctx *log_ctx, const obs_gbuffer *gb, const obs_params *p,
                                   obs__frame *f, char err[OBS_ERR_LEN])
{
    obs_camera cam;
    obs_status s = obs__gbuffer_validate(gb, err);
    if (s != OBS_OK)
        return s;
    s = obs_params_check(p, err);
    if (s != OBS_OK)
        return s;
    s = obs__camera_resolve(gb, p, &cam, err);
    if (s != OBS_OK)
        return s;

    memset(f, 0, sizeof *f);
    f->width = gb->width;
    f->height = gb->height;
    f->viewport[0] = (float)gb->display_x;
    f->viewport[1] = (float)gb->display_y;
    f->viewport[2] = (float)(gb->display_width > 0 ? gb->display_width : gb->width);
    f->viewport[3] = (float)(gb->display_height > 0 ? gb->display_height : gb->height);
    memcpy(f->proj, cam.projection, sizeof f->proj);
    f->depth_mode = p->depth_mode;
    /* The radius parameter is the ray-traced AO distance D (the reach of
     * Cycles' AO pass); the VAO kernel width R of eq 1 is k * D, so the
     * tangent sphere has radius k * D / 2: k = 2 when the AO is to be the
     * ray tracer's (ao_definition rays, converted after the blur by
     * obs__rays_from_volume), 1 for the paper's volumetric obscurance
     * (frame.h, OBS__RADIUS_K_*; bench/QUALITY.md "How --radius maps to
     * the AO distance").  Everything downstream (eq 2's F, eq 4's falloff,
     * the blur's depth threshold, eq 5) takes this R, the paper's "kernel
     * radius".  The comparison methods take D itself. */
    int vao_method = p->method == OBS_METHOD_VAOPP || p->method == OBS_METHOD_VAO;
    f->rays = vao_method && p->ao_definition == OBS_AO_RAYS;
    float k_r = f->rays ? OBS__RADIUS_K_RAYS : vao_method ? OBS__RADIUS_K_VOLUME : 1.0f;
    f->radius = k_r * p->radius / p->unit_scale;
    f->samples = p->samples;
    f->sample_xy = obs__samples(p->samples);
    f->sample_table = &obs__sample_table[0][0];
    /* Section 4.1: the area ratio against the disk of diameter D0 (a
     * fraction of the height) is D^2 / D0^2 with D^2 = r^2 |det J| vw / vh
     * (see obs__adaptive_count); the constant part is folded here. */
    f->adaptive = p->adaptive == OBS_ON;
    f->adaptive_k = f->viewport[2] / (f->viewport[3] * p->adaptive_diameter * p->adaptive_diameter);
    f->range_check = p->range_check == OBS_ON;
    f->range_u = p->range_u;
    f->range_normal = p->range_distance == OBS_RANGE_DISTANCE_NORMAL;
    /* Section 4.2: the pre-pass texture has one texel per 8 x 8 block. */
    f->culling = p->culling == OBS_CULLING_GREEDY ? 1 : p->culling == OBS_CULLING_CAREFUL ? 2 : 0;
    f->cull_threshold = 1.0f - p->culling_epsilon;
    f->cull_w = (f->width + OBS_CULL_BLOCK - 1) / OBS_CULL_BLOCK;
    f->cull_h = (f->height + OBS_CULL_BLOCK - 1) / OBS_CULL_BLOCK;
    f->blur_radius = p->blur == OBS_ON ? p->blur_radius : 0;
    f->half = p->ao_resolution == OBS_RESOLUTION_HALF;
    /* object masks (core/mask.c): full-size planes, read at the samples */
    f->mask_occl = gb->occluders.data;
    f->mask_id = gb->object_id.data;
    f->mask_on = f->mask_occl || f->mask_id;
    f->mask_plane = 0;
    /* ao_resolution half: the half frame reads half-size planes, each
     * half pixel the masks of the full pixel whose depth it keeps
     * (obs__frame_half, obs__half_source) */
    for (int k = 0; k <= f->blur_radius; k++) /* section 4.6: Gaussian kernel */
        f->blur_w[k] = expf(-(float)(k * k) / (2.0f * p->blur_sigma * p->blur_sigma));
    for (int k = 0; k < 9; k++)
        obs__pixel_rotation(k / 3, k % 3, &f->rot[k][0], &f->rot[k][1]);

    /* Sections 4.3 and 4.7 read the colour plane; without one they are off. */
    f->luminance = p->luminance == OBS_LUMINANCE_LUM ? 1 : p->luminance == OBS_LUMINANCE_VALUE ? 2 : 0;
    f->lum_threshold = p->lum_threshold;
    f->lum_width = p->lum_width;
    f->lum_sigma = p->lum_sigma;
    f->bleed_step = p->bleeding == OBS_BLEEDING_FULL   ? 1
                    : p->bleeding == OBS_BLEEDING_HALF ? 2
                    : p->bleeding == OBS_BLEEDING_QUARTER ? 4
                                                          : 0;
    if (!gb->color.data && f->luminance) {
        f->luminance = 0;
        obs__log(log_ctx, OBS_LOG_INFO, "no colour channel: luminance sensitivity is off");
    }
    if (!gb->color.data && f->bleed_step) {
        f->bleed_step = 0;
        obs__log(log_ctx, OBS_LOG_INFO, "no colour channel: colour bleeding is off");
    }
    if (f->half && f->bleed_step)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "ao_resolution half does not take bleeding: eq 5 gathers the colour "
                         "at each full-resolution pixel's samples (use ao_resolution full)");

    /* The comparison methods (parameter method): each fills its own
     * values, f->ms, after this (obs__frame_setup, methods/methods.c). */
    f->method = p->method;

    static const float identity3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(f->normal_matrix, identity3, sizeof identity3);
    if (!gb->normal.data) {
        f->reconstruct_normals = 1;
        obs__log(log_ctx, OBS_LOG_INFO, "no normal channel: reconstructing normals from depth");
    } else if (p->normal_space == OBS_NORMALS_WORLD) {
        if (!cam.has_world_to_camera) {
            f->reconstruct_normals = 1;
            /* info, not a warning: the input's sanity check says the cause
             * first (obs_gbuffer_sanity), with the flag that fixes it */
            obs__log(log_ctx, OBS_LOG_INFO,
                     "normals are world-space but the camera has no world_to_camera "
                     "(give --camera or --world-to-camera): reconstructing normals from depth");
        } else if (normal_matrix(cam.world_to_camera, f->normal_matrix) != 0) {
            return obs__fail(err, OBS_NO_CAMERA, "world_to_camera is singular");
        }
    }
    return OBS_OK;
}

obs_status obs__frame_check_outputs(const obs__frame *f, unsigned outputs, char err[OBS_ERR_LEN])
{
    if (f->half && (outputs & (OBS_OUTPUT_SAMPLE_COUNT | OBS_OUTPUT_CULL_MASK)))
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "ao_resolution half has no per-pixel sample_count or cull_mask output "
                         "(they are of the half-resolution pixels; use ao_resolution full)");
    return OBS_OK;
}

obs_status obs__gbuffer_validate(const obs_gbuffer *gb, char err[OBS_ERR_LEN])
{
    static const struct {
        const char *name;
        size_t off;
        int channels;
        int required;
    } planes[] = {
        {"depth", offsetof(obs_gbuffer, depth), 1, 1},
        {"normal", offsetof(obs_gbuffer, normal), 3, 0},
        {"color", offsetof(obs_gbuffer, color), 4, 0},
    };
    if (!gb)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no G-buffer");
    obs_status s = obs_check_size(NULL, gb->width, gb->height, err);
    if (s != OBS_OK)
        return s;
    if (gb->display_width < 0 || gb->display_height < 0)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "negative display window size");
    for (size_t i = 0; i < sizeof planes / sizeof planes[0]; i++) {
        const obs_plane *pl = (const obs_plane *)((const char *)gb + planes[i].off);
        if (!pl->data) {
            if (planes[i].required)
                return obs__fail(err, OBS_MISSING_CHANNEL, "G-buffer has no %s plane",
                                 planes[i].name);
            continue;
        }
        if (pl->channels != planes[i].channels)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "%s plane has %d channels, expected %d",
                             planes[i].name, pl->channels, planes[i].channels);
        size_t row = (size_t)gb->width * (size_t)pl->channels * sizeof(float);
        if (pl->row_stride != 0 && (pl->row_stride < row || pl->row_stride % (pl->channels * sizeof(float))))
            return obs__fail(err, OBS_INVALID_ARGUMENT,
                             "%s plane row stride %zu is smaller than a row (%zu bytes) or not a "
                             "whole number of pixels",
                             planes[i].name, pl->row_stride, row);
    }
    return OBS_OK;
}

void obs__frame_block_fill(const obs__frame *f, obs__frame_block *b)
{
    memset(b, 0, sizeof *b);
    memcpy(b->proj, f->proj, sizeof b->proj);
    memcpy(b->viewport, f->viewport, sizeof b->viewport);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            b->normal_matrix[r][c] = f->normal_matrix[3 * r + c];
    b->size[0] = f->width;
    b->size[1] = f->height;
    b->cull_size[0] = f->cull_w;
    b->cull_size[1] = f->cull_h;
    b->radius = f->radius;
    b->range_u = f->range_u;
    b->range_normal = f->range_normal;
    b->count = f->samples;
    b->adaptive_k = f->adaptive_k;
    b->culling = f->culling;
    b->cull_threshold = f->cull_threshold;
    b->bleed_step = f->bleed_step;
    b->luminance = f->luminance;
    b->lum_threshold = f->lum_threshold;
    b->lum_width = f->lum_width;
    b->lum_sigma = f->lum_sigma;
    for (int k = 0; k < 9; k++) {
        b->rot[k][0] = f->rot[k][0];
        b->rot[k][1] = f->rot[k][1];
    }
    for (int k = 0; k < OBS_SAMPLE_TABLE_LEN; k++) {
        b->samples[k][0] = f->sample_table[2 * k];
        b->samples[k][1] = f->sample_table[2 * k + 1];
    }
    for (int k = 0; k <= f->blur_radius && k <= OBS_MAX_BLUR; k++)
        b->blur_w[k][0] = f->blur_w[k];
}
