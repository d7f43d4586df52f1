/* The HTTP API's request and error formats, shared by the daemon and
 * (later) the remote client.  No sockets and no GL here: query parameters
 * in, a parsed request out; statuses to HTTP codes; JSON bodies.
 *
 *   POST /v1/ao?output=ao&format=exr&radius=0.5&fov_y=50 ...
 *
 * Query parameters are the core parameter table (same names as the CLI
 * flags, '-' or '_') plus the request options below. */
#ifndef OBSCURA_PROTOCOL_HTTP_H
#define OBSCURA_PROTOCOL_HTTP_H

#include "obscura/io.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum obs_http_format {
    OBS_HTTP_EXR,
    OBS_HTTP_PNG
} obs_http_format;

/* One POST /v1/ao request, as parsed from its query string. */
typedef struct obs_http_request {
    obs_params params;      /* the parameter table */
    unsigned outputs;       /* OBS_OUTPUT_* bits; default AO */
    obs_http_format format; /* default EXR */
    int float_exr;          /* EXR: 32-bit float channels (default half) */
    int png_bits;           /* 8 (default) or 16 */
    obs_channel_map map;    /* points into the buffers below */
    char preset[16];
    char depth[64];
    char normal[3][64];
    char color[4][64];
} obs_http_request;

/* Zeroes the request: every option at its default. */
void obs_http_request_init(obs_http_request *r);

/* Sets one query parameter.  Unknown names, bad values and values out of
 * range fail with OBS_INVALID_ARGUMENT and a message naming the
 * parameter and what it accepts. */
obs_status obs_http_request_set(obs_http_request *r, const char *name, const char *value,
                                char err[OBS_ERR_LEN]);

/* Checks the combination once every parameter is set (PNG holds one
 * image, so format=png with output=both is refused). */
obs_status obs_http_request_check(const obs_http_request *r, char err[OBS_ERR_LEN]);

/* The request options that are not in the parameter table, for
 * /v1/params and help: name, choices or type, default, doc. */
typedef struct obs_http_option {
    const char *name, *type, *def, *choices, *doc;
} obs_http_option;
extern const obs_http_option obs_http_options[]; /* ends with name NULL */

/* HTTP status for a core status, and the error code string of the JSON
 * body ("bad_parameter", "missing_channel", ...; static). */
int obs_http_status_of(obs_status s, const char **code);

/* {"error": {"code": CODE, "message": MESSAGE}}.  Caller frees with
 * free(); NULL when out of memory. */
char *obs_http_error_json(const char *code, const char *message);

/* The parameter table and the request options as JSON:
 * {"version": ..., "params": [{name, type, default, min, max | choices,
 * doc}], "options": [...]}.  Caller frees with free(). */
char *obs_http_params_json(void);

/* The value of a "Bearer TOKEN" Authorization header matches `token`,
 * compared in time independent of where they differ.  0 / 1. */
int obs_http_bearer_ok(const char *authorization, const char *token);

#ifdef __cplusplus
}
#endif

#endif
