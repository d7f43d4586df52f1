/* The daemon's counters and latency histograms, rendered as Prometheus
 * text for GET /metrics.  Thread-safe. */
#ifndef OBSD_STATS_H
#define OBSD_STATS_H

#include <stddef.h>
#include <stdint.h>

typedef enum obsd_route {
    OBSD_ROUTE_AO,
    OBSD_ROUTE_PARAMS,
    OBSD_ROUTE_INFO,
    OBSD_ROUTE_HEALTHZ,
    OBSD_ROUTE_READYZ,
    OBSD_ROUTE_METRICS,
    OBSD_ROUTE_STREAMS, /* /v1/streams and everything under it */
    OBSD_ROUTE_PAGE,    /* the preview page: / and /preview/... */
    OBSD_ROUTE_BINARY, /* the binary protocol (socket / TCP), not a URL */
    OBSD_ROUTE_OTHER,
    OBSD_ROUTE_COUNT
} obsd_route;

typedef enum obsd_stage {
    OBSD_STAGE_QUEUE,
    OBSD_STAGE_DECODE,
    OBSD_STAGE_GL,
    OBSD_STAGE_ENCODE,
    OBSD_STAGE_TOTAL,
    OBSD_STAGE_COUNT
} obsd_stage;

/* "/v1/ao", ... ; "other" for OBSD_ROUTE_OTHER. */
const char *obsd_route_path(obsd_route r);
/* The route of a URL path (exact match; /v1/streams/... and /preview/...
 * by prefix), OBSD_ROUTE_OTHER if none. */
obsd_route obsd_route_of(const char *path);

void obsd_stats_init(void);
/* One answered request. */
void obsd_stats_request(obsd_route route, int http_status, uint64_t bytes_in, uint64_t bytes_out);
/* One stage's latency of a frame, in milliseconds. */
void obsd_stats_stage(obsd_stage stage, double ms);
/* One frame computed, by its pixel count (resolution class). */
void obsd_stats_frame(int64_t width, int64_t height);

/* Gauges sampled when the text is made. */
typedef struct obsd_gauges {
    int queue_depth, queue_capacity, gl_running, in_flight, gl_alive;
    unsigned long long gl_recreations; /* GL contexts recreated after a failure */
    int streams, stream_frames, sse_subscribers;
    uint64_t stream_bytes;
} obsd_gauges;

/* The Prometheus text exposition; caller frees with free(). */
char *obsd_stats_text(const obsd_gauges *g, size_t *len);

#endif
