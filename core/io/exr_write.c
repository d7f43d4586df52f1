/* EXR output through OpenEXR's C API: one scanline part, ZIP (or the
 * compression asked for), half or float, each layer's channels under the
 * names the caller gives; chunks compressed by a few threads. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/exr_internal.h"
#include "io/out_file.h"
#include "io/provenance.h"
#include "internal.h"
#include "pool.h"

/* Names longer than this need the long-name flag in the file version. */
#define SHORT_NAME_MAX 31
#define NAME_MAX_LEN 255

/* ---- compression (the names: exr_msg.c) -------------------------------- */

static exr_compression_t exr_compression_of(obs_exr_compression c)
{
    switch (c) {
    case OBS_EXR_NONE: return EXR_COMPRESSION_NONE;
    case OBS_EXR_RLE: return EXR_COMPRESSION_RLE;
    case OBS_EXR_ZIPS: return EXR_COMPRESSION_ZIPS;
    case OBS_EXR_PIZ: return EXR_COMPRESSION_PIZ;
    case OBS_EXR_DWAA: return EXR_COMPRESSION_DWAA;
    default: return EXR_COMPRESSION_ZIP;
    }
}

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

/* The camera's attributes, as core/camera/exr.c gives them (none without
 * a world_to_camera). */
static exr_result_t write_camera(exr_context_t ctx, int part, const obs_camera *cam)
{
    obs__camera_attr a[OBS__CAMERA_ATTRS];
    int n = obs__camera_exr_attrs(cam, a);
    exr_result_t rv = EXR_ERR_SUCCESS;
    for (int i = 0; i < n && rv == EXR_ERR_SUCCESS; i++) {
        exr_attr_m44f_t m;
        memcpy(m.m, a[i].m, sizeof m.m);
        rv = exr_attr_set_m44f(ctx, part, a[i].name, &m);
    }
    return rv;
}

/* Points the encoder's channels (sorted by name by the library) at the
 * part's channel of the same name, rows from ci->start_y. */
