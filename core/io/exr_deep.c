/* Deep scanline EXR input through OpenEXR's C API (openexr.h): a pass over
 * the sample-count tables, then the samples.
 *
 * Files are untrusted.  OpenEXR 3.1's deep unpacker trusts the count
 * table (a decreasing cumulative count turns into a negative length), so
 * every table is checked here before samples are decoded: counts
 * cumulative per scanline (3.1 keeps the on-disk form; its
 * EXR_DECODE_SAMPLE_COUNTS_AS_INDIVIDUAL mode is not used, it crashes in
 * 3.1.5), non-decreasing, within OBS_DEEP_MAX_PER_PIXEL, and their sum
 * times the bytes of a sample within the chunk's unpacked size.  The
 * totals are checked against OBS_DEEP_MAX_SAMPLES before the sample
 * memory is allocated. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "obscura/deep.h"
#include "io/exr_internal.h"
#include "internal.h"

typedef obs__exr_mem mem_src;

/* The first deep part, or -1; *tiled says whether it is deep tiled. */
static int first_deep_part(exr_const_context_t ctx, int *tiled)
{
    int parts = 0;
    exr_storage_t s;
    if (exr_get_count(ctx, &parts) != EXR_ERR_SUCCESS)
        return -1;
    for (int p = 0; p < parts; p++)
        if (exr_get_storage(ctx, p, &s) == EXR_ERR_SUCCESS &&
            (s == EXR_STORAGE_DEEP_SCANLINE || s == EXR_STORAGE_DEEP_TILED)) {
            *tiled = s == EXR_STORAGE_DEEP_TILED;
            return p;
        }
    return -1;
}

/* Whether the file has a deep part, into *(int *)user. */
static obs_status deep_reader(exr_context_t ctx, int64_t size, void *user, char why[OBS_ERR_LEN])
{
    int tiled = 0;
    (void)size;
    (void)why;
    *(int *)user = first_deep_part(ctx, &tiled) >= 0;
    return OBS_OK;
}

obs_status obs_exr_is_deep(const char *path, int *deep, char err[OBS_ERR_LEN])
{
    if (!path || !deep)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_exr_is_deep: NULL argument");
    *deep = 0;
    return obs__exr_read_with(path, path, NULL, deep_reader, deep, err);
}

obs_status obs_exr_is_deep_mem(const void *buf, size_t len, int *deep, char err[OBS_ERR_LEN])
{
    mem_src mem = {buf, len};
    if (!deep)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_exr_is_deep_mem: NULL argument");
    *deep = 0;
    if (!buf || len == 0)
        return obs__fail(err, OBS_BAD_FILE, "EXR in memory: empty buffer");
    return obs__exr_read_with("EXR in memory", NULL, &mem, deep_reader, deep, err);
}

/* ---- channels ------------------------------------------------------------- */

/* Channel index of each sample value (OBS_DEEP_*), -1 where absent. */
typedef struct deep_map {
    int ch[OBS_DEEP_CH];
} deep_map;

static int find_channel(const exr_attr_chlist_t *cl, const char *name)
{
    for (int i = 0; i < cl->num_channels; i++)
        if (cl->entries[i].name.str && strcmp(cl->entries[i].name.str, name) == 0)
            return i;
    return -1;
}

