/* obscurad's configuration: one table of options (Redis static_configs
 * style).  A config file holds `name value` lines; every line is also a
 * flag (--name value or --name=value), and flags override the file.
 * `obscurad --help` is generated from the table. */
#ifndef OBSD_CONFIG_H
#define OBSD_CONFIG_H

#include <stdint.h>
#include <stdio.h>

#include "obscura/status.h"
#include "obscura/table.h"

#define OBSD_STR_LEN 256

/* X(name, type, min, max, default, doc)
 * type: STRING (max = longest length), INT, SIZE (bytes; k/m/g suffixes,
 * powers of 1024), ENUM (its choices are OBSD_CHOICES_name below; the
 * value is the 0-based index).  A new option is its row and its use:
 * parsing, the config file, the flag, --help and the README table follow
 * from the row. */
#define OBSD_CHOICES_backend "auto|egl-device|egl-surfaceless|osmesa|cpu"
#define OBSD_CHOICES_log_level "error|warn|info|debug"
#define OBSD_CONFIG_TABLE(X)                                                   \
    X(http, STRING, 0, OBSD_STR_LEN - 1, "127.0.0.1:8420",                     \
      "HTTP listen address IPV4:PORT or [IPV6]:PORT (port 0 picks a free "     \
      "port; empty: no HTTP)")                                                 \
    X(socket, STRING, 0, OBSD_STR_LEN - 1, "",                                 \
      "binary protocol (protocol/PROTOCOL.md) on this Unix socket path "      \
      "(empty: none)")       \
    X(tcp, STRING, 0, OBSD_STR_LEN - 1, "",                                    \
      "binary protocol on this TCP [HOST:]PORT (host 127.0.0.1 unless "       \
      "given; IPv6 in brackets: [::1]:PORT; port 0 picks a free port; "       \
      "empty: none)")                                                          \
    X(bin_connections, INT, 1, 4096, "256",                                    \
      "binary-protocol connections open at once; one more is answered 503 "   \
      "too_many_connections and closed")                                       \
    X(max_per_client, INT, 0, 4096, "64",                                      \
      "connections open at once from one client address, per listener "      \
      "(Unix-socket clients count as one address); one more is answered 503 " \
      "too_many_connections and closed (0: no limit)")                         \
    X(queue, INT, 1, 1024, "8",                                                \
      "frames that may wait for the GL worker; more are answered 503")         \
    X(threads, INT, 1, 64, "4",                                                \
      "HTTP threads (they read, decode and encode; one GL thread runs; the "  \
      "binary protocol has a thread per connection); the threads of the "     \
      "frames and bakes themselves are --render-threads")                     \
    X(render_threads, INT, 0, 64, "0",                                         \
      "threads the frames and bakes may run, as obscura --threads: "          \
      "llvmpipe's (LP_NUM_THREADS, unless set) and every worker pool's (EXR " \
      "decode, bake ray tracing, a bake job's threads parameter); 0: "        \
      "OBSCURA_THREADS, else every core")                                      \
    X(max_memory, INT, 0, 1073741824, "0",                                     \
      "MiB a frame on the CPU device may hold, as obscura --max-memory: over " \
      "it the frame runs in bands of rows, the same result; at most the "     \
      "usable memory (the machine's, or its cgroup limit when lower); 0: "    \
      "OBSCURA_MAX_MEMORY, else a quarter of the usable memory")              \
    X(max_pixels, SIZE, 1, 1073741824, "33554432",                             \
      "largest accepted width x height of a G-buffer (413 above)")             \
    X(max_body, SIZE, 1024, 17179869184, "1g",                                 \
      "largest accepted request body in bytes (413 above, before reading)")    \
    X(timeout, INT, 0, 86400, "60",                                            \
      "seconds a connection may stay idle (0: no limit)")                      \
    X(request_timeout, INT, 0, 86400, "300",                                   \
      "seconds a request may take to send its headers and body, however "     \
      "steadily it trickles (408, or closed, past it; 0: no limit)")           \
    X(http_connections, INT, 1, 65536, "512",                                  \
      "HTTP connections at once; at the limit a new one displaces the oldest " \
      "still waiting for its headers, else it may ask /healthz and /readyz "  \
      "only (16 more are kept for that)")                                      \
    X(token_file, STRING, 0, OBSD_STR_LEN - 1, "",                             \
      "file holding a bearer token; when set, /v1/* and /metrics need "        \
      "'Authorization: Bearer TOKEN'")                                         \
    X(cors, STRING, 0, OBSD_STR_LEN - 1, "",                                   \
      "allow a browser page from this origin (e.g. https://preview.example."  \
      "com, or *) to call the API: OPTIONS preflights answered 204, "         \
      "Access-Control-Allow-Origin on every answer (empty: off, OPTIONS is "  \
      "405)")                                                                  \
    X(streams, INT, 0, 1024, "16",                                             \
      "streams of frames kept for the preview page (POST /v1/streams/NAME/"   \
      "frames); a new one beyond drops the least recently posted-to (0: "      \
      "streams off)")                                                          \
    X(stream_frames, INT, 1, 1024, "8",                                        \
      "frames kept per stream (the oldest is dropped)")                        \
    X(stream_memory, SIZE, 1048576, 17179869184, "256m",                       \
      "memory a stream's frames may hold (input EXR, AO, composite, colour); " \
      "the oldest are dropped beyond it, the newest is always kept")          \
    X(max_bakes, INT, 0, 1024, "4",                                            \
      "bake jobs (POST /v1/bakes) queued or running at once; one more is "    \
      "answered 503 bake_queue_full (0: bakes off, 404)")                      \
    X(bake_workers, INT, 1, 16, "1",                                           \
      "bake jobs run at once, each on its own thread beside the GL worker "   \
      "(its ray tracing on every core unless its threads parameter says)")    \
    X(bake_keep, INT, 1, 1024, "16",                                           \
      "finished bake jobs kept for their state and result (in memory: a "     \
      "restart loses them); beyond it the oldest finished is dropped")        \
    X(max_level, SIZE, 1024, 17179869184, "256m",                              \
      "largest accepted level (POST /v1/bakes body) in bytes (413 above, "    \
      "before reading)")                                                       \
    X(bake_max_triangles, INT, 1, 2147483647, "20000000",                      \
      "most triangles of a bake job's level once instances are flattened "    \
      "(caps its max_triangles parameter: the bake's memory grows with it)")  \
    X(drain_timeout, INT, 0, 86400, "30",                                      \
      "seconds the drain after SIGTERM may wait for the requests and "         \
      "connections under way; then they are cut, logged, and the daemon "    \
      "exits 0 (0: wait for them)")                                            \
    X(max_cost, SIZE, 0, 1099511627776, "768m",                                \
      "largest work one frame may ask for, in samples: width x height x "      \
      "the method's samples per pixel (x nodes^2 for deep input, plus "       \
      "kept nodes x samples x nodes for output=deep on backend cpu); 422 "    \
      "too_costly above, before it runs (0: no limit; the default takes the "  \
      "default chain at the largest accepted frame, max_pixels x 16)")         \
    X(frame_deadline, INT, 0, 86400, "60",                                   \
      "seconds of GL work one frame may take; past it the frame is stopped "  \
      "(the AO pass runs in 16 bands of rows, the clock read between "        \
      "them; on the CPU device between passes and the AO pass's tiles) "      \
      "and answered 422 deadline_exceeded, and the GL worker takes "          \
      "the next frame (0: no deadline, the AO pass drawn at once)")           \
    X(keep_memory, SIZE, 0, 1099511627776, "512m",                             \
      "texture memory the GL worker keeps for the next frame of the same "     \
      "size (on the CPU device, its planes); above it, whenever the queue "  \
      "runs empty, it is released; "                                           \
      "freed heap memory is returned to the system (malloc_trim) once the "    \
      "queue has stayed empty for a second")                                   \
    X(cache_dir, STRING, 0, OBSD_STR_LEN - 1, "",                              \
      "program cache folder (default: OBSCURA_CACHE_DIR, else "                \
      "$XDG_CACHE_HOME/obscura, else ~/.cache/obscura; given empty: none); "  \
      "read-only when it cannot be written")                                   \
    X(backend, ENUM, 0, 0, "auto",                                             \
      "backend: auto|egl-device|egl-surfaceless|osmesa (a GL context) or "    \
      "cpu (the CPU device, no GL context); auto named: a GPU, else the "     \
      "faster of cpu and llvmpipe, measured once and kept in the cache "      \
      "folder (default: OBSCURA_BACKEND, else auto)")                          \
    X(log_level, ENUM, 0, 0, "info",                                           \
      "error|warn|info|debug; info logs one line per request")                \
    X(fail_gl_after, INT, 0, 1000000000, "0",                                  \
      "testing: report a GL failure on frame N (0: never)")

