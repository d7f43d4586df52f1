/* The HTTP API of obscurad: routes, limits, the frame path.
 *
 * (/v1/streams is in http_streams.c, the page in http_page.c.)
 *
 *   first call    route, method, token, query parameters, Content-Length
 *                 (413 before any of the body is read)
 *   body calls    append, 413 when it grows over --max-body
 *   last call     decode the EXR here (a network thread), suspend the
 *                 connection, queue the frame (503 when full)
 *   resumed       the GL worker is done: encode here, answer */
#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "http_internal.h"
#include "log.h"

typedef obsd__req req;

/* ---- answers --------------------------------------------------------- */

static void log_request(const req *r, const char *note)
{
    if (!obsd_log_enabled(OBSD_LOG_INFO))
        return;
    obsd_log(OBSD_LOG_INFO,
             "req=%llu peer=%s %s %s status=%d in=%zu out=%zu queue=%.1f decode=%.1f gl=%.1f "
             "encode=%.1f total=%.1f ms%s%s",
             (unsigned long long)r->id, r->peer, r->method, r->path, r->status,
             r->len + r->discarded, r->bytes_out, r->fp.ms_queue, r->fp.ms_decode, r->fp.ms_gl, r->fp.ms_encode,
             obsd_now_ms() - r->t0, note && *note ? " " : "", note ? note : "");
}

enum MHD_Result obsd__answer(req *r, int status, struct MHD_Response *resp, size_t body_len,
                              const char *note)
{
    if (!resp)
        return MHD_NO;
    r->status = status;
    r->bytes_out = body_len;
    r->state = REQ_ANSWERED;
    MHD_add_response_header(resp, "Server", "obscurad/" OBS_VERSION);
    enum MHD_Result rc = MHD_queue_response(r->conn, (unsigned)status, resp);
    MHD_destroy_response(resp);
    obsd_stats_request(r->route, status, r->len + r->discarded, body_len);
    if (r->route == OBSD_ROUTE_AO || r->op == STREAM_POST)
        obsd_stats_stage(OBSD_STAGE_TOTAL, obsd_now_ms() - r->t0);
    log_request(r, rc == MHD_YES ? note : "(could not queue the answer)");
    return rc;
}

enum MHD_Result obsd__answer_text(req *r, int status, const char *type, char *text, size_t len,
                                   const char *note)
{
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(len, text, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        free(text);
        return MHD_NO;
    }
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    return obsd__answer(r, status, resp, len, note);
}

enum MHD_Result obsd__answer_error(req *r, int status, const char *code, const char *msg,
                                    const char *hname, const char *hvalue)
{
    char *body = obs_http_error_json(code, msg);
    if (!body)
        return MHD_NO;
    size_t len = strlen(body);
    struct MHD_Response *resp = MHD_create_response_from_buffer(len, body, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        free(body);
        return MHD_NO;
    }
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, "application/json");
    if (hname)
        MHD_add_response_header(resp, hname, hvalue);
    char note[OBS_ERR_LEN + 32];
    snprintf(note, sizeof note, "error=%s: %s", code, msg);
    return obsd__answer(r, status, resp, len, note);
}

enum MHD_Result obsd__answer_status(req *r, obs_status s, const char *msg)
{
    const char *code;
    int http = obs_http_status_of(s, &code);
    return obsd__answer_error(r, http, code, msg && *msg ? msg : obs_status_message(s),
                        http == 503 ? MHD_HTTP_HEADER_RETRY_AFTER : NULL, "1");
}

/* ---- GET routes ------------------------------------------------------ */

static void gauges(obsd_http *h, obsd_gauges *g)
{
    int waiting, running, full;
    obsd_queue_stats(h->queue, &waiting, &running, &full);
    g->queue_depth = waiting;
    g->queue_capacity = h->cfg->queue;
    g->gl_running = running;
    g->in_flight = atomic_load(&h->in_flight);
    g->gl_alive = atomic_load(&h->gl->alive);
    g->gl_recreations = (unsigned long long)atomic_load(&h->gl->recreations);
    obsd_streams_gauges(h->streams, &g->streams, &g->stream_frames, &g->stream_bytes, &g->sse_subscribers);
}

