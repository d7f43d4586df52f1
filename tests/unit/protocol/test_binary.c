/* The binary protocol's encoder and decoder (protocol/binary.c): round
 * trips, every truncation of a valid frame, oversized sizes refused before
 * allocation, garbage. */
#include "testutil.h"

#include <math.h>

#include "../../../protocol/binary.h"

#define W 7
#define H 5

static float depth[W * H], normal[W * H * 3], color[W * H * 4];

static void fill_gbuffer(obs_gbuffer *gb)
{
    for (int i = 0; i < W * H; i++) {
        depth[i] = 1.0f + (float)i * 0.25f;
        for (int c = 0; c < 3; c++)
            normal[i * 3 + c] = (float)(i + c) / 100.0f;
        for (int c = 0; c < 4; c++)
            color[i * 4 + c] = (float)(i * 4 + c) / 7.0f;
    }
    memset(gb, 0, sizeof *gb);
    gb->width = W;
    gb->height = H;
    gb->display_x = 1;
    gb->display_y = 2;
    gb->display_width = 10;
    gb->display_height = 8;
    gb->depth = (obs_plane){depth, 1, 0};
    gb->normal = (obs_plane){normal, 3, 0};
    gb->color = (obs_plane){color, 4, 0};
    for (int k = 0; k < 16; k++) {
        gb->camera.world_to_camera[k] = (float)k;
        gb->camera.projection[k] = (float)-k;
    }
    gb->camera.has_world_to_camera = 1;
    gb->camera.has_projection = 1;
}

static const obs_bin_param params[] = {
    {"radius", "0.25"}, {"samples", "8"}, {"output", "both"}, {"format", "raw"}, {"token", "t0k"}};

static obs_bytes encode_raw_request(void)
{
    obs_gbuffer gb;
    obs_bytes out;
    char err[OBS_ERR_LEN] = "";
    fill_gbuffer(&gb);
    obs_bin_request_desc d = {.id = 42, .params = params, .param_count = 5, .gb = &gb};
    assert_int_equal(obs_bin_request_encode(&d, &out, err), OBS_OK);
    return out;
}

/* Decodes a whole frame (header + payload) from a fresh, exactly sized
 * heap copy, so that ASan sees any read past the end. */
static obs_status decode_frame(const unsigned char *frame, size_t len, obs_bin_request *q,
                               char err[OBS_ERR_LEN])
{
    obs_bin_header h;
    if (len < OBS_BIN_HEADER_LEN)
        return OBS_BAD_FILE;
    obs_status s = obs_bin_header_parse(frame, &h, 1u << 30, err);
    if (s != OBS_OK)
        return s;
    if (h.length != len - OBS_BIN_HEADER_LEN)
        return OBS_BAD_FILE; /* the stream would wait for more */
    size_t n = len - OBS_BIN_HEADER_LEN;
    unsigned char *copy = malloc(n ? n : 1);
    memcpy(copy, frame + OBS_BIN_HEADER_LEN, n);
    s = obs_bin_request_decode(copy, n, NULL, q, err);
    obs_bin_request_free(q);
    free(copy);
    return s;
}

static void test_raw_round_trip(void **state)
{
    (void)state;
    obs_bytes f = encode_raw_request();
    obs_bin_header h;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bin_header_parse(f.data, &h, f.size, err), OBS_OK);
    assert_int_equal(h.kind, OBS_BIN_REQUEST);
    assert_true(h.id == 42);
    assert_true(h.length == f.size - OBS_BIN_HEADER_LEN);

    obs_bin_request q;
    const unsigned char *payload = f.data + OBS_BIN_HEADER_LEN; /* malloc + 24: aligned */
    assert_int_equal(obs_bin_request_decode(payload, (size_t)h.length, NULL, &q, err), OBS_OK);
    assert_int_equal(q.body, OBS_BIN_RAW);
    assert_int_equal(q.raw_out, 1);
    assert_string_equal(q.token, "t0k");
    assert_true(q.hr.params.radius == 0.25f);
    assert_int_equal(q.hr.params.samples, 8);
    assert_int_equal(q.hr.outputs, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE);
    const obs_gbuffer *gb = &q.gf.gb;
    assert_int_equal(gb->width, W);
    assert_int_equal(gb->height, H);
    assert_int_equal(gb->display_x, 1);
    assert_int_equal(gb->display_y, 2);
    assert_int_equal(gb->display_width, 10);
    assert_int_equal(gb->display_height, 8);
    assert_null(q.gf.storage); /* zero copy: planes point into the payload */
    assert_memory_equal(gb->depth.data, depth, sizeof depth);
    assert_memory_equal(gb->normal.data, normal, sizeof normal);
    assert_memory_equal(gb->color.data, color, sizeof color);
    assert_true(gb->camera.has_world_to_camera && gb->camera.has_projection);
    assert_true(gb->camera.world_to_camera[15] == 15.0f && gb->camera.projection[3] == -3.0f);
    obs_bin_request_free(&q);

    /* a misaligned payload is copied, not read as floats in place */
    unsigned char *odd = malloc((size_t)h.length + 1);
    memcpy(odd + 1, payload, (size_t)h.length);
    assert_int_equal(obs_bin_request_decode(odd + 1, (size_t)h.length, NULL, &q, err), OBS_OK);
    assert_non_null(q.gf.storage);
    assert_memory_equal(q.gf.gb.color.data, color, sizeof color);
    assert_memory_equal(q.gf.gb.normal.data, normal, sizeof normal);
    obs_bin_request_free(&q);
    free(odd);
    obs_bytes_free(&f);
}