static obs_status map_channels(const exr_attr_chlist_t *cl, deep_map *m, char err[OBS_ERR_LEN])
{
    static const char *const names[] = {"Z", "ZBack", "R", "G", "B", "A"};
    static const char *const normals[][3] = {{"N.X", "N.Y", "N.Z"}, {"N.R", "N.G", "N.B"},
                                             {"normal.X", "normal.Y", "normal.Z"},
                                             {"Normal.X", "Normal.Y", "Normal.Z"}};
    for (int k = 0; k < OBS_DEEP_CH; k++)
        m->ch[k] = -1;
    for (int k = 0; k <= OBS_DEEP_A; k++)
        m->ch[k] = find_channel(cl, names[k]);
    for (size_t s = 0; s < sizeof normals / sizeof normals[0] && m->ch[OBS_DEEP_NX] < 0; s++) {
        int a = find_channel(cl, normals[s][0]), b = find_channel(cl, normals[s][1]);
        int c = find_channel(cl, normals[s][2]);
        if (a >= 0 && b >= 0 && c >= 0) {
            m->ch[OBS_DEEP_NX] = a;
            m->ch[OBS_DEEP_NY] = b;
            m->ch[OBS_DEEP_NZ] = c;
        }
    }
    m->ch[OBS_DEEP_FACING] = find_channel(cl, "Facing");
    if (m->ch[OBS_DEEP_Z] < 0) {
        const char *list[64];
        char buf[OBS__LIST_CHARS + 32];
        int n = cl->num_channels < 64 ? cl->num_channels : 64;
        for (int i = 0; i < n; i++)
            list[i] = cl->entries[i].name.str ? cl->entries[i].name.str : "";
        obs__list_names(list, n, buf, sizeof buf);
        return obs__fail(err, OBS_MISSING_CHANNEL, "deep part has no Z channel; it has: %s", buf);
    }
    for (int i = 0; i < cl->num_channels; i++)
        if (cl->entries[i].x_sampling != 1 || cl->entries[i].y_sampling != 1)
            return obs__fail(err, OBS_UNSUPPORTED, "channel '%.256s' is subsampled",
                             cl->entries[i].name.str);
    return OBS_OK;
}

/* ---- the two passes -------------------------------------------------------- */

typedef struct deep_job {
    exr_const_context_t ctx;
    int part;
    int width, height;
    exr_attr_box2i_t dw;
    int lines;            /* scanlines per chunk */
    int64_t chunks;
    uint64_t sample_bytes; /* bytes of one sample, every channel of the part */
    exr_compression_t comp;
    deep_map map;
} deep_job;

/* Reads chunk i's info and decodes its count table (flags: 0 for the
 * counts alone, else the samples too, into the bound pointers). */
static obs_status chunk_info(const deep_job *j, int64_t i, exr_chunk_info_t *ci,
                             char err[OBS_ERR_LEN])
{
    int64_t y = (int64_t)j->dw.min.y + i * j->lines;
    exr_result_t rv = exr_read_scanline_chunk_info(j->ctx, j->part, (int)y, ci);
    if (rv != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "reading a deep scanline chunk");
    if (ci->width != j->width || ci->height <= 0 || ci->height > j->lines ||
        (int64_t)ci->start_y != y || ci->start_x != j->dw.min.x ||
        (int64_t)ci->start_y + ci->height - 1 > j->dw.max.y)
        return obs__fail(err, OBS_BAD_FILE, "deep chunk at line %lld is %dx%d at (%d, %d), outside the data window",
                         (long long)y, ci->width, ci->height, ci->start_x, ci->start_y);
    /* 3.1 copies an uncompressed table only when its size is exact. */
    uint64_t table = (uint64_t)ci->width * (uint64_t)ci->height * 4u;
    if (j->comp == EXR_COMPRESSION_NONE && ci->sample_count_table_size != table)
        return obs__fail(err, OBS_BAD_FILE, "deep chunk at line %lld: sample count table of %llu bytes, expected %llu",
                         (long long)y, (unsigned long long)ci->sample_count_table_size,
                         (unsigned long long)table);
    return OBS_OK;
}

/* Checks a decoded count table (cumulative per scanline) and writes the
 * per-pixel counts to counts (ci->width * ci->height); *total gets their
 * sum. */
