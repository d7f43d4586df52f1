/* G-buffer EXR input through OpenEXR's C API (openexr.h).
 *
 * Files are untrusted: every size from a header is checked (overflow,
 * limits, what the file can hold) before anything is allocated, and
 * every library failure becomes a status with the library's message. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/exr_internal.h"
#include "internal.h"
#include "pool.h"

/* A decoded chunk is held whole by the library; the header decides its
 * size, so a damaged header could ask for gigabytes from a tiny file. */
#define MAX_CHUNK_BYTES ((uint64_t)1 << 30)

/* ---- opening ------------------------------------------------------------ */

typedef obs__exr_mem mem_src;

static int64_t mem_read(exr_const_context_t ctxt, void *user, void *buffer, uint64_t sz,
                        uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    const mem_src *m = user;
    (void)ctxt;
    (void)error_cb;
    if (offset >= m->len)
        return 0; /* end of data: the library reports the short read */
    uint64_t n = m->len - offset < sz ? m->len - offset : sz;
    memcpy(buffer, m->buf + offset, (size_t)n);
    return (int64_t)n;
}

static int64_t mem_size(exr_const_context_t ctxt, void *user)
{
    (void)ctxt;
    return (int64_t)((const mem_src *)user)->len;
}

obs_status obs__exr_open(const char *path, const mem_src *mem, exr_context_t *ctx,
                           int64_t *size, char err[OBS_ERR_LEN])
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    struct stat st;
    init.error_handler_fn = obs__exr_error_handler;
    /* A damaged offset table is an error, not a reason to scan the file. */
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    if (mem) {
        init.user_data = (void *)mem;
        init.read_fn = mem_read;
        init.size_fn = mem_size;
    }
    *ctx = NULL;
    *size = mem ? (int64_t)mem->len
            : stat(path, &st) == 0 && S_ISREG(st.st_mode) ? (int64_t)st.st_size : -1;
    obs__exr_msg_reset();
    exr_result_t rv = exr_start_read(ctx, mem ? "<memory>" : path, &init);
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(ctx);
        *ctx = NULL;
        return obs__exr_fail(err, rv, "not a readable OpenEXR file");
    }
    obs__exr_msg_reset(); /* header warnings the library got past */
    return OBS_OK;
}

obs_status obs__exr_read_with(const char *label, const char *path, const obs__exr_mem *mem,
                              obs__exr_reader read, void *user, char err[OBS_ERR_LEN])
{
    char why[OBS_ERR_LEN] = "";
    exr_context_t ctx = NULL;
    int64_t size;
    obs_status st = obs__exr_open(path, mem, &ctx, &size, why);
    if (st == OBS_OK)
        st = read(ctx, size, user, why);
    if (ctx)
        exr_finish(&ctx);
    if (st != OBS_OK)
        obs__fail(err, st, "%s: %s", label, why);
    return st;
}