static void test_exr_round_trip(void **state)
{
    (void)state;
    static const unsigned char exr[] = {0x76, 0x2f, 0x31, 0x01, 9, 9, 9};
    obs_bin_param p[] = {{"format", "png"}, {"output", "composite"}, {"png_bits", "16"}};
    obs_bin_request_desc d = {.id = 7, .params = p, .param_count = 3, .exr = exr, .exr_len = sizeof exr};
    obs_bytes f;
    obs_bin_request q;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bin_request_encode(&d, &f, err), OBS_OK);
    assert_int_equal(obs_bin_request_decode(f.data + OBS_BIN_HEADER_LEN, f.size - OBS_BIN_HEADER_LEN,
                                            NULL, &q, err), OBS_OK);
    assert_int_equal(q.body, OBS_BIN_EXR);
    assert_int_equal(q.raw_out, 0);
    assert_int_equal(q.hr.format, OBS_HTTP_PNG);
    assert_int_equal(q.hr.png_bits, 16);
    assert_int_equal(q.exr_len, sizeof exr);
    assert_memory_equal(q.exr, exr, sizeof exr);
    obs_bin_request_free(&q);
    obs_bytes_free(&f);
}

static void test_response_round_trip(void **state)
{
    (void)state;
    float ao[W * H], rgba[W * H * 4];
    for (int i = 0; i < W * H; i++)
        ao[i] = (float)i / (W * H);
    memcpy(rgba, color, sizeof rgba);
    obs_bin_image im[2] = {{OBS_OUTPUT_AO, {W, H, 1, ao}}, {OBS_OUTPUT_COMPOSITE, {W, H, 4, rgba}}};
    obs_bin_response_desc d = {.id = 9, .status = 200, .code = "ok", .message = "",
                               .body = OBS_BIN_RAW, .images = im, .image_count = 2};
    obs_bytes f;
    obs_bin_response r;
    obs_bin_header h;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bin_response_encode(&d, &f, err), OBS_OK);
    assert_int_equal(obs_bin_header_parse(f.data, &h, f.size, err), OBS_OK);
    assert_int_equal(h.kind, OBS_BIN_RESPONSE);
    assert_true(h.id == 9);
    assert_int_equal(obs_bin_response_decode(f.data + OBS_BIN_HEADER_LEN, (size_t)h.length, NULL, &r, err),
                     OBS_OK);
    assert_int_equal(r.status, 200);
    assert_int_equal(r.image_count, 2);
    assert_int_equal(r.images[1].output, OBS_OUTPUT_COMPOSITE);
    assert_int_equal(r.images[1].image.channels, 4);
    assert_memory_equal(r.images[0].image.data, ao, sizeof ao);
    assert_memory_equal(r.images[1].image.data, rgba, sizeof rgba);
    obs_bin_response_free(&r);
    /* every truncation of the payload is refused, never read past */
    for (size_t n = 0; n < (size_t)h.length; n++) {
        unsigned char *copy = malloc(n ? n : 1);
        memcpy(copy, f.data + OBS_BIN_HEADER_LEN, n);
        assert_int_not_equal(obs_bin_response_decode(copy, n, NULL, &r, err), OBS_OK);
        assert_int_equal(r.image_count, 0);
        free(copy);
    }
    obs_bytes_free(&f);

    /* an error: status, retry-after, code and message */
    obs_bin_response_desc e = {.id = 3, .status = 503, .retry_after = 1, .code = "queue_full",
                               .message = "the frame queue is full; retry later"};
    assert_int_equal(obs_bin_response_encode(&e, &f, err), OBS_OK);
    assert_int_equal(obs_bin_response_decode(f.data + OBS_BIN_HEADER_LEN, f.size - OBS_BIN_HEADER_LEN,
                                             NULL, &r, err), OBS_OK);
    assert_int_equal(r.status, 503);
    assert_int_equal(r.retry_after, 1);
    assert_string_equal(r.code, "queue_full");
    assert_string_equal(r.message, "the frame queue is full; retry later");
    assert_int_equal(r.body, OBS_BIN_NONE);
    obs_bytes_free(&f);
}

/* A 200's warnings in the message field, one a line: decoded as a list;
 * a line break inside one sent as a space; empty ones skipped; whole
 * warnings only up to the message's limit; a version-1 answer (message
 * "") has none, and an error's message is not split. */
static void test_response_warnings(void **state)
{
    (void)state;
    static char big[3000];
    memset(big, 'x', sizeof big - 1);
    const char *said[] = {"depth values above 1 are impossible under --depth-mode ndc", "",
                          "two\nlines", big, big};
    unsigned char exr[4] = {1, 2, 3, 4};
    obs_bin_response_desc d = {.id = 5, .status = 200, .code = "ok", .message = "", .warnings = said,
                               .warning_count = 5, .body = OBS_BIN_EXR, .blob = exr, .blob_len = 4};
    obs_bytes f;
    obs_bin_response r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bin_response_encode(&d, &f, err), OBS_OK);
    assert_int_equal(obs_bin_response_decode(f.data + OBS_BIN_HEADER_LEN, f.size - OBS_BIN_HEADER_LEN,
                                             NULL, &r, err), OBS_OK);
    assert_int_equal(r.warning_count, 3);
    assert_string_equal(r.warnings[0], said[0]);
    assert_string_equal(r.warnings[1], "two lines");
    assert_string_equal(r.warnings[2], big);
    assert_true(r.blob_len == 4 && !memcmp(r.blob, exr, 4));
    obs_bin_response_free(&r);
    obs_bytes_free(&f);

    d.warning_count = 0; /* what version 1 sent */
    assert_int_equal(obs_bin_response_encode(&d, &f, err), OBS_OK);
    assert_int_equal(obs_bin_response_decode(f.data + OBS_BIN_HEADER_LEN, f.size - OBS_BIN_HEADER_LEN,
                                             NULL, &r, err), OBS_OK);
    assert_int_equal(r.warning_count, 0);
    assert_string_equal(r.message, "");
    obs_bytes_free(&f);

    obs_bin_response_desc e = {.id = 6, .status = 422, .code = "bad_file", .message = "a\nb",
                               .warnings = said, .warning_count = 1};
    assert_int_equal(obs_bin_response_encode(&e, &f, err), OBS_OK);
    assert_int_equal(obs_bin_response_decode(f.data + OBS_BIN_HEADER_LEN, f.size - OBS_BIN_HEADER_LEN,
                                             NULL, &r, err), OBS_OK);
    assert_string_equal(r.message, "a\nb");
    assert_int_equal(r.warning_count, 0);
    obs_bytes_free(&f);
}

