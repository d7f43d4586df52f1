/* The HTTP API of obscurad: routes, limits, the frame path.
 *
 *   first call    route, method, token, query parameters, Content-Length
 *                 (413 before any of the body is read)
 *   body calls    append, 413 when it grows over --max-body
 *   last call     decode the EXR here (a network thread), suspend the
 *                 connection, queue the frame (503 when full)
 *   resumed       the GL worker is done: encode here, answer */
#include <arpa/inet.h>
#include <errno.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "http.h"
#include "http_server.h"
#include "io.h"
#include "log.h"
#include "stats.h"

struct obsd_http {
    struct MHD_Daemon *mhd;
    const obsd_config *cfg;
    const char *token;
    obsd_queue *queue;
    obsd_gl_worker *gl;
    int port;
    MHD_socket listen_fd;
    atomic_int in_flight;
    atomic_int draining;
    atomic_uint_fast64_t next_id;
};

typedef enum req_state {
    REQ_NEW,
    REQ_BODY,     /* reading the body of POST /v1/ao */
    REQ_QUEUED,   /* suspended; the GL worker has the job */
    REQ_REFUSED,  /* suspended and resumed at once: the queue was full */
    REQ_ANSWERED
} req_state;

typedef struct req {
    obsd_http *srv;
    struct MHD_Connection *conn;
    uint64_t id;
    obsd_route route;
    req_state state;
    char method[8];
    char peer[64];
    double t0;
    /* POST /v1/ao */
    unsigned char *body;
    size_t len, cap;
    int too_big;
    size_t discarded;    /* bytes thrown away after too_big */
    int before_drain;    /* started before SIGTERM: finished in the drain */
    obs_http_request hr;
    obs_gbuffer_file gf;
    obsd_job job;
    double ms_decode, ms_queue, ms_gl, ms_encode;
    /* answer */
    int status;
    size_t bytes_out;
} req;

/* ---- answers --------------------------------------------------------- */

static void log_request(const req *r, const char *note)
{
    if (!obsd_log_enabled(OBSD_LOG_INFO))
        return;
    obsd_log(OBSD_LOG_INFO,
             "req=%llu peer=%s %s %s status=%d in=%zu out=%zu queue=%.1f decode=%.1f gl=%.1f "
             "encode=%.1f total=%.1f ms%s%s",
             (unsigned long long)r->id, r->peer, r->method, obsd_route_path(r->route), r->status,
             r->len + r->discarded, r->bytes_out, r->ms_queue, r->ms_decode, r->ms_gl, r->ms_encode,
             obsd_now_ms() - r->t0, note && *note ? " " : "", note ? note : "");
}

/* Queues `resp` (taking it) with status; logs and counts the request. */
static enum MHD_Result answer(req *r, int status, struct MHD_Response *resp, size_t body_len,
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
    if (r->route == OBSD_ROUTE_AO)
        obsd_stats_stage(OBSD_STAGE_TOTAL, obsd_now_ms() - r->t0);
    log_request(r, rc == MHD_YES ? note : "(could not queue the answer)");
    return rc;
}

static enum MHD_Result answer_text(req *r, int status, const char *type, char *text, size_t len,
                                   const char *note)
{
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(len, text, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        free(text);
        return MHD_NO;
    }
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    return answer(r, status, resp, len, note);
}

/* The JSON error body; `extra` adds one header (name, value) when set. */
static enum MHD_Result answer_error(req *r, int status, const char *code, const char *msg,
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
    return answer(r, status, resp, len, note);
}

