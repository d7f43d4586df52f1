/* obscura bake (clients/bake.c): ambient obscurance baked onto a level's
 * vertices.  Returns the process exit code. */
#ifndef OBSCURA_CLIENT_BAKE_H
#define OBSCURA_CLIENT_BAKE_H

#include <stdio.h>

int cli_bake(int argc, char **argv);
void cli_bake_usage(FILE *f);

/* The report's "lods" object (clients/bake_lod.c). */
struct cJSON;
struct obs_bake_params;
struct obs_bake_stats;
void cli_bake_lod_report(struct cJSON *r, const struct obs_bake_params *p,
                         const struct obs_bake_stats *st);

#endif
