/* EXR output through OpenEXR's C API: one scanline part, ZIP, half or
 * float, each layer's channels under the names the caller gives. */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "io/exr_internal.h"
#include "internal.h"

/* Names longer than this need the long-name flag in the file version. */
#define SHORT_NAME_MAX 31
#define NAME_MAX_LEN 255

/* Checks layers before the file is created; the message names the layer
 * or channel at fault. */
static obs_status check_layers(const obs_exr_layer *layers, int count, int *longnames,
                               char err[OBS_ERR_LEN])
{
    if (!layers || count < 1)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no layers to write");
    *longnames = 0;
    for (int l = 0; l < count; l++) {
        const obs_image *img = layers[l].image, *first = layers[0].image;
        if (!img || !img->data || img->width <= 0 || img->height <= 0 || img->channels <= 0)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "layer %d: no image", l);
        if (img->width != first->width || img->height != first->height)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "layer %d is %dx%d, layer 0 is %dx%d", l,
                             img->width, img->height, first->width, first->height);
        /* The encoder's row stride is an int32. */
        if ((int64_t)img->width * img->channels * (int64_t)sizeof(float) > INT32_MAX)
            return obs__fail(err, OBS_TOO_LARGE, "layer %d: rows of %dx%d floats are too long", l,
                             img->width, img->channels);
        if (!layers[l].names)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "layer %d: no channel names", l);
        for (int c = 0; c < img->channels; c++) {
            const char *name = layers[l].names[c];
            size_t len = name ? strlen(name) : 0;
            if (len == 0 || len > NAME_MAX_LEN)
                return obs__fail(err, OBS_INVALID_ARGUMENT, "layer %d: channel %d needs a name of 1 to %d characters",
                                 l, c, NAME_MAX_LEN);
            *longnames |= len > SHORT_NAME_MAX;
            for (int l2 = 0; l2 <= l; l2++)
                for (int c2 = 0; c2 < (l2 == l ? c : layers[l2].image->channels); c2++)
                    if (strcmp(layers[l2].names[c2], name) == 0)
                        return obs__fail(err, OBS_INVALID_ARGUMENT, "channel '%s' is given twice", name);
        }
    }
    return OBS_OK;
}

/* Our camera as OpenEXR attributes: the exact inverse of the reader's
 * mapping (see camera_from_exr() in exr_read.c).  With F = diag(1,1,-1,1),
 * W = world_to_camera and P = projection:
 *   worldToCamera = (F W)^T
 *   q = (x_clip + w_clip)/2, (w_clip - y_clip)/2, z_clip, w_clip  (rows of Q)
 *   worldToNDC = (Q W)^T */
void obs__exr_camera_matrices(const obs_camera *cam, float wtc[16], float ndc[16])
{
    static const float F[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1};
    float fw[16], q[16], qw[16];
    const float *p = cam->projection;

    obs__mat4_mul(F, cam->world_to_camera, fw);
    obs__mat4_transpose(fw, wtc);
    for (int j = 0; j < 4; j++) {
        q[0 + j] = 0.5f * (p[0 + j] + p[12 + j]);
        q[4 + j] = 0.5f * (p[12 + j] - p[4 + j]);
        q[8 + j] = p[8 + j];
        q[12 + j] = p[12 + j];
    }
    obs__mat4_mul(q, cam->world_to_camera, qw);
    obs__mat4_transpose(qw, ndc);
}

static exr_result_t write_camera(exr_context_t ctx, int part, const obs_camera *cam)
{
    exr_attr_m44f_t wtc, ndc;
    exr_result_t rv;

    obs__exr_camera_matrices(cam, wtc.m, ndc.m);
    if ((rv = exr_attr_set_m44f(ctx, part, "worldToCamera", &wtc)) != EXR_ERR_SUCCESS ||
        !cam->has_projection)
        return rv;
    return exr_attr_set_m44f(ctx, part, "worldToNDC", &ndc);
}

/* Points the encoder's channels (sorted by name by the library) at the
 * layer channel of the same name, rows [start_y, start_y + height). */