/* The option types, as the table engine's (obscura/table.h) reads them:
 * STRING a char[OBSD_STR_LEN], INT an int of digits, SIZE an int64_t with
 * k/m/g, ENUM the 0-based index among the choices. */
typedef obs_table_type obsd_opt_type;
#define OBSD_OPT_STRING OBS_TABLE_STRING
#define OBSD_OPT_INT OBS_TABLE_WHOLE
#define OBSD_OPT_SIZE OBS_TABLE_SIZE
#define OBSD_OPT_ENUM OBS_TABLE_ENUM

typedef struct obsd_config {
#define OBSD__FIELD_STRING(n) char n[OBSD_STR_LEN];
#define OBSD__FIELD_INT(n) int n;
#define OBSD__FIELD_SIZE(n) int64_t n;
#define OBSD__FIELD_ENUM(n) int n;
#define OBSD__FIELD(name, type, lo, hi, def, doc) OBSD__FIELD_##type(name)
    OBSD_CONFIG_TABLE(OBSD__FIELD)
#undef OBSD__FIELD
    /* which options were given explicitly (file or flag), by table index */
    unsigned char set[32];
} obsd_config;

/* A row: name, type, default, min and max (STRING: the longest length),
 * choices (ENUM: "a|b|c"; the value is the index), doc, offset. */
