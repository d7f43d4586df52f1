/* The deep AO out (obs_deep_ao_nodes, obscura ao --output deep): the AO of
 * every node the list compression kept, the per-node AO of OITAO
 * Algorithm 1 (obs__deep_node_ao) that obs__deep_pixel blends into the
 * flat AO, kept per node instead; and the work it adds to a frame
 * (obs_deep_frame_cost). */
#include <stdlib.h>
#include <string.h>

#include "deep/deep_internal.h"

unsigned long long obs_deep_frame_cost(const obs_deep_image *d, const obs_params *params,
                                       unsigned outputs, int cpu)
{
    if (!d || !d->offset || d->width <= 0 || d->height <= 0)
        return 0;
    obs_params p;
    obs_params_resolve(params, &p);
    const int m = p.deep_layers;
    unsigned long long n = obs_frame_cost(&p, d->width, d->height, m);
    if (!(outputs & OBS_OUTPUT_DEEP) || !cpu)
        return n; /* GL: the pass keeps the nodes' AO (obs_deep_run_nodes) */
    /* obs_deep_ao_nodes apart from obs_deep_run_cpu: each kept
     * node (min(samples, m) a pixel, obs_deep_compress) with the
     * method's samples against the m nodes at their pixels, the unit
     * of the pass's m^2 a pixel */
    const unsigned long long per_node = obs_frame_cost(&p, 1, 1, 0) * (unsigned long long)m;
    const size_t npx = (size_t)d->width * (size_t)d->height;
    unsigned long long kept = 0;
    for (size_t i = 0; i < npx; i++) {
        uint64_t c = d->offset[i + 1] - d->offset[i];
        if (c > OBS_DEEP_MAX_PER_PIXEL)
            c = OBS_DEEP_MAX_PER_PIXEL;
        kept += c < (uint64_t)m ? c : (uint64_t)m;
    }
    return n + kept * per_node;
}

void obs_deep_ao_free(obs_deep_ao *a)
{
    if (!a)
        return;
    free(a->offset);
    free(a->node);
    memset(a, 0, sizeof *a);
}

obs_status obs__deep_ao_pack(const obs_deep_image *d, const obs__deep_frame *df,
                             const float *node_ao, obs_deep_ao *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    const size_t npx = (size_t)d->width * (size_t)d->height;
    /* at most m nodes a pixel: npx * m * OBS_DEEP_AO_CH floats, the
     * sizes the setup's node planes already took */
    out->offset = malloc((npx + 1) * sizeof *out->offset);
    out->node = malloc(npx * (size_t)df->m * OBS_DEEP_AO_CH * sizeof *out->node);
    if (!out->offset || !out->node) {
        obs_deep_ao_free(out);
        return obs__fail(err, OBS_NO_MEMORY, "deep AO nodes of %dx%d", d->width, d->height);
    }
    out->width = d->width;
    out->height = d->height;
    out->display_x = d->display_x;
    out->display_y = d->display_y;
    out->display_width = d->display_width;
    out->display_height = d->display_height;
    out->camera = d->camera;
    uint64_t n = 0;
    for (int y = 0; y < d->height; y++)
        for (int x = 0; x < d->width; x++) {
            size_t i = (size_t)y * d->width + x;
            out->offset[i] = n;
            /* nodes are packed front to back (obs__deep_pixel's walk) */
            for (int k = 0; k < df->m && df->pos[((size_t)k * npx + i) * 4 + 3] > 0.0f; k++) {
                const size_t at = (size_t)k * npx + i;
                const float *src = df->layers.node + at * OBS_DEEP_CH;
                float *o = out->node + n++ * OBS_DEEP_AO_CH;
                o[OBS_DEEP_AO_Z] = src[OBS_DEEP_Z];
                o[OBS_DEEP_AO_ZBACK] = src[OBS_DEEP_ZBACK];
                o[OBS_DEEP_AO_A] = df->nrm[at * 4 + 3];
                o[OBS_DEEP_AO_AO] = node_ao ? node_ao[at] : obs__deep_node_ao(df, x, y, k);
            }
        }
    out->offset[npx] = n;
    return OBS_OK;
}

obs_status obs_deep_ao_nodes(const obs_deep_image *d, const obs_params *params, obs_deep_ao *out,
                             char err[OBS_ERR_LEN])
{
    obs__deep_frame df;
    if (!out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_deep_ao_nodes: no output");
    memset(out, 0, sizeof *out);
    obs_status s = obs__deep_frame_setup(d, params, &df, err);
    if (s != OBS_OK)
        return s;
    s = obs__deep_ao_pack(d, &df, NULL, out, err);
    obs__deep_frame_free(&df);
    return s;
}
