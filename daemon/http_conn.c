/* obscurad's open HTTP connections: one record each (MHD's socket
 * context), in a list under the server's lock, oldest first.
 *
 *   deadline   --request-timeout for the headers and body of each request,
 *              however steadily they trickle: a sweeper thread answers 408
 *              past it (written to the socket: MHD cannot answer in the
 *              middle of a body) and shuts the socket; MHD closes it
 *   the limit  beyond --http-connections, a new connection displaces the
 *              oldest one that has not sent a whole request (stalled in
 *              its headers, or idle); when every one is inside a request,
 *              it may ask /healthz and /readyz only (the reserve)
 *   the cut    obsd_http_cut(): every connection shut at once, those
 *              suspended for the GL worker resumed (to close), their jobs
 *              left to free their requests */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>

#include "http_internal.h"
#include "list.h"
#include "log.h"

typedef obsd__req req;

/* The peer as "IP:PORT" into buf, its address alone into ip. */
static void addr_name(const struct sockaddr *sa, char *buf, size_t len, char ip[INET6_ADDRSTRLEN])
{
    snprintf(buf, len, "?");
    snprintf(ip, INET6_ADDRSTRLEN, "?");
    if (sa && sa->sa_family == AF_INET) {
        const struct sockaddr_in *in = (const struct sockaddr_in *)(const void *)sa;
        if (inet_ntop(AF_INET, &in->sin_addr, ip, INET6_ADDRSTRLEN))
            snprintf(buf, len, "%s:%u", ip, ntohs(in->sin_port));
    } else if (sa && sa->sa_family == AF_INET6) {
        const struct sockaddr_in6 *in6 = (const struct sockaddr_in6 *)(const void *)sa;
        if (inet_ntop(AF_INET6, &in6->sin6_addr, ip, INET6_ADDRSTRLEN))
            snprintf(buf, len, "[%s]:%u", ip, ntohs(in6->sin6_port));
    }
}

/* Under h->lock: c is one more than --max-per-client from its address
 * (counted here: MHD's own per-address limit resets the connection
 * without a word). */
static int over_client_limit(const obsd_http *h, const obsd__conn *c)
{
    int max = h->front.cfg->max_per_client, n = 0;
    if (max <= 0)
        return 0;
    for (const obsd__conn *o = h->conns; o; o = o->next)
        if (!atomic_load(&o->cut) && !o->over_client && !strcmp(o->ip, c->ip))
            n++;
    return n > max;
}

static double deadline_from(const obsd_http *h, double now)
{
    return h->front.cfg->request_timeout > 0 ? now + h->front.cfg->request_timeout * 1000.0 : 0.0;
}

/* Past its deadline: a 408 written straight to the socket (libmicrohttpd
 * cannot answer before the body is in), logged and counted as
 * http_reply.c does its answers; the caller shuts the socket.  Under
 * h->lock, so that it cannot cross an answer (obsd__req_hold). */
static void answer_timeout(obsd_http *h, obsd__conn *c)
{
    const obsd__req *r = c->r;
    char msg[160], head[256];
    snprintf(msg, sizeof msg, "the request took over %d s (--request-timeout) to send its %s",
             h->front.cfg->request_timeout, r ? "body" : "headers");
    char *body = obs_http_error_json("request_timeout", msg);
    size_t len = body ? strlen(body) : 0;
    int n = snprintf(head, sizeof head,
                     "HTTP/1.1 408 Request Timeout\r\nConnection: close\r\nContent-Type: application/json\r\n"
                     "Content-Length: %zu\r\nServer: obscurad/" OBS_VERSION "\r\n\r\n", len);
    /* Best effort: the client may not read, and nothing here may block. */
    if (send(c->fd, head, (size_t)n, MSG_NOSIGNAL | MSG_DONTWAIT) == n && body)
        (void)!send(c->fd, body, len, MSG_NOSIGNAL | MSG_DONTWAIT);
    free(body);
    size_t in = r ? r->len + r->discarded : 0;
    obsd_stats_request(r ? r->slot : OBSD_STATS_OTHER, 408, in, len);
    obsd_stats_refusal("request_timeout", c->peer, msg);
    if (r)
        obsd_log(OBSD_LOG_INFO, "req=%llu peer=%s %s %s status=408 in=%zu out=%zu total=%.1f ms "
                 "error=request_timeout: %s", (unsigned long long)r->id, r->peer, r->method, r->path, in, len,
                 obsd_now_ms() - r->t0, msg);
    else
        obsd_log(OBSD_LOG_INFO, "peer=%s status=408 error=request_timeout: %s", c->peer, msg);
}