static void bind_channels(exr_encode_pipeline_t *enc, const obs_exr_layer *layers, int count,
                          int start_y)
{
    for (int c = 0; c < enc->channel_count; c++) {
        exr_coding_channel_info_t *ch = &enc->channels[c];
        for (int l = 0; l < count; l++) {
            const obs_image *img = layers[l].image;
            for (int k = 0; k < img->channels; k++) {
                if (strcmp(layers[l].names[k], ch->channel_name) != 0)
                    continue;
                ch->encode_from_ptr = (const uint8_t *)(img->data + (size_t)start_y * (size_t)img->width * (size_t)img->channels + (size_t)k);
                ch->user_pixel_stride = img->channels * (int32_t)sizeof(float);
                ch->user_line_stride = img->width * img->channels * (int32_t)sizeof(float);
                ch->user_data_type = EXR_PIXEL_FLOAT;
                ch->user_bytes_per_element = sizeof(float);
            }
        }
    }
}

/* The in-memory stream: OpenEXR writes at offsets (the chunk table last,
 * back near the start), so the buffer is addressed, not appended. */
static int64_t mem_write(exr_const_context_t ctxt, void *user, const void *buf, uint64_t sz,
                         uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    if (obs__membuf_write(user, offset, buf, (size_t)sz) != 0) {
        if (error_cb)
            error_cb(ctxt, EXR_ERR_OUT_OF_MEMORY, "out of memory for %llu bytes at %llu",
                     (unsigned long long)sz, (unsigned long long)offset);
        return -1;
    }
    return (int64_t)sz;
}

/* Writes to `path`, or into `mem` when it is non-NULL (`path` then only
 * names the output in messages). */
static obs_status write_exr(const char *path, obs__membuf *mem, const obs_exr_layer *layers,
                            int layer_count, obs_exr_pixel pixel, const obs_camera *cam,
                            char err[OBS_ERR_LEN])
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    exr_context_t ctx = NULL;
    exr_chunk_info_t ci;
    exr_pixel_type_t type = pixel == OBS_EXR_FLOAT ? EXR_PIXEL_FLOAT : EXR_PIXEL_HALF;
    int part = 0, longnames = 0, started = 0;
    int32_t lines = 0;
    const char *what = "creating the file";
    exr_result_t rv;
    obs_status st;

    if (!path || !*path)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no EXR path given");
    if (pixel != OBS_EXR_HALF && pixel != OBS_EXR_FLOAT)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: unknown pixel type %d", path, (int)pixel);
    if ((st = check_layers(layers, layer_count, &longnames, err)) != OBS_OK)
        return st;
    const int w = layers[0].image->width, h = layers[0].image->height;

    init.error_handler_fn = obs__exr_error_handler;
    obs__exr_msg_reset();
    /* A temporary file renamed at the end: a failed write leaves no
     * half-written EXR behind for the next step of a render farm. */
    if (mem) {
        init.user_data = mem;
        init.write_fn = mem_write;
    }
    if ((rv = exr_start_write(&ctx, path, mem ? EXR_WRITE_FILE_DIRECTLY : EXR_INTERMEDIATE_TEMP_FILE,
                              &init)) != EXR_ERR_SUCCESS)
        goto fail;
    what = "writing the header";
    if ((rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part)) != EXR_ERR_SUCCESS ||
        (rv = exr_initialize_required_attr_simple(ctx, part, w, h, EXR_COMPRESSION_ZIP)) != EXR_ERR_SUCCESS ||
        (longnames && (rv = exr_set_longname_support(ctx, 1)) != EXR_ERR_SUCCESS))
        goto fail;
    for (int l = 0; l < layer_count; l++)
        for (int k = 0; k < layers[l].image->channels; k++)
            if ((rv = exr_add_channel(ctx, part, layers[l].names[k], type,
                                      EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1)) != EXR_ERR_SUCCESS)
                goto fail;
    if (cam && cam->has_world_to_camera && (rv = write_camera(ctx, part, cam)) != EXR_ERR_SUCCESS)
        goto fail;
    if ((rv = exr_write_header(ctx)) != EXR_ERR_SUCCESS ||
        (rv = exr_get_scanlines_per_chunk(ctx, part, &lines)) != EXR_ERR_SUCCESS)
        goto fail;

    what = "writing pixels";
    for (int y = 0; y < h; y += lines) {
        if ((rv = exr_write_scanline_chunk_info(ctx, part, y, &ci)) != EXR_ERR_SUCCESS)
            goto fail;
        rv = started ? exr_encoding_update(ctx, part, &ci, &enc)
                     : exr_encoding_initialize(ctx, part, &ci, &enc);
        started = 1;
        if (rv != EXR_ERR_SUCCESS)
            goto fail;
        bind_channels(&enc, layers, layer_count, ci.start_y);
        if ((rv = exr_encoding_choose_default_routines(ctx, part, &enc)) != EXR_ERR_SUCCESS ||
            (rv = exr_encoding_run(ctx, part, &enc)) != EXR_ERR_SUCCESS)
            goto fail;
    }
    exr_encoding_destroy(ctx, &enc);
    started = 0;
    what = "finishing the file";
    rv = exr_finish(&ctx);
