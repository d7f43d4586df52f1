/* Counters and histograms, and their Prometheus text (0.0.4) for GET
 * /metrics; the HTTP routes' labels are set by the server (their table
 * is routes.c). */
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <time.h>

#include "config.h"
#include "log.h"
#include "stats.h"

static const char *const stage_names[OBSD_STAGE_COUNT] = {"queue", "decode", "gl", "encode", "receive",
                                                                 "send", "total"};
/* The statuses the daemon answers; anything else counts as the last. */
static const int codes[] = {200, 202, 400, 401, 404, 405, 408, 409, 413, 415, 422, 500, 503, 0};
#define NCODES ((int)(sizeof codes / sizeof codes[0]))
/* Histogram bucket upper bounds in milliseconds (+Inf implied). */
static const double buckets[] = {1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000};
#define NBUCKETS ((int)(sizeof buckets / sizeof buckets[0]))
/* Frames by pixel count: up to 640x480, 1920x1080, 3840x2160, larger. */
static const char *const res_names[] = {"sd", "hd", "uhd", "larger"};
static const int64_t res_max[] = {640 * 480, 1920 * 1080, 3840 * 2160, INT64_MAX};
#define NRES 4

/* Refusals by reason: the first NREASONS reasons seen have their own
 * row, later ones share the last (reason "other"). */
#define NREASONS 16
typedef struct refusal {
    char reason[32];
    uint64_t n;
    double last_line; /* monotonic ms of its last log line */
    uint64_t unlogged; /* refusals since that line */
} refusal;

static struct {
    pthread_mutex_t lock;
    refusal refused[NREASONS];
    int nrefused;
    const char *labels[OBSD_STATS_SLOTS];
    uint64_t requests[OBSD_STATS_SLOTS][NCODES];
    uint64_t bytes_in, bytes_out;
    uint64_t hist[OBSD_STAGE_COUNT][NBUCKETS + 1];
    double sum[OBSD_STAGE_COUNT];
    uint64_t count[OBSD_STAGE_COUNT];
    uint64_t frames[NRES];
} st = {PTHREAD_MUTEX_INITIALIZER, .labels = {[OBSD_STATS_BINARY] = "binary", [OBSD_STATS_OTHER] = "other"}};

void obsd_stats_init(void)
{
    pthread_mutex_lock(&st.lock);
    memset(st.requests, 0, sizeof st.requests);
    memset(st.hist, 0, sizeof st.hist);
    memset(st.sum, 0, sizeof st.sum);
    memset(st.count, 0, sizeof st.count);
    memset(st.frames, 0, sizeof st.frames);
    st.bytes_in = st.bytes_out = 0;
    memset(st.refused, 0, sizeof st.refused);
    st.nrefused = 0;
    pthread_mutex_unlock(&st.lock);
}

void obsd_stats_label(int slot, const char *label)
{
    if (slot < 0 || slot >= OBSD_STATS_ROUTES)
        return;
    pthread_mutex_lock(&st.lock);
    st.labels[slot] = label;
    pthread_mutex_unlock(&st.lock);
}

void obsd_stats_request(int route, int http_status, uint64_t bytes_in, uint64_t bytes_out)
{
    int c = 0;
    while (c < NCODES - 1 && codes[c] != http_status)
        c++;
    pthread_mutex_lock(&st.lock);
    if (route < 0 || route >= OBSD_STATS_SLOTS || !st.labels[route])
        route = OBSD_STATS_OTHER;
    st.requests[route][c]++;
    st.bytes_in += bytes_in;
    st.bytes_out += bytes_out;
    pthread_mutex_unlock(&st.lock);
}

void obsd_stats_stage(obsd_stage stage, double ms)
{
    if (stage < 0 || stage >= OBSD_STAGE_COUNT || !(ms >= 0.0))
        return;
    int b = 0;
    while (b < NBUCKETS && ms > buckets[b])
        b++;
    pthread_mutex_lock(&st.lock);
    st.hist[stage][b]++;
    st.sum[stage] += ms / 1e3;
    st.count[stage]++;
    pthread_mutex_unlock(&st.lock);
}

void obsd_stats_frame(int64_t width, int64_t height)
{
    int64_t px = width * height;
    int r = 0;
    while (r < NRES - 1 && px > res_max[r])
        r++;
    pthread_mutex_lock(&st.lock);
    st.frames[r]++;
    pthread_mutex_unlock(&st.lock);
}

typedef struct sbuf {
    char *p;
    size_t len, cap;
    int failed;
} sbuf;

