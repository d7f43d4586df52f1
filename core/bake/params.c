/* The bake parameter table (OBS_BAKE_PARAM_TABLE, obscura/bake.h) and its
 * accessors obs_bake_param_count/at/find/set, obs_bake_params_resolve and
 * obs_bake_param_format: written once for the bake-style tables in
 * core/param_table.h, over the table engine (core/table.c). */
#include "obscura/bake.h"
#include "param_table.h"

#define OBS__PARAM_STRUCT obs_bake_params
OBS__PARAM_TABLE(bake_param, OBS_BAKE_PARAM_TABLE, "bake parameter")
