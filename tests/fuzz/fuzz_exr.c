/* libFuzzer target for the EXR readers (core/io/exr_read.c, core/io/exr_deep.c,
 * core/io/crypto.c, core/mask.c): every input is read from memory as a flat
 * G-buffer and as a deep image, each with its object masks (a Cryptomatte
 * selector and an ID-channel selector as receivers and occluders, and
 * self_only: the mask planes per pixel and per deep sample), its
 * Cryptomatte layers (manifest JSON) described,
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

    /* the masks: a Cryptomatte name pattern, an ID range, self_only */
    static obs_params masks;
    static int masks_set;
    if (!masks_set) {
        if (obs_param_set(&masks, "receivers", "*a*,id:id=1-3", err) != OBS_OK ||
            obs_param_set(&masks, "occluders", "b?", err) != OBS_OK ||
            obs_param_set(&masks, "self_only", "on", err) != OBS_OK)
            abort(); /* the harness's own parameters */
        masks_set = 1;
    }

    obs_gbuffer_file gf = {0};
    if (obs_gbuffer_read_exr_mem(data, size, NULL, &lim, &gf, err) == OBS_OK) {
        size_t px = (size_t)gf.gb.width * (size_t)gf.gb.height;
        for (size_t i = 0; i < px; i++)
            sink += gf.gb.depth.data[i];
        if (obs_gbuffer_read_masks(&gf, NULL, data, size, &masks, &lim, err) == OBS_OK &&
            gf.gb.receivers.data)
            for (size_t i = 0; i < px; i++)
                sink += gf.gb.receivers.data[i];
        obs_gbuffer_free(&gf);
    }
    int deep = 0;
    if (obs_exr_is_deep_mem(data, size, &deep, err) == OBS_OK && deep) {
        obs_deep_image d;
        if (obs_deep_read_exr_mem(data, size, &lim, &d, err) == OBS_OK) {
            size_t px = (size_t)d.width * (size_t)d.height;
            for (uint64_t k = 0; k < d.offset[px]; k++)
                sink += d.samples[k * OBS_DEEP_CH];
            if (obs_deep_read_masks(&d, NULL, data, size, &masks, &lim, err) == OBS_OK)
                for (uint64_t k = 0; k < d.offset[px]; k++)
                    sink += (d.occluders ? d.occluders[k] : 0.0f) +
                            (d.object_id ? d.object_id[k] : 0.0f);
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
