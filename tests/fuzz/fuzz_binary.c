/* libFuzzer target for the binary protocol's decoders (protocol/binary.c).
 *
 * Every input (raw, EXR and deep G-buffers) is decoded as a request payload and as a response payload,
 * from an exactly sized heap copy (ASan sees any read past the end), once
 * 8-aligned and once at an odd address (the raw planes' copy path); a
 * frame header is parsed from the first 24 bytes when there are that many.
 * Whatever a decoder allocates is freed (LeakSanitizer checks).  The limits
 * are small so that a valid-looking size cannot ask for much memory.
 *
 *   make fuzz && build/fuzz/fuzz_binary tests/fuzz/corpus/binary */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "binary.h"

static void decode_all(const unsigned char *p, size_t n)
{
    const obs_limits lim = {.max_width = 4096, .max_height = 4096, .max_pixels = 1u << 20, .threads = 1};
    char err[OBS_ERR_LEN];
    obs_bin_request q;
    obs_bin_response r;

    if (obs_bin_request_decode(p, n, &lim, &q, err) == OBS_OK) {
        /* Touch what the daemon touches: every plane value. */
        if (q.body == OBS_BIN_RAW) {
            const obs_gbuffer *gb = &q.gf.gb;
            size_t px = (size_t)gb->width * (size_t)gb->height;
            volatile float sink = 0;
            for (size_t i = 0; i < px; i++)
                sink += gb->depth.data[i];
            if (gb->normal.data)
                for (size_t i = 0; i < px * 3; i++)
                    sink += gb->normal.data[i];
            if (gb->color.data)
                for (size_t i = 0; i < px * 4; i++)
                    sink += gb->color.data[i];
            (void)sink;
        } else if (q.body == OBS_BIN_DEEP) {
            /* every offset and every sample value, as the deep chain reads them */
            const obs_deep_image *d = &q.deep;
            size_t px = (size_t)d->width * (size_t)d->height;
            volatile float sink = 0;
            for (size_t i = 0; i < px; i++)
                for (uint64_t k = d->offset[i]; k < d->offset[i + 1]; k++)
                    for (int c = 0; c < OBS_DEEP_CH; c++)
                        sink += d->samples[k * OBS_DEEP_CH + c];
            (void)sink;
        } else if (q.body == OBS_BIN_EXR) {
            volatile unsigned char s = q.exr[0] ^ q.exr[q.exr_len - 1];
            (void)s;
        }
    }
    obs_bin_request_free(&q);

    if (obs_bin_response_decode(p, n, &lim, &r, err) == OBS_OK) {
        volatile size_t s = strlen(r.code) + strlen(r.message);
        if (r.blob_len)
            s += r.blob[0] + r.blob[r.blob_len - 1];
        volatile float f = 0;
        for (int i = 0; i < r.image_count; i++) {
            const obs_image *im = &r.images[i].image;
            size_t k = (size_t)im->width * (size_t)im->height * (size_t)im->channels;
            f += im->data[0] + im->data[k - 1];
        }
        (void)s;
        (void)f;
    }
    obs_bin_response_free(&r);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* Inputs that start with a frame header are also decoded after it, the
     * way the daemon and the client see them. */
    if (size >= OBS_BIN_HEADER_LEN) {
        obs_bin_header h;
        char err[OBS_ERR_LEN];
        if (obs_bin_header_parse(data, &h, UINT64_MAX, err) == OBS_OK) {
            data += OBS_BIN_HEADER_LEN;
            size -= OBS_BIN_HEADER_LEN;
        }
    }
    /* 8-aligned (malloc) and at an odd address, both ending at the end of
     * their allocation. */
    unsigned char *a = malloc(size ? size : 1);
    unsigned char *b = malloc(size + 1);
    if (!a || !b) {
        free(a);
        free(b);
        return 0;
    }
    memcpy(a, data, size);
    memcpy(b + 1, data, size);
    decode_all(a, size);
    decode_all(b + 1, size);
    free(a);
    free(b);
    return 0;
}