static void test_every_truncation(void **state)
{
    (void)state;
    obs_bytes f = encode_raw_request();
    char err[OBS_ERR_LEN];
    obs_bin_request q;
    for (size_t n = 0; n < f.size; n++) {
        err[0] = '\0';
        assert_int_not_equal(decode_frame(f.data, n, &q, err), OBS_OK);
        /* and the payload alone, cut at n, with the header's length left
         * as it was: the decoder sees fewer bytes than the frame says */
        if (n >= OBS_BIN_HEADER_LEN) {
            size_t m = n - OBS_BIN_HEADER_LEN;
            unsigned char *copy = malloc(m ? m : 1);
            memcpy(copy, f.data + OBS_BIN_HEADER_LEN, m);
            assert_int_not_equal(obs_bin_request_decode(copy, m, NULL, &q, err), OBS_OK);
            assert_true(err[0] != '\0');
            assert_null(q.gf.storage);
            free(copy);
        }
    }
    assert_int_equal(decode_frame(f.data, f.size, &q, err), OBS_OK);
    obs_bytes_free(&f);
}

/* Writes a little-endian u32 at p. */
static void le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

static void test_oversized(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bin_header h;
    unsigned char hdr[OBS_BIN_HEADER_LEN];
    /* a payload length over the limit: refused from the header alone */
    obs_bin_header_write(hdr, OBS_BIN_REQUEST, 1, UINT64_MAX);
    assert_int_equal(obs_bin_header_parse(hdr, &h, 1u << 20, err), OBS_TOO_LARGE);
    assert_non_null(strstr(err, "over the limit"));

    /* planes claiming 65535 x 65535 (and 2^32-1 squared, which overflows
     * 32 bits): refused by the size check, nothing allocated */
    obs_bytes f = encode_raw_request();
    unsigned char *payload = f.data + OBS_BIN_HEADER_LEN;
    size_t len = f.size - OBS_BIN_HEADER_LEN;
    /* the raw header starts 8-aligned after the parameters: find width */
    size_t off = 0;
    for (size_t i = 0; i + 8 <= len; i += 8)
        if (payload[i] == W && payload[i + 1] == 0 && payload[i + 4] == H && payload[i + 5] == 0) {
            off = i;
            break;
        }
    assert_true(off > 0);
    obs_bin_request q;
    obs_limits lim = {.max_pixels = 10000};
    const uint32_t sizes[][2] = {{65535, 65535}, {0xffffffffu, 0xffffffffu}, {0, 5}, {20000, 1}, {200, 100}};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        le32(payload + off, sizes[k][0]);
        le32(payload + off + 4, sizes[k][1]);
        obs_status s = obs_bin_request_decode(payload, len, &lim, &q, err);
        assert_int_not_equal(s, OBS_OK);
        assert_null(q.gf.storage);
    }
    le32(payload + off, 200);
    le32(payload + off + 4, 100);
    assert_int_equal(obs_bin_request_decode(payload, len, &lim, &q, err), OBS_TOO_LARGE);
    /* within the limits but more pixels than the frame holds */
    le32(payload + off, W + 1);
    le32(payload + off + 4, H);
    assert_int_equal(obs_bin_request_decode(payload, len, &lim, &q, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "holds"));
    obs_bytes_free(&f);

    /* an EXR length past the frame */
    static const unsigned char exr[] = {1, 2, 3, 4};
    obs_bin_request_desc d = {.id = 1, .exr = exr, .exr_len = sizeof exr};
    assert_int_equal(obs_bin_request_encode(&d, &f, err), OBS_OK);
    unsigned char *lenp = f.data + f.size - sizeof exr - 8;
    le32(lenp, 0xffffffffu);
    assert_int_equal(obs_bin_request_decode(f.data + OBS_BIN_HEADER_LEN, f.size - OBS_BIN_HEADER_LEN,
                                            NULL, &q, err), OBS_BAD_FILE);
    obs_bytes_free(&f);
}

/* Reads a head the way the daemon does: from nothing, as many bytes as
 * the parser asks for, each time from a fresh, exactly sized copy (ASan
 * sees a read past what was "received"). */
static obs_status head_incremental(const unsigned char *payload, size_t len, const obs_limits *lim,
                                   obs_bin_head *h, size_t *calls, char err[OBS_ERR_LEN])
{
    size_t got = 0, need = 0;
    obs_status s;
    *calls = 0;
    for (;;) {
        unsigned char *copy = malloc(got ? got : 1);
        memcpy(copy, payload, got);
        s = obs_bin_request_head(copy, got, len, lim, h, &need, err);
        free(copy);
        ++*calls;
        if (s != OBS_OK || need == 0)
            return s;
        assert_true(need > got && need <= len);
        got = need;
    }
}

