/* The daemon's counters and latency histograms, and their Prometheus
 * text (served by the HTTP side on GET /metrics).  Thread-safe. */
#ifndef OBSD_STATS_H
#define OBSD_STATS_H

#include <stddef.h>
#include <stdint.h>

typedef enum obsd_stage {
    OBSD_STAGE_QUEUE,
    OBSD_STAGE_DECODE,
    OBSD_STAGE_GL,
    OBSD_STAGE_ENCODE,
    OBSD_STAGE_RECEIVE, /* HTTP: the request's headers to its body's end; binary: the payload after its header */
    OBSD_STAGE_SEND,    /* the answer queued (binary: written) to its last byte handed to the kernel */
    OBSD_STAGE_TOTAL,
    OBSD_STAGE_COUNT
} obsd_stage;

/* Requests are counted by route: the HTTP route table's rows (routes.h:
 * a row's index is its slot, its path the label), then the binary
 * protocol's and the unknown paths' slots. */
#define OBSD_STATS_ROUTES 32 /* HTTP rows at most */
enum { OBSD_STATS_BINARY = OBSD_STATS_ROUTES, OBSD_STATS_OTHER, OBSD_STATS_SLOTS };

void obsd_stats_init(void);
/* The label of an HTTP route's slot (0 .. OBSD_STATS_ROUTES - 1), set
 * before the server answers. */
void obsd_stats_label(int slot, const char *label);
/* One answered request; a slot out of range counts as OBSD_STATS_OTHER. */
void obsd_stats_request(int slot, int http_status, uint64_t bytes_in, uint64_t bytes_out);
/* One stage's latency of a frame, in milliseconds. */
void obsd_stats_stage(obsd_stage stage, double ms);
/* One frame computed, by its pixel count (resolution class). */
void obsd_stats_frame(int64_t width, int64_t height);

/* A client refused over a limit (reason: the error code, e.g.
 * "too_many_connections", "queue_full", "body_too_large",
 * "request_timeout"): counted in obscurad_refusals_total{reason} and
 * logged at warn, at most one line per reason a second, the line saying
 * how many were not logged since the last.  peer and msg: for the line. */
void obsd_stats_refusal(const char *reason, const char *peer, const char *msg);
/* An error answer (either protocol): a refusal over a limit (connections,
 * queue, size, time, the drain: 408, 413, 503, too_costly,
 * deadline_exceeded) goes to obsd_stats_refusal; any other is not one. */
void obsd_stats_error_answer(int status, const char *code, const char *peer, const char *msg);

/* Gauges sampled when the text is made. */
typedef struct obsd_gauges {
    int queue_depth, queue_capacity, gl_running, in_flight, gl_alive;
    unsigned long long gl_recreations; /* GL contexts recreated after a failure */
    unsigned long long gl_kept_bytes;  /* texture memory kept for the next frame */
    unsigned long long heap_trims;     /* freed heap returned to the system */
    unsigned long long programs_compiled, programs_loaded, programs_rejected; /* program cache */
    int streams, stream_frames, sse_subscribers;
    uint64_t stream_bytes;
} obsd_gauges;

/* The Prometheus text exposition; caller frees with free(). */
char *obsd_stats_text(const obsd_gauges *g, size_t *len);

#endif