fail:
    if (started)
        exr_encoding_destroy(ctx, &enc);
    if (ctx)
        exr_finish(&ctx);
    if (rv == EXR_ERR_SUCCESS)
        return OBS_OK;
    st = obs__exr_status(rv);
    /* Here a bad argument or attribute is ours, not the file's. */
    if (st == OBS_BAD_FILE)
        st = rv == EXR_ERR_INVALID_ARGUMENT || rv == EXR_ERR_NAME_TOO_LONG ? OBS_INVALID_ARGUMENT : OBS_IO;
    const char *msg = obs__exr_msg()[0] ? obs__exr_msg() : exr_get_default_error_message(rv);
    return obs__fail(err, st, "%s: %s: %s", path, what, msg);
}

obs_status obs_exr_write(const char *path, const obs_exr_layer *layers, int layer_count,
                         obs_exr_pixel pixel, const obs_camera *cam, char err[OBS_ERR_LEN])
{
    return write_exr(path, NULL, layers, layer_count, pixel, cam, err);
}

obs_status obs_exr_write_mem(const obs_exr_layer *layers, int layer_count, obs_exr_pixel pixel,
                             const obs_camera *cam, obs_bytes *out, char err[OBS_ERR_LEN])
{
    obs__membuf mem = {0};
    if (!out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_exr_write_mem: no output");
    *out = (obs_bytes){0};
    obs_status st = write_exr("(memory)", &mem, layers, layer_count, pixel, cam, err);
    if (st == OBS_OK)
        obs__membuf_take(&mem, out);
    free(mem.data);
    return st;
}

int obs_result_exr_layers(const obs_result *r, obs_exr_layer layers[OBS_RESULT_LAYERS])
{
    static const char *const ao[] = {"AO.Y"};
    static const char *const rgba[] = {"R", "G", "B", "A"};
    static const char *const count[] = {"Samples.Y"};
    static const char *const cull[] = {"Cull.Y"};
    static const char *const bleed[] = {"Bleed.R", "Bleed.G", "Bleed.B"};
    static const char *const lum[] = {"Luminance.Y"};
    int n = 0;
    if (r->ao.data)
        layers[n++] = (obs_exr_layer){&r->ao, ao};
    if (r->composite.data)
        layers[n++] = (obs_exr_layer){&r->composite, rgba};
    if (r->sample_count.data)
        layers[n++] = (obs_exr_layer){&r->sample_count, count};
    if (r->cull_mask.data)
        layers[n++] = (obs_exr_layer){&r->cull_mask, cull};
    if (r->bleed.data)
        layers[n++] = (obs_exr_layer){&r->bleed, bleed};
    if (r->luminance.data)
        layers[n++] = (obs_exr_layer){&r->luminance, lum};
    return n;
}
