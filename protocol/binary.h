/* The binary protocol of obscurad: length-prefixed frames on a stream
 * socket (Unix or TCP).  Encoding and decoding only; no sockets, no GL.
 * The wire format, byte by byte, is in protocol/PROTOCOL.md.
 *
 *   frame    = header (OBS_BIN_HEADER_LEN bytes) + payload (header.length)
 *   request  = parameters (name=value strings) + outputs + a G-buffer:
 *              an EXR file (flat or deep), raw float32/float16 planes and a
 *              camera, or a deep (layered) A-buffer: per-pixel sample
 *              counts and the packed samples
 *   response = status + code + message, then nothing, an EXR/PNG file or
 *              raw float32 planes; a 200's message holds the answer's
 *              warnings, one a line (version 1 sent "" there, so a reader
 *              that ignores a 200's message reads both)
 *
 * Every size read from the wire is checked (overflow, the limits the
 * caller passes, the bytes actually present) before anything is
 * allocated or read; a decoder never reads past the buffer it was given. */
#ifndef OBSCURA_PROTOCOL_BINARY_H
#define OBSCURA_PROTOCOL_BINARY_H

#include <stddef.h>
#include <stdint.h>

#include "http.h"
#include "obscura/deep.h"

#ifdef __cplusplus
extern "C" {
#endif

#define OBS_BIN_MAGIC "OBSP"
#define OBS_BIN_VERSION 1
#define OBS_BIN_HEADER_LEN 24
#define OBS_BIN_MAX_PARAMS 256
#define OBS_BIN_MAX_NAME 64
#define OBS_BIN_MAX_VALUE 4096
#define OBS_BIN_MAX_MESSAGE 4096
#define OBS_BIN_MAX_WARNINGS 16

typedef enum obs_bin_kind {
    OBS_BIN_REQUEST = 1,
    OBS_BIN_RESPONSE = 2
} obs_bin_kind;

/* The G-buffer of a request, and the body of a response. */
typedef enum obs_bin_body {
    OBS_BIN_NONE = 0, /* responses only: an error */
    OBS_BIN_EXR = 1,  /* an OpenEXR file */
    OBS_BIN_RAW = 2,  /* float32 planes (requests: or float16) */
    OBS_BIN_PNG = 3,  /* responses only: a PNG file */
    OBS_BIN_DEEP = 4  /* requests only: a deep (layered) A-buffer */
} obs_bin_body;

/* Raw G-buffer flags. */
enum {
    OBS_BIN_HAS_NORMAL = 1,
    OBS_BIN_HAS_COLOR = 2,
    OBS_BIN_HAS_WORLD_TO_CAMERA = 4,
    OBS_BIN_HAS_PROJECTION = 8
};

/* Deep G-buffer flags: which of a sample's values the renderer wrote
 * (the others are filled as the deep EXR reader fills them), and the
 * camera (the same bits as the raw G-buffer's). */
enum {
    OBS_BIN_DEEP_ZBACK = 1,
    OBS_BIN_DEEP_ALPHA = 2,
    OBS_BIN_DEEP_COLOR = 16,
    OBS_BIN_DEEP_NORMAL = 32,
    OBS_BIN_DEEP_FACING = 64
};

/* The `output` of a raw response image that holds the front node's AO of
 * deep input (its AO.Y, blended over the nodes, is OBS_OUTPUT_AO). */
#define OBS_BIN_OUTPUT_AO_FRONT 256u

/* Raw G-buffer plane types (the field after the flags).  Requests only:
 * float16 planes are converted to float32 by the decoder; responses and
 * the encoder use float32. */
enum {
    OBS_BIN_F32 = 0,
    OBS_BIN_F16 = 1
};

/* IEEE-754 half -> float, exact (subnormals, inf, NaN included). */
float obs_bin_half_to_float(uint16_t h);

typedef struct obs_bin_header {
    obs_bin_kind kind;
    uint64_t id;     /* chosen by the client, echoed in the response */
    uint64_t length; /* payload bytes that follow the header */
} obs_bin_header;

/* Writes a header into out[OBS_BIN_HEADER_LEN]. */
void obs_bin_header_write(unsigned char *out, obs_bin_kind kind, uint64_t id, uint64_t length);

/* Parses a header: magic, version, kind, and length <= max_payload.
 * OBS_BAD_FILE for a bad magic/version/kind, OBS_TOO_LARGE for a length
 * over the limit (h->length is set then, so the caller can say how big). */
obs_status obs_bin_header_parse(const unsigned char *in, obs_bin_header *h, uint64_t max_payload,
                                char err[OBS_ERR_LEN]);

/* ---- requests ------------------------------------------------------------ */

/* One name=value pair; names are the parameter table's plus the request
 * options of protocol/http.h (output, format, float, png_bits, preset,
 * depth, normal, color), format=raw, and token. */
typedef struct obs_bin_param {
    const char *name;
    const char *value;
} obs_bin_param;

/* What a client sends.  gb: raw planes (tightly packed or strided); exr:
 * an EXR file; deep: an A-buffer (each pixel's samples sorted by Z, front
 * to back, as obs_deep_read_exr gives them).  Exactly one of them is set. */
typedef struct obs_bin_request_desc {
    uint64_t id;
    const obs_bin_param *params;
    int param_count;
    const obs_gbuffer *gb;
    const void *exr;
    size_t exr_len;
    const obs_deep_image *deep;
} obs_bin_request_desc;

/* Encodes a whole request frame (header + payload).  Caller frees with
 * obs_bytes_free(). */
obs_status obs_bin_request_encode(const obs_bin_request_desc *d, obs_bytes *out,
                                  char err[OBS_ERR_LEN]);

/* A decoded request.  With body RAW, gf.gb's float32 planes point into
 * the payload when it is 4-byte aligned (else into gf.storage, a copy);
 * float16 planes are converted into gf.storage; with
 * EXR, exr/exr_len point into the payload; with DEEP, deep.offset is
 * owned and deep.samples points into the payload when it is 4-byte
 * aligned (else into gf.storage, a copy; samples of 9 values, without
 * Facing, are widened into gf.storage).  The deep image is read-only
 * (never pass it to obs_deep_free).  Either way the payload must outlive
 * the request.  Free with obs_bin_request_free(). */
typedef struct obs_bin_request {
    obs_http_request hr; /* parameters and response options */
    int raw_out;         /* format=raw: answer with float32 planes */
    char token[512];     /* token=..., "" when absent */
    obs_bin_body body;   /* EXR, RAW or DEEP */
    const unsigned char *exr;
    size_t exr_len;
    obs_gbuffer_file gf; /* RAW */
    obs_deep_image deep; /* DEEP */
} obs_bin_request;

/* Decodes a request payload (the bytes after the header).  Sizes are
 * checked against `lim` before any allocation.  Statuses: OBS_BAD_FILE
 * (malformed, truncated, trailing bytes), OBS_INVALID_ARGUMENT (a bad
 * parameter, named), OBS_TOO_LARGE, OBS_NO_MEMORY. */
obs_status obs_bin_request_decode(const unsigned char *payload, size_t len, const obs_limits *lim,
                                  obs_bin_request *out, char err[OBS_ERR_LEN]);
void obs_bin_request_free(obs_bin_request *r);

/* A request's head: what the first bytes of its payload say, so that a
 * server can refuse a frame before it reads (and buffers) its G-buffer.
 * The head is the parameters, the G-buffer kind and the G-buffer's fixed
 * fields (an EXR's length; raw and deep planes' sizes and flags, their
 * camera), at most about 1 MiB. */
typedef struct obs_bin_head {
    size_t len;        /* the head's bytes (0 while more are needed) */
    int params_done;   /* the parameters were read whole: `token` is known */
    char token[512];   /* token=..., "" when absent */
    obs_bin_body body; /* EXR, RAW or DEEP */
    uint32_t width, height; /* RAW and DEEP */
} obs_bin_head;

/* Parses the head of a `len`-byte request payload from its first
 * `have_len` bytes.  OBS_OK with *need > have_len: read the payload up to
 * *need bytes and call again; OBS_OK with *need == 0: h is filled.
 * Otherwise the error obs_bin_request_decode() gives for those bytes:
 * the parameters' framing (their values are not checked here), the
 * G-buffer kind, the size against `lim`, a deep frame's sample total,
 * and the bytes the G-buffer announces against the rest of the payload. */
obs_status obs_bin_request_head(const unsigned char *p, size_t have_len, size_t len, const obs_limits *lim,
                                obs_bin_head *h, size_t *need, char err[OBS_ERR_LEN]);

/* ---- responses ----------------------------------------------------------- */

/* One raw output image: which output (OBS_OUTPUT_* bit) and its pixels. */
typedef struct obs_bin_image {
    unsigned output;
    obs_image image; /* decoded: owned, free with obs_image_free() */
} obs_bin_image;

#define OBS_BIN_MAX_IMAGES 8

typedef struct obs_bin_response_desc {
    uint64_t id;
    int status;        /* HTTP-like: 200, 400, 401, 413, 415, 422, 500, 503 */
    int retry_after;   /* seconds, with 503; 0 otherwise */
    const char *code;  /* "ok", "bad_parameter", ... (as protocol/http.h) */
    const char *message; /* errors: what is wrong */
    /* status 200: the answer's warnings (X-Obscura-Warning over HTTP),
     * sent in the message field, one a line: a line break inside one is
     * sent as a space, and those past OBS_BIN_MAX_MESSAGE bytes (or
     * OBS_BIN_MAX_WARNINGS) are left out whole */
    const char *const *warnings;
    int warning_count;
    obs_bin_body body; /* NONE, EXR, PNG or RAW */
    const void *blob;  /* EXR or PNG */
    size_t blob_len;
    const obs_bin_image *images; /* RAW */
    int image_count;
} obs_bin_response_desc;

/* Encodes a whole response frame.  Caller frees with obs_bytes_free(). */
obs_status obs_bin_response_encode(const obs_bin_response_desc *d, obs_bytes *out,
                                   char err[OBS_ERR_LEN]);

typedef struct obs_bin_response {
    int status, retry_after;
    char code[64];
    char message[OBS_BIN_MAX_MESSAGE + 1];
    /* status 200: the message's lines, the answer's warnings (pointing
     * into warning_text) */
    int warning_count;
    const char *warnings[OBS_BIN_MAX_WARNINGS];
    char warning_text[OBS_BIN_MAX_MESSAGE + 1];
    obs_bin_body body;
    const unsigned char *blob; /* EXR/PNG: points into the payload */
    size_t blob_len;
    obs_bin_image images[OBS_BIN_MAX_IMAGES]; /* RAW: copies, owned */
    int image_count;
} obs_bin_response;

/* Decodes a response payload; raw images are checked against `lim` and
 * copied out.  Free with obs_bin_response_free(). */
obs_status obs_bin_response_decode(const unsigned char *payload, size_t len, const obs_limits *lim,
                                   obs_bin_response *out, char err[OBS_ERR_LEN]);
void obs_bin_response_free(obs_bin_response *r);

#ifdef __cplusplus
}
#endif

#endif
