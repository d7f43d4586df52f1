/* The LOD rows of obscura bake's report (clients/bake_lod.c). */
#ifndef OBSCURA_CLIENT_BAKE_LOD_H
#define OBSCURA_CLIENT_BAKE_LOD_H

struct cJSON;
struct obs_bake_params;
struct obs_bake_stats;

/* Adds the report's "lods" object to r. */
void cli_bake_lod_report(struct cJSON *r, const struct obs_bake_params *p,
                         const struct obs_bake_stats *st);

#endif