static enum MHD_Result get_info(req *r)
{
    obsd_http *h = r->srv;
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return MHD_NO;
    cJSON_AddStringToObject(o, "name", "obscurad");
    cJSON_AddStringToObject(o, "version", OBS_VERSION);
    cJSON_AddStringToObject(o, "backend", h->gl->backend);
    cJSON_AddStringToObject(o, "gl_version", h->gl->gl_version);
    cJSON_AddStringToObject(o, "gl_vendor", h->gl->gl_vendor);
    cJSON_AddStringToObject(o, "gl_renderer", h->gl->gl_renderer);
    cJSON_AddNumberToObject(o, "queue", h->cfg->queue);
    cJSON_AddNumberToObject(o, "max_pixels", (double)h->cfg->max_pixels);
    cJSON_AddNumberToObject(o, "max_body", (double)h->cfg->max_body);
    char *text = cJSON_Print(o);
    cJSON_Delete(o);
    return text ? obsd__answer_text(r, 200, "application/json", text, strlen(text), NULL) : MHD_NO;
}

static enum MHD_Result get_route(req *r)
{
    obsd_http *h = r->srv;
    switch (r->route) {
    case OBSD_ROUTE_PARAMS: {
        char *text = obs_http_params_json();
        return text ? obsd__answer_text(r, 200, "application/json", text, strlen(text), NULL) : MHD_NO;
    }
    case OBSD_ROUTE_INFO:
        return get_info(r);
    case OBSD_ROUTE_HEALTHZ: {
        char *text = strdup("ok\n");
        return text ? obsd__answer_text(r, 200, "text/plain", text, 3, NULL) : MHD_NO;
    }
    case OBSD_ROUTE_READYZ: {
        obsd_gauges g;
        int full;
        gauges(h, &g);
        obsd_queue_stats(h->queue, NULL, NULL, &full);
        const char *why = !g.gl_alive ? "GL context not alive"
                          : atomic_load(&h->draining) ? "shutting down"
                          : full ? "queue full" : NULL;
        if (why)
            return obsd__answer_error(r, 503, "not_ready", why, MHD_HTTP_HEADER_RETRY_AFTER, "1");
        char *text = strdup("ready\n");
        return text ? obsd__answer_text(r, 200, "text/plain", text, 6, NULL) : MHD_NO;
    }
    case OBSD_ROUTE_METRICS: {
        obsd_gauges g;
        size_t len = 0;
        gauges(h, &g);
        char *text = obsd_stats_text(&g, &len);
        return text ? obsd__answer_text(r, 200, "text/plain; version=0.0.4", text, len, NULL) : MHD_NO;
    }
    default:
        return obsd__answer_error(r, 404, "not_found", "no such route", NULL, NULL);
    }
}

/* ---- frames: POST /v1/ao and the streams' frames ---------------------- */

typedef struct arg_ctx {
    req *r;
    obs_status status;
    char err[OBS_ERR_LEN];
} arg_ctx;

static int record_pair(req *r, const char *key, const char *value)
{
    size_t kl = strlen(key) + 1, vl = strlen(value) + 1;
    if (r->query_len + kl + vl > r->query_cap) {
        size_t cap = (r->query_cap ? r->query_cap * 2 : 256) + kl + vl;
        char *p = realloc(r->query, cap);
        if (!p)
            return -1;
        r->query = p;
        r->query_cap = cap;
    }
    memcpy(r->query + r->query_len, key, kl);
    memcpy(r->query + r->query_len + kl, value, vl);
    r->query_len += kl + vl;
    return 0;
}

static int name_is(const char *name, const char *want)
{
    for (; *name && *want; name++, want++)
        if ((*name == '-' ? '_' : *name) != *want)
            return 0;
    return *name == *want;
}

