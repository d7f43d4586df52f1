/* The HTTP server of obscurad: libmicrohttpd set up, each request's
 * life (its first call, its row of the route table (routes.c), the row's
 * method and token checks, its end) and the dispatch to the row's
 * handlers, in the parts:
 *
 *   http_frames.c   POST /v1/ao and the frames of streams
 *   http_streams.c  /v1/streams
 *   http_bakes.c    /v1/bakes
 *   http_info.c     /v1/params, /v1/info, /healthz, /readyz, /metrics
 *   http_page.c     the preview page
 *   http_reply.c    the answers, logged and counted
 *   http_conn.c     the open connections: deadlines, room at the limit, the cut */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include "addr.h"
#include "http_internal.h"
#include "http_server.h"
#include "log.h"
#include "routes.h"

typedef obsd__req req;

/* ---- a request's first call: framing, route, checks, dispatch --------- */

typedef struct framing {
    int n_length, n_coding, lengths_differ;
    char length[32], coding[64];
} framing;

static enum MHD_Result on_header(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    framing *f = cls;
    (void)kind;
    if (!key)
        return MHD_YES;
    if (!value)
        value = "";
    if (!strcasecmp(key, MHD_HTTP_HEADER_CONTENT_LENGTH)) {
        if (f->n_length++ && strcmp(f->length, value) != 0)
            f->lengths_differ = 1;
        snprintf(f->length, sizeof f->length, "%s", value);
    } else if (!strcasecmp(key, MHD_HTTP_HEADER_TRANSFER_ENCODING)) {
        f->n_coding++;
        snprintf(f->coding, sizeof f->coding, "%s", value);
    }
    return MHD_YES;
}

/* Headers that make the body's length ambiguous (a request smuggled
 * past a proxy that reads them the other way) or unknown: 400 before any
 * of the body is read.  *has_body: the request announces one; *length:
 * its Content-Length (-1: none, chunked; an unreadable one is huge). */
static int framing_ok(req *r, int *has_body, unsigned long long *length, enum MHD_Result *rc)
{
    framing f = {0};
    char msg[160];
    MHD_get_connection_values(r->conn, MHD_HEADER_KIND, on_header, &f);
    *has_body = f.n_coding > 0 || (f.n_length > 0 && strcmp(f.length, "0") != 0);
    *length = (unsigned long long)-1;
    if (f.n_length && !f.n_coding) {
        char *end;
        errno = 0;
        unsigned long long n = strtoull(f.length, &end, 10);
        if (!errno && end != f.length && !*end)
            *length = n;
    }
    if (f.n_length && f.n_coding)
        snprintf(msg, sizeof msg, "both Content-Length and Transfer-Encoding: the body's length is ambiguous");
    else if (f.lengths_differ)
        snprintf(msg, sizeof msg, "two different Content-Length headers");
    else if (f.n_coding > 1 || (f.n_coding && strcasecmp(f.coding, "chunked") != 0))
        snprintf(msg, sizeof msg, "Transfer-Encoding '%.60s' is not supported (chunked only)", f.coding);
    else
        return 1;
    *rc = obsd__answer_error(r, 400, "bad_request", msg, NULL, NULL);
    return 0;
}

/* The method the row takes: "GET" takes HEAD too. */
static int method_ok(const obsd__route *rt, const char *method)
{
    return !strcmp(method, rt->methods) || (!strcmp(rt->methods, "GET") && !strcmp(method, "HEAD"));
}

