/* The HTTP server of obscurad: libmicrohttpd set up, each request's
 * life (its first call, the route, method and token checks, its end) and
 * the dispatch to the parts:
 *
 *   http_frames.c   POST /v1/ao and the frames of streams
 *   http_streams.c  /v1/streams
 *   http_info.c     /v1/params, /v1/info, /healthz, /readyz, /metrics
 *   http_page.c     the preview page
 *   http_reply.c    the answers, logged and counted */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "http_internal.h"
#include "log.h"

typedef obsd__req req;

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
            return obsd__info_route(r);
        return obsd__frame_start(r);
    }
    switch (r->state) {
    case REQ_BODY:
        return obsd__frame_body(r, upload_data, upload_data_size);
    case REQ_QUEUED:
        return r->route == OBSD_ROUTE_STREAMS ? obsd__streams_finish(r) : obsd__ao_finish(r);
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