static enum MHD_Result on_arg(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    arg_ctx *a = cls;
    req *r = a->r;
    (void)kind;
    if (a->status != OBS_OK)
        return MHD_NO;
    if (!value)
        value = "";
    if (r->op == STREAM_FRAME) {
        /* a stored frame: the view options, and anything else re-runs it */
        if (name_is(key, "exposure")) {
            char *end;
            double ev = strtod(value, &end);
            if (end == value || *end || !(ev >= -20.0 && ev <= 20.0)) {
                snprintf(a->err, OBS_ERR_LEN, "parameter exposure: '%.100s' is not a number in [-20, 20] "
                         "(stops)", value);
                a->status = OBS_INVALID_ARGUMENT;
                return MHD_NO;
            }
            r->exposure = ev;
            return MHD_YES;
        }
        if (name_is(key, "output") && !strcmp(value, "color")) {
            r->want_color = 1;
            return MHD_YES;
        }
        if (name_is(key, "output"))
            r->want_color = 0;
        else if (!name_is(key, "format") && !name_is(key, "float") && !name_is(key, "png_bits"))
            r->rerun = 1;
    }
    a->status = obs_http_request_set(&r->hr, key, value, a->err);
    if (a->status == OBS_OK && r->record_query && record_pair(r, key, value) != 0) {
        snprintf(a->err, OBS_ERR_LEN, "no memory for the query");
        a->status = OBS_NO_MEMORY;
    }
    return a->status == OBS_OK ? MHD_YES : MHD_NO;
}

int obsd__parse_query(req *r, enum MHD_Result *rc)
{
    arg_ctx a = {r, OBS_OK, ""};
    MHD_get_connection_values(r->conn, MHD_GET_ARGUMENT_KIND, on_arg, &a);
    if (a.status == OBS_OK)
        a.status = obs_http_request_check(&r->hr, a.err);
    if (a.status == OBS_OK)
        return 1;
    *rc = a.status == OBS_INVALID_ARGUMENT ? obsd__answer_error(r, 400, "bad_parameter", a.err, NULL, NULL)
                                           : obsd__answer_status(r, a.status, a.err);
    return 0;
}

/* Called on the GL worker thread: give the connection back to MHD. */
static void job_done(void *user)
{
    req *r = user;
    MHD_resume_connection(r->conn);
}

enum MHD_Result obsd__frame_start(req *r)
{
    obsd_http *h = r->srv;
    const char *v;
    enum MHD_Result rc;
    r->before_drain = !atomic_load(&h->draining);
    if (!r->before_drain)
        return obsd__answer_error(r, 503, "shutting_down", "the daemon is shutting down",
                            MHD_HTTP_HEADER_RETRY_AFTER, "5");
    obs_http_request_init(&r->hr);
    if (!obsd__parse_query(r, &rc))
        return rc;
    v = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_TYPE);
    if (v && strncmp(v, "image/x-exr", 11) != 0 && strncmp(v, "application/octet-stream", 24) != 0)
        return obsd__answer_error(r, 415, "unsupported_media_type",
                            "the body must be a G-buffer EXR (Content-Type: image/x-exr)", NULL, NULL);
    v = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
    if (v) {
        char *end;
        errno = 0;
        unsigned long long n = strtoull(v, &end, 10);
        if (errno == ERANGE || n > (unsigned long long)h->cfg->max_body) {
            char msg[160];
            snprintf(msg, sizeof msg, "body of %s bytes is over the limit of %lld bytes (--max-body)",
                     v, (long long)h->cfg->max_body);
            return obsd__answer_error(r, 413, "body_too_large", msg, NULL, NULL);
        }
        /* Sized by the claim, which is within the limit; grows if it lied. */
        r->cap = n ? (size_t)n : 0;
        if (r->cap && !(r->body = malloc(r->cap)))
            return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the body");
    }
    /* Refuse early when the queue is already full: no need for the body. */
    int full;
    obsd_queue_stats(h->queue, NULL, NULL, &full);
    if (full)
        return obsd__answer_error(r, 503, "queue_full", "the frame queue is full; retry later",
                            MHD_HTTP_HEADER_RETRY_AFTER, "1");
    r->state = REQ_BODY;
    return MHD_YES;
}