/* The checks of the route's row, then its start. */
static enum MHD_Result dispatch(req *r, const char *url, const char *method)
{
    obsd_http *h = r->srv;
    const obsd__route *rt = r->route;
    if (r->cn && r->cn->over_client && !(rt && (rt->flags & OBSD_ROUTE_PROBE))) {
        char msg[160];
        snprintf(msg, sizeof msg, "%d connections are open from this address (--max-per-client %d); "
                 "retry later", h->front.cfg->max_per_client, h->front.cfg->max_per_client);
        return obsd__answer_error(r, 503, "too_many_connections", msg, MHD_HTTP_HEADER_RETRY_AFTER, "1");
    }
    if (r->cn && r->cn->reserve && !(rt && (rt->flags & OBSD_ROUTE_PROBE))) {
        char msg[128];
        snprintf(msg, sizeof msg, "%d connections are open (--http-connections); retry later",
                 h->front.cfg->http_connections);
        return obsd__answer_error(r, 503, "too_many_connections", msg, MHD_HTTP_HEADER_RETRY_AFTER, "1");
    }
    if (!rt)
        return obsd__answer_error(r, 404, "not_found", "no such route (try GET /v1/params)", NULL, NULL);
    if (h->front.cfg->cors[0] && !strcmp(method, "OPTIONS")) /* a preflight carries no token */
        return obsd__answer_preflight(r, rt->methods ? rt->methods : "GET, HEAD, POST, DELETE");
    if (rt->methods && !method_ok(rt, method)) {
        char msg[64];
        snprintf(msg, sizeof msg, "%s takes %s", rt->path, rt->methods);
        return obsd__answer_error(r, 405, "method_not_allowed", msg, MHD_HTTP_HEADER_ALLOW, rt->methods);
    }
    /* Probes and the static page stay open; the API and the metrics need the token. */
    if (h->front.token && !(rt->flags & OBSD_ROUTE_OPEN) &&
        !obs_http_bearer_ok(MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND,
                                                        MHD_HTTP_HEADER_AUTHORIZATION),
                            h->front.token))
        return obsd__answer_error(r, 401, "unauthorized", "missing or wrong bearer token",
                                  MHD_HTTP_HEADER_WWW_AUTHENTICATE, "Bearer realm=\"obscurad\"");
    return rt->start(r, url);
}

/* A request's record, made on its first call; NULL on no memory. */
static req *req_new(obsd_http *h, struct MHD_Connection *conn, obsd__conn *c, const char *url,
                    const char *method)
{
    req *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    atomic_init(&r->job, JOB_NONE);
    r->srv = h;
    r->conn = conn;
    r->cn = c;
    r->id = atomic_fetch_add(&h->next_id, 1) + 1;
    r->t0 = obsd_now_ms();
    int row = obsd__route_find(url);
    r->route = row >= 0 ? &obsd__routes[row] : NULL;
    r->slot = row >= 0 ? row : OBSD_STATS_OTHER;
    r->label = row >= 0 ? r->route->path : "other";
    r->frame_total = r->route && (r->route->flags & OBSD_ROUTE_FRAME_TOTAL);
    snprintf(r->method, sizeof r->method, "%s", method);
    snprintf(r->path, sizeof r->path, "%s", url);
    for (char *p = r->path; *p; p++)
        if ((unsigned char)*p < 0x21 || (unsigned char)*p > 0x7e)
            *p = '?';
    snprintf(r->peer, sizeof r->peer, "%s", c ? c->peer : "?");
    return r;
}

/* The most of a body the route reads: what a held answer discards. */
static size_t body_max(const obsd_http *h, const obsd__route *rt)
{
    const obsd_config *cfg = h->front.cfg;
    return (size_t)(rt && (rt->flags & OBSD_ROUTE_LEVEL_BODY) ? cfg->max_level : cfg->max_body);
}

static int expects_continue(struct MHD_Connection *conn)
{
    const char *v = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_EXPECT);
    while (v && *v == ' ')
        v++;
    return v && !strncasecmp(v, "100-continue", 12);
}

/* A call with more of a body under a held answer: thrown away, up to
 * the route's limit and within the request's deadline. */
static enum MHD_Result discard_held(req *r, size_t *size)
{
    size_t n = *size;
    *size = 0;
    if (!obsd__req_alive(r))
        return MHD_NO;
    return obsd__discard_body(r, n, r->hold_max);
}

/* A request's first call: its record, its deadline, its framing; then
 * its start now (it reads a body, or has one), or on the next call. */
