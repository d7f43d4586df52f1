/* The LOD rows of obscura bake's report (parameter lods; core/bake/lod.c):
 * per level the counts, the RMS of the fit and of the vertex baseline
 * against the resampled values, and with lod_check the same at held-out
 * samples and against the direct bake of the LOD (traced on the LOD
 * geometry and fitted); the lod stage's parts in seconds. */
#include <cjson/cJSON.h>

#include "bake_lod.h"
#include "obscura/bake.h"

static cJSON *pair(const double v[2])
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "short", v[0]);
    cJSON_AddNumberToObject(o, "long", v[1]);
    return o;
}

void cli_bake_lod_report(cJSON *r, const obs_bake_params *p, const obs_bake_stats *st)
{
    cJSON *lod = cJSON_AddObjectToObject(r, "lods");
    cJSON_AddNumberToObject(lod, "levels", (double)st->lod_levels);
    cJSON *sec = cJSON_AddObjectToObject(lod, "seconds");
    static const char *const parts[4] = {"simplify", "resample", "fit", "check"};
    for (int i = 0; i < 4; i++)
        cJSON_AddNumberToObject(sec, parts[i], st->lod_seconds[i]);
    cJSON *lv = cJSON_AddArrayToObject(lod, "per_level");
    for (size_t k = 0; k < st->lod_levels && k < OBS_BAKE_MAX_LODS; k++) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddNumberToObject(o, "level", (double)(k + 1));
        cJSON_AddNumberToObject(o, "triangles", (double)st->lod_triangles[k]);
        cJSON_AddNumberToObject(o, "meshes_from_file", (double)st->lod_file_meshes[k]);
        cJSON_AddNumberToObject(o, "vertices", (double)st->lod_vertices[k]);
        cJSON_AddNumberToObject(o, "welded_vertices", (double)st->lod_welded[k]);
        cJSON_AddNumberToObject(o, "samples", (double)st->lod_samples[k]);
        cJSON *res = cJSON_AddObjectToObject(o, "resampled_rms");
        cJSON_AddItemToObject(res, "least_squares", pair(st->lod_fit[k]));
        cJSON_AddItemToObject(res, "vertex_sample", pair(st->lod_vertex[k]));
        if (p->lod_check) {
            cJSON *ho = cJSON_AddObjectToObject(o, "holdout_resampled_rms");
            cJSON_AddItemToObject(ho, "least_squares", pair(st->lod_holdout_fit[k]));
            cJSON_AddItemToObject(ho, "vertex_sample", pair(st->lod_holdout_vertex[k]));
            cJSON *tr = cJSON_AddObjectToObject(o, "direct_bake_rms");
            cJSON_AddNumberToObject(tr, "samples", (double)st->lod_traced_samples[k]);
            cJSON_AddItemToObject(tr, "least_squares", pair(st->lod_traced_fit[k]));
            cJSON_AddItemToObject(tr, "vertex_sample", pair(st->lod_traced_vertex[k]));
            cJSON_AddItemToObject(tr, "resampled", pair(st->lod_traced_resampled[k]));
            cJSON_AddItemToObject(tr, "direct_in_sample", pair(st->lod_direct_residual[k]));
        }
        cJSON_AddItemToArray(lv, o);
    }
}