static enum MHD_Result ao_body(req *r, const char *data, size_t *size)
{
    obsd_http *h = r->srv;
    const size_t max = (size_t)h->cfg->max_body;
    size_t n = *size;
    *size = 0;
    if (r->too_big || n > max - r->len) {
        /* No Content-Length (chunked), or more than it said.  libmicrohttpd
         * cannot answer in the middle of a body: keep nothing, discard up
         * to another --max-body so that the client gets its 413, and close
         * the connection on anything beyond that. */
        if (!r->too_big) {
            r->too_big = 1;
            free(r->body);
            r->body = NULL;
            r->cap = 0;
        }
        r->discarded += n;
        if (r->discarded > max) {
            obsd_log(OBSD_LOG_INFO, "req=%llu peer=%s %s %s: body over twice --max-body, "
                     "connection closed", (unsigned long long)r->id, r->peer, r->method,
                     obsd_route_path(r->route));
            return MHD_NO;
        }
        return MHD_YES;
    }
    if (r->len + n > r->cap) {
        size_t cap = r->cap ? r->cap : 1 << 16;
        while (cap < r->len + n)
            cap = cap > max / 2 ? max : cap * 2;
        unsigned char *p = realloc(r->body, cap);
        if (!p)
            return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the body");
        r->body = p;
        r->cap = cap;
    }
    memcpy(r->body + r->len, data, n);
    r->len += n;
    return MHD_YES;
}

enum MHD_Result obsd__queue_frame(req *r, const unsigned char *body, size_t len, unsigned outputs)
{
    obsd_http *h = r->srv;
    char err[OBS_ERR_LEN] = "";
    obs_limits lim = {.max_pixels = (uint64_t)h->cfg->max_pixels};
    /* A deep EXR runs on /v1/ao only: streams keep flat frames. */
    obs_status s = obsd_fp_decode(&r->fp, body, len, &r->hr.map, &lim,
                                  r->op == STREAM_POST ? "deep EXR input runs on POST /v1/ao, not in streams"
                                                       : NULL,
                                  err);
    if (s != OBS_OK)
        return obsd__answer_status(r, s, err);
    /* Suspend before queueing: the worker may finish and resume at once. */
    r->state = REQ_QUEUED;
    MHD_suspend_connection(r->conn);
    if ((atomic_load(&h->draining) && !r->before_drain) ||
        obsd_fp_queue(&r->fp, h->queue, &r->hr.params, outputs, job_done, r) != 0) {
        r->state = REQ_REFUSED;
        MHD_resume_connection(r->conn);
    }
    return MHD_YES;
}

static enum MHD_Result ao_run(req *r)
{
    if (r->len == 0) {
        char msg[128];
        snprintf(msg, sizeof msg, "%s %s needs a G-buffer EXR as its body", r->method,
                 r->op == STREAM_POST ? "/v1/streams/NAME/frames" : "/v1/ao");
        return obsd__answer_error(r, 400, "empty_body", msg, NULL, NULL);
    }
    if (r->op == STREAM_POST) /* the body is kept with the frame: re-runs decode it again */
        return obsd__queue_frame(r, r->body, r->len, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE);
    enum MHD_Result rc = obsd__queue_frame(r, r->body, r->len, r->hr.outputs);
    free(r->body);
    r->body = NULL;
    r->cap = 0;
    return rc;
}

/* A copy of a colour image with its RGB times 2^ev (alpha kept). */
static int expose(const obs_image *src, double ev, obs_image *out)
{
    size_t n = (size_t)src->width * (size_t)src->height;
    float k = (float)pow(2.0, ev);
    *out = *src;
    if (!(out->data = malloc(n * (size_t)src->channels * sizeof(float))))
        return -1;
    for (size_t i = 0; i < n * (size_t)src->channels; i++)
        out->data[i] = (src->channels == 4 && i % 4 == 3) ? src->data[i] : src->data[i] * k;
    return 0;
}

/* Answers 200 with an encoded image (taking `out`), the Server-Timing
 * header with `timing`, and one extra header when extra_name is set. */