static obs_status check_counts(const deep_job *j, const exr_chunk_info_t *ci, const int32_t *tab,
                               uint32_t *counts, uint64_t *total, char err[OBS_ERR_LEN])
{
    uint64_t sum = 0;
    for (int r = 0; r < ci->height; r++) {
        int32_t prev = 0;
        for (int x = 0; x < ci->width; x++) {
            int32_t c = tab[(size_t)r * (size_t)ci->width + (size_t)x];
            if (c < prev || c - prev > OBS_DEEP_MAX_PER_PIXEL)
                return obs__fail(err, OBS_BAD_FILE, "line %d: sample count table is not cumulative or too large at x = %d",
                                 ci->start_y + r, x);
            counts[(size_t)r * (size_t)ci->width + (size_t)x] = (uint32_t)(c - prev);
            prev = c;
        }
        sum += (uint64_t)prev;
    }
    if (sum * j->sample_bytes > ci->unpacked_size)
        return obs__fail(err, OBS_BAD_FILE, "line %d: %llu samples do not fit in a chunk of %llu bytes",
                         ci->start_y, (unsigned long long)sum, (unsigned long long)ci->unpacked_size);
    *total = sum;
    return OBS_OK;
}

static obs_status run_decoder(const deep_job *j, const exr_chunk_info_t *ci,
                              exr_decode_pipeline_t *dec, int counts_only, float *const *dst,
                              char err[OBS_ERR_LEN])
{
    exr_result_t rv = exr_decoding_initialize(j->ctx, j->part, ci, dec);
    if (rv != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "deep chunk");
    dec->decode_flags = counts_only ? EXR_DECODE_SAMPLE_DATA_ONLY : 0;
    for (int c = 0; c < dec->channel_count; c++) {
        exr_coding_channel_info_t *ch = &dec->channels[c];
        ch->decode_to_ptr = NULL;
        if (counts_only)
            continue;
        for (int k = 0; k < OBS_DEEP_CH; k++)
            if (j->map.ch[k] == c && dst[k]) {
                /* planar: the chunk's samples of this channel one after the other */
                ch->decode_to_ptr = (uint8_t *)dst[k];
                ch->user_pixel_stride = sizeof(float);
                ch->user_line_stride = 0;
                ch->user_data_type = EXR_PIXEL_FLOAT;
                ch->user_bytes_per_element = sizeof(float);
            }
    }
    if ((rv = exr_decoding_choose_default_routines(j->ctx, j->part, dec)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "deep chunk");
    if ((rv = exr_decoding_run(j->ctx, j->part, dec)) != EXR_ERR_SUCCESS) {
        obs_status st = obs__exr_fail(err, rv, "decoding a deep chunk");
        return rv == EXR_ERR_OUT_OF_MEMORY ? OBS_BAD_FILE : st;
    }
    if (!dec->sample_count_table)
        return obs__fail(err, OBS_BAD_FILE, "deep chunk at line %d has no sample count table", ci->start_y);
    return OBS_OK;
}

/* Pass 1: every chunk's counts into counts (width * height). */
static obs_status count_pass(const deep_job *j, uint32_t *counts, uint64_t *total,
                             char err[OBS_ERR_LEN])
{
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    obs_status st = OBS_OK;
    uint64_t sum = 0;
    for (int64_t i = 0; i < j->chunks && st == OBS_OK; i++) {
        exr_chunk_info_t ci;
        uint64_t n = 0;
        if ((st = chunk_info(j, i, &ci, err)) != OBS_OK)
            break;
        st = run_decoder(j, &ci, &dec, 1, NULL, err);
        if (st == OBS_OK) {
            size_t row0 = (size_t)(ci.start_y - j->dw.min.y) * (size_t)j->width;
            st = check_counts(j, &ci, dec.sample_count_table, counts + row0, &n, err);
        }
        exr_decoding_destroy(j->ctx, &dec);
        sum += n;
        if (st == OBS_OK && sum > OBS_DEEP_MAX_SAMPLES)
            st = obs__fail(err, OBS_TOO_LARGE, "more than %llu deep samples",
                           (unsigned long long)OBS_DEEP_MAX_SAMPLES);
    }
    *total = sum;
    return st;
}

static int cmp_z(const void *a, const void *b)
{
    float za = ((const float *)a)[OBS_DEEP_Z], zb = ((const float *)b)[OBS_DEEP_Z];
    za = isnan(za) ? INFINITY : za;
    zb = isnan(zb) ? INFINITY : zb;
    return za < zb ? -1 : za > zb ? 1 : 0;
}

/* Sorts one pixel's samples by Z, stable (insertion sort: lists are short
 * and mostly sorted already). */
static void sort_pixel(float *s, uint64_t n)
{
    float tmp[OBS_DEEP_CH];
    for (uint64_t i = 1; i < n; i++) {
        uint64_t k = i;
        memcpy(tmp, s + i * OBS_DEEP_CH, sizeof tmp);
        while (k > 0 && cmp_z(s + (k - 1) * OBS_DEEP_CH, tmp) > 0) {
            memcpy(s + k * OBS_DEEP_CH, s + (k - 1) * OBS_DEEP_CH, sizeof tmp);
            k--;
        }
        memcpy(s + k * OBS_DEEP_CH, tmp, sizeof tmp);
    }
}

/* Pass 2: the samples of every chunk, checked against pass 1's counts. */
static obs_status sample_pass(const deep_job *j, const uint32_t *counts, obs_deep_image *d,
                              char err[OBS_ERR_LEN])
{
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    float *scratch = NULL, *dst[OBS_DEEP_CH];
    size_t scratch_len = 0;
    obs_status st = OBS_OK;
    uint32_t *chunk_counts = NULL;

    if (!(chunk_counts = malloc((size_t)j->width * (size_t)j->lines * sizeof *chunk_counts)))
        return obs__fail(err, OBS_NO_MEMORY, "deep chunk counts");
    for (int64_t i = 0; i < j->chunks && st == OBS_OK; i++) {
        exr_chunk_info_t ci;
        if ((st = chunk_info(j, i, &ci, err)) != OBS_OK)
            break;
        size_t px0 = (size_t)(ci.start_y - j->dw.min.y) * (size_t)j->width;
        size_t npx = (size_t)ci.width * (size_t)ci.height;
        uint64_t n = d->offset[px0 + npx] - d->offset[px0];
        /* one plane of n floats per present channel */
        if (n * OBS_DEEP_CH > scratch_len) {
            free(scratch);
            scratch_len = 0;
            if (!(scratch = malloc((size_t)n * OBS_DEEP_CH * sizeof(float)))) {
                st = obs__fail(err, OBS_NO_MEMORY, "a deep chunk of %llu samples", (unsigned long long)n);
                break;
            }
            scratch_len = (size_t)n * OBS_DEEP_CH;
        }
        for (int k = 0; k < OBS_DEEP_CH; k++)
            dst[k] = j->map.ch[k] >= 0 && n > 0 ? scratch + (size_t)k * (size_t)n : NULL;
        st = run_decoder(j, &ci, &dec, 0, dst, err);
        uint64_t again = 0;
        if (st == OBS_OK)
            st = check_counts(j, &ci, dec.sample_count_table, chunk_counts, &again, err);
        if (st == OBS_OK && memcmp(chunk_counts, counts + px0, npx * sizeof *counts) != 0)
            st = obs__fail(err, OBS_BAD_FILE, "line %d: sample counts changed between reads", ci.start_y);
        exr_decoding_destroy(j->ctx, &dec);
        if (st != OBS_OK)
            break;
        /* planar chunk order -> interleaved per sample */
        float *out = d->samples + d->offset[px0] * OBS_DEEP_CH;
        for (uint64_t s = 0; s < n; s++) {
            float *o = out + s * OBS_DEEP_CH;
            for (int k = 0; k < OBS_DEEP_CH; k++)
                o[k] = dst[k] ? dst[k][s] : 0.0f;
            if (!dst[OBS_DEEP_ZBACK])
                o[OBS_DEEP_ZBACK] = o[OBS_DEEP_Z];
            if (!dst[OBS_DEEP_A])
                o[OBS_DEEP_A] = 1.0f;
        }
    }
    free(scratch);
    free(chunk_counts);
    return st;
}

/* extra: a channel read in the place of R (obs__deep_read_front); NULL:
 * none. */
static obs_status read_deep(exr_context_t ctx, int64_t file_size, const obs_limits *lim,
                            const char *extra, obs_deep_image *d, char err[OBS_ERR_LEN])
{
    deep_job j;
    const exr_attr_chlist_t *cl = NULL;
    exr_attr_box2i_t disp;
    uint32_t *counts = NULL;
    int32_t chunks = 0, lines = 0;
    uint64_t unpacked = 0, total = 0;
    int tiled = 0;
    exr_result_t rv;
    obs_status st;

    memset(&j, 0, sizeof j);
    j.ctx = ctx;
    if ((j.part = first_deep_part(ctx, &tiled)) < 0)
        return obs__fail(err, OBS_UNSUPPORTED, "the file holds no deep part");
    if (tiled)
        return obs__fail(err, OBS_UNSUPPORTED, "part %d is deep tiled; only deep scanline parts are read", j.part);
    if ((rv = exr_get_compression(ctx, j.part, &j.comp)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "compression");
    if (j.comp != EXR_COMPRESSION_NONE && j.comp != EXR_COMPRESSION_RLE &&
        j.comp != EXR_COMPRESSION_ZIPS && j.comp != EXR_COMPRESSION_ZIP)
        return obs__fail(err, OBS_UNSUPPORTED, "deep part %d uses compression %d; deep data is NONE, RLE, ZIPS or ZIP",
                         j.part, (int)j.comp);
    if ((rv = exr_get_channels(ctx, j.part, &cl)) != EXR_ERR_SUCCESS || !cl)
        return obs__exr_fail(err, rv ? rv : EXR_ERR_MISSING_REQ_ATTR, "channel list");
    if ((st = map_channels(cl, &j.map, err)) != OBS_OK)
        return st;
    if (extra && (j.map.ch[OBS_DEEP_R] = find_channel(cl, extra)) < 0)
        return obs__fail(err, OBS_MISSING_CHANNEL, "deep part has no channel '%.200s'", extra);
    for (int i = 0; i < cl->num_channels; i++) {
        exr_pixel_type_t t = cl->entries[i].pixel_type;
        if (t != EXR_PIXEL_HALF && t != EXR_PIXEL_FLOAT && t != EXR_PIXEL_UINT)
            return obs__fail(err, OBS_BAD_FILE, "channel %d has unknown pixel type %d", i, (int)t);
        j.sample_bytes += t == EXR_PIXEL_HALF ? 2u : 4u;
    }

    if ((rv = exr_get_data_window(ctx, j.part, &j.dw)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "data window");
    if ((rv = exr_get_display_window(ctx, j.part, &disp)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "display window");
    int64_t w = (int64_t)j.dw.max.x - j.dw.min.x + 1, h = (int64_t)j.dw.max.y - j.dw.min.y + 1;
    int64_t dispw = (int64_t)disp.max.x - disp.min.x + 1, disph = (int64_t)disp.max.y - disp.min.y + 1;
    int64_t ox = (int64_t)j.dw.min.x - disp.min.x, oy = (int64_t)j.dw.min.y - disp.min.y;
    if ((st = obs_check_size(lim, w, h, err)) != OBS_OK)
        return st;
    if (dispw <= 0 || disph <= 0 || dispw > INT32_MAX || disph > INT32_MAX || ox < INT32_MIN ||
        ox > INT32_MAX || oy < INT32_MIN || oy > INT32_MAX)
        return obs__fail(err, OBS_BAD_FILE, "display window %lldx%lld is not usable",
                         (long long)dispw, (long long)disph);
    j.width = (int)w;
    j.height = (int)h;

    if ((rv = exr_get_chunk_count(ctx, j.part, &chunks)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "chunk count");
    if ((rv = exr_get_scanlines_per_chunk(ctx, j.part, &lines)) != EXR_ERR_SUCCESS || lines < 1)
        return obs__exr_fail(err, rv ? rv : EXR_ERR_INVALID_ATTR, "scanlines per chunk");
    j.lines = lines;
    j.chunks = (h + lines - 1) / lines;
    if (chunks != j.chunks)
        return obs__fail(err, OBS_BAD_FILE, "deep part has %d chunks, its window needs %lld",
                         (int)chunks, (long long)j.chunks);
    if (file_size >= 0 && (uint64_t)chunks * 8u > (uint64_t)file_size)
        return obs__fail(err, OBS_BAD_FILE, "a table of %d chunks does not fit in a file of %lld bytes",
                         (int)chunks, (long long)file_size);
    if ((rv = exr_get_chunk_unpacked_size(ctx, j.part, &unpacked)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(err, rv, "chunk size");

    /* w x h is bounded by the limits; the counts come first. */
    size_t npx = (size_t)w * (size_t)h;
    if (!(counts = malloc(npx * sizeof *counts)) ||
        !(d->offset = malloc((npx + 1) * sizeof *d->offset))) {
        st = obs__fail(err, OBS_NO_MEMORY, "deep counts of %lldx%lld", (long long)w, (long long)h);
        goto fail;
    }
    if ((st = count_pass(&j, counts, &total, err)) != OBS_OK)
        goto fail;
    d->offset[0] = 0;
    for (size_t i = 0; i < npx; i++)
        d->offset[i + 1] = d->offset[i] + counts[i];
    /* total <= OBS_DEEP_MAX_SAMPLES: the product fits */
    if (!(d->samples = malloc((size_t)(total ? total : 1) * OBS_DEEP_CH * sizeof(float)))) {
        st = obs__fail(err, OBS_NO_MEMORY, "%llu deep samples", (unsigned long long)total);
        goto fail;
    }
    if ((st = sample_pass(&j, counts, d, err)) != OBS_OK)
        goto fail;
    for (size_t i = 0; i < npx; i++)
        sort_pixel(d->samples + d->offset[i] * OBS_DEEP_CH, d->offset[i + 1] - d->offset[i]);

    d->width = j.width;
    d->height = j.height;
    d->display_x = (int)ox;
    d->display_y = (int)oy;
    d->display_width = (int)dispw;
    d->display_height = (int)disph;
    d->has_zback = j.map.ch[OBS_DEEP_ZBACK] >= 0;
    d->has_alpha = j.map.ch[OBS_DEEP_A] >= 0;
    d->has_color = j.map.ch[OBS_DEEP_R] >= 0 && j.map.ch[OBS_DEEP_G] >= 0 && j.map.ch[OBS_DEEP_B] >= 0;
    d->has_normal = j.map.ch[OBS_DEEP_NX] >= 0;
    d->has_facing = j.map.ch[OBS_DEEP_FACING] >= 0;
    d->part = j.part;
    obs__exr_read_camera(ctx, j.part, &d->camera);
    obs__exr_msg_reset(); /* a missing attribute is not an error */
    st = OBS_OK;
fail:
    free(counts);
    return st;
}

/* read_deep's arguments, as obs__exr_read_with passes them. */
typedef struct image_job {
    const obs_limits *lim;
    obs_deep_image *out;
    const char *extra;
} image_job;

static obs_status image_reader(exr_context_t ctx, int64_t size, void *user, char why[OBS_ERR_LEN])
{
    const image_job *j = user;
    return read_deep(ctx, size, j->lim, j->extra, j->out, why);
}

static void image_release(void *out)
{
    obs_deep_free(out);
}

static obs_status read_any(const char *label, const char *path, const mem_src *mem,
                           const obs_limits *lim, obs_deep_image *out, char err[OBS_ERR_LEN])
{
    image_job j = {lim, out, NULL};
    return obs__exr_read_out(label, path, mem, image_reader, &j, out, sizeof *out,
                             image_release, err);
}

/* The deep image of path (or mem) with `channel` read in the place of R,
 * for the object masks' two readers below. */
static obs_status read_with_channel(const char *path, const obs__exr_mem *mem,
                                    const char *channel, const obs_limits *lim,
                                    obs_deep_image *d, char err[OBS_ERR_LEN])
{
    memset(d, 0, sizeof *d);
    image_job j = {lim, d, channel};
    return obs__exr_read_with(path ? path : "EXR in memory", mem ? NULL : path, mem, image_reader,
                              &j, err);
}

obs_status obs__deep_read_front(const char *path, const obs__exr_mem *mem, const char *channel,
                                const obs_limits *lim, obs_image *out, char err[OBS_ERR_LEN])
{
    obs_deep_image d;
    memset(out, 0, sizeof *out);
    obs_status st = read_with_channel(path, mem, channel, lim, &d, err);
    size_t n = (size_t)d.width * (size_t)d.height;
    if (st == OBS_OK && !(out->data = malloc((n ? n : 1) * sizeof(float))))
        st = obs__fail(err, OBS_NO_MEMORY, "channel of %dx%d", d.width, d.height);
    if (st == OBS_OK) {
        out->width = d.width;
        out->height = d.height;
        out->channels = 1;
        /* the lists are sorted front to back: the first is the surface seen */
        for (size_t i = 0; i < n; i++)
            out->data[i] = d.offset[i + 1] > d.offset[i]
                               ? d.samples[d.offset[i] * OBS_DEEP_CH + OBS_DEEP_R]
                               : 0.0f;
    }
    obs_deep_free(&d);
    return st;
}

obs_status obs__deep_read_samples(const char *path, const obs__exr_mem *mem, const char *channel,
                                  const obs_limits *lim, obs_image *out, char err[OBS_ERR_LEN])
{
    obs_deep_image d;
    memset(out, 0, sizeof *out);
    obs_status st = read_with_channel(path, mem, channel, lim, &d, err);
    const size_t n = st == OBS_OK ? (size_t)d.offset[(size_t)d.width * (size_t)d.height] : 0;
    if (st == OBS_OK && !(out->data = calloc(n ? n : 1, sizeof(float))))
        st = obs__fail(err, OBS_NO_MEMORY, "channel of %zu deep samples", n);
    if (st == OBS_OK) {
        out->width = n ? (int)n : 1; /* n <= OBS_DEEP_MAX_SAMPLES */
        out->height = 1;
        out->channels = 1;
        for (size_t i = 0; i < n; i++) /* in the reader's order: sorted front to back */
            out->data[i] = d.samples[i * OBS_DEEP_CH + OBS_DEEP_R];
    }
    obs_deep_free(&d);
    return st;
}

obs_status obs_deep_read_exr(const char *path, const obs_limits *lim, obs_deep_image *out,
                             char err[OBS_ERR_LEN])
{
    if (!path || !*path)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no EXR path given");
    return read_any(path, path, NULL, lim, out, err);
}

obs_status obs_deep_read_exr_mem(const void *buf, size_t len, const obs_limits *lim,
                                 obs_deep_image *out, char err[OBS_ERR_LEN])
{
    mem_src mem = {buf, len};
    if (!buf || len == 0)
        return obs__fail(err, OBS_BAD_FILE, "EXR in memory: empty buffer");
    return read_any("EXR in memory", NULL, &mem, lim, out, err);
}

void obs_deep_free(obs_deep_image *d)
{
    if (!d)
        return;
    free(d->offset);
    free(d->samples);
    free(d->receivers);
    free(d->occluders);
    free(d->object_id);
    memset(d, 0, sizeof *d);
}
