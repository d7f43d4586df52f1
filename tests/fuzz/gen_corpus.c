/* Writes the fuzz target's seed corpus: a few valid binary-protocol frames
 * (header + payload), made with the encoder.  Deterministic; each file is
 * well under 4 KB.
 *
 *   gen_corpus DIR */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "binary.h"

static int save(const char *dir, const char *name, const unsigned char *p, size_t n)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(p, 1, n, f) != n || fclose(f) != 0) {
        perror(path);
        return 1;
    }
    return 0;
}

static int save_bytes(const char *dir, const char *name, obs_bytes *b, obs_status s)
{
    if (s != OBS_OK) {
        fprintf(stderr, "gen_corpus: %s: encoding failed\n", name);
        return 1;
    }
    int rc = save(dir, name, b->data, b->size);
    obs_bytes_free(b);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: gen_corpus DIR\n");
        return 2;
    }
    const char *dir = argv[1];
    char err[OBS_ERR_LEN];
    obs_bytes b;
    int rc = 0;

    /* raw, depth only, 2 x 1 (the PROTOCOL.md example) */
    static const float depth2[2] = {1.0f, 2.0f};
    obs_bin_param fov[] = {{"fov_y", "50"}};
    obs_gbuffer gb = {.width = 2, .height = 1, .depth = {depth2, 1, 0}};
    obs_bin_request_desc d = {.id = 7, .params = fov, .param_count = 1, .gb = &gb};
    rc |= save_bytes(dir, "request_raw_depth", &b, obs_bin_request_encode(&d, &b, err));

    /* raw, all planes and a camera, 3 x 2, format=raw */
    float depth[6], normal[18], color[24];
    for (int i = 0; i < 6; i++) {
        depth[i] = 1.0f + (float)i;
        for (int c = 0; c < 3; c++)
            normal[i * 3 + c] = c == 2 ? 1.0f : 0.0f;
        for (int c = 0; c < 4; c++)
            color[i * 4 + c] = 0.5f;
    }
    obs_gbuffer full = {.width = 3, .height = 2, .display_width = 4, .display_height = 3,
                        .depth = {depth, 1, 0}, .normal = {normal, 3, 0}, .color = {color, 4, 0}};
    for (int k = 0; k < 16; k++) {
        full.camera.world_to_camera[k] = k % 5 == 0 ? 1.0f : 0.0f;
        full.camera.projection[k] = k % 5 == 0 ? 1.0f : 0.0f;
    }
    full.camera.has_world_to_camera = full.camera.has_projection = 1;
    obs_bin_param many[] = {{"radius", "0.5"}, {"samples", "8"}, {"output", "both"},
                            {"format", "raw"}, {"token", "secret"}};
    d = (obs_bin_request_desc){.id = 8, .params = many, .param_count = 5, .gb = &full};
    rc |= save_bytes(dir, "request_raw_full", &b, obs_bin_request_encode(&d, &b, err));

    /* the same with float16 planes (plane type 1): values 1 + k/1024 */
    if (obs_bin_request_encode(&d, &b, err) == OBS_OK) {
        size_t values = 6 * 8, raw = b.size - values * 4 - 160, n = raw + 160 + values * 2;
        b.data[raw + 28] = 1;
        for (size_t k = 0; k < values; k++) {
            b.data[raw + 160 + 2 * k] = (unsigned char)(0x3c00 + k);
            b.data[raw + 160 + 2 * k + 1] = (unsigned char)((0x3c00 + k) >> 8);
        }
        obs_bin_header_write(b.data, OBS_BIN_REQUEST, 9, n - OBS_BIN_HEADER_LEN);
        b.size = n;
        rc |= save_bytes(dir, "request_raw_f16", &b, OBS_OK);
    } else
        rc = 1;

    /* an EXR G-buffer (the bytes are not decoded by the protocol) */
    static const unsigned char exr[] = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
    obs_bin_param png[] = {{"format", "png"}, {"png_bits", "16"}, {"preset", "blender"}};
    d = (obs_bin_request_desc){.id = 10, .params = png, .param_count = 3, .exr = exr,
                               .exr_len = sizeof exr};
    rc |= save_bytes(dir, "request_exr", &b, obs_bin_request_encode(&d, &b, err));

    /* a deep (layered) G-buffer, 2 x 2: counts 2, 0, 1, 3, a camera */
    static const uint64_t offset[5] = {0, 2, 2, 3, 6};
    float samples[6 * OBS_DEEP_CH];
    for (int k = 0; k < 6 * OBS_DEEP_CH; k++)
        samples[k] = k % OBS_DEEP_CH == OBS_DEEP_Z ? 1.0f + (float)k : 0.5f;
    obs_deep_image deep = {.width = 2, .height = 2, .display_width = 2, .display_height = 2,
                           .offset = (uint64_t *)offset, .samples = samples, .has_alpha = 1,
                           .has_color = 1, .camera = full.camera};
    obs_bin_param dp[] = {{"deep_layers", "2"}, {"format", "raw"}, {"output", "both"}};
    d = (obs_bin_request_desc){.id = 11, .params = dp, .param_count = 3, .deep = &deep};
    rc |= save_bytes(dir, "request_deep", &b, obs_bin_request_encode(&d, &b, err));

    /* responses: an error, a PNG, raw images */
    obs_bin_response_desc r = {.id = 7, .status = 503, .retry_after = 1, .code = "queue_full",
                               .message = "the queue is full"};
    rc |= save_bytes(dir, "response_error", &b, obs_bin_response_encode(&r, &b, err));
    static const unsigned char pngb[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    r = (obs_bin_response_desc){.id = 8, .status = 200, .code = "ok", .body = OBS_BIN_PNG,
                                .blob = pngb, .blob_len = sizeof pngb};
    rc |= save_bytes(dir, "response_png", &b, obs_bin_response_encode(&r, &b, err));
    obs_bin_image im[2] = {{1, {.width = 3, .height = 2, .channels = 1, .data = depth}},
                           {2, {.width = 3, .height = 2, .channels = 4, .data = color}}};
    r = (obs_bin_response_desc){.id = 9, .status = 200, .code = "ok", .body = OBS_BIN_RAW,
                                .images = im, .image_count = 2};
    rc |= save_bytes(dir, "response_raw", &b, obs_bin_response_encode(&r, &b, err));
    return rc;
}