static enum MHD_Result answer_bytes(req *r, obs_bytes *out, const char *type, int timing,
                                    const char *extra_name, const char *extra_value)
{
    struct MHD_Response *resp = MHD_create_response_from_buffer(out->size, out->data, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        obs_bytes_free(out);
        return MHD_NO;
    }
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    if (timing) {
        char t[192];
        snprintf(t, sizeof t, "queue;dur=%.2f, decode;dur=%.2f, gl;dur=%.2f, encode;dur=%.2f",
                 r->fp.ms_queue, r->fp.ms_decode, r->fp.ms_gl, r->fp.ms_encode);
        MHD_add_response_header(resp, "Server-Timing", t);
    }
    if (extra_name)
        MHD_add_response_header(resp, extra_name, extra_value);
    return obsd__answer(r, 200, resp, out->size, NULL);
}

enum MHD_Result obsd__answer_images(req *r, const obsd_fp_images *im, const obs_camera *cam, int timing,
                                    const char *extra_name, const char *extra_value)
{
    char err[OBS_ERR_LEN] = "";
    obsd_fp_images shown = *im;
    obs_image exposed = {0};
    /* exposure is a view of a colour PNG; the AO is never exposed */
    const obs_image *img = obsd_fp_png_image(im);
    if (r->hr.format != OBS_HTTP_EXR && img != im->ao && r->exposure != 0.0) {
        if (expose(img, r->exposure, &exposed) != 0)
            return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the image");
        shown.composite = &exposed;
    }
    obs_bytes out;
    obs_status s = obsd_fp_encode(&r->fp, &shown, &r->hr, 0, cam, &out, err);
    obs_image_free(&exposed);
    if (s != OBS_OK)
        return obsd__answer_error(r, 500, "encode_failed", err, NULL, NULL);
    return answer_bytes(r, &out, r->hr.format == OBS_HTTP_EXR ? "image/x-exr" : "image/png", timing,
                        extra_name, extra_value);
}

/* Called again once the GL worker resumed the connection.  Deep input
 * answers an EXR of AO.Y, AOFront.Y and R,G,B,A as `obscura ao` writes
 * it, or a PNG of the blended AO or the composite. */
static enum MHD_Result ao_finish(req *r)
{
    obs_status s = obsd_fp_finished(&r->fp);
    if (s != OBS_OK)
        return obsd__answer_status(r, s, r->fp.job.err);
    obsd_fp_images im;
    obsd_fp_images_of(&r->fp, r->hr.outputs, &im);
    return obsd__answer_images(r, &im, obsd_fp_camera(&r->fp), 1, NULL, NULL);
}

/* ---- dispatch -------------------------------------------------------- */

