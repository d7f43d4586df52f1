/* The small GET routes of the HTTP API: /v1/params, /v1/info, /healthz,
 * /readyz and /metrics (the counters are stats.c's; the gauges are read
 * here, from the queue, the GL worker and the stream store). */
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "http_internal.h"

typedef obsd__req req;

static void gauges(obsd_http *h, obsd_gauges *g)
{
    int waiting, running, full;
    obsd_queue_stats(h->front.queue, &waiting, &running, &full);
    g->queue_depth = waiting;
    g->queue_capacity = h->front.cfg->queue;
    g->gl_running = running;
    g->in_flight = atomic_load(&h->in_flight);
    g->gl_alive = atomic_load(&h->front.gl->alive);
    g->gl_recreations = (unsigned long long)atomic_load(&h->front.gl->recreations);
    g->gl_kept_bytes = (unsigned long long)atomic_load(&h->front.gl->kept_bytes);
    g->heap_trims = (unsigned long long)atomic_load(&h->front.gl->heap_trims);
    g->programs_compiled = (unsigned long long)atomic_load(&h->front.gl->programs_compiled);
    g->programs_loaded = (unsigned long long)atomic_load(&h->front.gl->programs_loaded);
    g->programs_rejected = (unsigned long long)atomic_load(&h->front.gl->programs_rejected);
    obsd_streams_gauges(h->streams, &g->streams, &g->stream_frames, &g->stream_bytes, &g->sse_subscribers);
}

enum MHD_Result obsd__info_get(req *r, const char *url)
{
    (void)url;
    obsd_http *h = r->srv;
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return MHD_NO;
    cJSON_AddStringToObject(o, "name", "obscurad");
    cJSON_AddStringToObject(o, "version", OBS_VERSION);
    cJSON_AddStringToObject(o, "backend", h->front.gl->backend);
    cJSON_AddStringToObject(o, "gl_version", h->front.gl->gl_version);
    cJSON_AddStringToObject(o, "gl_vendor", h->front.gl->gl_vendor);
    cJSON_AddStringToObject(o, "gl_renderer", h->front.gl->gl_renderer);
    cJSON_AddNumberToObject(o, "queue", h->front.cfg->queue);
    cJSON_AddNumberToObject(o, "max_pixels", (double)h->front.cfg->max_pixels);
    cJSON_AddNumberToObject(o, "max_body", (double)h->front.cfg->max_body);
    cJSON *pc = cJSON_AddObjectToObject(o, "program_cache");
    if (pc) {
        if (h->front.gl->cache_dir[0])
            cJSON_AddStringToObject(pc, "dir", h->front.gl->cache_dir);
        else
            cJSON_AddNullToObject(pc, "dir");
        cJSON_AddBoolToObject(pc, "writable", h->front.gl->cache_dir[0] && h->front.gl->cache_writable);
        cJSON_AddNumberToObject(pc, "compiled", (double)atomic_load(&h->front.gl->programs_compiled));
        cJSON_AddNumberToObject(pc, "loaded", (double)atomic_load(&h->front.gl->programs_loaded));
        cJSON_AddNumberToObject(pc, "rejected", (double)atomic_load(&h->front.gl->programs_rejected));
    }
    char *text = cJSON_Print(o);
    cJSON_Delete(o);
    return text ? obsd__answer_text(r, 200, "application/json", text, strlen(text), NULL) : MHD_NO;
}

enum MHD_Result obsd__params_get(req *r, const char *url)
{
    (void)url;
    char *text = obs_http_params_json();
    return text ? obsd__answer_text(r, 200, "application/json", text, strlen(text), NULL) : MHD_NO;
}

enum MHD_Result obsd__healthz_get(req *r, const char *url)
{
    (void)url;
    char *text = strdup("ok\n");
    return text ? obsd__answer_text(r, 200, "text/plain", text, 3, NULL) : MHD_NO;
}

enum MHD_Result obsd__readyz_get(req *r, const char *url)
{
    obsd_http *h = r->srv;
    obsd_gauges g;
    int full;
    (void)url;
    gauges(h, &g);
    obsd_queue_stats(h->front.queue, NULL, NULL, &full);
    const char *why = !g.gl_alive ? "GL context not alive"
                      : atomic_load(&h->draining) ? "shutting down"
                      : full ? "queue full" : NULL;
    if (why)
        return obsd__answer_error(r, 503, "not_ready", why, MHD_HTTP_HEADER_RETRY_AFTER, "1");
    char *text = strdup("ready\n");
    return text ? obsd__answer_text(r, 200, "text/plain", text, 6, NULL) : MHD_NO;
}

enum MHD_Result obsd__metrics_get(req *r, const char *url)
{
    obsd_gauges g;
    size_t len = 0;
    (void)url;
    gauges(r->srv, &g);
    char *text = obsd_stats_text(&g, &len);
    return text ? obsd__answer_text(r, 200, "text/plain; version=0.0.4", text, len, NULL) : MHD_NO;
}