static enum MHD_Result answer_status(req *r, obs_status s, const char *msg)
{
    const char *code;
    int http = obs_http_status_of(s, &code);
    return answer_error(r, http, code, msg && *msg ? msg : obs_status_message(s),
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
    return text ? answer_text(r, 200, "application/json", text, strlen(text), NULL) : MHD_NO;
}

static enum MHD_Result get_route(req *r)
{
    obsd_http *h = r->srv;
    switch (r->route) {
    case OBSD_ROUTE_PARAMS: {
        char *text = obs_http_params_json();
        return text ? answer_text(r, 200, "application/json", text, strlen(text), NULL) : MHD_NO;
    }
    case OBSD_ROUTE_INFO:
        return get_info(r);
    case OBSD_ROUTE_HEALTHZ: {
        char *text = strdup("ok\n");
        return text ? answer_text(r, 200, "text/plain", text, 3, NULL) : MHD_NO;
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
            return answer_error(r, 503, "not_ready", why, MHD_HTTP_HEADER_RETRY_AFTER, "1");
        char *text = strdup("ready\n");
        return text ? answer_text(r, 200, "text/plain", text, 6, NULL) : MHD_NO;
    }
    case OBSD_ROUTE_METRICS: {
        obsd_gauges g;
        size_t len = 0;
        gauges(h, &g);
        char *text = obsd_stats_text(&g, &len);
        return text ? answer_text(r, 200, "text/plain; version=0.0.4", text, len, NULL) : MHD_NO;
    }
    default:
        return answer_error(r, 404, "not_found", "no such route", NULL, NULL);
    }
}

/* ---- POST /v1/ao ----------------------------------------------------- */

typedef struct arg_ctx {
    obs_http_request *hr;
    obs_status status;
    char err[OBS_ERR_LEN];
} arg_ctx;

static enum MHD_Result on_arg(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    arg_ctx *a = cls;
    (void)kind;
    if (a->status != OBS_OK)
        return MHD_NO;
    a->status = obs_http_request_set(a->hr, key, value, a->err);
    return a->status == OBS_OK ? MHD_YES : MHD_NO;
}

/* Called on the GL worker thread: give the connection back to MHD. */
static void job_done(obsd_job *job, void *user)
{
    (void)job;
    req *r = user;
    MHD_resume_connection(r->conn);
}

static enum MHD_Result ao_start(req *r)
{
    obsd_http *h = r->srv;
    const char *v;
    r->before_drain = !atomic_load(&h->draining);
    if (!r->before_drain)
        return answer_error(r, 503, "shutting_down", "the daemon is shutting down",
                            MHD_HTTP_HEADER_RETRY_AFTER, "5");
    arg_ctx a = {&r->hr, OBS_OK, ""};
    obs_http_request_init(&r->hr);
    MHD_get_connection_values(r->conn, MHD_GET_ARGUMENT_KIND, on_arg, &a);
    if (a.status == OBS_OK)
        a.status = obs_http_request_check(&r->hr, a.err);
    if (a.status != OBS_OK)
        return answer_error(r, 400, "bad_parameter", a.err, NULL, NULL);
    v = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_TYPE);
    if (v && strncmp(v, "image/x-exr", 11) != 0 && strncmp(v, "application/octet-stream", 24) != 0)
        return answer_error(r, 415, "unsupported_media_type",
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
            return answer_error(r, 413, "body_too_large", msg, NULL, NULL);
        }
        /* Sized by the claim, which is within the limit; grows if it lied. */
        r->cap = n ? (size_t)n : 0;
        if (r->cap && !(r->body = malloc(r->cap)))
            return answer_status(r, OBS_NO_MEMORY, "no memory for the body");
    }
    /* Refuse early when the queue is already full: no need for the body. */
    int full;
    obsd_queue_stats(h->queue, NULL, NULL, &full);
    if (full)
        return answer_error(r, 503, "queue_full", "the frame queue is full; retry later",
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
            obsd_log(OBSD_LOG_INFO, "req=%llu peer=%s POST /v1/ao: body over twice --max-body, "
                     "connection closed", (unsigned long long)r->id, r->peer);
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
            return answer_status(r, OBS_NO_MEMORY, "no memory for the body");
        r->body = p;
        r->cap = cap;
    }
    memcpy(r->body + r->len, data, n);
    r->len += n;
    return MHD_YES;
}

static enum MHD_Result ao_run(req *r)
{
    obsd_http *h = r->srv;
    char err[OBS_ERR_LEN] = "";
    obs_limits lim = {.max_pixels = (uint64_t)h->cfg->max_pixels};
    if (r->len == 0)
        return answer_error(r, 400, "empty_body", "POST /v1/ao needs a G-buffer EXR as its body",
                            NULL, NULL);
    double t0 = obsd_now_ms();
    obs_status s = obs_gbuffer_read_exr_mem(r->body, r->len, &r->hr.map, &lim, &r->gf, err);
    r->ms_decode = obsd_now_ms() - t0;
    obsd_stats_stage(OBSD_STAGE_DECODE, r->ms_decode);
    free(r->body);
    r->body = NULL;
    r->cap = 0;
    if (s != OBS_OK)
        return answer_status(r, s, err);

    r->job = (obsd_job){.gb = &r->gf.gb, .params = &r->hr.params, .outputs = r->hr.outputs,
                        .done = job_done, .user = r};
    /* Suspend before queueing: the worker may finish and resume at once. */
    r->state = REQ_QUEUED;
    MHD_suspend_connection(r->conn);
    if ((atomic_load(&h->draining) && !r->before_drain) || obsd_queue_push(h->queue, &r->job) != 0) {
        r->state = REQ_REFUSED;
        MHD_resume_connection(r->conn);
    }
    return MHD_YES;
}

/* Called again once the GL worker resumed the connection. */
static enum MHD_Result ao_finish(req *r)
{
    obsd_job *job = &r->job;
    char err[OBS_ERR_LEN] = "";
    r->ms_queue = job->t_started - job->t_queued;
    r->ms_gl = job->t_finished - job->t_started;
    obsd_stats_stage(OBSD_STAGE_QUEUE, r->ms_queue);
    obsd_stats_stage(OBSD_STAGE_GL, r->ms_gl);
    if (job->status != OBS_OK)
        return answer_status(r, job->status, job->err);
    obsd_stats_frame(r->gf.gb.width, r->gf.gb.height);

