/* The binary protocol: frame headers, requests and responses (see
 * protocol/PROTOCOL.md).  Little-endian on the wire; the reader is a
 * bounds-checked cursor, the writer counts first and fills second, so a
 * frame is allocated once, at its exact size. */
#include "binary.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the binary protocol copies float32 planes as they are: little-endian hosts only"
#endif

#define RAW_HEADER_LEN 160  /* width .. projection, see PROTOCOL.md */
#define DEEP_HEADER_LEN 176 /* width .. projection of a deep G-buffer */
#define DEEP_FLAGS (OBS_BIN_DEEP_ZBACK | OBS_BIN_DEEP_ALPHA | OBS_BIN_HAS_WORLD_TO_CAMERA | \
                    OBS_BIN_HAS_PROJECTION | OBS_BIN_DEEP_COLOR | OBS_BIN_DEEP_NORMAL | \
                    OBS_BIN_DEEP_FACING)

/* The message into err (when set), and s.  This file's own: the protocol
 * is built against the public headers, not core's internal ones. */
#define fail obs_status_fail

/* a * b * c without overflow; 0 on overflow. */
static int mul3(uint64_t a, uint64_t b, uint64_t c, uint64_t *out)
{
    if ((b && a > UINT64_MAX / b) || (c && a * b > UINT64_MAX / c))
        return 0;
    *out = a * b * c;
    return 1;
}

/* The fields both G-buffer headers open with: the data window's size,
 * the display window, the flags. */
typedef struct window_fields {
    uint32_t width, height, dx, dy, dw, dh, flags;
} window_fields;

/* ---- writer: counts when p is NULL ---------------------------------------- */

typedef struct writer {
    unsigned char *p;
    size_t n;
} writer;

static void put(writer *w, const void *src, size_t len)
{
    if (w->p && len)
        memcpy(w->p + w->n, src, len);
    w->n += len;
}