static void peer_name(struct MHD_Connection *c, char *buf, size_t len)
{
    const union MHD_ConnectionInfo *ci = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    snprintf(buf, len, "?");
    if (ci && ci->client_addr && ci->client_addr->sa_family == AF_INET) {
        const struct sockaddr_in *in = (const struct sockaddr_in *)(const void *)ci->client_addr;
        char ip[INET_ADDRSTRLEN];
        if (inet_ntop(AF_INET, &in->sin_addr, ip, sizeof ip))
            snprintf(buf, len, "%s:%u", ip, ntohs(in->sin_port));
    }
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url,
                                  const char *method, const char *version, const char *upload_data,
                                  size_t *upload_data_size, void **con_cls)
{
    obsd_http *h = cls;
    req *r = *con_cls;
    (void)version;
    if (!r) {
        if (!(r = calloc(1, sizeof *r)))
            return MHD_NO;
        *con_cls = r;
        atomic_fetch_add(&h->in_flight, 1);
        obsd_fp_init(&r->fp);
        r->srv = h;
        r->conn = conn;
        r->id = atomic_fetch_add(&h->next_id, 1) + 1;
        r->t0 = obsd_now_ms();
        r->route = obsd_route_of(url);
        snprintf(r->method, sizeof r->method, "%s", method);
        snprintf(r->path, sizeof r->path, "%s", url);
        for (char *c = r->path; *c; c++)
            if ((unsigned char)*c < 0x21 || (unsigned char)*c > 0x7e)
                *c = '?';
        peer_name(conn, r->peer, sizeof r->peer);

        if (r->route == OBSD_ROUTE_PAGE) /* the page is static: no token */
            return obsd__page(r, url);
        if (r->route == OBSD_ROUTE_OTHER)
            return obsd__answer_error(r, 404, "not_found", "no such route (try GET /v1/params)", NULL, NULL);
        const char *allowed = r->route == OBSD_ROUTE_AO ? "POST" : "GET";
        if (r->route != OBSD_ROUTE_STREAMS && strcmp(method, allowed) != 0 &&
            !(r->route != OBSD_ROUTE_AO && !strcmp(method, "HEAD"))) {
            char msg[64];
            snprintf(msg, sizeof msg, "%s takes %s", obsd_route_path(r->route), allowed);
            return obsd__answer_error(r, 405, "method_not_allowed", msg, MHD_HTTP_HEADER_ALLOW, allowed);
        }
        /* Probes stay open; the API and the metrics need the token. */
        if (h->token && r->route != OBSD_ROUTE_HEALTHZ && r->route != OBSD_ROUTE_READYZ &&
            !obs_http_bearer_ok(MHD_lookup_connection_value(conn, MHD_HEADER_KIND,
                                                            MHD_HTTP_HEADER_AUTHORIZATION),
                                h->token))
            return obsd__answer_error(r, 401, "unauthorized", "missing or wrong bearer token",
                                MHD_HTTP_HEADER_WWW_AUTHENTICATE, "Bearer realm=\"obscurad\"");
        if (r->route == OBSD_ROUTE_STREAMS)
            return obsd__streams_start(r, url);
        if (r->route != OBSD_ROUTE_AO)
            return get_route(r);
        return obsd__frame_start(r);
    }
    switch (r->state) {
    case REQ_BODY:
        if (*upload_data_size)
            return ao_body(r, upload_data, upload_data_size);
        if (r->too_big) {
            char msg[160];
            snprintf(msg, sizeof msg, "body is over the limit of %lld bytes (--max-body)",
                     (long long)h->cfg->max_body);
            return obsd__answer_error(r, 413, "body_too_large", msg, NULL, NULL);
        }
        return ao_run(r);
    case REQ_QUEUED:
        return r->route == OBSD_ROUTE_STREAMS ? obsd__streams_finish(r) : ao_finish(r);
    case REQ_REFUSED:
        return obsd__answer_error(r, 503, atomic_load(&h->draining) ? "shutting_down" : "queue_full",
                            "the frame queue is full; retry later", MHD_HTTP_HEADER_RETRY_AFTER, "1");
    default:
        /* Answered already; discard what else the client sends. */
        *upload_data_size = 0;
        return MHD_YES;
    }
}

static void on_completed(void *cls, struct MHD_Connection *conn, void **con_cls,
                         enum MHD_RequestTerminationCode why)
{
    obsd_http *h = cls;
    req *r = *con_cls;
    (void)conn;
    if (!r)
        return;
    if (why != MHD_REQUEST_TERMINATED_COMPLETED_OK && r->state != REQ_ANSWERED)
        obsd_log(OBSD_LOG_INFO, "req=%llu peer=%s %s %s ended without an answer (reason %d)",
                 (unsigned long long)r->id, r->peer, r->method, obsd_route_path(r->route), (int)why);
    obsd__streams_done(r);
    free(r->body);
    obsd_fp_free(&r->fp);
    free(r);
    *con_cls = NULL;
    atomic_fetch_sub(&h->in_flight, 1);
}

static void on_mhd_log(void *cls, const char *fmt, va_list ap)
{
    char msg[512];
    (void)cls;
    vsnprintf(msg, sizeof msg, fmt, ap);
    size_t n = strlen(msg);
    while (n && msg[n - 1] == '\n')
        msg[--n] = '\0';
    obsd_log(OBSD_LOG_DEBUG, "microhttpd: %s", msg);
}