static void bind_channels(exr_encode_pipeline_t *enc, const obs__wpart *p, const exr_chunk_info_t *ci)
{
    for (int c = 0; c < enc->channel_count; c++) {
        exr_coding_channel_info_t *ch = &enc->channels[c];
        for (int k = 0; k < p->nch; k++) {
            const obs__wchan *w = &p->ch[k];
            if (strcmp(w->name, ch->channel_name) != 0)
                continue;
            ch->encode_from_ptr = w->base + (size_t)((int64_t)ci->start_y - p->dw.min.y) * (size_t)w->line_stride;
            ch->user_pixel_stride = w->pixel_stride;
            ch->user_line_stride = w->line_stride;
            ch->user_data_type = w->user_type;
            ch->user_bytes_per_element = (int16_t)w->user_bytes;
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

static int has_attr(exr_const_context_t ctx, int part, const char *name)
{
    const exr_attribute_t *a = NULL;
    int has = exr_get_attribute_by_name(ctx, part, name, &a) == EXR_ERR_SUCCESS && a;
    obs__exr_msg_reset(); /* a missing attribute is not an error */
    return has;
}

/* ---- pixels: chunks compressed by a few threads ---------------------------
 *
 * OpenEXR's C API writes a scanline part's chunks in order, but packing
 * and compressing a chunk (exr_encoding_run up to its write step) touches
 * only that chunk's pipeline.  So each thread runs its own pipeline over
 * chunks handed out in order (pool.h), with the write step replaced by a
 * copy of the compressed bytes into the chunk's slot; then this thread
 * writes the slots in order with exr_write_scanline_chunk.  The bytes are
 * those one thread writes, whatever the thread count.  On failure the
 * lowest failing chunk's error (and the library's message, which is per
 * thread) is kept. */

typedef struct enc_slot {
    void *data;
    uint64_t size;
} enc_slot;

typedef struct enc_job {
    exr_context_t ctx;
    int part;
    const obs__wpart *p;
    const exr_chunk_info_t *ci;
    enc_slot *slot;
    obs__exr_chunk_fail fail; /* under the pool's lock */
} enc_job;

typedef struct enc_local {
    exr_encode_pipeline_t enc;
    int started;
    obs__exr_chunk_fail fail;
} enc_local;

/* The write step of a thread's pipeline: keep the chunk's bytes. */
static exr_result_t stash_chunk(exr_encode_pipeline_t *enc)
{
    enc_slot *s = enc->encoding_user_data;
    if (!(s->data = malloc(enc->compressed_bytes ? (size_t)enc->compressed_bytes : 1)))
        return EXR_ERR_OUT_OF_MEMORY;
    memcpy(s->data, enc->compressed_buffer, (size_t)enc->compressed_bytes);
    s->size = enc->compressed_bytes;
    return EXR_ERR_SUCCESS;
}

static void enc_begin(void *ctx, void *local)
{
    (void)ctx;
    enc_local *l = local;
    l->enc = (exr_encode_pipeline_t)EXR_ENCODE_PIPELINE_INITIALIZER;
    l->fail.code = EXR_ERR_SUCCESS;
    obs__exr_msg_reset();
}

static int enc_one(void *ctx, void *local, size_t i, size_t i1)
{
    (void)i1; /* ranges of one chunk */
    enc_job *j = ctx;
    enc_local *l = local;
    const exr_chunk_info_t *ci = &j->ci[i];
    exr_result_t rv = l->started ? exr_encoding_update(j->ctx, j->part, ci, &l->enc)
                                 : exr_encoding_initialize(j->ctx, j->part, ci, &l->enc);
    l->started |= rv == EXR_ERR_SUCCESS;
    if (rv == EXR_ERR_SUCCESS) {
        bind_channels(&l->enc, j->p, ci);
        rv = exr_encoding_choose_default_routines(j->ctx, j->part, &l->enc);
    }
    if (rv == EXR_ERR_SUCCESS) {
        l->enc.encoding_user_data = &j->slot[i];
        l->enc.yield_until_ready_fn = NULL; /* the order is this file's: written after */
        l->enc.write_fn = stash_chunk;
        rv = exr_encoding_run(j->ctx, j->part, &l->enc);
    }
    if (rv == EXR_ERR_SUCCESS)
        return 0;
    l->fail.chunk = (int64_t)i;
    l->fail.code = rv;
    snprintf(l->fail.msg, sizeof l->fail.msg, "%s", obs__exr_msg());
    return 1;
}

/* Under the pool's lock. */
static void enc_end(void *ctx, void *local)
{
    enc_job *j = ctx;
    enc_local *l = local;
    obs__exr_chunk_fail_keep(&j->fail, &l->fail);
    if (l->started)
        exr_encoding_destroy(j->ctx, &l->enc);
}

/* Part `part`'s pixels: the chunks [first, first + chunks) (the rows of
 * p's channels from the data window's first), in order. */
static exr_result_t write_chunks(exr_context_t ctx, int part, const obs__wpart *p, int threads,
                                 int64_t first, int64_t chunks, int32_t lines)
{
    exr_result_t rv = EXR_ERR_SUCCESS;
    exr_chunk_info_t *ci = calloc((size_t)chunks, sizeof *ci);
    enc_job j = {.ctx = ctx, .part = part, .p = p, .ci = ci, .fail = {.chunk = INT64_MAX}};
    j.slot = calloc((size_t)chunks, sizeof *j.slot);
    if (!ci || !j.slot)
        rv = EXR_ERR_OUT_OF_MEMORY;
    for (int64_t c = 0; c < chunks && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_write_scanline_chunk_info(ctx, part, (int)(p->dw.min.y + (first + c) * lines), &ci[c]);
    if (rv == EXR_ERR_SUCCESS) {
        obs__pool_for f = {.end = (size_t)chunks, .chunk = 1,
                           .threads = obs__exr_chunk_threads(threads, chunks),
                           .range = enc_one, .ctx = &j, .local_size = sizeof(enc_local),
                           .begin = enc_begin, .end_thread = enc_end};
        if (obs__pool_run(&f, NULL) < 0)
            rv = EXR_ERR_OUT_OF_MEMORY;
        else if ((rv = (exr_result_t)j.fail.code) != EXR_ERR_SUCCESS && j.fail.msg[0])
            obs__exr_error_handler(ctx, rv, j.fail.msg); /* the worker's message, on this thread */
    }
    for (int64_t c = 0; c < chunks && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_write_scanline_chunk(ctx, part, j.ci[c].start_y, j.slot[c].data, j.slot[c].size);
    for (int64_t c = 0; j.slot && c < chunks; c++)
        free(j.slot[c].data);
    free(j.slot);
    free(ci);
    return rv;
}

/* Part `part`'s pixels, every chunk, in order. */
static exr_result_t write_pixels(exr_context_t ctx, int part, const obs__wpart *p, int threads)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    if (lines < 1)
        return EXR_ERR_INVALID_ARGUMENT;
    return write_chunks(ctx, part, p, threads, 0, ((int64_t)p->dw.max.y - p->dw.min.y + lines) / lines,
                        lines);
}

/* `skip` and the input part's obscura/... attributes, NULL-ended in
 * out[max]: the keys of an earlier run are left out of the part that
 * gets this run's, so no key of one run stands beside another's. */
static const char *const *prov_skip(exr_const_context_t src, int src_part, const char *const *skip,
                                    const char **out, int max)
{
    int n = 0;
    int32_t count = 0;
    for (; skip && *skip && n < max - 1; skip++)
        out[n++] = *skip;
    if (exr_get_attribute_count(src, src_part, &count) == EXR_ERR_SUCCESS)
        for (int32_t i = 0; i < count && n < max - 1; i++) {
            const exr_attribute_t *a = NULL;
            if (exr_get_attribute_by_index(src, src_part, EXR_ATTR_LIST_FILE_ORDER, i, &a) == EXR_ERR_SUCCESS &&
                a && a->name && !strncmp(a->name, "obscura/", 8))
                out[n++] = a->name;
        }
    out[n] = NULL;
    return out;
}

/* The obscura/... strings. */
static exr_result_t write_prov(exr_context_t ctx, int part, const obs__prov *prov)
{
    exr_result_t rv = EXR_ERR_SUCCESS;
    for (int i = 0; i < prov->count && rv == EXR_ERR_SUCCESS; i++)
        rv = exr_attr_set_string(ctx, part, prov->key[i], prov->value[i]);
    return rv;
}

/* Writes the parts' headers and pixels into ctx.  With `src`, each part
 * carries the attributes of its src_part; the camera goes on the part of
 * `cam_part` unless the input has one there, the provenance on it
 * always. */
static exr_result_t write_parts(exr_context_t ctx, const obs__wpart *parts, int np, exr_const_context_t src,
                                const char *const *skip, const obs_camera *cam, const obs__prov *prov,
                                int cam_part, int threads, int pixels, const char **what, const char **attr)
{
    static const exr_attr_v2f_t centre = {{{0.0f, 0.0f}}};
    int longnames = 0;
    exr_result_t rv = EXR_ERR_SUCCESS;

    *what = "writing the header";
    for (int i = 0; i < np; i++) {
        for (int k = 0; k < parts[i].nch; k++)
            longnames |= strlen(parts[i].ch[k].name) > SHORT_NAME_MAX;
        longnames |= src && parts[i].src_part >= 0 && obs__exr_attrs_long_names(src, parts[i].src_part);
    }
    if (longnames && (rv = exr_set_longname_support(ctx, 1)) != EXR_ERR_SUCCESS)
        return rv;
    for (int i = 0; i < np; i++) {
        const obs__wpart *p = &parts[i];
        int part = 0;
        if ((rv = exr_add_part(ctx, p->name, EXR_STORAGE_SCANLINE, &part)) != EXR_ERR_SUCCESS ||
            (rv = exr_initialize_required_attr(ctx, part, &p->disp, &p->dw, 1.0f, &centre, 1.0f,
                                               EXR_LINEORDER_INCREASING_Y, p->compression)) != EXR_ERR_SUCCESS)
            return rv;
        for (int k = 0; k < p->nch; k++)
            if ((rv = exr_add_channel(ctx, part, p->ch[k].name, p->ch[k].type, p->ch[k].plinear, 1, 1)) !=
                EXR_ERR_SUCCESS)
                return rv;
        const char *skip_prov[32];
        if (src && p->src_part >= 0 &&
            (rv = obs__exr_copy_attrs(ctx, part, src, p->src_part,
                                      i == cam_part ? prov_skip(src, p->src_part, skip, skip_prov, 32) : skip,
                                      attr)) != EXR_ERR_SUCCESS)
            return rv;
        if (i == cam_part && obs__camera_exr_attrs(cam, NULL) &&
            !(src && p->src_part >= 0 && has_attr(src, p->src_part, OBS__CAMERA_ATTR_WTC)) &&
            (rv = write_camera(ctx, part, cam)) != EXR_ERR_SUCCESS)
            return rv;
        if (i == cam_part && (rv = write_prov(ctx, part, prov)) != EXR_ERR_SUCCESS)
            return rv;
    }
    if ((rv = exr_write_header(ctx)) != EXR_ERR_SUCCESS)
        return rv;

    *what = "writing pixels";
    for (int i = 0; pixels && i < np && rv == EXR_ERR_SUCCESS; i++)
        rv = write_pixels(ctx, i, &parts[i], threads);
    return rv;
}

/* The one part of a plain output: the layers' channels, as `type`. */
static obs_status layers_part(const obs_exr_layer *layers, int count, exr_pixel_type_t type, obs__wpart *p,
                              char err[OBS_ERR_LEN])
{
    int n = 0;
    for (int l = 0; l < count; l++)
        n += layers[l].image->channels;
    if (!(p->ch = calloc((size_t)n, sizeof *p->ch)))
        return obs__fail(err, OBS_NO_MEMORY, "channel list");
    for (int l = 0; l < count; l++) {
        const obs_image *img = layers[l].image;
        for (int k = 0; k < img->channels; k++)
            p->ch[p->nch++] = (obs__wchan){layers[l].names[k], type, EXR_PERCEPTUALLY_LOGARITHMIC,
                                           (const uint8_t *)(img->data + k), img->channels * (int32_t)sizeof(float),
                                           img->width * img->channels * (int32_t)sizeof(float), EXR_PIXEL_FLOAT,
                                           sizeof(float)};
    }
    return OBS_OK;
}

/* The windows of a plain output: the source part's, or those the options
 * give. */
static obs_status plain_windows(const obs_exr_options *o, exr_const_context_t src, int w, int h, obs__wpart *p,
                                char err[OBS_ERR_LEN])
{
    if (src) {
        exr_result_t rv;
        if ((rv = exr_get_data_window(src, o->src->part, &p->dw)) != EXR_ERR_SUCCESS ||
            (rv = exr_get_display_window(src, o->src->part, &p->disp)) != EXR_ERR_SUCCESS)
            return obs__exr_fail(err, rv, "the input's windows");
        int64_t iw = (int64_t)p->dw.max.x - p->dw.min.x + 1, ih = (int64_t)p->dw.max.y - p->dw.min.y + 1;
        if (iw != w || ih != h)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "the images are %dx%d but the input part %d's data window is %lldx%lld",
                             w, h, o->src->part, (long long)iw, (long long)ih);
        return OBS_OK;
    }
    int dw = o->display_width > 0 ? o->display_width : w, dh = o->display_height > 0 ? o->display_height : h;
    int64_t x1 = (int64_t)o->display_x + w - 1, y1 = (int64_t)o->display_y + h - 1;
    if (x1 > INT32_MAX || y1 > INT32_MAX || o->display_height < 0 || o->display_width < 0)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "a data window at (%d, %d) of %dx%d does not fit",
                         o->display_x, o->display_y, w, h);
    p->disp.min.x = 0;
    p->disp.min.y = 0;
    p->disp.max.x = dw - 1;
    p->disp.max.y = dh - 1;
    p->dw.min.x = o->display_x;
    p->dw.min.y = o->display_y;
    p->dw.max.x = (int32_t)x1;
    p->dw.max.y = (int32_t)y1;
    return OBS_OK;
}

/* The path, the pixel type, the layers and the compression of a write
 * (the compression unless appending, which keeps the input's). */
static obs_status check_write(const char *path, const obs_exr_options *o, const obs_exr_layer *layers,
                              int layer_count, int *longnames, char err[OBS_ERR_LEN])
{
    char sub[OBS_ERR_LEN] = "";
    obs_status st;
    if (!path || !*path)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no EXR path given");
    if (o->pixel != OBS_EXR_HALF && o->pixel != OBS_EXR_FLOAT)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: unknown pixel type %d", path, (int)o->pixel);
    if ((st = check_layers(layers, layer_count, longnames, err)) != OBS_OK)
        return st;
    if (!o->append && (st = obs_exr_compression_check(o->compression, sub)) != OBS_OK)
        return obs__fail(err, st, "%s: %s", path, sub);
    return OBS_OK;
}

/* The status of the library's rv while `what` (the input's attribute
 * attr, when not NULL), its message into sub. */
static obs_status write_status(exr_result_t rv, const char *what, const char *attr, char sub[OBS_ERR_LEN])
{
    if (rv == EXR_ERR_SUCCESS)
        return OBS_OK;
    obs_status st = obs__exr_status(rv);
    /* Here a bad argument or attribute is ours, not the file's. */
    if (st == OBS_BAD_FILE)
        st = rv == EXR_ERR_INVALID_ARGUMENT || rv == EXR_ERR_NAME_TOO_LONG ? OBS_INVALID_ARGUMENT : OBS_IO;
    const char *msg = obs__exr_msg()[0] ? obs__exr_msg() : exr_get_default_error_message(rv);
    if (attr)
        obs__fail(sub, st, "%s: the input's attribute '%.100s': %s", what, attr, msg);
    else
        obs__fail(sub, st, "%s: %s", what, msg);
    return st;
}

/* Writes to `path`, or into `mem` when it is non-NULL (`path` then only
 * names the output in messages). */
static obs_status write_exr(const char *path, obs__membuf *mem, const obs_exr_layer *layers,
                            int layer_count, const obs_exr_options *o, char err[OBS_ERR_LEN])
{
    static const char *const plain_skip[] = {"multiView", NULL};
    static const obs_exr_options zero = {0};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t ctx = NULL, src = NULL;
    obs__wpart one = {0}, *parts = &one;
    void *bufs = NULL;
    int np = 1, longnames = 0;
    int64_t src_size = -1;
    const char *what = "reading the input's header", *attr = NULL;
    char sub[OBS_ERR_LEN] = "";
    exr_result_t rv = EXR_ERR_SUCCESS;
    obs_status st;
    obs__out_file out = {0};
    obs__prov prov;

    if (!o)
        o = &zero;
    if ((st = check_write(path, o, layers, layer_count, &longnames, err)) != OBS_OK)
        return st;
    if (o->append && !o->src)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: appending needs the input file", path);
    exr_pixel_type_t type = o->pixel == OBS_EXR_FLOAT ? EXR_PIXEL_FLOAT : EXR_PIXEL_HALF;
    const int w = layers[0].image->width, h = layers[0].image->height;

    /* the input in memory: the read context points at it until the end */
    obs__exr_mem m = {o->src ? o->src->buf : NULL, o->src ? o->src->len : 0};
    if (o->src) {
        if (!o->src->path && (!o->src->buf || !o->src->len)) {
            st = obs__fail(sub, OBS_INVALID_ARGUMENT, "the input is neither a file nor bytes");
            goto fail;
        }
        if ((st = obs__exr_open(o->src->path, o->src->path ? NULL : &m, &src, &src_size, sub)) != OBS_OK)
            goto fail;
        int count = 0;
        if (exr_get_count(src, &count) != EXR_ERR_SUCCESS || o->src->part < 0 || o->src->part >= count) {
            st = obs__fail(sub, OBS_INVALID_ARGUMENT, "the input has no part %d", o->src->part);
            goto fail;
        }
    }
    if (o->append) {
        if ((st = obs__exr_append_parts(src, src_size, o->src->part, layers, layer_count, type, &parts, &np,
                                        &bufs, sub)) != OBS_OK) {
            parts = &one;
            np = 1;
            goto fail;
        }
    } else {
        one.src_part = src ? o->src->part : -1;
        one.compression = exr_compression_of(o->compression);
        if ((st = layers_part(layers, layer_count, type, &one, sub)) != OBS_OK ||
            (st = plain_windows(o, src, w, h, &one, sub)) != OBS_OK)
            goto fail;
    }

    init.error_handler_fn = obs__exr_error_handler;
    obs__exr_msg_reset();
    /* A temporary sibling renamed at the end (out_file.h): a failed or
     * killed write leaves no half-written EXR for the next step of a farm. */
    if (mem) {
        init.user_data = mem;
        init.write_fn = mem_write;
    }
    what = "creating the file";
    if ((rv = exr_start_write(&ctx, mem ? path : obs__out_begin(&out, path), EXR_WRITE_FILE_DIRECTLY,
                              &init)) == EXR_ERR_SUCCESS) {
        int cam_part = 0;
        for (int i = 0; o->append && i < np; i++)
            if (parts[i].src_part == o->src->part)
                cam_part = i;
        obs__prov_build(o->prov, &prov);
        rv = write_parts(ctx, parts, np, src, o->append ? NULL : plain_skip, o->cam, &prov, cam_part,
                         o->threads, 1, &what, &attr);
        if (rv == EXR_ERR_SUCCESS) {
            what = "finishing the file";
            rv = exr_finish(&ctx);
        }
    }
    st = write_status(rv, what, attr, sub);
fail:
    if (ctx)
        exr_finish(&ctx);
    if (out.path)
        st = obs__out_end(&out, st, sub);
    if (src)
        exr_finish(&src);
    if (parts == &one)
        free(one.ch);
    else
        obs__exr_append_free(parts, np, bufs);
    if (st != OBS_OK)
        return obs__fail(err, st, "%s: %s", path, sub);
    return OBS_OK;
}

obs_status obs_exr_write(const char *path, const obs_exr_layer *layers, int layer_count,
                         obs_exr_pixel pixel, const obs_camera *cam, char err[OBS_ERR_LEN])
{
    obs_exr_options o = {.pixel = pixel, .cam = cam};
    return write_exr(path, NULL, layers, layer_count, &o, err);
}

obs_status obs_exr_write_ex(const char *path, const obs_exr_layer *layers, int layer_count,
                            const obs_exr_options *opt, char err[OBS_ERR_LEN])
{
    return write_exr(path, NULL, layers, layer_count, opt, err);
}

obs_status obs_exr_write_ex_mem(const obs_exr_layer *layers, int layer_count, const obs_exr_options *opt,
                                obs_bytes *out, char err[OBS_ERR_LEN])
{
    obs__membuf mem = {0};
    if (!out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_exr_write_mem: no output");
    *out = (obs_bytes){0};
    obs_status st = write_exr("(memory)", &mem, layers, layer_count, opt, err);
    if (st == OBS_OK)
        obs__membuf_take(&mem, out);
    free(mem.data);
    return st;
}

obs_status obs_exr_write_mem(const obs_exr_layer *layers, int layer_count, obs_exr_pixel pixel,
                             const obs_camera *cam, obs_bytes *out, char err[OBS_ERR_LEN])
{
    obs_exr_options o = {.pixel = pixel, .cam = cam};
    return obs_exr_write_ex_mem(layers, layer_count, &o, out, err);
}


/* ---- by rows: a frame never whole in memory --------------------------------
 *
 * The header goes out at the open; rows come in order, are kept until
 * BATCH_CHUNKS chunks are complete, and those are compressed (by a few
 * threads, write_chunks) and written: the writer holds a batch of rows,
 * never the image. */
#define BATCH_CHUNKS 8

struct obs_exr_rows {
    exr_context_t ctx;
    obs__out_file out;
    obs__wpart part;
    const uint8_t **base; /* each channel's place in buf */
    float *buf;           /* a batch of rows of every layer, layer after layer */
    int nl, lch[OBS_RESULT_LAYERS + 4];
    int width, height, lines, batch, threads;
    int next;             /* the rows received */
    int first;            /* the first row in buf */
    char path[4096];
};

/* Compresses and writes the rows in buf ([first, next)). */
static obs_status rows_flush(obs_exr_rows *w, char sub[OBS_ERR_LEN])
{
    if (w->next <= w->first)
        return OBS_OK;
    for (int k = 0; k < w->part.nch; k++) /* the channels from the data window's first row */
        w->part.ch[k].base = w->base[k] - (size_t)w->first * (size_t)w->part.ch[k].line_stride;
    int64_t c0 = w->first / w->lines, c1 = ((int64_t)w->next + w->lines - 1) / w->lines;
    exr_result_t rv = write_chunks(w->ctx, 0, &w->part, w->threads, c0, c1 - c0, w->lines);
    w->first = w->next;
    return write_status(rv, "writing pixels", NULL, sub);
}

static obs_status rows_free(obs_exr_rows *w, obs_status st, char sub[OBS_ERR_LEN]);

obs_status obs_exr_rows_open(const char *path, const obs_exr_layer *layers, int layer_count, int height,
                             const obs_exr_options *opt, obs_exr_rows **out, char err[OBS_ERR_LEN])
{
    static const char *const plain_skip[] = {"multiView", NULL};
    static const obs_exr_options zero = {0};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t src = NULL;
    int64_t src_size = -1;
    int longnames = 0;
    const char *what = "reading the input's header", *attr = NULL;
    char sub[OBS_ERR_LEN] = "";
    obs_status st;
    const obs_exr_options *o = opt ? opt : &zero;
    obs__prov prov;

    *out = NULL;
    if ((st = check_write(path, o, layers, layer_count, &longnames, err)) != OBS_OK)
        return st;
    if (layer_count > OBS_RESULT_LAYERS + 4 || o->append || (o->src && !o->src->path) || height <= 0)
        return obs__fail(err, OBS_UNSUPPORTED, "%s: written by rows: a plain output of a file's rows only", path);
    obs_exr_rows *w = calloc(1, sizeof *w);
    if (!w)
        return obs__fail(err, OBS_NO_MEMORY, "%s: a writer", path);
    snprintf(w->path, sizeof w->path, "%s", path);
    w->width = layers[0].image->width;
    w->height = height;
    w->threads = o->threads;
    w->nl = layer_count;
    exr_pixel_type_t type = o->pixel == OBS_EXR_FLOAT ? EXR_PIXEL_FLOAT : EXR_PIXEL_HALF;
    /* the batch's images: the layers' channels over the batch's rows */
    int per_px = 0;
    for (int l = 0; l < layer_count; l++)
        per_px += w->lch[l] = layers[l].image->channels;
    w->part.src_part = o->src ? o->src->part : -1;
    w->part.compression = exr_compression_of(o->compression);
    obs_image imgs[OBS_RESULT_LAYERS + 4];
    obs_exr_layer batch[OBS_RESULT_LAYERS + 4];
    if (o->src && (st = obs__exr_open(o->src->path, NULL, &src, &src_size, sub)) != OBS_OK)
        goto fail;
    init.error_handler_fn = obs__exr_error_handler;
    obs__exr_msg_reset();
    what = "creating the file";
    exr_result_t rv = exr_start_write(&w->ctx, obs__out_begin(&w->out, w->path), EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS) {
        obs__prov_build(o->prov, &prov);
        /* the windows first: the chunk size follows the compression */
        for (int l = 0; l < layer_count; l++) {
            imgs[l] = (obs_image){w->width, height, layers[l].image->channels, layers[l].image->data};
            batch[l] = (obs_exr_layer){&imgs[l], layers[l].names};
        }
        if ((st = layers_part(batch, layer_count, type, &w->part, sub)) != OBS_OK ||
            (st = plain_windows(o, src, w->width, height, &w->part, sub)) != OBS_OK)
            goto fail;
        rv = write_parts(w->ctx, &w->part, 1, src, plain_skip, o->cam, &prov, 0, o->threads, 0, &what, &attr);
    }
    if (rv == EXR_ERR_SUCCESS && (rv = exr_get_scanlines_per_chunk(w->ctx, 0, &w->lines)) == EXR_ERR_SUCCESS &&
        w->lines < 1)
        rv = EXR_ERR_INVALID_ARGUMENT;
    if ((st = write_status(rv, what, attr, sub)) != OBS_OK)
        goto fail;
    w->batch = w->lines * BATCH_CHUNKS;
    size_t n = (size_t)w->width * (size_t)w->batch * (size_t)per_px;
    if (!(w->buf = malloc(n * sizeof(float))) || !(w->base = calloc((size_t)w->part.nch, sizeof *w->base))) {
        st = obs__fail(sub, OBS_NO_MEMORY, "%d rows of %d pixels", w->batch, w->width);
        goto fail;
    }
    /* each channel at its place in the batch: layer l's rows after the
     * layers before it */
    float *at = w->buf;
    for (int l = 0, k = 0; l < layer_count; l++) {
        for (int c = 0; c < w->lch[l]; c++, k++)
            w->base[k] = (const uint8_t *)(at + c);
        at += (size_t)w->width * (size_t)w->batch * (size_t)w->lch[l];
    }
    if (src)
        exr_finish(&src);
    *out = w;
    return OBS_OK;
fail:
    if (src)
        exr_finish(&src);
    char ignored[OBS_ERR_LEN];
    rows_free(w, st, ignored);
    return obs__fail(err, st, "%s: %s", path, sub);
}

obs_status obs_exr_rows_write(obs_exr_rows *w, const obs_exr_layer *layers, int layer_count,
                              char err[OBS_ERR_LEN])
{
    char sub[OBS_ERR_LEN] = "";
    if (layer_count != w->nl)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: %d layers, the file has %d", w->path, layer_count, w->nl);
    const int rows = layers[0].image->height;
    for (int l = 0; l < layer_count; l++)
        if (layers[l].image->width != w->width || layers[l].image->height != rows ||
            layers[l].image->channels != w->lch[l])
            return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: layer %d is not the file's", w->path, l);
    if (rows <= 0 || rows > w->height - w->next)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: %d rows more than the %d of the image", w->path, rows,
                         w->height);
    for (int y = 0; y < rows;) {
        /* into the batch: the rows it has room for */
        int take = w->first + w->batch - w->next < rows - y ? w->first + w->batch - w->next : rows - y;
        float *at = w->buf;
        for (int l = 0; l < layer_count; l++) {
            const size_t row = (size_t)w->width * (size_t)w->lch[l];
            memcpy(at + (size_t)(w->next - w->first) * row, layers[l].image->data + (size_t)y * row,
                   (size_t)take * row * sizeof(float));
            at += (size_t)w->batch * row;
        }
        w->next += take;
        y += take;
        obs_status st = OBS_OK;
        if (w->next - w->first == w->batch || w->next == w->height)
            st = rows_flush(w, sub);
        if (st != OBS_OK)
            return obs__fail(err, st, "%s: %s", w->path, sub);
    }
    return OBS_OK;
}

/* Finishes (st OBS_OK) or removes the file, frees w; the message of a
 * failure here into sub. */
static obs_status rows_free(obs_exr_rows *w, obs_status st, char sub[OBS_ERR_LEN])
{
    if (w->ctx) {
        exr_result_t rv = exr_finish(&w->ctx);
        if (st == OBS_OK)
            st = write_status(rv, "finishing the file", NULL, sub);
    }
    if (w->out.path)
        st = obs__out_end(&w->out, st, sub);
    free(w->part.ch);
    free(w->base);
    free(w->buf);
    free(w);
    return st;
}

obs_status obs_exr_rows_close(obs_exr_rows *w, obs_status st, char err[OBS_ERR_LEN])
{
    char sub[OBS_ERR_LEN] = "", path[4096];
    if (!w)
        return st;
    snprintf(path, sizeof path, "%s", w->path);
    if (st == OBS_OK && w->next != w->height)
        st = obs__fail(sub, OBS_INVALID_ARGUMENT, "%d of its %d rows were written", w->next, w->height);
    st = rows_free(w, st, sub);
    if (st != OBS_OK && sub[0])
        obs__fail(err, st, "%s: %s", path, sub);
    return st;
}
