/* The parameter table of obscura bake-dynamic (OBS_DYN_PARAM_TABLE,
 * obscura/dynamic.h) and its accessors obs_dyn_param_count/at/find/set,
 * obs_dyn_params_resolve and obs_dyn_param_format: the bake's kind of
 * table (core/param_table.h) over the table engine (core/table.c). */
#include "obscura/dynamic.h"
#include "param_table.h"

#define OBS__PARAM_STRUCT obs_dyn_params
OBS__PARAM_TABLE(dyn_param, OBS_DYN_PARAM_TABLE, "bake-dynamic parameter")