/* Under h->lock.  The socket is shut down here; its MHD thread sees the
 * end and closes the connection (the record goes with it). */
static void cut_conn(obsd_http *h, obsd__conn *c, int why)
{
    atomic_store(&c->cut, why);
    if (why == CUT_EVICTED)
        h->evicting++;
    shutdown(c->fd, SHUT_RDWR);
}

int obsd__conn_attach(obsd_http *h, obsd__conn *c, req *r, double now)
{
    pthread_mutex_lock(&h->lock);
    c->r = r;
    int late = c->deadline > 0.0 && now > c->deadline && !atomic_load(&c->cut);
    if (late) /* answered by the caller, not the sweeper */
        c->deadline = 0.0;
    pthread_mutex_unlock(&h->lock);
    return late;
}

void obsd__conn_detach(obsd_http *h, obsd__conn *c)
{
    pthread_mutex_lock(&h->lock);
    c->r = NULL;
    atomic_store(&c->events, 0);
    c->deadline = deadline_from(h, obsd_now_ms()); /* the next request's, on a kept connection */
    pthread_mutex_unlock(&h->lock);
}

void obsd__conn_notify(void *cls, struct MHD_Connection *mc, void **socket_context,
                       enum MHD_ConnectionNotificationCode toe)
{
    obsd_http *h = cls;
    obsd__conn *c = *socket_context;
    if (toe == MHD_CONNECTION_NOTIFY_CLOSED) {
        if (!c)
            return;
        pthread_mutex_lock(&h->lock);
        if (!c->next)
            h->conns_tail = c->prev;
        OBSD_LIST_UNLINK(h->conns, c);
        h->open--;
        if (atomic_load(&c->cut) == CUT_EVICTED)
            h->evicting--;
        pthread_mutex_unlock(&h->lock);
        free(c);
        *socket_context = NULL;
        return;
    }
    const union MHD_ConnectionInfo *fi = MHD_get_connection_info(mc, MHD_CONNECTION_INFO_CONNECTION_FD);
    const union MHD_ConnectionInfo *ai = MHD_get_connection_info(mc, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    if (!fi)
        return;
    if (!(c = calloc(1, sizeof *c))) {
        shutdown(fi->connect_fd, SHUT_RDWR); /* no record, no connection */
        return;
    }
    c->mc = mc;
    c->fd = fi->connect_fd;
    addr_name(ai ? ai->client_addr : NULL, c->peer, sizeof c->peer, c->ip);
    c->deadline = deadline_from(h, obsd_now_ms());
    atomic_init(&c->cut, CUT_NONE);
    atomic_init(&c->events, 0);
    pthread_mutex_lock(&h->lock);
    c->prev = h->conns_tail;
    if (h->conns_tail)
        h->conns_tail->next = c;
    else
        h->conns = c;
    h->conns_tail = c;
    h->open++;
    c->over_client = over_client_limit(h, c);
    if (h->open - h->evicting > h->front.cfg->http_connections) {
        /* At the limit: the oldest connection that has not sent a whole
         * request (stalled in its headers, or idle between requests) makes
         * room; when every one is inside a request, this one may ask the
         * probes only. */
        obsd__conn *o = h->conns;
        while (o && (o == c || o->r || atomic_load(&o->cut)))
            o = o->next;
        if (o) {
            obsd_log(OBSD_LOG_INFO, "peer=%s: connection closed to make room (--http-connections %d open, "
                     "it had sent no whole request)", o->peer, h->front.cfg->http_connections);
            cut_conn(h, o, CUT_EVICTED);
        } else {
            c->reserve = 1;
        }
    }
    pthread_mutex_unlock(&h->lock);
    *socket_context = c;
}

int obsd__req_hold(req *r)
{
    obsd__conn *c = r->cn;
    if (!c)
        return 1;
    pthread_mutex_lock(&r->srv->lock);
    int ok = !atomic_load(&c->cut);
    if (ok)
        c->deadline = 0.0;
    pthread_mutex_unlock(&r->srv->lock);
    return ok;
}

int obsd__req_alive(req *r)
{
    obsd__conn *c = r->cn;
    if (!c)
        return 1;
    if (atomic_load(&c->cut))
        return 0;
    obsd_http *h = r->srv;
    double now = obsd_now_ms();
    pthread_mutex_lock(&h->lock);
    int ok = !atomic_load(&c->cut);
    if (ok && c->deadline > 0.0 && now > c->deadline) {
        answer_timeout(h, c);
        cut_conn(h, c, CUT_DEADLINE);
        ok = 0;
    }
    pthread_mutex_unlock(&h->lock);
    return ok;
}

/* Under h->lock: an event stream whose client closed or reset.  Parked
 * (suspended) it is not polled by MHD, so its departure would be seen
 * only at its next event: the subscriber (and its gauge) would stay. */
static int client_gone(const obsd__conn *c)
{
    char b;
    if (!atomic_load(&c->events) || atomic_load(&c->cut))
        return 0;
    ssize_t n = recv(c->fd, &b, 1, MSG_PEEK | MSG_DONTWAIT);
    return n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR);
}