    double t0 = obsd_now_ms();
    obs_bytes out = {0};
    obs_status s;
    const char *type;
    const obs_result *res = &job->result;
    if (r->hr.format == OBS_HTTP_EXR) {
        obs_exr_layer layers[OBS_RESULT_LAYERS];
        int n = obs_result_exr_layers(res, layers);
        const obs_camera *cam = r->gf.gb.camera.has_projection ? &r->gf.gb.camera : NULL;
        s = obs_exr_write_mem(layers, n, r->hr.float_exr ? OBS_EXR_FLOAT : OBS_EXR_HALF, cam, &out, err);
        type = "image/x-exr";
    } else {
        const obs_image *img = res->ao.data ? &res->ao : &res->composite;
        s = obs_png_write_mem(img, r->hr.png_bits, img == &res->composite, &out, err);
        type = "image/png";
    }
    r->ms_encode = obsd_now_ms() - t0;
    obsd_stats_stage(OBSD_STAGE_ENCODE, r->ms_encode);
    obs_result_free(&job->result);
    if (s != OBS_OK)
        return answer_error(r, 500, "encode_failed", err, NULL, NULL);

    struct MHD_Response *resp = MHD_create_response_from_buffer(out.size, out.data, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        obs_bytes_free(&out);
        return MHD_NO;
    }
    char timing[192];
    snprintf(timing, sizeof timing, "queue;dur=%.2f, decode;dur=%.2f, gl;dur=%.2f, encode;dur=%.2f",
             r->ms_queue, r->ms_decode, r->ms_gl, r->ms_encode);
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    MHD_add_response_header(resp, "Server-Timing", timing);
    return answer(r, 200, resp, out.size, NULL);
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
        r->srv = h;
        r->conn = conn;
        r->id = atomic_fetch_add(&h->next_id, 1) + 1;
        r->t0 = obsd_now_ms();
        r->route = obsd_route_of(url);
        snprintf(r->method, sizeof r->method, "%s", method);
        peer_name(conn, r->peer, sizeof r->peer);

        if (r->route == OBSD_ROUTE_OTHER)
            return answer_error(r, 404, "not_found", "no such route (try GET /v1/params)", NULL, NULL);
        const char *allowed = r->route == OBSD_ROUTE_AO ? "POST" : "GET";
        if (strcmp(method, allowed) != 0 && !(r->route != OBSD_ROUTE_AO && !strcmp(method, "HEAD"))) {
            char msg[64];
            snprintf(msg, sizeof msg, "%s takes %s", obsd_route_path(r->route), allowed);
            return answer_error(r, 405, "method_not_allowed", msg, MHD_HTTP_HEADER_ALLOW, allowed);
        }
        /* Probes stay open; the API and the metrics need the token. */
        if (h->token && r->route != OBSD_ROUTE_HEALTHZ && r->route != OBSD_ROUTE_READYZ &&
            !obs_http_bearer_ok(MHD_lookup_connection_value(conn, MHD_HEADER_KIND,
                                                            MHD_HTTP_HEADER_AUTHORIZATION),
                                h->token))
            return answer_error(r, 401, "unauthorized", "missing or wrong bearer token",
                                MHD_HTTP_HEADER_WWW_AUTHENTICATE, "Bearer realm=\"obscurad\"");
        if (r->route != OBSD_ROUTE_AO)
            return get_route(r);
        return ao_start(r);
    }
    switch (r->state) {
    case REQ_BODY:
        if (*upload_data_size)
            return ao_body(r, upload_data, upload_data_size);
        if (r->too_big) {
            char msg[160];
            snprintf(msg, sizeof msg, "body is over the limit of %lld bytes (--max-body)",
                     (long long)h->cfg->max_body);
            return answer_error(r, 413, "body_too_large", msg, NULL, NULL);
        }
        return ao_run(r);
    case REQ_QUEUED:
        return ao_finish(r);
    case REQ_REFUSED:
        return answer_error(r, 503, atomic_load(&h->draining) ? "shutting_down" : "queue_full",
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
    free(r->body);
    obs_result_free(&r->job.result);
    obs_gbuffer_free(&r->gf);
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
    if (h->listen_fd == MHD_INVALID_SOCKET)
        h->listen_fd = MHD_quiesce_daemon(h->mhd);
}

int obsd_http_in_flight(obsd_http *h) { return atomic_load(&h->in_flight); }

void obsd_http_stop(obsd_http *h)
{
    if (!h)
        return;
    MHD_stop_daemon(h->mhd);
    /* MHD hands the quiesced socket to us, to close after the stop. */
    if (h->listen_fd != MHD_INVALID_SOCKET)
        close(h->listen_fd);
    free(h);
}
