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

#include <stddef.h>

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
    int compression;        /* EXR: obs_exr_compression; 0 (auto): the writer's default */
    int png_bits;           /* 8 (default) or 16 */
    int png_transfer;       /* obs_png_transfer of the AO PNG: sRGB (default) or linear */
    int strict;             /* sanity warnings on the input are errors */
    int solve_camera;       /* no camera: solve it from the position pass */
    obs_channel_map map;    /* points into the buffers below */
    char preset[16];
    char depth[64];
    char normal[3][64];
    char color[4][64];
    char part[64];
    char view[64];
    /* the output's channel names: layer=NAME gives NAME.Y (AO) and
     * NAME.R,G,B,A (composite); NULL: AO.Y and R,G,B,A */
    const char *layer;
    char layer_name[64];
    int append;             /* EXR: the input's parts and channels, the AO added */
    /* baked=CH: a baked AO channel of the input combined with the chain's
     * AO (baked_combine); NULL: _AO when the input has it; "none": not */
    const char *baked;
    char baked_name[64];
} obs_http_request;

/* Zeroes the request: every option at its default. */
void obs_http_request_init(obs_http_request *r);

/* Sets one query parameter.  Unknown names, bad values and values out of
 * range fail with OBS_INVALID_ARGUMENT and a message naming the
 * parameter and what it accepts. */
obs_status obs_http_request_set(obs_http_request *r, const char *name, const char *value,
                                char err[OBS_ERR_LEN]);

/* A query parameter as the wire holds it, `len` bytes of value: a NUL
 * inside the name or the value (%00) is refused, naming the parameter
 * (the C string would end there and the rest be dropped unseen); then
 * obs_http_request_set(). */
obs_status obs_http_request_set_n(obs_http_request *r, const char *name, size_t name_len, const char *value,
                                  size_t len, char err[OBS_ERR_LEN]);

/* OBS_OK when `name` (name_len bytes) and `value` (len bytes) hold no NUL;
 * else OBS_INVALID_ARGUMENT and a message naming the parameter. */
obs_status obs_http_value_check(const char *name, size_t name_len, const char *value, size_t len,
                                char err[OBS_ERR_LEN]);

/* Checks the combination once every parameter is set (PNG holds one
 * image, so format=png with output=both is refused). */
obs_status obs_http_request_check(const obs_http_request *r, char err[OBS_ERR_LEN]);

/* Where an option's value comes from: a query parameter of obscurad
 * (HTTP, or a name=value pair of the binary protocol), or a flag of
 * `obscura ao` (clients/ao_flags.c).  The CLI takes a little more where a
 * row says so: the debug outputs, which obscurad does not return, and a
 * comma list of outputs (the CLI writes several files). */
typedef enum obs_http_from {
    OBS_HTTP_QUERY = 1,
    OBS_HTTP_CLI = 2
} obs_http_from;

/* How a request option's value is parsed and stored. */
typedef enum obs_http_option_kind {
    OBS_HTTP_OPT_CHOICE, /* one of `choices` (a comma list, or'ed, where `list`), stored as an int */
    OBS_HTTP_OPT_BOOL,   /* 1, true or empty; 0 or false; stored as an int (the CLI: a switch) */
    OBS_HTTP_OPT_NAMES   /* min..max comma-separated names into the request's slots, the
                          * channel map pointing at them; max 1: the value whole */
} obs_http_option_kind;

/* One name an OBS_HTTP_OPT_CHOICE row takes: the int it stores and
 * where it is taken (OBS_HTTP_QUERY | OBS_HTTP_CLI bits). */
typedef struct obs_http_choice {
    const char *name;
    int value;
    unsigned from;
} obs_http_choice;

/* The request options that are not in the parameter table: one row
 * each, which both obs_http_request_set() and the CLI's flags parse
 * through obs_http_option_set(), and which /v1/params lists. */
typedef struct obs_http_option {
    const char *name;
    obs_http_option_kind kind;
    size_t field;                   /* offsetof(obs_http_request, ...): the int, or the first slot */
    const char *def;                /* CHOICE, BOOL: set by obs_http_request_init(); NAMES: shown
                                     * only (unset is the map's NULL: the preset decides) */
    const obs_http_choice *choices; /* CHOICE: ends with name NULL */
    unsigned list;                  /* CHOICE: where a comma list is taken */
    const char *const *names;       /* NAMES: the names taken, NULL-ended; NULL: any */
    int min, max;                   /* NAMES: how many names */
    size_t slot;                    /* NAMES: bytes of one slot (with its '\0') */
    size_t map;                     /* NAMES: offsetof(obs_http_request, map...), max pointers */
    const char *what;               /* NAMES without `names`: what the value must be, for errors */
    const char *doc;
} obs_http_option;
extern const obs_http_option obs_http_options[]; /* ends with name NULL */

/* The row named `name` ('-' or '_'), or NULL. */
const obs_http_option *obs_http_option_find(const char *name);

/* Parses `value` by the row and stores it in r (nothing when it fails:
 * OBS_INVALID_ARGUMENT, and a message naming the parameter and what it
 * accepts).  `from` says which choices are taken. */
obs_status obs_http_option_set(obs_http_request *r, const obs_http_option *op, const char *value,
                               obs_http_from from, char err[OBS_ERR_LEN]);

/* HTTP status for a core status, and the error code string of the JSON
 * body ("bad_parameter", "missing_channel", ...; static). */
int obs_http_status_of(obs_status s, const char **code);

/* {"error": {"code": CODE, "message": MESSAGE}}, valid UTF-8 whatever
 * the message echoes (a byte that is not UTF-8 becomes U+FFFD; control
 * characters are escaped).  Caller frees with free(); NULL when out of
 * memory. */
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