/* Connections past their deadline, found a few times a second: the
 * ones that trickle their headers, or a body with nothing for a while;
 * and event streams whose client left (shut, resumed: MHD closes them,
 * the route's done unsubscribes). */
void *obsd__conn_sweeper(void *arg)
{
    obsd_http *h = arg;
    const struct timespec tick = {0, 100 * 1000 * 1000};
    while (!atomic_load(&h->sweeper_stop)) {
        nanosleep(&tick, NULL);
        double now = obsd_now_ms();
        pthread_mutex_lock(&h->lock);
        for (obsd__conn *c = h->conns; c; c = c->next)
            if (!atomic_load(&c->cut) && c->deadline > 0.0 && now > c->deadline) {
                answer_timeout(h, c);
                cut_conn(h, c, CUT_DEADLINE);
            } else if (client_gone(c)) {
                cut_conn(h, c, CUT_GONE);
                MHD_resume_connection(c->mc); /* harmless when it is not suspended */
            }
        pthread_mutex_unlock(&h->lock);
    }
    return NULL;
}

void obsd__req_free(req *r)
{
    free(r->body);
    if (r->held) /* the connection ended before the body did */
        MHD_destroy_response(r->held);
    free(r->held_note);
    if (r->fr) { /* the frame's state is freed here, not by a route's done: the GL worker may hold it longer */
        obsd_fp_free(&r->fr->fp);
        free(r->fr->query);
        free(r->fr);
    }
    free(r);
}

int obsd_http_cut(obsd_http *h)
{
    int n = 0;
    if (!h)
        return 0;
    obsd_streams_end_all(h->streams); /* parked event streams resume and end */
    obsd_bakes_cancel_all(h->bakes);  /* and the bakes' */
    pthread_mutex_lock(&h->lock);
    for (obsd__conn *c = h->conns; c; c = c->next) {
        if (!atomic_load(&c->cut)) {
            cut_conn(h, c, CUT_DRAIN);
            n++;
        }
        req *r = c->r;
        if (!r)
            continue;
        /* A connection suspended for the GL worker: resume it here (it
         * closes); the job runs on and its request is freed after both.
         * JOB_DONE: the worker claimed it and resumes it, maybe not yet;
         * resuming again is harmless while the connection exists (its
         * record is in the list: MHD frees it after the CLOSED notice). */
        int s = JOB_PENDING;
        if (atomic_compare_exchange_strong(&r->job, &s, JOB_CUT) || s == JOB_DONE)
            MHD_resume_connection(c->mc);
    }
    pthread_mutex_unlock(&h->lock);
    return n;
}