typedef obs_table_row obsd_opt_info;

int obsd_opt_count(void);
const obsd_opt_info *obsd_opt_at(int i);
/* By name; '-' and '_' are interchangeable.  NULL when unknown. */
const obsd_opt_info *obsd_opt_find(const char *name);

/* Every option at its default. */
void obsd_config_defaults(obsd_config *c);

/* Sets one option from text, checking type and range; the message names
 * the option and what it accepts. */
obs_status obsd_config_set(obsd_config *c, const char *name, const char *value,
                           char err[OBS_ERR_LEN]);

/* Reads `name value` lines (# comments, blank lines); the message names
 * the file and line. */
obs_status obsd_config_load(obsd_config *c, const char *path, char err[OBS_ERR_LEN]);

/* Parses argv[1..]: --config FILE is read first, then every other flag
 * overrides it.  *help is set by --help / -h.  Returns OBS_OK or
 * OBS_INVALID_ARGUMENT / OBS_IO with a message. */
obs_status obsd_config_args(obsd_config *c, int argc, char **argv, int *help,
                            char err[OBS_ERR_LEN]);

/* --help text, generated from the table. */
void obsd_config_help(FILE *f);

/* The current value of an option as text (for logs and tests). */
void obsd_config_format(const obsd_config *c, const obsd_opt_info *o, char *buf, size_t len);

/* Index values of the ENUM options. */
enum { OBSD_LOG_ERROR, OBSD_LOG_WARN, OBSD_LOG_INFO, OBSD_LOG_DEBUG };

#endif