/* v as an n-byte little-endian unsigned (n 1 to 8). */
static void put_le(writer *w, uint64_t v, size_t n)
{
    unsigned char b[8];
    for (size_t i = 0; i < n; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    put(w, b, n);
}
#define put_u8(w, v) put_le(w, v, 1)
#define put_u16(w, v) put_le(w, v, 2)
#define put_u32(w, v) put_le(w, v, 4)
#define put_u64(w, v) put_le(w, v, 8)

static void put_window(writer *w, const window_fields *f)
{
    put_u32(w, f->width);
    put_u32(w, f->height);
    put_u32(w, f->dx);
    put_u32(w, f->dy);
    put_u32(w, f->dw);
    put_u32(w, f->dh);
    put_u32(w, f->flags);
}

/* Zero bytes up to the next multiple of 8 of the payload offset. */
static void put_pad8(writer *w, size_t payload_start)
{
    static const unsigned char zero[8];
    put(w, zero, (8 - (w->n - payload_start) % 8) % 8);
}

/* A plane of w x h pixels, `ch` floats each, tightly packed on the wire. */
static void put_plane(writer *w, const obs_plane *pl, int width, int height, int ch)
{
    size_t row = (size_t)width * (size_t)ch * sizeof(float);
    size_t stride = pl->row_stride ? pl->row_stride : row;
    if (!w->p) {
        w->n += row * (size_t)height;
        return;
    }
    if (stride == row) {
        put(w, pl->data, row * (size_t)height);
        return;
    }
    for (int y = 0; y < height; y++)
        put(w, (const unsigned char *)pl->data + (size_t)y * stride, row);
}

/* A frame (header and payload) that write(w, desc, payload length) writes:
 * counted first, then written into one allocation of its exact size. */
static obs_status write_frame(void (*write)(writer *w, const void *desc, uint64_t payload_len),
                              const void *desc, const char *what, obs_bytes *out,
                              char err[OBS_ERR_LEN])
{
    writer w = {NULL, 0};
    write(&w, desc, 0);
    if (!(w.p = malloc(w.n)))
        return fail(err, OBS_NO_MEMORY, "no memory for a %zu-byte %s", w.n, what);
    size_t total = w.n;
    w.n = 0;
    write(&w, desc, total - OBS_BIN_HEADER_LEN);
    out->data = w.p;
    out->size = total;
    return OBS_OK;
}

/* ---- reader ---------------------------------------------------------------- */

typedef struct reader {
    const unsigned char *p;
    size_t n, off;
    const char *what; /* "request" or "response", for messages */
    /* A request's head is parsed from the part of the payload read so
     * far: full is the whole payload's length (n or more), and a field
     * that lies beyond n but within full sets `want` (the bytes needed)
     * instead of being an error. */
    size_t full, want;
} reader;

static int have(reader *r, uint64_t len)
{
    if (len <= r->n - r->off)
        return 1;
    if (r->full > r->n && len <= r->full - r->off)
        r->want = r->off + (size_t)len;
    return 0;
}

static int get(reader *r, void *dst, size_t len)
{
    if (!have(r, len))
        return 0;
    memcpy(dst, r->p + r->off, len);
    r->off += len;
    return 1;
}

/* The n-byte little-endian unsigned at b (n 1 to 8): every field the
 * reader takes, and the deep counts and float16 values read in place. */
static uint64_t le_bytes(const unsigned char *b, size_t n)
{
    uint64_t v = 0;
    while (n--)
        v = v << 8 | b[n];
    return v;
}

static int get_le(reader *r, size_t n, uint64_t *v)
{
    unsigned char b[8];
    if (!get(r, b, n))
        return 0;
    *v = le_bytes(b, n);
    return 1;
}

/* A field of 1, 2 or 4 bytes. */
static int get_le32(reader *r, size_t n, uint32_t *v)
{
    uint64_t x;
    if (!get_le(r, n, &x))
        return 0;
    *v = (uint32_t)x;
    return 1;
}
#define get_u8(r, v) get_le32(r, 1, v)
#define get_u16(r, v) get_le32(r, 2, v)
#define get_u32(r, v) get_le32(r, 4, v)
#define get_u64(r, v) get_le(r, 8, v)

static int get_pad8(reader *r)
{
    size_t pad = (8 - r->off % 8) % 8;
    if (!have(r, pad))
        return 0;
    for (size_t i = 0; i < pad; i++)
        if (r->p[r->off + i] != 0)
            return 0;
    r->off += pad;
    return 1;
}

static obs_status truncated(const reader *r, const char *field, char err[OBS_ERR_LEN])
{
    return fail(err, OBS_BAD_FILE, "malformed %s: %s at byte %zu of a %zu-byte payload "
                "(truncated or corrupt)", r->what, field, r->off, r->full > r->n ? r->full : r->n);
}

/* ---- header ---------------------------------------------------------------- */

void obs_bin_header_write(unsigned char *out, obs_bin_kind kind, uint64_t id, uint64_t length)
{
    writer w = {out, 0};
    put(&w, OBS_BIN_MAGIC, 4);
    put_u16(&w, OBS_BIN_VERSION);
    put_u16(&w, (unsigned)kind);
    put_u64(&w, id);
    put_u64(&w, length);
}

obs_status obs_bin_header_parse(const unsigned char *in, obs_bin_header *h, uint64_t max_payload,
                                char err[OBS_ERR_LEN])
{
    reader r = {in, OBS_BIN_HEADER_LEN, 4, "header"};
    uint32_t version = 0, kind = 0;
    memset(h, 0, sizeof *h);
    if (memcmp(in, OBS_BIN_MAGIC, 4) != 0)
        return fail(err, OBS_BAD_FILE, "not an obscura binary-protocol frame (magic is not '%s')",
                    OBS_BIN_MAGIC);
    get_u16(&r, &version);
    get_u16(&r, &kind);
    get_u64(&r, &h->id);
    get_u64(&r, &h->length);
    if (version != OBS_BIN_VERSION)
        return fail(err, OBS_UNSUPPORTED, "protocol version %u is not supported (this is version %d)",
                    version, OBS_BIN_VERSION);
    if (kind != OBS_BIN_REQUEST && kind != OBS_BIN_RESPONSE)
        return fail(err, OBS_BAD_FILE, "frame kind %u is neither request (1) nor response (2)", kind);
    h->kind = (obs_bin_kind)kind;
    if (h->length > max_payload)
        return fail(err, OBS_TOO_LARGE, "frame payload of %llu bytes is over the limit of %llu bytes",
                    (unsigned long long)h->length, (unsigned long long)max_payload);
    return OBS_OK;
}

/* ---- requests -------------------------------------------------------------- */

static obs_status check_gbuffer(const obs_gbuffer *gb, char err[OBS_ERR_LEN])
{
    if (!gb->depth.data || gb->width <= 0 || gb->height <= 0)
        return fail(err, OBS_INVALID_ARGUMENT, "raw G-buffer: depth plane and a size are required");
    if (gb->depth.channels != 1 || (gb->normal.data && gb->normal.channels != 3) ||
        (gb->color.data && gb->color.channels != 4))
        return fail(err, OBS_INVALID_ARGUMENT, "raw G-buffer: planes must be depth 1, normal 3, "
                    "colour 4 channels");
    return OBS_OK;
}

/* A deep image the encoder can send: sizes within the decoder's limits,
 * each pixel's samples sorted front to back. */
static obs_status check_deep(const obs_deep_image *d, char err[OBS_ERR_LEN])
{
    if (!d->offset || d->width <= 0 || d->height <= 0)
        return fail(err, OBS_INVALID_ARGUMENT, "deep G-buffer: offsets and a size are required");
    size_t npx = (size_t)d->width * (size_t)d->height;
    if (d->offset[0] != 0 || d->offset[npx] > OBS_DEEP_MAX_SAMPLES || (d->offset[npx] && !d->samples))
        return fail(err, OBS_INVALID_ARGUMENT, "deep G-buffer: %llu samples (at most %llu)",
                    (unsigned long long)d->offset[npx], (unsigned long long)OBS_DEEP_MAX_SAMPLES);
    for (size_t i = 0; i < npx; i++)
        if (d->offset[i + 1] < d->offset[i] || d->offset[i + 1] - d->offset[i] > OBS_DEEP_MAX_PER_PIXEL)
            return fail(err, OBS_INVALID_ARGUMENT, "deep G-buffer: pixel %zu holds a bad sample count", i);
    return OBS_OK;
}

static void write_deep(writer *w, const obs_deep_image *d)
{
    const obs_camera *cam = &d->camera;
    size_t npx = (size_t)d->width * (size_t)d->height;
    uint32_t flags = (d->has_zback ? OBS_BIN_DEEP_ZBACK : 0) | (d->has_alpha ? OBS_BIN_DEEP_ALPHA : 0) |
                     (cam->has_world_to_camera ? OBS_BIN_HAS_WORLD_TO_CAMERA : 0) |
                     (cam->has_projection ? OBS_BIN_HAS_PROJECTION : 0) |
                     (d->has_color ? OBS_BIN_DEEP_COLOR : 0) | (d->has_normal ? OBS_BIN_DEEP_NORMAL : 0) |
                     (d->has_facing ? OBS_BIN_DEEP_FACING : 0);
    put_window(w, &(window_fields){(uint32_t)d->width, (uint32_t)d->height, (uint32_t)d->display_x,
                                   (uint32_t)d->display_y, (uint32_t)d->display_width,
                                   (uint32_t)d->display_height, flags});
    put_u32(w, OBS_DEEP_CH);
    put_u32(w, OBS_BIN_F32);
    put_u32(w, 0);
    put_u64(w, d->offset[npx]);
    put(w, cam->world_to_camera, sizeof cam->world_to_camera);
    put(w, cam->projection, sizeof cam->projection);
    if (!w->p) {
        w->n += npx * 4 + (size_t)d->offset[npx] * OBS_DEEP_CH * sizeof(float);
        return;
    }
    for (size_t i = 0; i < npx; i++)
        put_u32(w, (uint32_t)(d->offset[i + 1] - d->offset[i]));
    put(w, d->samples, (size_t)d->offset[npx] * OBS_DEEP_CH * sizeof(float));
}

static void write_request(writer *w, const void *desc, uint64_t payload_len)
{
    const obs_bin_request_desc *d = desc;
    unsigned char hdr[OBS_BIN_HEADER_LEN];
    obs_bin_header_write(hdr, OBS_BIN_REQUEST, d->id, payload_len);
    put(w, hdr, sizeof hdr);
    size_t start = w->n;
    put_u32(w, (uint32_t)d->param_count);
    for (int i = 0; i < d->param_count; i++) {
        size_t nl = strlen(d->params[i].name), vl = strlen(d->params[i].value);
        put_u16(w, (unsigned)nl);
        put(w, d->params[i].name, nl);
        put_u32(w, (uint32_t)vl);
        put(w, d->params[i].value, vl);
    }
    if (d->exr) {
        put_u8(w, OBS_BIN_EXR);
        put_pad8(w, start);
        put_u64(w, d->exr_len);
        put(w, d->exr, d->exr_len);
        return;
    }
    if (d->deep) {
        put_u8(w, OBS_BIN_DEEP);
        put_pad8(w, start);
        write_deep(w, d->deep);
        return;
    }
    const obs_gbuffer *gb = d->gb;
    const obs_camera *cam = &gb->camera;
    uint32_t flags = (gb->normal.data ? OBS_BIN_HAS_NORMAL : 0) | (gb->color.data ? OBS_BIN_HAS_COLOR : 0) |
                     (cam->has_world_to_camera ? OBS_BIN_HAS_WORLD_TO_CAMERA : 0) |
                     (cam->has_projection ? OBS_BIN_HAS_PROJECTION : 0);
    put_u8(w, OBS_BIN_RAW);
    put_pad8(w, start);
    put_window(w, &(window_fields){(uint32_t)gb->width, (uint32_t)gb->height, (uint32_t)gb->display_x,
                                   (uint32_t)gb->display_y, (uint32_t)gb->display_width,
                                   (uint32_t)gb->display_height, flags});
    put_u32(w, 0);
    put(w, cam->world_to_camera, sizeof cam->world_to_camera);
    put(w, cam->projection, sizeof cam->projection);
    put_plane(w, &gb->depth, gb->width, gb->height, 1);
    if (gb->normal.data)
        put_plane(w, &gb->normal, gb->width, gb->height, 3);
    if (gb->color.data)
        put_plane(w, &gb->color, gb->width, gb->height, 4);
}

obs_status obs_bin_request_encode(const obs_bin_request_desc *d, obs_bytes *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    if (!!d->gb + !!d->exr + !!d->deep != 1)
        return fail(err, OBS_INVALID_ARGUMENT, "a request carries one of raw planes, an EXR or a "
                    "deep G-buffer");
    if (d->param_count < 0 || d->param_count > OBS_BIN_MAX_PARAMS)
        return fail(err, OBS_INVALID_ARGUMENT, "at most %d parameters", OBS_BIN_MAX_PARAMS);
    for (int i = 0; i < d->param_count; i++) {
        size_t nl = strlen(d->params[i].name), vl = strlen(d->params[i].value);
        if (nl == 0 || nl > OBS_BIN_MAX_NAME || vl > OBS_BIN_MAX_VALUE)
            return fail(err, OBS_INVALID_ARGUMENT, "parameter '%.64s': name of 1 to %d bytes and "
                        "value of at most %d bytes", d->params[i].name, OBS_BIN_MAX_NAME, OBS_BIN_MAX_VALUE);
    }
    obs_status s = d->gb ? check_gbuffer(d->gb, err) : d->deep ? check_deep(d->deep, err) : OBS_OK;
    if (s != OBS_OK)
        return s;
    return write_frame(write_request, d, "request", out, err);
}

/* Sets one name=value pair of a request. */
static obs_status request_param(obs_bin_request *q, const char *name, const char *value,
                                char err[OBS_ERR_LEN])
{
    if (!strcmp(name, "token")) {
        size_t n = strlen(value);
        if (n >= sizeof q->token)
            return fail(err, OBS_INVALID_ARGUMENT, "parameter token: longer than %zu bytes",
                        sizeof q->token - 1);
        memcpy(q->token, value, n + 1);
        return OBS_OK;
    }
    if (!strcmp(name, "format") && !strcmp(value, "raw")) {
        q->raw_out = 1;
        return OBS_OK;
    }
    if (!strcmp(name, "format"))
        q->raw_out = 0;
    return obs_http_request_set(&q->hr, name, value, err);
}

/* Parameter i: name and value, NUL-terminated. */
static obs_status get_param(reader *r, uint32_t i, char name[OBS_BIN_MAX_NAME + 1],
                            char value[OBS_BIN_MAX_VALUE + 1], char err[OBS_ERR_LEN])
{
    uint32_t nl, vl;
    if (!get_u16(r, &nl))
        return truncated(r, "parameter name length", err);
    if (nl == 0 || nl > OBS_BIN_MAX_NAME)
        return fail(err, OBS_BAD_FILE, "malformed request: parameter %u has a name of %u bytes "
                    "(1 to %d)", i, nl, OBS_BIN_MAX_NAME);
    if (!get(r, name, nl))
        return truncated(r, "parameter name", err);
    name[nl] = '\0';
    if (!get_u32(r, &vl))
        return truncated(r, "parameter value length", err);
    if (vl > OBS_BIN_MAX_VALUE)
        return fail(err, OBS_BAD_FILE, "malformed request: parameter '%.64s' has a value of %u "
                    "bytes (at most %d)", name, vl, OBS_BIN_MAX_VALUE);
    if (!get(r, value, vl))
        return truncated(r, "parameter value", err);
    value[vl] = '\0';
    if (memchr(name, 0, nl) || memchr(value, 0, vl))
        return fail(err, OBS_BAD_FILE, "malformed request: a NUL byte in parameter %u", i);
    return OBS_OK;
}

/* A plane of `ch` floats per pixel at the reader's offset: points into
 * the payload when aligned, else into dst (a copy). */
static const float *take_plane(reader *r, uint64_t bytes, float *dst)
{
    const unsigned char *src = r->p + r->off;
    r->off += (size_t)bytes;
    if (((uintptr_t)src & 3u) == 0)
        return (const float *)(const void *)src;
    memcpy(dst, src, (size_t)bytes);
    return dst;
}

/* IEEE-754 binary16 -> binary32, exactly: every half is a float.
 * Subnormal halves become normal floats; inf stays inf; a NaN keeps its
 * sign and payload (shifted into the float's top mantissa bits). */
float obs_bin_half_to_float(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16, exp = (h >> 10) & 0x1fu, man = h & 0x3ffu, bits;
    if (exp == 0x1f)
        bits = sign | 0x7f800000u | man << 13;
    else if (exp)
        bits = sign | (exp + 112) << 23 | man << 13;
    else if (!man)
        bits = sign;
    else {
        /* man * 2^-24: normalise so the leading 1 lands on bit 10. */
        exp = 113;
        while (!(man & 0x400u)) {
            man <<= 1;
            exp--;
        }
        bits = sign | exp << 23 | (man & 0x3ffu) << 13;
    }
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* Float16 planes: converted into q->gf.storage, depth then normal then
 * colour, `channels` floats per pixel in all. */
static obs_status take_half_planes(reader *r, uint64_t px, uint64_t channels, obs_bin_request *q,
                                   char err[OBS_ERR_LEN])
{
    size_t n = (size_t)(px * channels);
    if (!(q->gf.storage = malloc(n * sizeof(float))))
        return fail(err, OBS_NO_MEMORY, "no memory for %zu float16 values", n);
    const unsigned char *src = r->p + r->off;
    for (size_t i = 0; i < n; i++)
        q->gf.storage[i] = obs_bin_half_to_float((uint16_t)le_bytes(src + 2 * i, 2));
    r->off += n * 2;
    return OBS_OK;
}

/* 0 when the payload is shorter than the header's header_len bytes. */
static int get_window(reader *r, uint64_t header_len, window_fields *w)
{
    if (!have(r, header_len))
        return 0;
    get_u32(r, &w->width);
    get_u32(r, &w->height);
    get_u32(r, &w->dx);
    get_u32(r, &w->dy);
    get_u32(r, &w->dw);
    get_u32(r, &w->dh);
    get_u32(r, &w->flags);
    return 1;
}

/* The two matrices after a header's fields (have() counted them in),
 * each the camera's where the flags say it is given. */
static void get_camera(reader *r, uint32_t flags, obs_camera *cam)
{
    get(r, cam->world_to_camera, sizeof cam->world_to_camera);
    get(r, cam->projection, sizeof cam->projection);
    obs_camera_from_request(cam, flags & OBS_BIN_HAS_WORLD_TO_CAMERA, flags & OBS_BIN_HAS_PROJECTION);
}

/* The window's size against the limits, the display window's a size
 * (what: the header's name for the messages). */
static obs_status check_window(const window_fields *w, const obs_limits *lim, const char *what,
                               char err[OBS_ERR_LEN])
{
    obs_status s = obs_check_size(lim, w->width, w->height, err);
    if (s != OBS_OK)
        return s;
    if ((int32_t)w->dw < 0 || (int32_t)w->dh < 0 || w->dw > (1u << 20) || w->dh > (1u << 20))
        return fail(err, OBS_BAD_FILE, "%s: display window %u x %u is not a size", what, w->dw,
                    w->dh);
    return OBS_OK;
}

/* The fixed fields of a raw G-buffer, before its planes. */
typedef struct raw_fields {
    window_fields w;
    uint32_t type;
    uint64_t px, channels, bytes; /* the planes: pixels, channels, bytes */
} raw_fields;

/* Reads and checks the fields of a raw G-buffer's header (the matrices
 * stay for the caller), and that the planes they announce are the rest
 * of the payload (`rest` bytes after the header), exactly. */
static obs_status get_raw_fields(reader *r, const obs_limits *lim, raw_fields *f, char err[OBS_ERR_LEN])
{
    if (!get_window(r, RAW_HEADER_LEN, &f->w))
        return truncated(r, "raw G-buffer header", err);
    get_u32(r, &f->type);
    if (f->w.flags & ~0xfu)
        return fail(err, OBS_BAD_FILE, "raw G-buffer: unknown flags 0x%x", f->w.flags);
    if (f->type != OBS_BIN_F32 && f->type != OBS_BIN_F16)
        return fail(err, OBS_BAD_FILE, "raw G-buffer: plane type %u is neither float32 (0) nor "
                    "float16 (1)", f->type);
    obs_status s = check_window(&f->w, lim, "raw G-buffer", err);
    if (s != OBS_OK)
        return s;
    /* Exactly the planes the flags announce, and nothing after them. */
    size_t full = r->full > r->n ? r->full : r->n, rest = full - r->off - 128;
    uint64_t value_size = f->type == OBS_BIN_F16 ? 2 : sizeof(float);
    f->px = (uint64_t)f->w.width * f->w.height;
    f->channels = 1 + ((f->w.flags & OBS_BIN_HAS_NORMAL) ? 3 : 0) + ((f->w.flags & OBS_BIN_HAS_COLOR) ? 4 : 0);
    f->bytes = 0;
    if (!mul3(f->px, f->channels, value_size, &f->bytes) || f->bytes != rest)
        return fail(err, OBS_BAD_FILE, "raw G-buffer: %u x %u with %llu %s channels needs %llu bytes "
                    "of planes, the frame holds %zu", f->w.width, f->w.height, (unsigned long long)f->channels,
                    f->type == OBS_BIN_F16 ? "float16" : "float32", (unsigned long long)f->bytes, rest);
    return OBS_OK;
}

/* A raw G-buffer after its fixed fields (get_raw_fields): the matrices
 * and the planes. */
static obs_status decode_raw(reader *r, const raw_fields *rf, obs_bin_request *q, char err[OBS_ERR_LEN])
{
    uint32_t width = rf->w.width, height = rf->w.height, dx = rf->w.dx, dy = rf->w.dy, dw = rf->w.dw;
    uint32_t dh = rf->w.dh, flags = rf->w.flags, type = rf->type;
    obs_gbuffer *gb = &q->gf.gb;
    get_camera(r, flags, &gb->camera);
    uint64_t px = rf->px, channels = rf->channels, bytes = rf->bytes;
    gb->width = (int)width;
    gb->height = (int)height;
    gb->display_x = (int32_t)dx;
    gb->display_y = (int32_t)dy;
    gb->display_width = (int)dw;
    gb->display_height = (int)dh;
    if (type == OBS_BIN_F16) {
        obs_status hs = take_half_planes(r, px, channels, q, err);
        if (hs != OBS_OK)
            return hs;
        float *f = q->gf.storage;
        gb->depth = (obs_plane){f, 1, 0};
        if (flags & OBS_BIN_HAS_NORMAL)
            gb->normal = (obs_plane){f + px, 3, 0};
        if (flags & OBS_BIN_HAS_COLOR)
            gb->color = (obs_plane){f + px * (channels - 4), 4, 0};
        return OBS_OK;
    }
    if (((uintptr_t)(r->p + r->off) & 3u) != 0 && !(q->gf.storage = malloc((size_t)bytes)))
        return fail(err, OBS_NO_MEMORY, "no memory for %llu bytes of planes", (unsigned long long)bytes);
    float *copy = q->gf.storage;
    gb->depth = (obs_plane){take_plane(r, px * 4, copy), 1, 0};
    if (flags & OBS_BIN_HAS_NORMAL)
        gb->normal = (obs_plane){take_plane(r, px * 12, copy ? copy + px : NULL), 3, 0};
    if (flags & OBS_BIN_HAS_COLOR)
        gb->color = (obs_plane){take_plane(r, px * 16, copy ? copy + px * (channels - 4) : NULL), 4, 0};
    return OBS_OK;
}

/* Z as the deep reader sorts it: NaN after everything. */
static float sort_key(float z) { return z != z ? INFINITY : z; }

/* A deep G-buffer (PROTOCOL.md, "Deep G-buffer"): every size is checked
 * before anything is allocated: the window against the limits, the
 * sample total against OBS_DEEP_MAX_SAMPLES, the counts' and samples'
 * bytes against the rest of the payload, then each count against
 * OBS_DEEP_MAX_PER_PIXEL and their sum against the total. */
/* The fixed fields of a deep G-buffer, before its counts. */
typedef struct deep_fields {
    window_fields w;
    uint32_t values, type, reserved;
    uint64_t total, npx, sample_bytes;
} deep_fields;

/* Reads and checks the fields of a deep G-buffer's header (the matrices
 * stay for the caller), and that the counts and samples they announce
 * are the rest of the payload, exactly. */
static obs_status get_deep_fields(reader *r, const obs_limits *lim, deep_fields *f, char err[OBS_ERR_LEN])
{
    if (!get_window(r, DEEP_HEADER_LEN, &f->w))
        return truncated(r, "deep G-buffer header", err);
    get_u32(r, &f->values);
    get_u32(r, &f->type);
    get_u32(r, &f->reserved);
    get_u64(r, &f->total);
    if (f->w.flags & ~(uint32_t)DEEP_FLAGS)
        return fail(err, OBS_BAD_FILE, "deep G-buffer: unknown flags 0x%x", f->w.flags);
    if (f->values != OBS_DEEP_CH && f->values != OBS_DEEP_CH - 1)
        return fail(err, OBS_BAD_FILE, "deep G-buffer: %u values per sample; the layout has %d "
                    "(Z, ZBack, R, G, B, A, N.X, N.Y, N.Z, Facing) or %d (without Facing)",
                    f->values, OBS_DEEP_CH, OBS_DEEP_CH - 1);
    if (f->values != OBS_DEEP_CH && (f->w.flags & OBS_BIN_DEEP_FACING))
        return fail(err, OBS_BAD_FILE, "deep G-buffer: flag 64 (facing written) with %u values "
                    "per sample, which have no Facing", f->values);
    if (f->type != OBS_BIN_F32 || f->reserved != 0)
        return fail(err, OBS_BAD_FILE, "deep G-buffer: sample type %u (only float32, 0) or reserved "
                    "field %u (0)", f->type, f->reserved);
    obs_status s = check_window(&f->w, lim, "deep G-buffer", err);
    if (s != OBS_OK)
        return s;
    if (f->total > OBS_DEEP_MAX_SAMPLES)
        return fail(err, OBS_TOO_LARGE, "deep G-buffer: %llu samples, over the limit of %llu",
                    (unsigned long long)f->total, (unsigned long long)OBS_DEEP_MAX_SAMPLES);
    /* width x height within the limits, total < 2^25: no overflow below */
    size_t full = r->full > r->n ? r->full : r->n, rest = full - r->off - 128;
    f->npx = (uint64_t)f->w.width * f->w.height;
    f->sample_bytes = f->total * f->values * sizeof(float);
    if (f->npx * 4 + f->sample_bytes != rest)
        return fail(err, OBS_BAD_FILE, "deep G-buffer: %u x %u counts and %llu samples need %llu bytes, "
                    "the frame holds %zu", f->w.width, f->w.height, (unsigned long long)f->total,
                    (unsigned long long)(f->npx * 4 + f->sample_bytes), rest);
    return OBS_OK;
}

/* A deep G-buffer after its fixed fields (get_deep_fields): the
 * matrices, the counts and the samples. */
static obs_status decode_deep(reader *r, const deep_fields *f, obs_bin_request *q, char err[OBS_ERR_LEN])
{
    uint32_t width = f->w.width, height = f->w.height, dx = f->w.dx, dy = f->w.dy, dw = f->w.dw;
    uint32_t dh = f->w.dh, flags = f->w.flags, values = f->values;
    uint64_t total = f->total, npx = f->npx, sample_bytes = f->sample_bytes;
    get_camera(r, flags, &q->deep.camera);
    const unsigned char *cp = r->p + r->off;
    uint64_t sum = 0;
    for (uint64_t i = 0; i < npx; i++) {
        uint32_t c = (uint32_t)le_bytes(cp + 4 * i, 4);
        if (c > OBS_DEEP_MAX_PER_PIXEL)
            return fail(err, OBS_TOO_LARGE, "deep G-buffer: pixel (%llu, %llu) holds %u samples, over the "
                        "limit of %d", (unsigned long long)(i % width), (unsigned long long)(i / width), c,
                        OBS_DEEP_MAX_PER_PIXEL);
        sum += c;
    }
    if (sum != total)
        return fail(err, OBS_BAD_FILE, "deep G-buffer: the pixels' counts sum to %llu samples, the "
                    "header says %llu", (unsigned long long)sum, (unsigned long long)total);
    obs_deep_image *d = &q->deep;
    if (!(d->offset = malloc((size_t)(npx + 1) * sizeof *d->offset)))
        return fail(err, OBS_NO_MEMORY, "no memory for the offsets of %u x %u pixels", width, height);
    d->offset[0] = 0;
    for (uint64_t i = 0; i < npx; i++)
        d->offset[i + 1] = d->offset[i] + le_bytes(cp + 4 * i, 4);
    r->off += (size_t)npx * 4;
    if (total && values != OBS_DEEP_CH) {
        /* the layout without Facing: widened, facing 0 (not known) */
        if (!(q->gf.storage = calloc((size_t)total, OBS_DEEP_CH * sizeof(float))))
            return fail(err, OBS_NO_MEMORY, "no memory for %llu deep samples", (unsigned long long)total);
        for (uint64_t k = 0; k < total; k++)
            memcpy(q->gf.storage + k * OBS_DEEP_CH, r->p + r->off + k * values * sizeof(float),
                   values * sizeof(float));
        d->samples = q->gf.storage;
    } else if (total && ((uintptr_t)(r->p + r->off) & 3u) != 0) {
        if (!(q->gf.storage = malloc((size_t)sample_bytes)))
            return fail(err, OBS_NO_MEMORY, "no memory for %llu deep samples", (unsigned long long)total);
        memcpy(q->gf.storage, r->p + r->off, (size_t)sample_bytes);
        d->samples = q->gf.storage;
    } else {
        /* read-only use: the core takes the image as const */
        d->samples = total ? (float *)(uintptr_t)(r->p + r->off) : NULL;
    }
    r->off += (size_t)sample_bytes;
    /* front to back, as the deep reader leaves them (core/io/exr_deep.c) */
    for (uint64_t i = 0; i < npx; i++)
        for (uint64_t k = d->offset[i] + 1; k < d->offset[i + 1]; k++)
            if (sort_key(d->samples[(k - 1) * OBS_DEEP_CH + OBS_DEEP_Z]) >
                sort_key(d->samples[k * OBS_DEEP_CH + OBS_DEEP_Z]))
                return fail(err, OBS_BAD_FILE, "deep G-buffer: the samples of pixel (%llu, %llu) are not "
                            "sorted by Z, front to back", (unsigned long long)(i % width),
                            (unsigned long long)(i / width));
    d->width = (int)width;
    d->height = (int)height;
    d->display_x = (int32_t)dx;
    d->display_y = (int32_t)dy;
    d->display_width = dw ? (int)dw : (int)width;
    d->display_height = dh ? (int)dh : (int)height;
    d->has_zback = !!(flags & OBS_BIN_DEEP_ZBACK);
    d->has_alpha = !!(flags & OBS_BIN_DEEP_ALPHA);
    d->has_color = !!(flags & OBS_BIN_DEEP_COLOR);
    d->has_normal = !!(flags & OBS_BIN_DEEP_NORMAL);
    d->has_facing = !!(flags & OBS_BIN_DEEP_FACING);
    return OBS_OK;
}

/* A G-buffer's fixed fields, as parse_head leaves them for the body. */
typedef union body_fields {
    raw_fields raw;
    deep_fields deep;
} body_fields;

/* A request's head, read and checked: the parameters into q (their
 * framing first: the token is known even when a value is bad), their
 * checks, the G-buffer's kind, an EXR's length or a raw or deep
 * G-buffer's fixed fields into *bf (the reader left before its
 * matrices).  obs_bin_request_head() and obs_bin_request_decode() both
 * read requests through it, so the first error is the same. */
static obs_status parse_head(reader *r, const obs_limits *lim, obs_bin_head *h, obs_bin_request *q,
                             body_fields *bf, char err[OBS_ERR_LEN])
{
    uint32_t count, body;
    obs_status s = OBS_OK;
    memset(q, 0, sizeof *q);
    obs_http_request_init(&q->hr);
    if (!get_u32(r, &count))
        return truncated(r, "parameter count", err);
    if (count > OBS_BIN_MAX_PARAMS)
        return fail(err, OBS_BAD_FILE, "malformed request: %u parameters (at most %d)", count,
                    OBS_BIN_MAX_PARAMS);
    /* a bad value's error is the answer, after the token */
    obs_status bad_value = OBS_OK;
    char bad_err[OBS_ERR_LEN] = "";
    for (uint32_t i = 0; i < count; i++) {
        char name[OBS_BIN_MAX_NAME + 1], value[OBS_BIN_MAX_VALUE + 1];
        if ((s = get_param(r, i, name, value, err)) != OBS_OK)
            return bad_value != OBS_OK ? (snprintf(err, OBS_ERR_LEN, "%s", bad_err), bad_value) : s;
        if (!strcmp(name, "token") && strlen(value) < sizeof h->token)
            memcpy(h->token, value, strlen(value) + 1);
        if (bad_value == OBS_OK && (s = request_param(q, name, value, bad_err)) != OBS_OK)
            bad_value = s;
    }
    h->params_done = 1;
    if (bad_value != OBS_OK)
        return snprintf(err, OBS_ERR_LEN, "%s", bad_err), bad_value;
    if ((s = obs_http_request_check(&q->hr, err)) != OBS_OK)
        return s;
    if (q->raw_out && q->hr.format != OBS_HTTP_EXR)
        return fail(err, OBS_INVALID_ARGUMENT, "format: raw and png at once");
    if (q->raw_out && (q->hr.outputs & OBS_OUTPUT_DEEP))
        return fail(err, OBS_INVALID_ARGUMENT, "output=deep answers a deep EXR: it needs format=exr, not raw");
    if (q->raw_out && q->hr.append)
        return fail(err, OBS_INVALID_ARGUMENT, "append=1 writes an EXR: it needs format=exr, not raw");
    if (!get_u8(r, &body))
        return truncated(r, "G-buffer kind", err);
    if (!get_pad8(r))
        return truncated(r, "padding", err);
    size_t full = r->full > r->n ? r->full : r->n;
    if (body == OBS_BIN_EXR) {
        uint64_t n;
        if (!get_u64(r, &n))
            return truncated(r, "EXR length", err);
        if (n != full - r->off)
            return fail(err, OBS_BAD_FILE, "malformed request: EXR of %llu bytes, the frame holds %zu",
                        (unsigned long long)n, full - r->off);
        if (n == 0)
            return fail(err, OBS_BAD_FILE, "malformed request: empty EXR");
    } else if (body == OBS_BIN_DEEP || body == OBS_BIN_RAW) {
        q->body = (obs_bin_body)body;
        s = body == OBS_BIN_DEEP ? get_deep_fields(r, lim, &bf->deep, err)
                                 : get_raw_fields(r, lim, &bf->raw, err);
        if (s != OBS_OK)
            return s;
        const window_fields *w = body == OBS_BIN_DEEP ? &bf->deep.w : &bf->raw.w;
        h->width = w->width;
        h->height = w->height;
    } else {
        return fail(err, OBS_BAD_FILE, "malformed request: G-buffer kind %u is not EXR (1), raw (2) "
                    "or deep (4)", body);
    }
    h->body = (obs_bin_body)body;
    return OBS_OK;
}

obs_status obs_bin_request_decode(const unsigned char *payload, size_t len, const obs_limits *lim,
                                  obs_bin_request *out, char err[OBS_ERR_LEN])
{
    reader r = {payload, len, 0, "request"};
    obs_bin_head h;
    body_fields bf;
    memset(&h, 0, sizeof h);
    obs_status s = parse_head(&r, lim, &h, out, &bf, err);
    if (s != OBS_OK)
        return s;
    if (h.body == OBS_BIN_EXR) {
        out->body = OBS_BIN_EXR;
        out->exr = r.p + r.off;
        out->exr_len = r.n - r.off; /* the EXR's length, checked */
        return OBS_OK;
    }
    s = h.body == OBS_BIN_DEEP ? decode_deep(&r, &bf.deep, out, err)
                               : decode_raw(&r, &bf.raw, out, err);
    if (s != OBS_OK)
        obs_bin_request_free(out);
    return s;
}

obs_status obs_bin_request_head(const unsigned char *p, size_t have_len, size_t len, const obs_limits *lim,
                                obs_bin_head *h, size_t *need, char err[OBS_ERR_LEN])
{
    reader r = {p, have_len < len ? have_len : len, 0, "request", len, 0};
    obs_bin_request scratch;
    body_fields bf;
    memset(h, 0, sizeof *h);
    obs_status s = parse_head(&r, lim, h, &scratch, &bf, err);
    *need = r.want;
    if (r.want) {
        h->len = 0;
        return OBS_OK;
    }
    if (s == OBS_OK && h->body != OBS_BIN_EXR)
        r.off += 128; /* the matrices: have() counted them in */
    h->len = s == OBS_OK ? r.off : 0;
    return s;
}

void obs_bin_request_free(obs_bin_request *q)
{
    if (!q)
        return;
    free(q->gf.storage);
    memset(&q->gf, 0, sizeof q->gf);
    free(q->deep.offset);
    memset(&q->deep, 0, sizeof q->deep);
    q->exr = NULL;
    q->exr_len = 0;
}

/* ---- responses ------------------------------------------------------------- */

/* A 200's message: its warnings, one a line, whole ones only, in
 * out[OBS_BIN_MAX_MESSAGE + 1]. */
static const char *warning_lines(const obs_bin_response_desc *d, char *out)
{
    size_t n = 0;
    out[0] = '\0';
    for (int i = 0; i < d->warning_count && i < OBS_BIN_MAX_WARNINGS; i++) {
        const char *t = d->warnings[i] ? d->warnings[i] : "";
        size_t len = strlen(t);
        if (len == 0)
            continue;
        if (n + (n > 0) + len > OBS_BIN_MAX_MESSAGE)
            break;
        if (n > 0)
            out[n++] = '\n';
        for (size_t k = 0; k < len; k++)
            out[n++] = t[k] == '\n' || t[k] == '\r' ? ' ' : t[k];
        out[n] = '\0';
    }
    return out;
}

static void write_response(writer *w, const void *desc, uint64_t payload_len)
{
    const obs_bin_response_desc *d = desc;
    unsigned char hdr[OBS_BIN_HEADER_LEN];
    char lines[OBS_BIN_MAX_MESSAGE + 1];
    obs_bin_header_write(hdr, OBS_BIN_RESPONSE, d->id, payload_len);
    put(w, hdr, sizeof hdr);
    size_t start = w->n;
    const char *code = d->code ? d->code : "";
    const char *msg = d->status == 200 && d->warning_count > 0 ? warning_lines(d, lines)
                      : d->message                            ? d->message
                                                              : "";
    size_t cl = strnlen(code, 63), ml = strnlen(msg, OBS_BIN_MAX_MESSAGE);
    put_u16(w, (unsigned)d->status);
    put_u16(w, (unsigned)d->retry_after);
    put_u16(w, (unsigned)cl);
    put(w, code, cl);
    put_u32(w, (uint32_t)ml);
    put(w, msg, ml);
    put_u8(w, d->body);
    put_pad8(w, start);
    if (d->body == OBS_BIN_EXR || d->body == OBS_BIN_PNG) {
        put_u64(w, d->blob_len);
        put(w, d->blob, d->blob_len);
    } else if (d->body == OBS_BIN_RAW) {
        put_u32(w, (uint32_t)d->image_count);
        for (int i = 0; i < d->image_count; i++) {
            const obs_image *im = &d->images[i].image;
            put_u32(w, d->images[i].output);
            put_u32(w, (uint32_t)im->width);
            put_u32(w, (uint32_t)im->height);
            put_u32(w, (uint32_t)im->channels);
            put(w, im->data, (size_t)im->width * im->height * im->channels * sizeof(float));
        }
    }
}

obs_status obs_bin_response_encode(const obs_bin_response_desc *d, obs_bytes *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    if (d->status < 100 || d->status > 599 || d->retry_after < 0 || d->retry_after > 65535)
        return fail(err, OBS_INVALID_ARGUMENT, "response status %d or retry-after %d out of range",
                    d->status, d->retry_after);
    if (d->body == OBS_BIN_RAW) {
        if (d->image_count < 1 || d->image_count > OBS_BIN_MAX_IMAGES)
            return fail(err, OBS_INVALID_ARGUMENT, "1 to %d raw images", OBS_BIN_MAX_IMAGES);
        for (int i = 0; i < d->image_count; i++) {
            const obs_image *im = &d->images[i].image;
            if (!im->data || im->width <= 0 || im->height <= 0 || im->channels < 1 || im->channels > 4)
                return fail(err, OBS_INVALID_ARGUMENT, "raw image %d is empty or has %d channels", i,
                            im->channels);
        }
    }
    return write_frame(write_response, d, "response", out, err);
}

/* A 200's message into its lines, the warnings (empty lines skipped). */
static void split_warnings(obs_bin_response *out)
{
    memcpy(out->warning_text, out->message, sizeof out->warning_text);
    for (char *p = out->warning_text; *p && out->warning_count < OBS_BIN_MAX_WARNINGS;) {
        size_t len = strcspn(p, "\n");
        char *next = p[len] ? p + len + 1 : p + len;
        p[len] = '\0';
        if (len > 0)
            out->warnings[out->warning_count++] = p;
        p = next;
    }
}

obs_status obs_bin_response_decode(const unsigned char *payload, size_t len, const obs_limits *lim,
                                   obs_bin_response *out, char err[OBS_ERR_LEN])
{
    reader r = {payload, len, 0, "response"};
    uint32_t status, retry, cl, body, ml;
    obs_status s = OBS_OK;
    memset(out, 0, sizeof *out);
    if (!get_u16(&r, &status) || !get_u16(&r, &retry) || !get_u16(&r, &cl))
        return truncated(&r, "status", err);
    if (cl >= sizeof out->code)
        return fail(err, OBS_BAD_FILE, "malformed response: code of %u bytes", cl);
    if (!get(&r, out->code, cl))
        return truncated(&r, "code", err);
    if (!get_u32(&r, &ml))
        return truncated(&r, "message length", err);
    if (ml > OBS_BIN_MAX_MESSAGE)
        return fail(err, OBS_BAD_FILE, "malformed response: message of %u bytes", ml);
    if (!get(&r, out->message, ml))
        return truncated(&r, "message", err);
    if (!get_u8(&r, &body) || !get_pad8(&r))
        return truncated(&r, "body kind", err);
    out->status = (int)status;
    out->retry_after = (int)retry;
    out->body = (obs_bin_body)body;
    if (status == 200)
        split_warnings(out);
    switch (body) {
    case OBS_BIN_NONE:
        break;
    case OBS_BIN_EXR:
    case OBS_BIN_PNG: {
        uint64_t n;
        if (!get_u64(&r, &n))
            return truncated(&r, "file length", err);
        if (!have(&r, n))
            return truncated(&r, "file", err);
        out->blob = r.p + r.off;
        out->blob_len = (size_t)n;
        r.off += (size_t)n;
        break;
    }
    case OBS_BIN_RAW: {
        uint32_t count;
        if (!get_u32(&r, &count))
            return truncated(&r, "image count", err);
        if (count < 1 || count > OBS_BIN_MAX_IMAGES)
            return fail(err, OBS_BAD_FILE, "malformed response: %u images (1 to %d)", count,
                        OBS_BIN_MAX_IMAGES);
        for (uint32_t i = 0; i < count; i++) {
            uint32_t output, w, h, c;
            uint64_t bytes = 0;
            if (!get_u32(&r, &output) || !get_u32(&r, &w) || !get_u32(&r, &h) || !get_u32(&r, &c)) {
                s = truncated(&r, "image header", err);
                goto fail;
            }
            if (c < 1 || c > 4) {
                s = fail(err, OBS_BAD_FILE, "malformed response: image %u has %u channels", i, c);
                goto fail;
            }
            if ((s = obs_check_size(lim, w, h, err)) != OBS_OK)
                goto fail;
            if (!mul3((uint64_t)w * h, c, sizeof(float), &bytes) || !have(&r, bytes)) {
                s = truncated(&r, "image pixels", err);
                goto fail;
            }
            obs_image *im = &out->images[i].image;
            if (!(im->data = malloc((size_t)bytes))) {
                s = fail(err, OBS_NO_MEMORY, "no memory for a %u x %u image", w, h);
                goto fail;
            }
            get(&r, im->data, (size_t)bytes);
            im->width = (int)w;
            im->height = (int)h;
            im->channels = (int)c;
            out->images[i].output = output;
            out->image_count = (int)i + 1;
        }
        break;
    }
    default:
        return fail(err, OBS_BAD_FILE, "malformed response: body kind %u", body);
    }
    if (r.off != r.n) {
        s = fail(err, OBS_BAD_FILE, "malformed response: %zu bytes after the body", r.n - r.off);
        goto fail;
    }
    return OBS_OK;
fail:
    obs_bin_response_free(out);
    return s;
}

void obs_bin_response_free(obs_bin_response *r)
{
    if (!r)
        return;
    for (int i = 0; i < r->image_count; i++)
        obs_image_free(&r->images[i].image);
    r->image_count = 0;
}