static void test_head(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bin_head h;
    size_t calls, need;
    obs_bytes f = encode_raw_request();
    unsigned char *payload = f.data + OBS_BIN_HEADER_LEN;
    size_t len = f.size - OBS_BIN_HEADER_LEN;
    size_t planes = (size_t)W * H * (1 + 3 + 4) * sizeof(float);
    assert_int_equal(head_incremental(payload, len, NULL, &h, &calls, err), OBS_OK);
    assert_true(h.len == len - planes); /* the planes are never asked for */
    assert_int_equal(h.params_done, 1);
    assert_string_equal(h.token, "t0k");
    assert_int_equal(h.body, OBS_BIN_RAW);
    assert_int_equal(h.width, W);
    assert_int_equal(h.height, H);
    assert_true(calls > 2 && calls < 40);
    /* with the whole payload at hand: the same head at once */
    assert_int_equal(obs_bin_request_head(payload, len, len, NULL, &h, &need, err), OBS_OK);
    assert_true(need == 0 && h.len == len - planes);
    size_t head = h.len;

    /* every cut of the payload (the frame's own length then): the head
     * fails as the decoder does, with the same status */
    obs_bin_request q;
    for (size_t n = 0; n < len; n++) {
        unsigned char *copy = malloc(n ? n : 1);
        memcpy(copy, payload, n);
        obs_status sd = obs_bin_request_decode(copy, n, NULL, &q, err);
        obs_status sh = obs_bin_request_head(copy, n, n, NULL, &h, &need, err);
        assert_int_not_equal(sh, OBS_OK);
        assert_int_equal(sh, sd);
        free(copy);
    }

    /* sizes over the limits: refused from the head, the planes unread */
    size_t off = head - 160; /* the raw header */
    obs_limits lim = {.max_pixels = 10000};
    le32(payload + off, 200);
    le32(payload + off + 4, 100);
    assert_int_equal(obs_bin_request_head(payload, head, len, &lim, &h, &need, err), OBS_TOO_LARGE);
    assert_int_equal(obs_bin_request_decode(payload, len, &lim, &q, err), OBS_TOO_LARGE);
    /* more planes than the frame holds: known from the head */
    le32(payload + off, W + 1);
    le32(payload + off + 4, H);
    assert_int_equal(obs_bin_request_head(payload, len - planes, len, &lim, &h, &need, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "holds"));
    le32(payload + off, W);
    le32(payload + off + 4, H);
    obs_bytes_free(&f);

    /* a broken parameter list: params_done stays 0 (the token unknown) */
    static const unsigned char exr[] = {1, 2, 3};
    obs_bin_param p[] = {{"token", "secret"}, {"radius", "0.5"}};
    obs_bin_request_desc d = {.id = 1, .params = p, .param_count = 2, .exr = exr, .exr_len = sizeof exr};
    assert_int_equal(obs_bin_request_encode(&d, &f, err), OBS_OK);
    payload = f.data + OBS_BIN_HEADER_LEN;
    len = f.size - OBS_BIN_HEADER_LEN;
    assert_int_equal(head_incremental(payload, len, NULL, &h, &calls, err), OBS_OK);
    assert_string_equal(h.token, "secret");
    assert_int_equal(h.body, OBS_BIN_EXR);
    assert_true(h.len == len - sizeof exr);
    /* a bad value, then broken padding: the value's error first, as the
     * decoder gives it, and the token is known */
    p[1].value = "-1";
    obs_bytes g;
    assert_int_equal(obs_bin_request_encode(&d, &g, err), OBS_OK);
    unsigned char *gp = g.data + OBS_BIN_HEADER_LEN;
    size_t glen = g.size - OBS_BIN_HEADER_LEN;
    gp[glen - sizeof exr - 8 - 1] = 7; /* the padding before the EXR length */
    assert_int_equal(obs_bin_request_decode(gp, glen, NULL, &q, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(head_incremental(gp, glen, NULL, &h, &calls, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "radius"));
    assert_int_equal(h.params_done, 1);
    assert_string_equal(h.token, "secret");
    obs_bytes_free(&g);
    le32(payload, 300); /* 300 parameters */
    assert_int_equal(obs_bin_request_head(payload, 4, len, NULL, &h, &need, err), OBS_BAD_FILE);
    assert_int_equal(h.params_done, 0);
    le32(payload, 2);
    payload[4 + 2 + 5 + 4 + 6] = 0; /* the second name's length: 0 */
    payload[4 + 2 + 5 + 4 + 6 + 1] = 0;
    assert_int_equal(head_incremental(payload, len, NULL, &h, &calls, err), OBS_BAD_FILE);
    assert_int_equal(h.params_done, 0);
    obs_bytes_free(&f);
}

/* append=1 writes an EXR: with format=raw it is refused, by the decoder
 * and by the head's check alike; layer= and append= are parsed. */
static void test_append_raw(void **state)
{
    (void)state;
    static const unsigned char exr[] = {1, 2, 3};
    obs_bin_param p[] = {{"append", "1"}, {"layer", "occ"}, {"format", "raw"}};
    obs_bin_request_desc d = {.id = 1, .params = p, .param_count = 3, .exr = exr, .exr_len = sizeof exr};
    obs_bytes f;
    obs_bin_request q;
    obs_bin_head h;
    size_t need;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bin_request_encode(&d, &f, err), OBS_OK);
    unsigned char *payload = f.data + OBS_BIN_HEADER_LEN;
    size_t len = f.size - OBS_BIN_HEADER_LEN;
    assert_int_equal(obs_bin_request_decode(payload, len, NULL, &q, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "append=1"));
    assert_int_equal(obs_bin_request_head(payload, len, len, NULL, &h, &need, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "append=1"));
    obs_bytes_free(&f);
    p[2].value = "exr";
    assert_int_equal(obs_bin_request_encode(&d, &f, err), OBS_OK);
    assert_int_equal(obs_bin_request_decode(f.data + OBS_BIN_HEADER_LEN, f.size - OBS_BIN_HEADER_LEN, NULL, &q, err),
                     OBS_OK);
    assert_int_equal(q.hr.append, 1);
    assert_string_equal(q.hr.layer, "occ");
    obs_bin_request_free(&q);
    obs_bytes_free(&f);
}

static void test_garbage(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bin_header h;
    obs_bin_request q;
    unsigned char hdr[OBS_BIN_HEADER_LEN];
    /* an HTTP request on the socket */
    memcpy(hdr, "GET / HTTP/1.1\r\nHost: x\r\n", OBS_BIN_HEADER_LEN);
    assert_int_equal(obs_bin_header_parse(hdr, &h, 1u << 20, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "magic"));
    obs_bin_header_write(hdr, OBS_BIN_REQUEST, 1, 10);
    hdr[4] = 2; /* version 2 */
    assert_int_equal(obs_bin_header_parse(hdr, &h, 1u << 20, err), OBS_UNSUPPORTED);
    obs_bin_header_write(hdr, (obs_bin_kind)3, 1, 10);
    assert_int_equal(obs_bin_header_parse(hdr, &h, 1u << 20, err), OBS_BAD_FILE);

    /* pseudo-random payloads: never accepted as a frame, never a crash */
    uint32_t x = 12345;
    for (int round = 0; round < 2000; round++) {
        size_t n = (size_t)(round % 300);
        unsigned char *buf = malloc(n ? n : 1);
        for (size_t i = 0; i < n; i++) {
            x = x * 1664525u + 1013904223u;
            buf[i] = (unsigned char)(x >> 24);
        }
        if (n >= 4 && round % 3 == 0)
            le32(buf, (uint32_t)(round % 4)); /* a plausible parameter count */
        obs_status s = obs_bin_request_decode(buf, n, NULL, &q, err);
        if (s == OBS_OK)
            obs_bin_request_free(&q);
        obs_bin_response r;
        if (obs_bin_response_decode(buf, n, NULL, &r, err) == OBS_OK)
            obs_bin_response_free(&r);
        free(buf);
    }

    /* a bad parameter is named, a NUL in a name is malformed */
    obs_bin_param bad[] = {{"samples", "64"}};
    obs_bytes f;
    static const unsigned char exr[] = {1};
    obs_bin_request_desc d = {.id = 1, .params = bad, .param_count = 1, .exr = exr, .exr_len = 1};
    assert_int_equal(obs_bin_request_encode(&d, &f, err), OBS_OK);
    assert_int_equal(obs_bin_request_decode(f.data + OBS_BIN_HEADER_LEN, f.size - OBS_BIN_HEADER_LEN,
                                            NULL, &q, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "samples"));
    f.data[OBS_BIN_HEADER_LEN + 7] = 0; /* inside "samples" */
    assert_int_equal(obs_bin_request_decode(f.data + OBS_BIN_HEADER_LEN, f.size - OBS_BIN_HEADER_LEN,
                                            NULL, &q, err), OBS_BAD_FILE);
    obs_bytes_free(&f);
    /* trailing bytes after a raw G-buffer */
    obs_bytes g = encode_raw_request();
    unsigned char *longer = malloc(g.size + 4);
    memcpy(longer, g.data, g.size);
    memset(longer + g.size, 0, 4);
    assert_int_equal(obs_bin_request_decode(longer + OBS_BIN_HEADER_LEN, g.size + 4 - OBS_BIN_HEADER_LEN,
                                            NULL, &q, err), OBS_BAD_FILE);
    free(longer);
    obs_bytes_free(&g);
}

static uint32_t float_bits(float f)
{
    uint32_t b;
    memcpy(&b, &f, sizeof b);
    return b;
}

/* half -> float against known bit patterns */
static void test_half_to_float(void **state)
{
    (void)state;
    static const struct {
        uint16_t h;
        uint32_t f;
    } cases[] = {
        {0x0000, 0x00000000}, /* +0 */
        {0x8000, 0x80000000}, /* -0 */
        {0x3c00, 0x3f800000}, /* 1 */
        {0xbc00, 0xbf800000}, /* -1 */
        {0x4000, 0x40000000}, /* 2 */
        {0x3555, 0x3eaaa000}, /* 0.333251953125 */
        {0x7bff, 0x477fe000}, /* 65504, largest finite */
        {0x0400, 0x38800000}, /* 2^-14, smallest normal */
        {0x0001, 0x33800000}, /* 2^-24, smallest subnormal */
        {0x8001, 0xb3800000}, /* -2^-24 */
        {0x0002, 0x34000000}, /* 2^-23 */
        {0x0003, 0x34400000}, /* 3 * 2^-24 */
        {0x0200, 0x38000000}, /* 2^-15 */
        {0x03ff, 0x387fc000}, /* largest subnormal, 1023 * 2^-24 */
        {0x7c00, 0x7f800000}, /* +inf */
        {0xfc00, 0xff800000}, /* -inf */
        {0x7e00, 0x7fc00000}, /* quiet NaN */
        {0x7c01, 0x7f802000}, /* signalling NaN, payload kept */
        {0xfe00, 0xffc00000}, /* negative NaN */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        float f = obs_bin_half_to_float(cases[i].h);
        if (float_bits(f) != cases[i].f)
            fail_msg("half 0x%04x: float bits 0x%08x, expected 0x%08x", cases[i].h, float_bits(f),
                     cases[i].f);
    }
    assert_true(obs_bin_half_to_float(0x0001) == 5.9604644775390625e-8f);
    assert_true(isnan(obs_bin_half_to_float(0x7fff)) && isinf(obs_bin_half_to_float(0x7c00)));
    /* every half: finite ones scale back to their integer mantissa exactly */
    for (uint32_t h = 0; h < 0x10000; h++) {
        float f = obs_bin_half_to_float((uint16_t)h);
        unsigned e = (h >> 10) & 0x1f, m = h & 0x3ff;
        if (e == 0x1f) {
            assert_true(m ? isnan(f) : isinf(f));
            continue;
        }
        double v = e ? ldexp(1024 + m, (int)e - 25) : ldexp(m, -24);
        if (h & 0x8000)
            v = -v;
        if ((double)f != v || !!signbit(f) != !!(h & 0x8000))
            fail_msg("half 0x%04x: %a, expected %a", h, (double)f, v);
    }
}

/* The raw request of encode_raw_request() with float16 planes: value k
 * (depth, then normal, then colour) is the half 0x3c00 + k = 1 + k/1024. */
static obs_bytes encode_f16_request(void)
{
    obs_bytes f32 = encode_raw_request();
    size_t values = (size_t)W * H * 8, raw = f32.size - values * 4 - 160;
    obs_bytes f = {malloc(raw + 160 + values * 2), raw + 160 + values * 2};
    memcpy(f.data, f32.data, raw + 160);
    le32(f.data + raw + 28, 1); /* plane type float16 */
    for (size_t k = 0; k < values; k++) {
        f.data[raw + 160 + 2 * k] = (unsigned char)(0x3c00 + k);
        f.data[raw + 160 + 2 * k + 1] = (unsigned char)((0x3c00 + k) >> 8);
    }
    obs_bin_header_write(f.data, OBS_BIN_REQUEST, 42, f.size - OBS_BIN_HEADER_LEN);
    obs_bytes_free(&f32);
    return f;
}

static void test_f16_planes(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bytes f = encode_f16_request();
    obs_bin_request q;
    size_t n = f.size - OBS_BIN_HEADER_LEN, px = (size_t)W * H;
    for (int shift = 0; shift < 2; shift++) { /* aligned and not */
        unsigned char *copy = malloc(n + 1);
        memcpy(copy + shift, f.data + OBS_BIN_HEADER_LEN, n);
        assert_int_equal(obs_bin_request_decode(copy + shift, n, NULL, &q, err), OBS_OK);
        const obs_gbuffer *gb = &q.gf.gb;
        assert_int_equal(gb->width, W);
        assert_int_equal(gb->height, H);
        assert_int_equal(gb->display_width, 10);
        assert_non_null(q.gf.storage);
        assert_true(gb->camera.world_to_camera[15] == 15.0f);
        for (size_t k = 0; k < px * 8; k++) {
            float v = k < px ? gb->depth.data[k]
                    : k < px * 4 ? gb->normal.data[k - px] : gb->color.data[k - px * 4];
            if (v != 1.0f + (float)k / 1024.0f)
                fail_msg("value %zu: %g", k, (double)v);
        }
        assert_int_equal(gb->normal.channels, 3);
        assert_int_equal(gb->color.channels, 4);
        obs_bin_request_free(&q);
        free(copy);
    }
    /* every truncation: refused, never read past */
    for (size_t len = OBS_BIN_HEADER_LEN; len < f.size; len++) {
        unsigned char *cut = malloc(len);
        memcpy(cut, f.data, len);
        obs_bin_header_write(cut, OBS_BIN_REQUEST, 42, len - OBS_BIN_HEADER_LEN);
        assert_int_not_equal(decode_frame(cut, len, &q, err), OBS_OK);
        free(cut);
    }
    /* float32-sized planes with type float16, and an unknown type */
    obs_bytes g = encode_raw_request();
    size_t raw = g.size - px * 8 * 4 - 160;
    le32(g.data + raw + 28, 1);
    assert_int_equal(decode_frame(g.data, g.size, &q, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "float16"));
    le32(g.data + raw + 28, 2);
    assert_int_equal(decode_frame(g.data, g.size, &q, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "plane type 2"));
    obs_bytes_free(&g);
    obs_bytes_free(&f);
}

/* ---- deep (layered) G-buffers ---------------------------------------------- */

#define DW 3
#define DH 2
/* samples per pixel: 2, 0, 1, 3, 1, 0 (7 in all) */
static const uint64_t deep_offset[DW * DH + 1] = {0, 2, 2, 3, 6, 7, 7};
static float deep_samples[7 * OBS_DEEP_CH];

static void fill_deep(obs_deep_image *d)
{
    for (int s = 0; s < 7; s++)
        for (int c = 0; c < OBS_DEEP_CH; c++)
            deep_samples[s * OBS_DEEP_CH + c] = c == OBS_DEEP_Z ? 1.0f + (float)s : (float)(s * 10 + c) / 64.0f;
    memset(d, 0, sizeof *d);
    d->width = DW;
    d->height = DH;
    d->display_x = -1;
    d->display_y = 2;
    d->display_width = 8;
    d->display_height = 4;
    d->offset = (uint64_t *)deep_offset;
    d->samples = deep_samples;
    d->has_zback = d->has_alpha = d->has_color = d->has_facing = 1;
    for (int k = 0; k < 16; k++)
        d->camera.projection[k] = (float)k / 3.0f;
    d->camera.has_projection = 1;
}

/* A deep request with no parameters: the deep header starts at payload
 * byte 8 (count, kind, padding). */
#define DEEP_AT (OBS_BIN_HEADER_LEN + 8)
static obs_bytes encode_deep_request(void)
{
    obs_deep_image d;
    obs_bytes out;
    char err[OBS_ERR_LEN] = "";
    fill_deep(&d);
    obs_bin_request_desc desc = {.id = 5, .deep = &d};
    assert_int_equal(obs_bin_request_encode(&desc, &out, err), OBS_OK);
    assert_int_equal(out.size, DEEP_AT + 176 + DW * DH * 4 + 7 * OBS_DEEP_CH * 4);
    return out;
}

static obs_status decode_payload(const obs_bytes *f, const obs_limits *lim, obs_bin_request *q,
                                 char err[OBS_ERR_LEN])
{
    size_t n = f->size - OBS_BIN_HEADER_LEN;
    unsigned char *copy = malloc(n);
    memcpy(copy, f->data + OBS_BIN_HEADER_LEN, n);
    err[0] = '\0';
    obs_status s = obs_bin_request_decode(copy, n, lim, q, err);
    if (s != OBS_OK) {
        assert_true(err[0] != '\0');
        assert_null(q->deep.offset); /* nothing kept on failure */
        assert_null(q->gf.storage);
    }
    obs_bin_request_free(q);
    free(copy);
    return s;
}

static void test_deep_round_trip(void **state)
{
    (void)state;
    obs_bytes f = encode_deep_request();
    char err[OBS_ERR_LEN] = "";
    obs_bin_request q;
    obs_bin_header h;
    assert_int_equal(obs_bin_header_parse(f.data, &h, 1u << 20, err), OBS_OK);
    assert_int_equal(h.length, f.size - OBS_BIN_HEADER_LEN);
    /* aligned (samples used in place) and at an odd address (copied) */
    for (int odd = 0; odd < 2; odd++) {
        size_t n = f.size - OBS_BIN_HEADER_LEN;
        unsigned char *buf = malloc(n + 1);
        memcpy(buf + odd, f.data + OBS_BIN_HEADER_LEN, n);
        if (obs_bin_request_decode(buf + odd, n, NULL, &q, err) != OBS_OK)
            fail_msg("%s", err);
        assert_int_equal(q.body, OBS_BIN_DEEP);
        const obs_deep_image *d = &q.deep;
        assert_int_equal(d->width, DW);
        assert_int_equal(d->height, DH);
        assert_int_equal(d->display_x, -1);
        assert_int_equal(d->display_y, 2);
        assert_int_equal(d->display_width, 8);
        assert_int_equal(d->display_height, 4);
        assert_true(d->has_zback && d->has_alpha && d->has_color && !d->has_normal);
        assert_true(d->has_facing); /* flag 64, the tenth value */
        assert_true(d->camera.has_projection && !d->camera.has_world_to_camera);
        for (int k = 0; k < 16; k++)
            assert_true(d->camera.projection[k] == (float)k / 3.0f);
        assert_memory_equal(d->offset, deep_offset, sizeof deep_offset);
        assert_memory_equal(d->samples, deep_samples, sizeof deep_samples);
        assert_true(odd ? q.gf.storage != NULL : q.gf.storage == NULL);
        obs_bin_request_free(&q);
        free(buf);
    }
    obs_bytes_free(&f);
}

static void test_deep_truncated(void **state)
{
    (void)state;
    obs_bytes f = encode_deep_request();
    char err[OBS_ERR_LEN];
    obs_bin_request q;
    for (size_t n = OBS_BIN_HEADER_LEN; n < f.size; n++) {
        size_t m = n - OBS_BIN_HEADER_LEN;
        unsigned char *copy = malloc(m ? m : 1);
        memcpy(copy, f.data + OBS_BIN_HEADER_LEN, m);
        err[0] = '\0';
        assert_int_equal(obs_bin_request_decode(copy, m, NULL, &q, err), OBS_BAD_FILE);
        assert_true(err[0] != '\0');
        assert_null(q.deep.offset);
        assert_null(q.gf.storage);
        free(copy);
    }
    /* a cut inside the header names it; a cut in the samples, the sizes */
    f.size = DEEP_AT + 100;
    assert_int_equal(decode_payload(&f, NULL, &q, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "deep G-buffer header"));
    f.size = DEEP_AT + 176 + DW * DH * 4 + 10;
    assert_int_equal(decode_payload(&f, NULL, &q, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "the frame holds"));
    obs_bytes_free(&f);
}

static void test_deep_bad_counts(void **state)
{
    (void)state;
    obs_bytes f = encode_deep_request();
    char err[OBS_ERR_LEN];
    obs_bin_request q;
    unsigned char *counts = f.data + DEEP_AT + 176;
    /* counts that do not sum to the total (bytes still add up) */
    le32(counts, 1);
    le32(counts + 4, 1);
    assert_int_equal(decode_payload(&f, NULL, &q, err), OBS_OK);
    le32(counts + 4, 2);
    assert_int_equal(decode_payload(&f, NULL, &q, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "sum to 8 samples, the header says 7"));
    /* a count that would wrap a 32-bit sum */
    le32(counts, 0xffffffffu);
    assert_int_equal(decode_payload(&f, NULL, &q, err), OBS_TOO_LARGE);
    assert_non_null(strstr(err, "pixel (0, 0) holds 4294967295 samples"));
    le32(counts, 2);
    le32(counts + 4, 0);
    /* samples out of order in pixel (0, 1), samples 3..5: Z 4, 5, 6 -> 4, 7, 6 */
    float z = 7.0f;
    memcpy(f.data + f.size - (7 - 4) * OBS_DEEP_CH * 4 + OBS_DEEP_Z * 4, &z, 4);
    assert_int_equal(decode_payload(&f, NULL, &q, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "pixel (0, 1) are not sorted"));
    obs_bytes_free(&f);
}

static void test_deep_bad_sizes(void **state)
{
    (void)state;
    obs_bytes f = encode_deep_request();
    char err[OBS_ERR_LEN];
    obs_bin_request q;
    unsigned char *hd = f.data + DEEP_AT;
    obs_limits lim = {.max_pixels = 10000};
    /* too many samples: refused from the total before anything else */
    le32(hd + 40, 0);
    le32(hd + 44, 1); /* 2^32 */
    assert_int_equal(decode_payload(&f, &lim, &q, err), OBS_TOO_LARGE);
    assert_non_null(strstr(err, "4294967296 samples, over the limit"));
    le32(hd + 44, 0);
    le32(hd + 40, (uint32_t)OBS_DEEP_MAX_SAMPLES + 1);
    assert_int_equal(decode_payload(&f, &lim, &q, err), OBS_TOO_LARGE);
    /* a total the frame's bytes do not hold */
    le32(hd + 40, 8);
    assert_int_equal(decode_payload(&f, &lim, &q, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "need"));
    le32(hd + 40, 7);
    /* a window over the limits, of no pixels, or bigger than the frame */
    const uint32_t sizes[][3] = {{65535, 65535, OBS_TOO_LARGE}, {0xffffffffu, 0xffffffffu, OBS_TOO_LARGE},
                                 {0, 2, 0}, {200, 100, OBS_TOO_LARGE}, {DW + 1, DH, OBS_BAD_FILE}};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        le32(hd, sizes[k][0]);
        le32(hd + 4, sizes[k][1]);
        obs_status s = decode_payload(&f, &lim, &q, err);
        assert_int_not_equal(s, OBS_OK);
        if (sizes[k][2])
            assert_int_equal(s, (obs_status)sizes[k][2]);
    }
    le32(hd, DW);
    le32(hd + 4, DH);
    assert_int_equal(decode_payload(&f, &lim, &q, err), OBS_OK);
    /* values per sample, sample type, reserved, flags */
    const size_t field[] = {28, 32, 36, 24};
    const uint32_t value[] = {8, 1, 1, 0x100};
    const char *const says[] = {"8 values per sample", "sample type 1", "reserved", "unknown flags"};
    for (int k = 0; k < 4; k++) {
        uint32_t keep = (uint32_t)hd[field[k]] | (uint32_t)hd[field[k] + 1] << 8;
        le32(hd + field[k], value[k]);
        assert_int_equal(decode_payload(&f, &lim, &q, err), OBS_BAD_FILE);
        assert_non_null(strstr(err, says[k]));
        le32(hd + field[k], keep);
    }
    assert_int_equal(decode_payload(&f, &lim, &q, err), OBS_OK);
    /* the encoder refuses what the decoder would */
    obs_deep_image d;
    fill_deep(&d);
    uint64_t bad[DW * DH + 1];
    memcpy(bad, deep_offset, sizeof bad);
    bad[2] = 1; /* decreasing */
    d.offset = bad;
    obs_bin_request_desc desc = {.id = 1, .deep = &d};
    obs_bytes g;
    assert_int_equal(obs_bin_request_encode(&desc, &g, err), OBS_INVALID_ARGUMENT);
    obs_bytes_free(&f);
}