static void put(sbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(sbuf *b, const char *fmt, ...)
{
    for (int tries = 0; tries < 2 && !b->failed; tries++) {
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(b->p + b->len, b->cap - b->len, fmt, ap);
        va_end(ap);
        if (n < 0) {
            b->failed = 1;
            return;
        }
        if ((size_t)n < b->cap - b->len) {
            b->len += (size_t)n;
            return;
        }
        size_t cap = (b->cap + (size_t)n) * 2;
        char *p = realloc(b->p, cap);
        if (!p) {
            b->failed = 1;
            return;
        }
        b->p = p;
        b->cap = cap;
    }
}

static double mono_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

void obsd_stats_error_answer(int status, const char *code, const char *peer, const char *msg)
{
    if (status == 408 || status == 413 || status == 503 || !strcmp(code, "too_costly") ||
        !strcmp(code, "deadline_exceeded"))
        obsd_stats_refusal(code, peer, msg);
}

void obsd_stats_refusal(const char *reason, const char *peer, const char *msg)
{
    double now = mono_ms();
    uint64_t unlogged = 0;
    int line = 0;
    pthread_mutex_lock(&st.lock);
    refusal *f = NULL;
    for (int i = 0; i < st.nrefused && !f; i++)
        if (!strcmp(st.refused[i].reason, reason))
            f = &st.refused[i];
    if (!f && st.nrefused < NREASONS) {
        f = &st.refused[st.nrefused++];
        snprintf(f->reason, sizeof f->reason, "%s", st.nrefused == NREASONS ? "other" : reason);
        f->last_line = now - 1e4;
    }
    if (!f)
        f = &st.refused[NREASONS - 1];
    f->n++;
    if (now - f->last_line >= 1000.0) { /* a flood of refusals is one line a second */
        line = 1;
        unlogged = f->unlogged;
        f->unlogged = 0;
        f->last_line = now;
    } else {
        f->unlogged++;
    }
    pthread_mutex_unlock(&st.lock);
    if (line) {
        char more[64] = "";
        if (unlogged)
            snprintf(more, sizeof more, " (%llu more since the last such line)", (unsigned long long)unlogged);
        obsd_log(OBSD_LOG_WARN, "refused %s, peer=%s: %s%s", reason, peer ? peer : "?", msg ? msg : "", more);
    }
}

char *obsd_stats_text(const obsd_gauges *g, size_t *len)
{
    sbuf b = {malloc(8192), 0, 8192, 0};
    if (!b.p)
        return NULL;
    b.p[0] = '\0';
    pthread_mutex_lock(&st.lock);
    put(&b, "# HELP obscurad_requests_total HTTP requests answered, by route and status.\n"
            "# TYPE obscurad_requests_total counter\n");
    for (int r = 0; r < OBSD_STATS_SLOTS; r++)
        for (int c = 0; c < NCODES; c++)
            if (st.requests[r][c])
                put(&b, "obscurad_requests_total{route=\"%s\",code=\"%s%d\"} %llu\n", st.labels[r],
                    codes[c] ? "" : "other", codes[c] ? codes[c] : 0,
                    (unsigned long long)st.requests[r][c]);
    put(&b, "# HELP obscurad_stage_seconds Latency of each stage of a frame "
            "(queue wait, EXR decode, GL run, encode; HTTP: receive, send; total).\n"
            "# TYPE obscurad_stage_seconds histogram\n");
    for (int s = 0; s < OBSD_STAGE_COUNT; s++) {
        uint64_t cum = 0;
        for (int k = 0; k <= NBUCKETS; k++) {
            cum += st.hist[s][k];
            if (k < NBUCKETS)
                put(&b, "obscurad_stage_seconds_bucket{stage=\"%s\",le=\"%g\"} %llu\n", stage_names[s],
                    buckets[k] / 1e3, (unsigned long long)cum);
            else
                put(&b, "obscurad_stage_seconds_bucket{stage=\"%s\",le=\"+Inf\"} %llu\n", stage_names[s],
                    (unsigned long long)cum);
        }
        put(&b, "obscurad_stage_seconds_sum{stage=\"%s\"} %.6f\n", stage_names[s], st.sum[s]);
        put(&b, "obscurad_stage_seconds_count{stage=\"%s\"} %llu\n", stage_names[s],
            (unsigned long long)st.count[s]);
    }
    put(&b, "# HELP obscurad_refusals_total Clients refused over a limit (connections, queue, "
            "body size, deadlines, the drain), by reason (the error code).\n"
            "# TYPE obscurad_refusals_total counter\n");
    for (int i = 0; i < st.nrefused; i++)
        put(&b, "obscurad_refusals_total{reason=\"%s\"} %llu\n", st.refused[i].reason,
            (unsigned long long)st.refused[i].n);
    put(&b, "# HELP obscurad_frames_total Frames computed, by resolution class "
            "(sd <= 640x480 < hd <= 1920x1080 < uhd <= 3840x2160 < larger).\n"
            "# TYPE obscurad_frames_total counter\n");
    for (int r = 0; r < NRES; r++)
        put(&b, "obscurad_frames_total{class=\"%s\"} %llu\n", res_names[r], (unsigned long long)st.frames[r]);
    put(&b, "# HELP obscurad_bytes_received_total Request body bytes received.\n"
            "# TYPE obscurad_bytes_received_total counter\n"
            "obscurad_bytes_received_total %llu\n"
            "# HELP obscurad_bytes_sent_total Response body bytes sent.\n"
            "# TYPE obscurad_bytes_sent_total counter\n"
            "obscurad_bytes_sent_total %llu\n",
        (unsigned long long)st.bytes_in, (unsigned long long)st.bytes_out);
    pthread_mutex_unlock(&st.lock);
    put(&b, "# HELP obscurad_queue_depth Frames waiting for the GL worker.\n"
            "# TYPE obscurad_queue_depth gauge\n"
            "obscurad_queue_depth %d\n"
            "# HELP obscurad_queue_capacity Frames that may wait (--queue).\n"
            "# TYPE obscurad_queue_capacity gauge\n"
            "obscurad_queue_capacity %d\n"
            "# HELP obscurad_gl_busy 1 while the GL worker runs a frame.\n"
            "# TYPE obscurad_gl_busy gauge\n"
            "obscurad_gl_busy %d\n"
            "# HELP obscurad_in_flight HTTP requests being served.\n"
            "# TYPE obscurad_in_flight gauge\n"
            "obscurad_in_flight %d\n"
            "# HELP obscurad_gl_up 1 while the GL context is alive.\n"
            "# TYPE obscurad_gl_up gauge\n"
            "obscurad_gl_up %d\n"
            "# HELP obscurad_gl_context_recreations_total GL contexts recreated after a GL failure.\n"
            "# TYPE obscurad_gl_context_recreations_total counter\n"
            "obscurad_gl_context_recreations_total %llu\n"
            "# HELP obscurad_gl_kept_bytes Texture memory the GL worker keeps for the next frame "
            "(on the CPU device its planes; --keep-memory).\n"
            "# TYPE obscurad_gl_kept_bytes gauge\n"
            "obscurad_gl_kept_bytes %llu\n"
            "# HELP obscurad_heap_trims_total Times freed heap memory was returned to the "
            "system (malloc_trim), each once the queue had stayed empty 1 s after frames.\n"
            "# TYPE obscurad_heap_trims_total counter\n"
            "obscurad_heap_trims_total %llu\n"
            "# HELP obscurad_programs_compiled_total GL programs built from source.\n"
            "# TYPE obscurad_programs_compiled_total counter\n"
            "obscurad_programs_compiled_total %llu\n"
            "# HELP obscurad_programs_loaded_total GL programs loaded from the program cache (--cache-dir).\n"
            "# TYPE obscurad_programs_loaded_total counter\n"
            "obscurad_programs_loaded_total %llu\n"
            "# HELP obscurad_programs_rejected_total Program cache entries found unusable (damaged, another "
            "driver's) and rebuilt.\n"
            "# TYPE obscurad_programs_rejected_total counter\n"
            "obscurad_programs_rejected_total %llu\n",
        g->queue_depth, g->queue_capacity, g->gl_running, g->in_flight, g->gl_alive,
        g->gl_recreations, g->gl_kept_bytes, g->heap_trims, g->programs_compiled, g->programs_loaded,
        g->programs_rejected);
    put(&b, "# HELP obscurad_streams Streams of frames kept for the preview page.\n"
            "# TYPE obscurad_streams gauge\n"
            "obscurad_streams %d\n"
            "# HELP obscurad_stream_frames Frames kept over all streams.\n"
            "# TYPE obscurad_stream_frames gauge\n"
            "obscurad_stream_frames %d\n"
            "# HELP obscurad_stream_bytes Memory held by the kept frames.\n"
            "# TYPE obscurad_stream_bytes gauge\n"
            "obscurad_stream_bytes %llu\n"
            "# HELP obscurad_event_subscribers Open event streams (GET /v1/streams/NAME/events).\n"
            "# TYPE obscurad_event_subscribers gauge\n"
            "obscurad_event_subscribers %d\n",
        g->streams, g->stream_frames, (unsigned long long)g->stream_bytes, g->sse_subscribers);
    if (b.failed) {
        free(b.p);
        return NULL;
    }
    if (len)
        *len = b.len;
    return b.p;
}
