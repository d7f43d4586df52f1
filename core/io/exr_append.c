/* --append: the input EXR's flat parts decoded, every channel in its own
 * pixel type, so that the writer (exr_write.c) stores them unchanged
 * beside the AO layer. */
#include <stdlib.h>
#include <string.h>

#include "io/exr_internal.h"
#include "internal.h"

/* Compressions that give back the bytes they were given: the input's is
 * kept when it is one, else ZIP (re-encoding a lossy one would change
 * the pixels a second time). */
static exr_compression_t lossless(exr_compression_t c)
{
    switch (c) {
    case EXR_COMPRESSION_NONE:
    case EXR_COMPRESSION_RLE:
    case EXR_COMPRESSION_ZIPS:
    case EXR_COMPRESSION_ZIP:
    case EXR_COMPRESSION_PIZ: return c;
    default: return EXR_COMPRESSION_ZIP;
    }
}

static int32_t type_bytes(exr_pixel_type_t t)
{
    return t == EXR_PIXEL_HALF ? 2 : 4;
}

/* Decodes every chunk of a flat part (scanlines, or the tiles of level
 * 0) into the part's channel buffers. */
static obs_status decode_native(exr_const_context_t ctx, int part, const obs__wpart *p, char err[OBS_ERR_LEN])
{
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    exr_storage_t storage;
    exr_result_t rv = exr_get_storage(ctx, part, &storage);
    int64_t w = (int64_t)p->dw.max.x - p->dw.min.x + 1, h = (int64_t)p->dw.max.y - p->dw.min.y + 1;
    int64_t chunks = 0, ntx = 1;
    int32_t lines = 1;
    uint32_t tw = 0, th = 0;
    int started = 0;

    if (rv == EXR_ERR_SUCCESS && storage == EXR_STORAGE_TILED) {
        exr_tile_level_mode_t level;
        exr_tile_round_mode_t round;
        rv = exr_get_tile_descriptor(ctx, part, &tw, &th, &level, &round);
        if (rv == EXR_ERR_SUCCESS && (tw == 0 || th == 0))
            rv = EXR_ERR_INVALID_ATTR;
        ntx = (w + tw - 1) / (tw ? tw : 1);
        chunks = ntx * ((h + th - 1) / (th ? th : 1));
    } else if (rv == EXR_ERR_SUCCESS) {
        rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
        chunks = lines > 0 ? (h + lines - 1) / lines : 0;
    }
    if (rv != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "part layout");
    for (int64_t i = 0; i < chunks && rv == EXR_ERR_SUCCESS; i++) {
        exr_chunk_info_t ci;
        rv = storage == EXR_STORAGE_TILED
                 ? exr_read_tile_chunk_info(ctx, part, (int)(i % ntx), (int)(i / ntx), 0, 0, &ci)
                 : exr_read_scanline_chunk_info(ctx, part, (int)(p->dw.min.y + i * lines), &ci);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = started ? exr_decoding_update(ctx, part, &ci, &dec) : exr_decoding_initialize(ctx, part, &ci, &dec);
        started = 1;
        if (rv != EXR_ERR_SUCCESS)
            break;
        for (int c = 0; c < dec.channel_count; c++) {
            exr_coding_channel_info_t *ch = &dec.channels[c];
            const obs__wchan *t = NULL;
            for (int k = 0; k < p->nch && !t; k++)
                if (!strcmp(p->ch[k].name, ch->channel_name))
                    t = &p->ch[k];
            if (!t) { /* every channel of the part has a buffer */
                rv = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            /* a tile's start_x/start_y are its tile indices, a
             * scanline chunk's its first pixel */
            int64_t x0 = storage == EXR_STORAGE_TILED ? (i % ntx) * (int64_t)tw : 0;
            int64_t y0 = storage == EXR_STORAGE_TILED ? (i / ntx) * (int64_t)th : (int64_t)ci.start_y - p->dw.min.y;
            size_t off = (size_t)y0 * (size_t)t->line_stride + (size_t)x0 * (size_t)t->pixel_stride;
            ch->decode_to_ptr = (uint8_t *)(uintptr_t)(t->base + off);
            ch->user_pixel_stride = t->pixel_stride;
            ch->user_line_stride = t->line_stride;
            ch->user_data_type = t->user_type;
            ch->user_bytes_per_element = (int16_t)t->user_bytes;
        }
        if (rv == EXR_ERR_SUCCESS && (rv = exr_decoding_choose_default_routines(ctx, part, &dec)) == EXR_ERR_SUCCESS)
            rv = exr_decoding_run(ctx, part, &dec);
    }
    if (started)
        exr_decoding_destroy(ctx, &dec);
    if (rv != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "decoding the input part");
    return OBS_OK;
}

/* Sizes of one part, checked; the bytes its channels need. */
static obs_status part_bytes(exr_const_context_t src, int part, int64_t file_size, obs__wpart *p,
                             const exr_attr_chlist_t **cl, size_t *bytes, char err[OBS_ERR_LEN])
{
    exr_storage_t storage;
    exr_result_t rv;
    obs_status st;

    if ((rv = exr_get_storage(src, part, &storage)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "part type");
    if (storage == EXR_STORAGE_DEEP_SCANLINE || storage == EXR_STORAGE_DEEP_TILED)
        return obs__fail(err, OBS_UNSUPPORTED, "part %d holds deep data: appending the AO to a deep file is not "
                         "supported (write the AO on its own, without append)", part);
    if ((st = obs__exr_check_part(src, part, file_size, NULL, &p->dw, err)) != OBS_OK)
        return st;
    if ((rv = exr_get_display_window(src, part, &p->disp)) != EXR_ERR_SUCCESS ||
        (rv = exr_get_compression(src, part, &p->compression)) != EXR_ERR_SUCCESS ||
        (rv = exr_get_channels(src, part, cl)) != EXR_ERR_SUCCESS || !*cl)
        return obs__exr_fail(err, rv ? rv : EXR_ERR_MISSING_REQ_ATTR, "part header");
    p->compression = lossless(p->compression);
    size_t px = (size_t)((int64_t)p->dw.max.x - p->dw.min.x + 1) * (size_t)((int64_t)p->dw.max.y - p->dw.min.y + 1);
    *bytes = 0;
    for (int k = 0; k < (*cl)->num_channels; k++) {
        size_t b;
        if (obs__size_mul3(px, (size_t)type_bytes((*cl)->entries[k].pixel_type), 1, &b) != 0 || *bytes + b < b)
            return obs__fail(err, OBS_TOO_LARGE, "part %d does not fit in memory", part);
        *bytes += b;
    }
    return OBS_OK;
}

obs_status obs__exr_append_parts(exr_const_context_t src, int64_t file_size, int src_part,
                                 const obs_exr_layer *layers, int layer_count, exr_pixel_type_t type,
                                 obs__wpart **parts_out, int *nparts, void **bufs_out, char err[OBS_ERR_LEN])
{
    const exr_attr_chlist_t *cl = NULL;
    obs__wpart *parts = NULL;
    uint8_t *buf = NULL;
    size_t total = 0, at = 0;
    int np = 0, extra = 0;
    obs_status st = OBS_OK;

    *parts_out = NULL;
    *nparts = 0;
    *bufs_out = NULL;
    if (exr_get_count(src, &np) != EXR_ERR_SUCCESS || np < 1)
        return obs__fail(err, OBS_BAD_FILE, "the input has no parts");
    if (!(parts = calloc((size_t)np, sizeof *parts)))
        return obs__fail(err, OBS_NO_MEMORY, "part list");
    for (int l = 0; l < layer_count; l++)
        extra += layers[l].image->channels;

    /* First every part's sizes, then one allocation. */
    for (int i = 0; i < np; i++) {
        size_t b = 0;
        if ((st = part_bytes(src, i, file_size, &parts[i], &cl, &b, err)) != OBS_OK)
            goto fail;
        if (total + b < total) {
            st = obs__fail(err, OBS_TOO_LARGE, "the input does not fit in memory");
            goto fail;
        }
        total += b;
        parts[i].src_part = i;
        const char *name = NULL;
        if (np > 1 && exr_get_name(src, i, &name) == EXR_ERR_SUCCESS)
            parts[i].name = name;
        obs__exr_msg_reset();
        int n = cl->num_channels + (i == src_part ? extra : 0);
        if (!(parts[i].ch = calloc((size_t)n > 0 ? (size_t)n : 1, sizeof *parts[i].ch))) {
            st = obs__fail(err, OBS_NO_MEMORY, "channel list");
            goto fail;
        }
        for (int k = 0; k < cl->num_channels; k++) {
            const exr_attr_chlist_entry_t *e = &cl->entries[k];
            parts[i].ch[parts[i].nch++] = (obs__wchan){e->name.str, e->pixel_type, (exr_perceptual_treatment_t)e->p_linear,
                                                       NULL, type_bytes(e->pixel_type), 0, e->pixel_type,
                                                       type_bytes(e->pixel_type)};
        }
    }
    if (!(buf = malloc(total ? total : 1))) {
        st = obs__fail(err, OBS_NO_MEMORY, "the input's %zu bytes of pixels", total);
        goto fail;
    }
    for (int i = 0; i < np; i++) {
        obs__wpart *p = &parts[i];
        int64_t w = (int64_t)p->dw.max.x - p->dw.min.x + 1, h = (int64_t)p->dw.max.y - p->dw.min.y + 1;
        for (int k = 0; k < p->nch; k++) {
            p->ch[k].base = buf + at;
            p->ch[k].line_stride = (int32_t)(w * p->ch[k].pixel_stride);
            at += (size_t)(w * h) * (size_t)p->ch[k].pixel_stride;
        }
        if ((st = decode_native(src, i, p, err)) != OBS_OK) {
            obs__fail(err, st, "part %d: %s", i, obs__exr_msg()[0] ? obs__exr_msg() : "cannot be decoded");
            goto fail;
        }
    }

    /* The AO layer joins the part the G-buffer came from. */
    obs__wpart *p = &parts[src_part];
    int64_t w = (int64_t)p->dw.max.x - p->dw.min.x + 1, h = (int64_t)p->dw.max.y - p->dw.min.y + 1;
    if (layer_count > 0 && (layers[0].image->width != w || layers[0].image->height != h)) {
        st = obs__fail(err, OBS_INVALID_ARGUMENT, "the images are %dx%d but part %d's data window is %lldx%lld",
                       layers[0].image->width, layers[0].image->height, src_part, (long long)w, (long long)h);
        goto fail;
    }
    int own = p->nch;
    for (int l = 0; l < layer_count; l++) {
        const obs_image *img = layers[l].image;
        for (int k = 0; k < img->channels; k++) {
            const char *name = layers[l].names[k];
            for (int j = 0; j < own; j++)
                if (!strcmp(p->ch[j].name, name)) {
                    st = obs__fail(err, OBS_INVALID_ARGUMENT, "the input already has a channel '%.200s': give the AO "
                                   "another layer name (layer=NAME, --layer NAME)", name);
                    goto fail;
                }
            p->ch[p->nch++] = (obs__wchan){name, type, EXR_PERCEPTUALLY_LOGARITHMIC, (const uint8_t *)(img->data + k),
                                           img->channels * (int32_t)sizeof(float),
                                           img->width * img->channels * (int32_t)sizeof(float), EXR_PIXEL_FLOAT,
                                           sizeof(float)};
        }
    }
    *parts_out = parts;
    *nparts = np;
    *bufs_out = buf;
    return OBS_OK;
fail:
    obs__exr_append_free(parts, np, buf);
    return st;
}

void obs__exr_append_free(obs__wpart *parts, int nparts, void *bufs)
{
    for (int i = 0; parts && i < nparts; i++)
        free(parts[i].ch);
    free(parts);
    free(bufs);
}