/* "HOST:PORT" (IPv4) into addr. */
static int parse_addr(const char *s, struct sockaddr_in *addr, char err[OBS_ERR_LEN])
{
    const char *colon = strrchr(s, ':');
    char host[64];
    if (!colon || (size_t)(colon - s) >= sizeof host) {
        snprintf(err, OBS_ERR_LEN, "--http '%s' is not HOST:PORT", s);
        return -1;
    }
    snprintf(host, sizeof host, "%.*s", (int)(colon - s), s);
    char *end;
    long port = strtol(colon + 1, &end, 10);
    memset(addr, 0, sizeof *addr);
    addr->sin_family = AF_INET;
    if (!colon[1] || *end || port < 0 || port > 65535 ||
        inet_pton(AF_INET, host[0] ? host : "0.0.0.0", &addr->sin_addr) != 1) {
        snprintf(err, OBS_ERR_LEN, "--http '%s' is not IPv4-HOST:PORT with a port in 0..65535", s);
        return -1;
    }
    addr->sin_port = htons((uint16_t)port);
    return 0;
}

obs_status obsd_http_start(const obsd_config *cfg, const char *token, obsd_queue *q,
                           obsd_gl_worker *gl, obsd_http **out, char err[OBS_ERR_LEN])
{
    struct sockaddr_in addr;
    if (parse_addr(cfg->http, &addr, err) != 0)
        return OBS_INVALID_ARGUMENT;
    obsd_http *h = calloc(1, sizeof *h);
    if (!h)
        return OBS_NO_MEMORY;
    h->cfg = cfg;
    h->token = token && *token ? token : NULL;
    h->queue = q;
    h->gl = gl;
    h->listen_fd = MHD_INVALID_SOCKET;
    if (!(h->streams = obsd_streams_new(cfg->streams, cfg->stream_frames, cfg->stream_memory))) {
        free(h);
        return OBS_NO_MEMORY;
    }
    atomic_init(&h->in_flight, 0);
    atomic_init(&h->draining, 0);
    atomic_init(&h->next_id, 0);
    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_EPOLL | MHD_USE_ITC |
                     MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ERROR_LOG;
    h->mhd = MHD_start_daemon(flags, 0, NULL, NULL, on_request, h,
                              MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr,
                              MHD_OPTION_THREAD_POOL_SIZE, (unsigned)cfg->threads,
                              MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)cfg->timeout,
                              MHD_OPTION_NOTIFY_COMPLETED, on_completed, h,
                              MHD_OPTION_EXTERNAL_LOGGER, on_mhd_log, h,
                              MHD_OPTION_END);
    if (!h->mhd) {
        snprintf(err, OBS_ERR_LEN, "cannot listen on %s (in use, or not an address of this host?)",
                 cfg->http);
        obsd_streams_free(h->streams);
        free(h);
        return OBS_IO;
    }
    const union MHD_DaemonInfo *di = MHD_get_daemon_info(h->mhd, MHD_DAEMON_INFO_BIND_PORT);
    h->port = di ? di->port : ntohs(addr.sin_port);
    *out = h;
    return OBS_OK;
}

int obsd_http_port(const obsd_http *h) { return h->port; }

void obsd_http_quiesce(obsd_http *h)
{
    atomic_store(&h->draining, 1);
    obsd_streams_end_all(h->streams); /* event streams end, so that the drain ends */
    if (h->listen_fd == MHD_INVALID_SOCKET)
        h->listen_fd = MHD_quiesce_daemon(h->mhd);
}

int obsd_http_in_flight(obsd_http *h) { return atomic_load(&h->in_flight); }

void obsd_http_tick(obsd_http *h)
{
    if (h)
        obsd_streams_tick(h->streams, obsd_now_ms());
}

void obsd_http_stop(obsd_http *h)
{
    if (!h)
        return;
    MHD_stop_daemon(h->mhd);
    /* MHD hands the quiesced socket to us, to close after the stop. */
    if (h->listen_fd != MHD_INVALID_SOCKET)
        close(h->listen_fd);
    obsd_streams_free(h->streams);
    free(h);
}
