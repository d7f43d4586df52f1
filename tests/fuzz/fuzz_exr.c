/* libFuzzer target for the EXR readers (core/io/exr_read.c, core/io/exr_deep.c,
 * core/io/crypto.c): every input is read from memory as a flat G-buffer and
 * as a deep image, its Cryptomatte layers (manifest JSON) described,
 * with small size limits so that a valid-looking header cannot ask for
 * much memory; whatever a reader returns is touched and freed (ASan and
 * LeakSanitizer check).  Seeds: the EXRs of tests/data and tests/data/damaged.
 *
 *   make fuzz && build/fuzz/fuzz_exr NEW_DIR tests/data/damaged */
#include <stdint.h>
#include <stdlib.h>

#include "obscura/deep.h"
#include "obscura/io.h"
#include "obscura/mask.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const obs_limits lim = {.max_width = 2048, .max_height = 2048, .max_pixels = 1u << 20, .threads = 1};
    char err[OBS_ERR_LEN];
    volatile float sink = 0;

    obs_gbuffer_file gf = {0};
    if (obs_gbuffer_read_exr_mem(data, size, NULL, &lim, &gf, err) == OBS_OK) {
        size_t px = (size_t)gf.gb.width * (size_t)gf.gb.height;
        for (size_t i = 0; i < px; i++)
            sink += gf.gb.depth.data[i];
        obs_gbuffer_free(&gf);
    }
    int deep = 0;
    if (obs_exr_is_deep_mem(data, size, &deep, err) == OBS_OK && deep) {
        obs_deep_image d;
        if (obs_deep_read_exr_mem(data, size, &lim, &d, err) == OBS_OK) {
            size_t px = (size_t)d.width * (size_t)d.height;
            for (uint64_t k = 0; k < d.offset[px]; k++)
                sink += d.samples[k * OBS_DEEP_CH];
            obs_deep_free(&d);
        }
    }
    obs_crypto_info ci;
    if (obs_crypto_describe(NULL, data, size, &ci, err) == OBS_OK) {
        for (int l = 0; l < ci.layer_count; l++)
            for (int k = 0; k < ci.layers[l].entry_count; k++)
                sink += (float)ci.layers[l].ids[k] + (float)ci.layers[l].names[k][0];
        obs_crypto_info_free(&ci);
    }
    (void)sink;
    return 0;
}