static enum MHD_Result first_call(obsd_http *h, struct MHD_Connection *conn, const char *url,
                                  const char *method, void **con_cls)
{
    const union MHD_ConnectionInfo *si = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    obsd__conn *c = si ? si->socket_context : NULL;
    if (c && atomic_load(&c->cut))
        return MHD_NO;
    req *r = req_new(h, conn, c, url, method);
    if (!r)
        return MHD_NO;
    *con_cls = r;
    atomic_fetch_add(&h->in_flight, 1);
    if (c && obsd__conn_attach(h, c, r, r->t0)) { /* its headers came too late */
        char msg[128];
        snprintf(msg, sizeof msg, "the request took over %d s (--request-timeout) to send its headers",
                 h->front.cfg->request_timeout);
        return obsd__answer_error(r, 408, "request_timeout", msg, NULL, NULL);
    }
    int has_body;
    unsigned long long length;
    enum MHD_Result rc;
    if (!framing_ok(r, &has_body, &length, &rc))
        return rc;
    /* A route that reads its body starts now; anything else without one
     * is answered on the next call, once MHD holds the whole request, so
     * that the connection stays open for the next (an answer queued now
     * closes it).  With a body it starts now too. */
    const char *rb = r->route ? r->route->reads_body : NULL;
    if (!(rb && (!strcmp(rb, "*") || !strcmp(rb, method))) && !has_body) {
        r->state = REQ_DEFERRED;
        return MHD_YES;
    }
    /* A client that does not wait for 100 Continue is sending its body
     * already: an answer now (a bad parameter, 415, 503) is held until
     * the body's end (REQ_HELD), or the connection would close with its
     * bytes unread and the kernel's reset destroy the answer.  One that
     * waits is answered now, as is a body over the limit (413): the
     * client has not sent it, or we would not read it all. */
    r->hold_max = body_max(h, r->route);
    r->body_in = has_body && !expects_continue(conn) && (length == (unsigned long long)-1 || length <= r->hold_max);
    rc = dispatch(r, url, method);
    if (has_body && r->state != REQ_ANSWERED)
        r->body_in = 1; /* from now the client sends it (after MHD's 100 Continue) */
    return rc;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url,
                                  const char *method, const char *version, const char *upload_data,
                                  size_t *upload_data_size, void **con_cls)
{
    obsd_http *h = cls;
    req *r = *con_cls;
    (void)version;
    if (!r)
        return first_call(h, conn, url, method, con_cls);
    int job = atomic_load(&r->job);
    if (job == JOB_CUT || job == JOB_CUT_DONE)
        return MHD_NO; /* resumed by the cut: the connection closes */
    if (r->body_in && !*upload_data_size)
        r->body_in = 0; /* the body's end: an answer is queued now */
    switch (r->state) {
    case REQ_HELD:
        return *upload_data_size ? discard_held(r, upload_data_size) : obsd__answer_held(r);
    case REQ_DEFERRED:
        if (*upload_data_size) {
            *upload_data_size = 0;
            return MHD_YES;
        }
        return dispatch(r, url, method);
    case REQ_BODY: /* only a row with a body handler enters REQ_BODY */
        return r->route->body(r, upload_data, upload_data_size);
    case REQ_QUEUED: /* only a row with a finish handler queues a frame */
        return r->route->finish(r);
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
    obsd__conn *c = r->cn;
    int cut = c ? atomic_load(&c->cut) : CUT_NONE;
    if (why != MHD_REQUEST_TERMINATED_COMPLETED_OK && r->state != REQ_ANSWERED && cut != CUT_DEADLINE)
        obsd_log(OBSD_LOG_INFO, "req=%llu peer=%s %s %s ended without an answer (reason %d%s)",
                 (unsigned long long)r->id, r->peer, r->method, r->label, (int)why,
                 cut == CUT_DRAIN ? ", cut by the drain" : cut == CUT_EVICTED ? ", evicted" : "");
    /* the answer of a frame is out: the send stage (its bytes handed to
     * the kernel; the client may still be reading them) */
    if (why == MHD_REQUEST_TERMINATED_COMPLETED_OK && r->frame_total && r->status == 200 && r->t_answered > 0)
        obsd_stats_stage(OBSD_STAGE_SEND, obsd_now_ms() - r->t_answered);
    if (c)
        obsd__conn_detach(h, c);
    if (r->route && r->route->done)
        r->route->done(r);
    *con_cls = NULL;
    atomic_fetch_sub(&h->in_flight, 1);
    /* cut while the GL worker had its frame: the worker frees it */
    int s = JOB_CUT;
    if (!atomic_compare_exchange_strong(&r->job, &s, JOB_ORPHAN))
        obsd__req_free(r);
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

/* "HOST:PORT" (IPv4, the host may be empty: any) or "[HOST]:PORT"
 * (IPv6) into addr; host gets the host as written, for the log. */
static int parse_addr(const char *s, struct sockaddr_storage *addr, socklen_t *alen, char *host, size_t hlen,
                      char err[OBS_ERR_LEN])
{
    const char *colon = strrchr(s, ':');
    char name[OBSD_STR_LEN];
    int v6 = s[0] == '[';
    if (!colon || (v6 && (colon == s || colon[-1] != ']')) || (size_t)(colon - s) >= sizeof name ||
        (size_t)(colon - s) >= hlen) {
        snprintf(err, OBS_ERR_LEN, "--http '%s' is not HOST:PORT or [IPV6]:PORT", s);
        return -1;
    }
    snprintf(host, hlen, "%.*s", (int)(colon - s), s);
    if (v6)
        snprintf(name, sizeof name, "%.*s", (int)(colon - s) - 2, s + 1);
    else
        snprintf(name, sizeof name, "%s", host[0] ? host : "0.0.0.0");
    char *end;
    long port = strtol(colon + 1, &end, 10);
    int ok = colon[1] && !*end && port >= 0 && port <= 65535 &&
             obsd_addr_fill(v6, name, (uint16_t)port, addr, alen) == 0;
    if (!ok) {
        snprintf(err, OBS_ERR_LEN, "--http '%s' is not IPV4:PORT or [IPV6]:PORT with a port in 0..65535", s);
        return -1;
    }
    return 0;
}

obs_status obsd_http_start(const obsd_front *f, obsd_http **out, char err[OBS_ERR_LEN])
{
    const obsd_config *cfg = f->cfg;
    struct sockaddr_storage addr;
    socklen_t alen;
    char host[OBSD_STR_LEN];
    if (parse_addr(cfg->http, &addr, &alen, host, sizeof host, err) != 0)
        return OBS_INVALID_ARGUMENT;
    obsd_http *h = calloc(1, sizeof *h);
    if (!h)
        return OBS_NO_MEMORY;
    h->front = *f;
    h->listen_fd = MHD_INVALID_SOCKET;
    h->family = addr.ss_family;
    snprintf(h->host, sizeof h->host, "%s", host);
    if (!(h->streams = obsd_streams_new(cfg->streams, cfg->stream_frames, cfg->stream_memory))) {
        free(h);
        return OBS_NO_MEMORY;
    }
    if (!(h->bakes = obsd_bakes_new(cfg->max_bakes, cfg->bake_workers, cfg->bake_keep,
                                    cfg->bake_max_triangles))) {
        obsd_streams_free(h->streams);
        free(h);
        return OBS_NO_MEMORY;
    }
    atomic_init(&h->in_flight, 0);
    atomic_init(&h->draining, 0);
    atomic_init(&h->next_id, 0);
    atomic_init(&h->sweeper_stop, 0);
    pthread_mutex_init(&h->lock, NULL);
    for (int i = 0; i < obsd__route_count; i++)
        obsd_stats_label(i, obsd__routes[i].path);
    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_EPOLL | MHD_USE_ITC |
                     MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ERROR_LOG;
    if (h->family == AF_INET6)
        flags |= MHD_USE_IPv6;
    /* MHD refuses beyond its limit before anything of ours runs: the
     * reserve above --http-connections is where on_connection makes room
     * or lets a probe in.  --max-per-client is counted by http_conn.c,
     * so that the connection over it is answered (MHD's would reset it). */
    h->mhd = MHD_start_daemon(flags, 0, NULL, NULL, on_request, h,
                              MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr,
                              MHD_OPTION_THREAD_POOL_SIZE, (unsigned)cfg->threads,
                              MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)cfg->timeout,
                              MHD_OPTION_CONNECTION_LIMIT, (unsigned)(cfg->http_connections + OBSD_HTTP_RESERVE),
                              MHD_OPTION_NOTIFY_CONNECTION, obsd__conn_notify, h,
                              MHD_OPTION_NOTIFY_COMPLETED, on_completed, h,
                              MHD_OPTION_EXTERNAL_LOGGER, on_mhd_log, h,
                              MHD_OPTION_END);
    (void)alen;
    if (!h->mhd) {
        snprintf(err, OBS_ERR_LEN, "cannot listen on %s (in use, or not an address of this host?)",
                 cfg->http);
        goto fail;
    }
    if (pthread_create(&h->sweeper, NULL, obsd__conn_sweeper, h) != 0) {
        snprintf(err, OBS_ERR_LEN, "cannot start the HTTP deadline thread");
        MHD_stop_daemon(h->mhd);
        goto fail;
    }
    h->sweeper_running = 1;
    const union MHD_DaemonInfo *di = MHD_get_daemon_info(h->mhd, MHD_DAEMON_INFO_BIND_PORT);
    h->port = di ? di->port : 0;
    *out = h;
    return OBS_OK;
fail:
    pthread_mutex_destroy(&h->lock);
    obsd_bakes_free(h->bakes);
    obsd_streams_free(h->streams);
    free(h);
    return OBS_IO;
}

int obsd_http_port(const obsd_http *h) { return h->port; }

void obsd_http_url(const obsd_http *h, char *buf, size_t len)
{
    snprintf(buf, len, "http://%s:%d", h->host, h->port);
}

void obsd_http_quiesce(obsd_http *h)
{
    atomic_store(&h->draining, 1);
    obsd_streams_end_all(h->streams); /* event streams end, so that the drain ends */
    obsd_bakes_cancel_all(h->bakes);  /* running bakes stop between batches of rays */
    if (h->listen_fd == MHD_INVALID_SOCKET) {
        h->listen_fd = MHD_quiesce_daemon(h->mhd);
        /* MHD no longer accepts, but the kernel still would, into a
         * backlog nobody reads: stop listening, so that a client is
         * refused at once (the socket is closed after the stop). */
        if (h->listen_fd != MHD_INVALID_SOCKET)
            shutdown(h->listen_fd, SHUT_RDWR);
    }
}

int obsd_http_in_flight(obsd_http *h) { return atomic_load(&h->in_flight); }

void obsd_http_tick(obsd_http *h)
{
    if (h) {
        obsd_streams_tick(h->streams, obsd_now_ms());
        obsd_bakes_tick(h->bakes, obsd_now_ms());
    }
}

void obsd_http_stop(obsd_http *h)
{
    if (!h)
        return;
    if (h->sweeper_running) {
        atomic_store(&h->sweeper_stop, 1);
        pthread_join(h->sweeper, NULL);
    }
    /* Whatever the clients do: every connection is shut, and every one
     * suspended for the GL worker resumed (MHD must hold none suspended
     * when it stops). */
    obsd_http_cut(h);
    MHD_stop_daemon(h->mhd);
    obsd_bakes_free(h->bakes); /* cancelled in the quiesce: the workers end */
    /* MHD hands the quiesced socket to us, to close after the stop. */
    if (h->listen_fd != MHD_INVALID_SOCKET)
        close(h->listen_fd);
    obsd_streams_free(h->streams);
    pthread_mutex_destroy(&h->lock);
    free(h);
}