/* A deep frame's head: the fixed fields, not the counts or samples; the
 * sample total and the window against the limits from the head alone. */
static void test_deep_head(void **state)
{
    (void)state;
    obs_bytes f = encode_deep_request();
    char err[OBS_ERR_LEN];
    obs_bin_head h;
    size_t calls, need;
    unsigned char *payload = f.data + OBS_BIN_HEADER_LEN, *hd = f.data + DEEP_AT;
    size_t len = f.size - OBS_BIN_HEADER_LEN, head = DEEP_AT - OBS_BIN_HEADER_LEN + 176;
    assert_int_equal(head_incremental(payload, len, NULL, &h, &calls, err), OBS_OK);
    assert_int_equal(h.body, OBS_BIN_DEEP);
    assert_true(h.len == head && h.width == DW && h.height == DH && h.token[0] == '\0');
    obs_limits lim = {.max_pixels = 10000};
    le32(hd + 40, (uint32_t)OBS_DEEP_MAX_SAMPLES + 1);
    assert_int_equal(obs_bin_request_head(payload, head, len, &lim, &h, &need, err), OBS_TOO_LARGE);
    le32(hd + 40, 8);
    assert_int_equal(obs_bin_request_head(payload, head, len, &lim, &h, &need, err), OBS_BAD_FILE);
    le32(hd + 40, 7);
    le32(hd, 200);
    le32(hd + 4, 100);
    assert_int_equal(obs_bin_request_head(payload, head, len, &lim, &h, &need, err), OBS_TOO_LARGE);
    le32(hd, DW);
    le32(hd + 4, DH);
    le32(hd + 28, 7); /* values per sample */
    assert_int_equal(obs_bin_request_head(payload, head, len, &lim, &h, &need, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "7 values per sample"));
    obs_bytes_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_raw_round_trip),      cmocka_unit_test(test_exr_round_trip),
        cmocka_unit_test(test_response_round_trip), cmocka_unit_test(test_every_truncation),
        cmocka_unit_test(test_oversized),           cmocka_unit_test(test_append_raw),
        cmocka_unit_test(test_garbage),
        cmocka_unit_test(test_half_to_float),       cmocka_unit_test(test_f16_planes),
        cmocka_unit_test(test_deep_round_trip),     cmocka_unit_test(test_deep_truncated),
        cmocka_unit_test(test_deep_bad_counts),     cmocka_unit_test(test_deep_bad_sizes),
        cmocka_unit_test(test_head),                cmocka_unit_test(test_deep_head),
        cmocka_unit_test(test_response_warnings),
    };
    return cmocka_run_group_tests_name("protocol_binary", tests, NULL, NULL);
}
