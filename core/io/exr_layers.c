/* The output's channel names: the result's layers (AO.Y, R,G,B,A, ...)
 * and --layer's renaming of them.  No OpenEXR calls: the request parser
 * (protocol/http.c) checks a layer name with them too. */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "obscura/io.h"
#include "internal.h"

obs_status obs_exr_layers_rename(obs_exr_layer *layers, int layer_count, const char *name,
                                 obs_exr_names *store, char err[OBS_ERR_LEN])
{
    size_t len = name ? strlen(name) : 0, used = 0;
    if (len == 0 || len > OBS_EXR_LAYER_MAX || name[0] == '.' || name[len - 1] == '.')
        return obs__fail(err, OBS_INVALID_ARGUMENT, "layer name '%.100s' must be 1 to %d characters, not starting or ending with '.'",
                         name ? name : "", OBS_EXR_LAYER_MAX);
    for (const char *c = name; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "layer name '%.100s' holds a control character", name);
    for (int l = 0; l < layer_count; l++) {
        int ch = layers[l].image->channels;
        if (used + (size_t)ch > sizeof store->ptr / sizeof store->ptr[0])
            return obs__fail(err, OBS_INVALID_ARGUMENT, "too many channels to rename");
        for (int k = 0; k < ch; k++) {
            const char *old = layers[l].names[k];
            /* AO.Y -> NAME.Y; R -> NAME.R; Samples.Y -> NAME.Samples.Y */
            const char *rest = !strncmp(old, "AO.", 3) ? old + 3 : old;
            snprintf(store->name[used + k], sizeof store->name[0], "%s.%.30s", name, rest);
            store->ptr[used + k] = store->name[used + k];
        }
        layers[l].names = store->ptr + used;
        used += (size_t)ch;
    }
    return OBS_OK;
}

int obs_result_exr_layers(const obs_result *r, obs_exr_layer layers[OBS_RESULT_LAYERS])
{
    static const char *const ao[] = {"AO.Y"};
    static const char *const rgba[] = {"R", "G", "B", "A"};
    static const char *const count[] = {"Samples.Y"};
    static const char *const cull[] = {"Cull.Y"};
    static const char *const bleed[] = {"Bleed.R", "Bleed.G", "Bleed.B"};
    static const char *const lum[] = {"Luminance.Y"};
    static const char *const screen[] = {"AOScreen.Y"}, *const baked[] = {"AOBaked.Y"};
    static const char *const mb[] = {"AOMultiBounce.R", "AOMultiBounce.G", "AOMultiBounce.B"};
    static const char *const bent[] = {"BentNormal.X", "BentNormal.Y", "BentNormal.Z"};
    /* The result's images in the file's order, each with its channels. */
    static const struct {
        size_t offset;
        const char *const *names;
    } rows[] = {{offsetof(obs_result, ao), ao},
                {offsetof(obs_result, composite), rgba},
                {offsetof(obs_result, sample_count), count},
                {offsetof(obs_result, cull_mask), cull},
                {offsetof(obs_result, bleed), bleed},
                {offsetof(obs_result, luminance), lum},
                {offsetof(obs_result, ao_screen), screen},
                {offsetof(obs_result, ao_baked), baked},
                {offsetof(obs_result, multibounce), mb},
                {offsetof(obs_result, bent), bent}};
    int n = 0;
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        const obs_image *im = (const obs_image *)((const char *)r + rows[i].offset);
        if (im->data)
            layers[n++] = (obs_exr_layer){im, rows[i].names};
    }
    return n;
}