obs_status obs__exr_read_out(const char *label, const char *path, const obs__exr_mem *mem,
                             obs__exr_reader read, void *user, void *out, size_t out_size,
                             void (*release)(void *out), char err[OBS_ERR_LEN])
{
    if (!out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: no output", label);
    memset(out, 0, out_size);
    obs_status st = obs__exr_read_with(label, path, mem, read, user, err);
    if (st != OBS_OK)
        release(out);
    return st;
}

/* ---- parts and channels -------------------------------------------------- */

/* Channel names of one part, pointing into the context (valid until
 * exr_finish()).  Caller frees the array. */
static obs_status part_names(exr_const_context_t ctx, int part, const char ***names,
                             int *count, char err[OBS_ERR_LEN])
{
    const exr_attr_chlist_t *cl = NULL;
    exr_result_t rv = exr_get_channels(ctx, part, &cl);
    if (rv != EXR_ERR_SUCCESS || !cl)
        return obs__exr_fail(err, rv ? rv : EXR_ERR_MISSING_REQ_ATTR, "channel list");
    if (cl->num_channels < 0)
        return obs__fail(err, OBS_BAD_FILE, "part %d: negative channel count", part);
    *names = malloc(((size_t)cl->num_channels + 1) * sizeof **names);
    if (!*names)
        return obs__fail(err, OBS_NO_MEMORY, "channel list of %d names", cl->num_channels);
    for (int i = 0; i < cl->num_channels; i++)
        (*names)[i] = cl->entries[i].name.str ? cl->entries[i].name.str : "";
    *count = cl->num_channels;
    return OBS_OK;
}

static const char *compression_name(exr_compression_t c, int upper)
{
    static const char *const lower[] = {"none", "rle", "zips", "zip", "piz",
                                        "pxr24", "b44", "b44a", "dwaa", "dwab"};
    static const char *const caps[] = {"NONE", "RLE", "ZIPS", "ZIP", "PIZ",
                                       "PXR24", "B44", "B44A", "DWAA", "DWAB"};
    if ((int)c < 0 || c >= EXR_COMPRESSION_LAST_TYPE)
        return "unknown";
    return upper ? caps[c] : lower[c];
}

/* What a part looks like, checked before anything is decoded. */
typedef struct part_geom {
    exr_attr_box2i_t dw, disp;
    int width, height;
    int tiled;
    exr_compression_t compression;
} part_geom;

/* Refuses what the decoder cannot or should not handle, and checks every
 * size the header gives: storage kind, compression, sampling, windows
 * against the limits, and the chunk table against the file size. */
static obs_status check_part(exr_const_context_t ctx, int part, int64_t file_size,
                             const obs_limits *lim, part_geom *g, char err[OBS_ERR_LEN])
{
    exr_storage_t storage;
    const exr_attr_chlist_t *cl = NULL;
    int32_t chunks = 0;
    uint64_t unpacked = 0;
    exr_result_t rv;
    obs_status st;

    memset(g, 0, sizeof *g);
    if ((rv = exr_get_storage(ctx, part, &storage)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "part type");
    if (storage == EXR_STORAGE_DEEP_SCANLINE || storage == EXR_STORAGE_DEEP_TILED)
        return obs__fail(err, OBS_UNSUPPORTED, "part %d holds deep (%s) data; deep input is not supported",
                         part, storage == EXR_STORAGE_DEEP_TILED ? "tiled" : "scanline");
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED)
        return obs__fail(err, OBS_UNSUPPORTED, "part %d has unknown storage type %d", part, (int)storage);
    g->tiled = storage == EXR_STORAGE_TILED;

    /* Checked from the header: 3.1's C API cannot decode DWA at all. */
    if ((rv = exr_get_compression(ctx, part, &g->compression)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "compression");
    if (g->compression == EXR_COMPRESSION_DWAA || g->compression == EXR_COMPRESSION_DWAB)
        return obs__fail(err, OBS_UNSUPPORTED, "compression %s is not supported by OpenEXR 3.1's C API",
                         compression_name(g->compression, 1));
    if ((int)g->compression < 0 || g->compression >= EXR_COMPRESSION_LAST_TYPE)
        return obs__fail(err, OBS_UNSUPPORTED, "unknown compression %d", (int)g->compression);

    if ((rv = exr_get_channels(ctx, part, &cl)) != EXR_ERR_SUCCESS || !cl)
        return obs__exr_fail(err, rv ? rv : EXR_ERR_MISSING_REQ_ATTR, "channel list");
    for (int i = 0; i < cl->num_channels; i++)
        if (cl->entries[i].x_sampling != 1 || cl->entries[i].y_sampling != 1)
            return obs__fail(err, OBS_UNSUPPORTED, "channel '%.256s' is subsampled (%dx%d); subsampled channels are not supported",
                             cl->entries[i].name.str, cl->entries[i].x_sampling, cl->entries[i].y_sampling);
        else if ((int)cl->entries[i].pixel_type < 0 || cl->entries[i].pixel_type >= EXR_PIXEL_LAST_TYPE)
            return obs__fail(err, OBS_BAD_FILE, "channel '%.256s' has unknown pixel type %d",
                             cl->entries[i].name.str, (int)cl->entries[i].pixel_type);

    if ((rv = exr_get_data_window(ctx, part, &g->dw)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "data window");
    if ((rv = exr_get_display_window(ctx, part, &g->disp)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "display window");
    int64_t w = (int64_t)g->dw.max.x - g->dw.min.x + 1, h = (int64_t)g->dw.max.y - g->dw.min.y + 1;
    int64_t dispw = (int64_t)g->disp.max.x - g->disp.min.x + 1;
    int64_t disph = (int64_t)g->disp.max.y - g->disp.min.y + 1;
    if ((st = obs_check_size(lim, w, h, err)) != OBS_OK)
        return st;
    /* Row strides handed to the decoder are int32 (4 floats a pixel). */
    if (w > INT32_MAX / 16)
        return obs__fail(err, OBS_TOO_LARGE, "data window %lld pixels wide", (long long)w);
    int64_t ox = (int64_t)g->dw.min.x - g->disp.min.x, oy = (int64_t)g->dw.min.y - g->disp.min.y;
    if (dispw <= 0 || disph <= 0 || dispw > INT_MAX || disph > INT_MAX || ox < INT_MIN ||
        ox > INT_MAX || oy < INT_MIN || oy > INT_MAX)
        return obs__fail(err, OBS_BAD_FILE, "display window %lldx%lld at an offset of (%lld, %lld) is not usable",
                         (long long)dispw, (long long)disph, (long long)ox, (long long)oy);
    g->width = (int)w;
    g->height = (int)h;

    /* Each chunk has an 8-byte entry in the offset table, so a file
     * smaller than the table is damaged; this keeps the library from
     * allocating a table the file cannot hold. */
    if ((rv = exr_get_chunk_count(ctx, part, &chunks)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "chunk count");
    if (chunks <= 0)
        return obs__fail(err, OBS_BAD_FILE, "part %d has no chunks", part);
    if (file_size >= 0 && (uint64_t)chunks * 8u > (uint64_t)file_size)
        return obs__fail(err, OBS_BAD_FILE, "a table of %d chunks does not fit in a file of %lld bytes",
                         (int)chunks, (long long)file_size);
    if ((rv = exr_get_chunk_unpacked_size(ctx, part, &unpacked)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "chunk size");
    if (unpacked > MAX_CHUNK_BYTES)
        return obs__fail(err, OBS_TOO_LARGE, "a chunk of %llu bytes exceeds the limit of %llu",
                         (unsigned long long)unpacked, (unsigned long long)MAX_CHUNK_BYTES);
    return OBS_OK;
}

obs_status obs__exr_check_part(exr_const_context_t ctx, int part, int64_t file_size, const obs_limits *lim,
                               exr_attr_box2i_t *dw, char err[OBS_ERR_LEN])
{
    part_geom g;
    obs_status st = check_part(ctx, part, file_size, lim, &g, err);
    *dw = g.dw;
    return st;
}

/* ---- decoding ----------------------------------------------------------- */

/* Where one EXR channel goes: `base` is its value at pixel (0, 0) of a
 * plane of `pch` interleaved floats a pixel, width g->width. */
typedef struct target {
    const char *name;
    float *base;
    int pch;
} target;

/* One decode pipeline reused across the chunks of a part. */
typedef struct decoder {
    exr_decode_pipeline_t dec;
    int started;
    float *scratch; /* sink for channels nobody asked for, see below */
    size_t scratch_len;
} decoder;

/* OpenEXR 3.1 picks its half-to-float fast paths for 3- and 4-channel
 * parts without checking that every channel has a destination, and then
 * writes through the NULL ones.  Such parts get a scratch destination for
 * their unmapped channels. */
static obs_status bind_scratch(decoder *d, const exr_chunk_info_t *ci, char err[OBS_ERR_LEN])
{
    size_t n = (size_t)ci->width * (size_t)ci->height; /* within the data window */
    if (d->dec.channel_count > 4)
        return OBS_OK;
    if (n > d->scratch_len) {
        free(d->scratch);
        d->scratch_len = 0;
        if (!(d->scratch = malloc(n * sizeof(float))))
            return obs__fail(err, OBS_NO_MEMORY, "decoding a chunk of %dx%d", ci->width, ci->height);
        d->scratch_len = n;
    }
    for (int c = 0; c < d->dec.channel_count; c++) {
        exr_coding_channel_info_t *ch = &d->dec.channels[c];
        if (ch->decode_to_ptr)
            continue;
        ch->decode_to_ptr = (uint8_t *)d->scratch;
        ch->user_pixel_stride = sizeof(float);
        ch->user_line_stride = ci->width * (int32_t)sizeof(float);
        ch->user_data_type = EXR_PIXEL_FLOAT;
        ch->user_bytes_per_element = sizeof(float);
    }
    return OBS_OK;
}

static obs_status decode_chunk(exr_const_context_t ctx, int part, const part_geom *g,
                               const exr_chunk_info_t *ci, int64_t x0, int64_t y0,
                               const target *t, int nt, decoder *d, char err[OBS_ERR_LEN])
{
    char what[96];
    exr_result_t rv;
    obs_status st;

    snprintf(what, sizeof what, "decoding the chunk at (%lld, %lld)", (long long)x0, (long long)y0);
    if (ci->width <= 0 || ci->height <= 0 || x0 < 0 || y0 < 0 ||
        x0 + ci->width > g->width || y0 + ci->height > g->height)
        return obs__fail(err, OBS_BAD_FILE, "%s: chunk of %dx%d lies outside the data window",
                         what, ci->width, ci->height);
    rv = d->started ? exr_decoding_update(ctx, part, ci, &d->dec)
                    : exr_decoding_initialize(ctx, part, ci, &d->dec);
    d->started = 1;
    if (rv != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, what);
    for (int c = 0; c < d->dec.channel_count; c++) {
        exr_coding_channel_info_t *ch = &d->dec.channels[c];
        ch->decode_to_ptr = NULL;
        for (int k = 0; k < nt; k++) {
            if (strcmp(ch->channel_name, t[k].name) != 0)
                continue;
            if (ch->width != ci->width || ch->height != ci->height)
                return obs__fail(err, OBS_BAD_FILE, "%s: channel '%.256s' is %dx%d in a %dx%d chunk",
                                 what, t[k].name, ch->width, ch->height, ci->width, ci->height);
            float *p = t[k].base + ((size_t)y0 * (size_t)g->width + (size_t)x0) * (size_t)t[k].pch;
            ch->decode_to_ptr = (uint8_t *)p;
            ch->user_pixel_stride = t[k].pch * (int32_t)sizeof(float);
            ch->user_line_stride = g->width * t[k].pch * (int32_t)sizeof(float);
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = sizeof(float);
        }
    }
    if ((st = bind_scratch(d, ci, err)) != OBS_OK)
        return st;
    if ((rv = exr_decoding_choose_default_routines(ctx, part, &d->dec)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, what);
    if ((rv = exr_decoding_run(ctx, part, &d->dec)) != EXR_ERR_SUCCESS) {
        st = obs__exr_fail(err, rv, what);
        /* 3.1 reports some corrupt compressed chunks as out of memory;
         * its buffers here are bounded by MAX_CHUNK_BYTES, so the file is
         * the likelier culprit. */
        return rv == EXR_ERR_OUT_OF_MEMORY ? OBS_BAD_FILE : st;
    }
    return OBS_OK;
}

/* Level 0 of a part, decoded by a few threads at once.  OpenEXR's C API
 * lets many threads read and decode chunks of one context concurrently
 * (openexr_context.h, openexr_decode.h), each with its own decode
 * pipeline; mem_read() reads at explicit offsets, so it is safe too.
 * Chunks are handed out in file order from a counter, and on failure the
 * error of the lowest failing chunk is kept: every chunk before it was
 * handed out before it and is finished, so the result is the one a single
 * thread gives, whatever the timing. */
typedef struct part_job {
    exr_const_context_t ctx;
    int part;
    const part_geom *g;
    const target *t;
    int nt;
    int32_t lines;        /* scanlines per chunk (scanline parts) */
    uint32_t tw, th;      /* tile size (tiled parts) */
    int64_t ntx, chunks;  /* tiles across; chunks to decode */
    int64_t first;        /* the first of them (a range of rows: obs_gbuffer_rows) */
    obs__exr_chunk_fail fail; /* under the pool's lock */
} part_job;

static obs_status decode_nth(part_job *j, int64_t i, decoder *d, char err[OBS_ERR_LEN])
{
    const part_geom *g = j->g;
    i += j->first;
    exr_chunk_info_t ci;
    exr_result_t rv;

    if (!g->tiled) {
        int64_t y = g->dw.min.y + i * j->lines;
        if ((rv = exr_read_scanline_chunk_info(j->ctx, j->part, (int)y, &ci)) != EXR_ERR_SUCCESS)
            return obs__exr_fail(err, rv, "reading a scanline chunk");
        return decode_chunk(j->ctx, j->part, g, &ci, (int64_t)ci.start_x - g->dw.min.x,
                            (int64_t)ci.start_y - g->dw.min.y, j->t, j->nt, d, err);
    }
    int64_t tx = i % j->ntx, ty = i / j->ntx;
    if ((rv = exr_read_tile_chunk_info(j->ctx, j->part, (int)tx, (int)ty, 0, 0, &ci)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "reading a tile");
    return decode_chunk(j->ctx, j->part, g, &ci, tx * j->tw, ty * j->th, j->t, j->nt, d, err);
}

/* One decoder per thread; a failure is kept until the thread ends. */
typedef struct decode_local {
    decoder d;
    obs__exr_chunk_fail fail;
} decode_local;

static void decode_begin(void *ctx, void *local)
{
    (void)ctx;
    decode_local *l = local;
    l->d = (decoder){EXR_DECODE_PIPELINE_INITIALIZER};
    l->fail.code = OBS_OK;
    obs__exr_msg_reset(); /* the library's messages are per thread */
}

/* One chunk; a failure stops handing out more. */
static int decode_one(void *ctx, void *local, size_t i, size_t i1)
{
    (void)i1; /* ranges of one chunk */
    decode_local *l = local;
    obs_status st = decode_nth(ctx, (int64_t)i, &l->d, l->fail.msg);
    if (st == OBS_OK)
        return 0;
    l->fail.chunk = (int64_t)i;
    l->fail.code = st;
    return 1;
}

/* Under the pool's lock. */
static void decode_end(void *ctx, void *local)
{
    part_job *j = ctx;
    decode_local *l = local;
    obs__exr_chunk_fail_keep(&j->fail, &l->fail);
    if (l->d.started)
        exr_decoding_destroy(j->ctx, &l->d.dec);
    free(l->d.scratch);
}

/* Decodes the chunks of level 0 of a part that hold rows [y0, y1) of its
 * data window into the targets (a chunk's rows outside the range too:
 * obs__exr_chunk_rows gives the rows the targets must hold). */
static obs_status decode_rows(exr_const_context_t ctx, int part, const part_geom *g,
                              const target *t, int nt, const obs_limits *lim, int y0, int y1,
                              char err[OBS_ERR_LEN]);

/* Decodes level 0 of a part into the targets. */
static obs_status decode_part(exr_const_context_t ctx, int part, const part_geom *g,
                              const target *t, int nt, const obs_limits *lim,
                              char err[OBS_ERR_LEN])
{
    return decode_rows(ctx, part, g, t, nt, lim, 0, g->height, err);
}

/* Scanlines (or tile rows) per chunk of a part. */
static obs_status chunk_lines(exr_const_context_t ctx, int part, const part_geom *g, int32_t *lines,
                              uint32_t *tw, char err[OBS_ERR_LEN])
{
    exr_result_t rv;
    if (!g->tiled) {
        if ((rv = exr_get_scanlines_per_chunk(ctx, part, lines)) != EXR_ERR_SUCCESS || *lines < 1)
            return obs__exr_fail(err, rv ? rv : EXR_ERR_INVALID_ATTR, "scanlines per chunk");
        return OBS_OK;
    }
    exr_tile_level_mode_t level;
    exr_tile_round_mode_t round;
    uint32_t th = 0;
    rv = exr_get_tile_descriptor(ctx, part, tw, &th, &level, &round);
    if (rv != EXR_ERR_SUCCESS || *tw == 0 || th == 0 || th > INT32_MAX)
        return obs__exr_fail(err, rv ? rv : EXR_ERR_INVALID_ATTR, "tile description");
    *lines = (int32_t)th;
    return OBS_OK;
}

static obs_status decode_rows(exr_const_context_t ctx, int part, const part_geom *g,
                              const target *t, int nt, const obs_limits *lim, int y0, int y1,
                              char err[OBS_ERR_LEN])
{
    part_job j = {.ctx = ctx, .part = part, .g = g, .t = t, .nt = nt, .fail = {.chunk = INT64_MAX}};
    int32_t lines = 0;
    uint32_t tw = 0;
    obs_status cs = chunk_lines(ctx, part, g, &lines, &tw, err);
    if (cs != OBS_OK)
        return cs;
    /* the chunk rows holding [y0, y1) */
    const int64_t r0 = y0 / lines, r1 = ((int64_t)y1 + lines - 1) / lines;
    if (!g->tiled) {
        j.lines = lines;
        j.first = r0;
        j.chunks = r1 - r0;
    } else {
        j.tw = tw;
        j.th = (uint32_t)lines;
        j.ntx = ((int64_t)g->width + j.tw - 1) / j.tw;
        j.first = r0 * j.ntx;
        j.chunks = j.ntx * (r1 - r0);
    }
    obs__pool_for f = {.end = (size_t)j.chunks, .chunk = 1,
                       .threads = obs__exr_chunk_threads(lim ? lim->threads : 0, j.chunks),
                       .range = decode_one, .ctx = &j, .local_size = sizeof(decode_local),
                       .begin = decode_begin, .end_thread = decode_end};
    if (obs__pool_run(&f, NULL) < 0)
        return obs__fail(err, OBS_NO_MEMORY, "decode threads");
    if (j.fail.code != OBS_OK)
        memcpy(err, j.fail.msg, OBS_ERR_LEN);
    return (obs_status)j.fail.code;
}

/* ---- G-buffer ----------------------------------------------------------- */

/* The first selected part holding the mapped depth; with a view, the
 * channels of the view's parts together (*owner: the part of each name).
 * When none does, the message lists the channels of every part. */
static obs_status find_part(exr_const_context_t ctx, const obs__part_set *ps,
                            const obs_channel_map *map, int *part, obs__channel_match *m,
                            const char ***names, int **owner, char err[OBS_ERR_LEN])
{
    const char **all = NULL, **pn = NULL;
    int nall = 0, n = 0, parts = ps->count, *own = NULL;
    obs_status st = OBS_OK;
    char perr[OBS_ERR_LEN] = "", first_err[OBS_ERR_LEN] = "", why[96];

    *owner = NULL;
    for (int i = 0; i < parts; i++) {
        int p = ps->part[i];
        if ((st = part_names(ctx, p, &pn, &n, err)) != OBS_OK)
            goto fail;
        const char *detected = obs__preset_detect(ctx, p, why, sizeof why);
        obs__exr_msg_reset(); /* a missing attribute is not an error */
        if (!ps->by_view && (st = obs__channel_map_resolve_for(map, detected, pn, n, m, perr)) == OBS_OK) {
            *part = p;
            *names = pn;
            pn = NULL;
            goto fail;
        }
        if (!ps->by_view && st != OBS_MISSING_CHANNEL) {
            obs__fail(err, st, "%s", perr);
            goto fail;
        }
        if (i == 0)
            memcpy(first_err, perr, sizeof perr);
        const char **grown = realloc(all, ((size_t)nall + (size_t)n + 1) * sizeof *all);
        int *grown_own = realloc(own, ((size_t)nall + (size_t)n + 1) * sizeof *own);
        if (grown)
            all = grown;
        if (grown_own)
            own = grown_own;
        if (!grown || !grown_own) {
            st = obs__fail(err, OBS_NO_MEMORY, "channel list");
            goto fail;
        }
        memcpy(all + nall, pn, (size_t)n * sizeof *pn);
        for (int k = 0; k < n; k++)
            own[nall + k] = p;
        nall += n;
        free(pn);
        pn = NULL;
    }
    /* A view's parts: their channels together, the first part's renderer. */
    if (ps->by_view) {
        const char *detected = obs__preset_detect(ctx, ps->part[0], why, sizeof why);
        obs__exr_msg_reset();
        if ((st = obs__channel_map_resolve_for(map, detected, all, nall, m, err)) == OBS_OK) {
            *part = own[m->depth];
            *names = all;
            *owner = own;
            all = NULL;
            own = NULL;
        }
        goto fail;
    }
    /* Resolving against the union gives one message naming every part's
     * channels; should that succeed (channels split across parts), part
     * 0's message stands. */
    st = OBS_MISSING_CHANNEL;
    if (parts <= 1 || obs__channel_map_resolve(map, all, nall, m, err) != OBS_MISSING_CHANNEL)
        obs__fail(err, st, "%s", first_err);
fail:
    free(pn);
    free(all);
    free(own);
    return st;
}

/* Decodes the targets of a view's parts other than the depth's, part by
 * part; each part's data window must be the depth part's. */
static obs_status decode_other_parts(exr_const_context_t ctx, int64_t file_size, int part,
                                     const part_geom *g, const target *t, const int *tpart, int nt,
                                     const obs_limits *lim, char err[OBS_ERR_LEN])
{
    for (int i = 0; i < nt; i++) {
        int q = tpart[i], seen = q == part;
        for (int k = 0; k < i && !seen; k++)
            seen = tpart[k] == q;
        if (seen)
            continue;
        part_geom gq;
        target sub[11];
        int ns = 0;
        obs_status st = check_part(ctx, q, file_size, lim, &gq, err);
        if (st != OBS_OK)
            return st;
        if (gq.dw.min.x != g->dw.min.x || gq.dw.min.y != g->dw.min.y || gq.width != g->width ||
            gq.height != g->height)
            return obs__fail(err, OBS_UNSUPPORTED, "part %d's data window (%dx%d at %d,%d) is not "
                             "the depth part's (%dx%d at %d,%d): channels of one view are gathered "
                             "from parts of the same window only (give --part)", q, gq.width,
                             gq.height, gq.dw.min.x, gq.dw.min.y, g->width, g->height,
                             g->dw.min.x, g->dw.min.y);
        for (int k = 0; k < nt; k++)
            if (tpart[k] == q)
                sub[ns++] = t[k];
        if ((st = decode_part(ctx, q, &gq, sub, ns, lim, err)) != OBS_OK)
            return st;
    }
    return OBS_OK;
}

static void copy_name(char *dst, size_t len, const char *const *names, int idx)
{
    snprintf(dst, len, "%s", idx >= 0 ? names[idx] : "");
}

/* The targets of the channels m maps, planes at depth (1 float a pixel),
 * normal (3), color (4), position (3) (NULL: not read); idx[i]: the
 * channel of target i.  Returns how many. */
static int gbuffer_targets(const char *const *names, const obs__channel_match *m, float *depth,
                           float *normal, float *color, float *position, target t[11], int idx[11])
{
    int nt = 0;
    idx[nt] = m->depth;
    t[nt++] = (target){names[m->depth], depth, 1};
    for (int i = 0; normal && i < 3; i++)
        idx[nt] = m->normal[i], t[nt++] = (target){names[m->normal[i]], normal + i, 3};
    for (int i = 0; color && i < 4; i++)
        if (m->color[i] >= 0)
            idx[nt] = m->color[i], t[nt++] = (target){names[m->color[i]], color + i, 4};
    for (int i = 0; position && i < 3; i++)
        idx[nt] = m->position[i], t[nt++] = (target){names[m->position[i]], position + i, 3};
    return nt;
}

/* A G-buffer read by rows (obs_gbuffer_rows_open): the open file, its
 * part, geometry and channels, and the rows last read. */
struct obs_gbuffer_rows {
    exr_context_t ctx;
    obs_limits lim;
    int part;
    part_geom g;
    obs__channel_match m;
    const char **names; /* point into ctx */
    obs_gbuffer gb;     /* the frame; planes NULL */
    float *buf;         /* the rows last read: each plane cap_rows rows */
    int cap_rows;
    int h0, h1;         /* the data window's rows buf holds (chunk rows) */
};

/* With rows: the header, part and channels into *rows, no pixels (a view
 * whose channels lie in several parts is refused). */
static obs_status read_gbuffer(exr_context_t ctx, int64_t file_size, const obs_channel_map *map,
                               const obs_limits *lim, obs_gbuffer_file *out,
                               obs_gbuffer_rows *rows, char err[OBS_ERR_LEN])
{
    const char **names = NULL;
    int *owner = NULL;
    obs__part_set ps = {0};
    obs__channel_match m;
    part_geom g;
    int parts = 0, part = 0;
    exr_result_t rv;
    obs_status st;

    if ((rv = exr_get_count(ctx, &parts)) != EXR_ERR_SUCCESS || parts < 1) {
        st = obs__exr_fail(err, rv ? rv : EXR_ERR_FILE_BAD_HEADER, "part count");
        goto fail;
    }
    if ((st = obs__exr_select_parts(ctx, parts, map, &ps, err)) != OBS_OK)
        goto fail;
    if ((st = find_part(ctx, &ps, map, &part, &m, &names, &owner, err)) != OBS_OK)
        goto fail;
    if ((st = check_part(ctx, part, file_size, lim, &g, err)) != OBS_OK)
        goto fail;

    /* Planes: depth (1), normal (3), colour (4), position (3), in one
     * allocation. */
    int has_n = m.normal[0] >= 0, has_c = m.color[0] >= 0, has_p = m.position[0] >= 0;
    float *depth = NULL, *normal = NULL, *color = NULL, *position = NULL;
    target t[11];
    int nt = 0, tpart[11], idx[11];
    if (rows && owner) {
        st = obs__fail(err, OBS_UNSUPPORTED, "the channels lie in several parts of the view: "
                       "read by rows from one part only");
        goto fail;
    }
    if (!rows) {
        size_t px = (size_t)g.width * (size_t)g.height, bytes;
        if (obs__size_mul3((size_t)g.width, (size_t)g.height,
                           (size_t)(1 + 3 * has_n + 4 * has_c + 3 * has_p) * sizeof(float), &bytes) != 0) {
            st = obs__fail(err, OBS_TOO_LARGE, "G-buffer of %dx%d does not fit in memory", g.width, g.height);
            goto fail;
        }
        if (!(out->storage = calloc(1, bytes))) {
            st = obs__fail(err, OBS_NO_MEMORY, "G-buffer of %dx%d", g.width, g.height);
            goto fail;
        }
        depth = out->storage;
        normal = has_n ? depth + px : NULL;
        color = has_c ? depth + px * (1 + 3 * has_n) : NULL;
        position = has_p ? depth + px * (1 + 3 * has_n + 4 * has_c) : NULL;
        nt = gbuffer_targets(names, &m, depth, normal, color, position, t, idx);
        /* a view's channels may lie in several parts: the depth part's here,
         * the others' by decode_other_parts() */
        target here[11];
        int nt_here = 0;
        for (int i = 0; i < nt; i++) {
            tpart[i] = owner ? owner[idx[i]] : part;
            if (tpart[i] == part)
                here[nt_here++] = t[i];
        }
        if (has_c && m.color[3] < 0) /* colour without alpha is opaque */
            for (size_t i = 0; i < px; i++)
                color[i * 4 + 3] = 1.0f;
        if ((st = decode_part(ctx, part, &g, here, nt_here, lim, err)) != OBS_OK ||
            (st = decode_other_parts(ctx, file_size, part, &g, t, tpart, nt, lim, err)) != OBS_OK)
            goto fail;
    }

    obs_gbuffer *gb = &out->gb;
    gb->width = g.width;
    gb->height = g.height;
    gb->display_x = (int)((int64_t)g.dw.min.x - g.disp.min.x);
    gb->display_y = (int)((int64_t)g.dw.min.y - g.disp.min.y);
    gb->display_width = (int)((int64_t)g.disp.max.x - g.disp.min.x + 1);
    gb->display_height = (int)((int64_t)g.disp.max.y - g.disp.min.y + 1);
    gb->depth = (obs_plane){depth, 1, 0};
    gb->normal = (obs_plane){normal, has_n ? 3 : 0, 0};
    gb->color = (obs_plane){color, has_c ? 4 : 0, 0};
    gb->position = (obs_plane){position, has_p && !rows ? 3 : 0, 0};
    gb->depth_mode = m.depth_mode;
    gb->normal_space = m.normal_space;

    obs_exr_info *info = &out->info;
    obs__exr_describe(ctx, part, &m, gb, info);
    obs__exr_msg_reset();
    info->part = part;
    info->part_count = parts;
    info->tiled = g.tiled;
    info->compression = compression_name(g.compression, 0);
    copy_name(info->depth, sizeof info->depth, names, m.depth);
    for (int i = 0; i < 3; i++)
        copy_name(info->normal[i], sizeof info->normal[i], names, m.normal[i]);
    for (int i = 0; i < 4; i++)
        copy_name(info->color[i], sizeof info->color[i], names, m.color[i]);
    for (int i = 0; i < 3; i++)
        copy_name(info->position[i], sizeof info->position[i], names, m.position[i]);
    snprintf(info->preset, sizeof info->preset, "%s", m.preset);
    snprintf(info->view, sizeof info->view, "%s", ps.view);
    info->parts_read = 1;
    if (rows) { /* the rows' reader keeps the part and the names */
        rows->part = part;
        rows->g = g;
        rows->m = m;
        rows->names = names;
        rows->gb = *gb;
        names = NULL;
    }
    for (int i = 1; i < nt; i++) {
        int seen = 0;
        for (int k = 0; k < i; k++)
            seen |= tpart[k] == tpart[i];
        info->parts_read += !seen;
    }
    st = OBS_OK;
fail:
    free(names);
    free(owner);
    obs__part_set_free(&ps);
    return st;
}

/* read_gbuffer's arguments, as obs__exr_read_with passes them. */
typedef struct gbuffer_job {
    const obs_channel_map *map;
    const obs_limits *lim;
    obs_gbuffer_file *out;
} gbuffer_job;

static obs_status gbuffer_reader(exr_context_t ctx, int64_t size, void *user,
                                 char why[OBS_ERR_LEN])
{
    const gbuffer_job *j = user;
    return read_gbuffer(ctx, size, j->map, j->lim, j->out, NULL, why);
}

static void gbuffer_release(void *out)
{
    obs_gbuffer_free(out);
}

/* Shared by the file and memory readers; `label` prefixes messages. */
static obs_status read_any(const char *label, const char *path, const mem_src *mem,
                           const obs_channel_map *map, const obs_limits *lim,
                           obs_gbuffer_file *out, char err[OBS_ERR_LEN])
{
    gbuffer_job j = {map, lim, out};
    return obs__exr_read_out(label, path, mem, gbuffer_reader, &j, out, sizeof *out,
                             gbuffer_release, err);
}

obs_status obs_gbuffer_read_exr(const char *path, const obs_channel_map *map,
                                const obs_limits *lim, obs_gbuffer_file *out,
                                char err[OBS_ERR_LEN])
{
    if (!path || !*path)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no EXR path given");
    return read_any(path, path, NULL, map, lim, out, err);
}

obs_status obs_gbuffer_read_exr_mem(const void *buf, size_t len, const obs_channel_map *map,
                                    const obs_limits *lim, obs_gbuffer_file *out,
                                    char err[OBS_ERR_LEN])
{
    mem_src mem = {buf, len};
    if (!buf || len == 0)
        return obs__fail(err, OBS_BAD_FILE, "EXR in memory: empty buffer");
    return read_any("EXR in memory", NULL, &mem, map, lim, out, err);
}

obs_status obs_gbuffer_rows_open(const char *path, const obs_channel_map *map, const obs_limits *lim,
                                 obs_gbuffer_rows **rows, obs_gbuffer_file *meta, char err[OBS_ERR_LEN])
{
    char why[OBS_ERR_LEN] = "";
    int64_t size;
    *rows = NULL;
    memset(meta, 0, sizeof *meta);
    if (!path || !*path)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no EXR path given");
    obs_gbuffer_rows *r = calloc(1, sizeof *r);
    if (!r)
        return obs__fail(err, OBS_NO_MEMORY, "%s: a reader", path);
    if (lim)
        r->lim = *lim;
    obs_status st = obs__exr_open(path, NULL, &r->ctx, &size, why);
    if (st == OBS_OK)
        st = read_gbuffer(r->ctx, size, map, lim, meta, r, why);
    if (st != OBS_OK) {
        obs_gbuffer_rows_close(r);
        obs_gbuffer_free(meta);
        return obs__fail(err, st, "%s: %s", path, why);
    }
    *rows = r;
    return OBS_OK;
}

/* Decodes rows [y0, y1) (chunk rows) into the reader's buffer, whose row
 * 0 is the data window's row h0. */
static obs_status rows_decode(obs_gbuffer_rows *r, int h0, int y0, int y1, char err[OBS_ERR_LEN])
{
    const part_geom *g = &r->g;
    if (y0 >= y1)
        return OBS_OK;
    const size_t plane = (size_t)g->width * (size_t)r->cap_rows, w = (size_t)g->width;
    const int has_n = r->gb.normal.channels > 0, has_c = r->gb.color.channels > 0;
    float *depth = r->buf, *normal = has_n ? depth + plane : NULL;
    float *color = has_c ? depth + plane * (size_t)(1 + 3 * has_n) : NULL;
    if (has_c && r->m.color[3] < 0) /* colour without alpha is opaque */
        for (size_t i = (size_t)(y0 - h0) * w; i < (size_t)(y1 - h0) * w; i++)
            color[i * 4 + 3] = 1.0f;
    /* the targets' row 0 is the data window's: h0 rows before the buffer */
    const size_t back = (size_t)h0 * w;
    target t[11];
    int idx[11];
    int nt = gbuffer_targets(r->names, &r->m, depth - back, normal ? normal - 3 * back : NULL,
                             color ? color - 4 * back : NULL, NULL, t, idx);
    return decode_rows(r->ctx, r->part, g, t, nt, &r->lim, y0, y1, err);
}

obs_status obs_gbuffer_rows_read(obs_gbuffer_rows *r, int y0, int y1, obs_gbuffer *out,
                                 char err[OBS_ERR_LEN])
{
    const part_geom *g = &r->g;
    int32_t lines = 0;
    uint32_t tw = 0;
    if (y0 < 0 || y1 > g->height || y0 >= y1)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "rows %d-%d of a G-buffer of %d rows", y0, y1,
                         g->height);
    obs_status st = chunk_lines(r->ctx, r->part, g, &lines, &tw, err);
    if (st != OBS_OK)
        return st;
    /* the rows of the chunks holding [y0, y1) */
    const int n0 = y0 / lines * lines;
    const int64_t up = ((int64_t)y1 + lines - 1) / lines * lines;
    const int n1 = up < g->height ? (int)up : g->height;
    const int has_n = r->gb.normal.channels > 0, has_c = r->gb.color.channels > 0;
    const int per_px = 1 + 3 * has_n + 4 * has_c;
    const size_t w = (size_t)g->width;
    /* the rows held before that are asked again (the bands go down the
     * frame, each with a halo over the last one's): kept, not decoded;
     * the rows before and after them decoded */
    int k0 = n0 > r->h0 ? n0 : r->h0, k1 = n1 < r->h1 ? n1 : r->h1;
    if (!(r->h1 > r->h0 && k0 < k1))
        k0 = k1 = n1; /* nothing kept */
    if (n1 - n0 > r->cap_rows) {
        /* a larger buffer (grown in place where the allocator can: the
         * old and the new are not held at once), each plane's kept rows
         * moved to its new place, the last plane first */
        float *nb = realloc(r->buf, (size_t)(n1 - n0) * w * (size_t)per_px * sizeof(float));
        if (!nb)
            return obs__fail(err, OBS_NO_MEMORY, "%d rows of a %dx%d G-buffer", n1 - n0, g->width,
                             g->height);
        r->buf = nb;
        const size_t oplane = w * (size_t)r->cap_rows, nplane = w * (size_t)(n1 - n0);
        const int chs[3] = {1, 3 * has_n, 4 * has_c}, at[3] = {0, 1, 1 + 3 * has_n};
        for (int c = 2; k1 > k0 && c >= 0; c--)
            if (chs[c])
                memmove(nb + nplane * (size_t)at[c] + (size_t)(k0 - n0) * w * (size_t)chs[c],
                        nb + oplane * (size_t)at[c] + (size_t)(k0 - r->h0) * w * (size_t)chs[c],
                        (size_t)(k1 - k0) * w * (size_t)chs[c] * sizeof(float));
        r->cap_rows = n1 - n0;
    } else if (k1 > k0 && n0 != r->h0) { /* in place (memmove: either way within a plane) */
        const size_t plane = w * (size_t)r->cap_rows;
        const int chs[3] = {1, 3 * has_n, 4 * has_c}, at[3] = {0, 1, 1 + 3 * has_n};
        for (int c = 0; c < 3; c++)
            if (chs[c])
                memmove(r->buf + plane * (size_t)at[c] + (size_t)(k0 - n0) * w * (size_t)chs[c],
                        r->buf + plane * (size_t)at[c] + (size_t)(k0 - r->h0) * w * (size_t)chs[c],
                        (size_t)(k1 - k0) * w * (size_t)chs[c] * sizeof(float));
    }
    r->h0 = r->h1 = 0;
    if ((st = rows_decode(r, n0, n0, k0, err)) != OBS_OK || (st = rows_decode(r, n0, k1, n1, err)) != OBS_OK)
        return st;
    r->h0 = n0;
    r->h1 = n1;
    const size_t plane = w * (size_t)r->cap_rows, skip = (size_t)(y0 - n0) * w;
    *out = r->gb;
    out->depth.data = r->buf + skip;
    out->normal.data = has_n ? r->buf + plane + 3 * skip : NULL;
    out->color.data = has_c ? r->buf + plane * (size_t)(1 + 3 * has_n) + 4 * skip : NULL;
    return OBS_OK;
}

void obs_gbuffer_rows_no_color(obs_gbuffer_rows *r)
{
    r->gb.color = (obs_plane){NULL, 0, 0};
    for (int i = 0; i < 4; i++)
        r->m.color[i] = -1;
    free(r->buf); /* the rows' layout changes: nothing held */
    r->buf = NULL;
    r->cap_rows = r->h0 = r->h1 = 0;
}

void obs_gbuffer_rows_close(obs_gbuffer_rows *r)
{
    if (!r)
        return;
    free(r->names);
    if (r->ctx)
        exr_finish(&r->ctx);
    free(r->buf);
    free(r);
}

void obs_gbuffer_free(obs_gbuffer_file *f)
{
    if (!f)
        return;
    free(f->storage);
    free(f->mask_storage);
    memset(f, 0, sizeof *f);
}

/* ---- single channels and channel lists ---------------------------------- */

/* obs_exr_read_channel(_mem) and obs__exr_read_channels: n channels of
 * the file at path, or of the buffer mem (path then names it in
 * messages), all from one part that holds channels[0]: one of `view`
 * (its "view" attribute; NULL or "": none wanted), else part `prefer`,
 * else the first; decoded in one pass over its chunks. */
obs_status obs__exr_read_channels(const char *path, const obs__exr_mem *mem, int prefer,
                                  const char *view, const char *const *channels, int n,
                                  const obs_limits *lim, obs_image *out, char err[OBS_ERR_LEN])
{
    char sub[OBS_ERR_LEN] = "";
    exr_context_t ctx = NULL;
    const char **names = NULL;
    target *t = NULL;
    int64_t size;
    int parts = 0, nn = 0, found = -1, score = -1, missing = -1;
    part_geom g;
    exr_result_t rv;
    obs_status st;

    if ((!path && !mem) || !channels || n < 1 || !out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_exr_read_channel: NULL argument");
    memset(out, 0, (size_t)n * sizeof *out);
    if ((st = obs__exr_open(mem ? NULL : path, mem, &ctx, &size, sub)) != OBS_OK)
        goto fail;
    if ((rv = exr_get_count(ctx, &parts)) != EXR_ERR_SUCCESS) {
        st = obs__exr_fail(sub, rv, "part count");
        goto fail;
    }
    for (int p = 0; p < parts && score < 2; p++) {
        if ((st = part_names(ctx, p, &names, &nn, sub)) != OBS_OK)
            goto fail;
        int has = 0;
        for (int i = 0; i < nn && !has; i++)
            has = strcmp(names[i], channels[0]) == 0;
        free(names);
        names = NULL;
        if (!has)
            continue;
        const char *v = obs__exr_attr_string(ctx, p, "view");
        int sc = view && *view && v && !strcmp(v, view) ? 2 : p == prefer ? 1 : 0;
        if (sc > score) {
            score = sc;
            found = p;
        }
    }
    /* the part chosen, or part 0 for the message */
    if ((st = part_names(ctx, found < 0 ? 0 : found, &names, &nn, sub)) != OBS_OK)
        goto fail;
    for (int k = 1; found >= 0 && k < n && missing < 0; k++) {
        int has = 0;
        for (int i = 0; i < nn && !has; i++)
            has = strcmp(names[i], channels[k]) == 0;
        if (!has)
            missing = k;
    }
    if (found < 0 || missing >= 0) {
        char list[OBS__LIST_CHARS + 32];
        obs__list_names(names, nn, list, sizeof list);
        st = obs__fail(sub, OBS_MISSING_CHANNEL, "channel '%.256s' not found; the %s has: %s",
                       channels[found < 0 ? 0 : missing], found < 0 ? "file" : "part", list);
        goto fail;
    }
    if ((st = check_part(ctx, found, size, lim, &g, sub)) != OBS_OK)
        goto fail;
    if (!(t = calloc((size_t)n, sizeof *t))) {
        st = obs__fail(sub, OBS_NO_MEMORY, "%d channels", n);
        goto fail;
    }
    /* check_part() bounded width x height by the limits. */
    for (int k = 0; k < n; k++) {
        if (!(out[k].data = malloc((size_t)g.width * (size_t)g.height * sizeof(float)))) {
            st = obs__fail(sub, OBS_NO_MEMORY, "channel of %dx%d", g.width, g.height);
            goto fail;
        }
        out[k].width = g.width;
        out[k].height = g.height;
        out[k].channels = 1;
        t[k] = (target){channels[k], out[k].data, 1};
    }
    st = decode_part(ctx, found, &g, t, n, lim, sub);
fail:
    free(t);
    free(names);
    if (ctx)
        exr_finish(&ctx);
    if (st != OBS_OK) {
        for (int k = 0; k < n; k++)
            obs_image_free(&out[k]);
        obs__fail(err, st, "%s: %s", path ? path : "EXR", sub);
    }
    return st;
}

static obs_status read_channel(const char *path, const obs__exr_mem *mem, const char *channel,
                               const obs_limits *lim, obs_image *out, char err[OBS_ERR_LEN])
{
    const char *const one[1] = {channel};
    if (!channel)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_exr_read_channel: NULL argument");
    return obs__exr_read_channels(path, mem, -1, NULL, one, 1, lim, out, err);
}

obs_status obs_exr_read_channel(const char *path, const char *channel, const obs_limits *lim,
                                obs_image *out, char err[OBS_ERR_LEN])
{
    if (!path)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_exr_read_channel: NULL argument");
    return read_channel(path, NULL, channel, lim, out, err);
}

obs_status obs_exr_read_channel_mem(const void *data, size_t len, const char *channel,
                                    const obs_limits *lim, obs_image *out, char err[OBS_ERR_LEN])
{
    if (!data)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_exr_read_channel_mem: NULL argument");
    const obs__exr_mem mem = {data, len};
    return read_channel(NULL, &mem, channel, lim, out, err);
}

/* The names of part 0's channels into *(char ***)user, a NULL-ended
 * list of copies. */
static obs_status names_reader(exr_context_t ctx, int64_t size, void *user,
                               char why[OBS_ERR_LEN])
{
    const char **names = NULL;
    char **v = NULL;
    int n = 0;
    (void)size;
    obs_status st = part_names(ctx, 0, &names, &n, why);
    if (st != OBS_OK)
        goto fail;
    if (!(v = calloc((size_t)n + 1, sizeof *v))) {
        st = obs__fail(why, OBS_NO_MEMORY, "list of %d channel names", n);
        goto fail;
    }
    for (int i = 0; i < n; i++)
        if (!(v[i] = strdup(names[i]))) {
            st = obs__fail(why, OBS_NO_MEMORY, "channel name");
            goto fail;
        }
    *(char ***)user = v;
    v = NULL;
fail:
    obs_strv_free(v);
    free(names);
    return st;
}

obs_status obs_exr_list_channels(const char *path, char ***names_out, char err[OBS_ERR_LEN])
{
    if (!path || !names_out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_exr_list_channels: NULL argument");
    *names_out = NULL;
    return obs__exr_read_with(path, path, NULL, names_reader, names_out, err);
}

void obs_strv_free(char **v)
{
    if (!v)
        return;
    for (char **p = v; *p; p++)
        free(*p);
    free(v);
}
