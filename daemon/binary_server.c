/* The binary protocol's listeners and connections.
 *
 *   accept thread   poll() on the Unix and TCP listeners (200 ms ticks, so
 *                   it sees the drain), a detached thread per connection;
 *                   over --bin-connections, or --max-per-client from one
 *                   address, a connection is answered 503
 *                   too_many_connections and closed (what it sends is read
 *                   and dropped for a moment, so that the answer arrives)
 *   connection      non-blocking socket.  Read a header (idle --timeout),
 *                   check it; read the request's head (its parameters and
 *                   the G-buffer's fixed fields, obs_bin_request_head) and
 *                   check the token, the drain, the sizes and the queue
 *                   before a byte of the G-buffer is read (a refusal is
 *                   answered and the connection closed: the stream cannot
 *                   be resynchronised); read the rest, decode the request,
 *                   then the frame path (frame_path.c: the EXR, the GL
 *                   worker, the encode), answer; then the next frame.
 *                   Answers go in request order.  A send that makes no
 *                   progress for --timeout seconds gives up and closes.
 *   drain           no new frame starts: a frame that comes is answered
 *                   503 shutting_down and the connection closed; the frame
 *                   under way is answered.  obsd_bin_cut() shuts every
 *                   connection's socket down at once. */
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "binary.h"
#include "binary_server.h"
#include "frame_path.h"
#include "log.h"
#include "stats.h"

#define TICK_MS 200
/* Before closing a connection that was answered without reading all it
 * sent, what it still sends is read and dropped for so long (or so many
 * bytes): closing with unread bytes resets the connection, and the
 * client could lose the answer. */
#define LINGER_MS 2000
#define LINGER_BYTES ((size_t)64 << 20)
/* Refused connections lingering in the accept thread at once. */
#define REFUSED_MAX 64

typedef struct conn conn;

struct conn {
    struct obsd_bin *srv;
    int fd;
    char peer[80]; /* for the log: IP:port, [IPv6]:port or unix */
    char addr[64]; /* for max_per_client: the IP, or "unix" */
    conn *prev, *next;
};

/* A refused connection, answered, its sends dropped until `until`. */
typedef struct refused {
    int fd;
    double until;
    size_t dropped;
} refused;

struct obsd_bin {
    const obsd_config *cfg;
    const char *token;
    obsd_queue *queue;
    obsd_gl_worker *gl;
    int unix_fd, tcp_fd, tcp_port;
    pthread_t acceptor;
    int accepting;
    atomic_int draining;
    atomic_int connections;
    atomic_uint_fast64_t next_id;
    pthread_mutex_t lock; /* guards conns (obsd_bin_cut shuts their sockets) */
    conn *conns;
    /* the accept thread's own */
    refused refused[REFUSED_MAX];
    int nrefused;
    unsigned long refused_total;
    double refused_logged;
};

/* ---- socket I/O with deadlines ------------------------------------------- */

/* Waits until fd is ready for `events`.  1 ready, 0 timed out (or the
 * drain began and `idle`), -1 error. */
static int wait_fd(obsd_bin *b, int fd, short events, double deadline, int idle)
{
    for (;;) {
        struct pollfd p = {fd, events, 0};
        int rc = poll(&p, 1, TICK_MS);
        if (rc > 0)
            return (p.revents & (events | POLLHUP)) ? 1 : -1;
        if (rc < 0 && errno != EINTR)
            return -1;
        if (idle && atomic_load(&b->draining))
            return 0;
        if (deadline > 0 && obsd_now_ms() >= deadline)
            return 0;
    }
}

/* Reads exactly len bytes.  1 done, 0 clean EOF before any byte (only
 * when `idle`), -1 error, timeout or EOF in the middle. */
static int read_all(obsd_bin *b, int fd, void *buf, size_t len, int idle)
{
    const int timeout = b->cfg->timeout;
    double deadline = timeout ? obsd_now_ms() + timeout * 1000.0 : 0;
    size_t got = 0;
    while (got < len) {
        int w = wait_fd(b, fd, POLLIN, deadline, idle && got == 0);
        if (w <= 0)
            return idle && got == 0 && w == 0 ? 0 : -1;
        ssize_t n = recv(fd, (char *)buf + got, len - got, 0);
        if (n == 0)
            return idle && got == 0 ? 0 : -1;
        if (n < 0) {
            if (errno == EINTR || errno == EAGAIN)
                continue;
            return -1;
        }
        got += (size_t)n;
    }
    return 1;
}

/* Sends len bytes.  0 done; -1 the connection is gone (or cut); -2 no
 * byte went for --timeout seconds (a client that does not read). */
static int write_all(obsd_bin *b, int fd, const void *buf, size_t len)
{
    const int timeout = b->cfg->timeout;
    double deadline = timeout ? obsd_now_ms() + timeout * 1000.0 : 0;
    size_t put = 0;
    while (put < len) {
        ssize_t n = send(fd, (const char *)buf + put, len - put, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n > 0) {
            put += (size_t)n;
            deadline = timeout ? obsd_now_ms() + timeout * 1000.0 : 0;
            continue;
        }
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            int w = wait_fd(b, fd, POLLOUT, deadline, 0);
            if (w <= 0)
                return w == 0 ? -2 : -1;
            continue;
        }
        return -1;
    }
    return 0;
}

/* Before closing after an answer given before all the client sent was
 * read: shuts our side, then reads and drops what comes for a moment, so
 * that the close does not reset the connection under the answer. */
static void linger(int fd)
{
    char scratch[16384];
    double until = obsd_now_ms() + LINGER_MS;
    size_t dropped = 0;
    shutdown(fd, SHUT_WR);
    while (dropped < LINGER_BYTES) {
        double left = until - obsd_now_ms();
        if (left <= 0)
            break;
        struct pollfd p = {fd, POLLIN, 0};
        int rc = poll(&p, 1, left < TICK_MS ? (int)left + 1 : TICK_MS);
        if (rc < 0 && errno != EINTR)
            break;
        if (rc <= 0)
            continue;
        ssize_t n = recv(fd, scratch, sizeof scratch, MSG_DONTWAIT);
        if (n == 0 || (n < 0 && errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK))
            break;
        if (n > 0)
            dropped += (size_t)n;
    }
}

/* ---- one frame ------------------------------------------------------------ */

typedef struct frame {
    conn *c;
    uint64_t id, rid;
    double t0;
    size_t bytes_in, bytes_out;
    double ms_decode, ms_queue, ms_gl, ms_encode;
    int status;
    int close_after; /* answered shutting_down: no frame follows */
    char note[OBS_ERR_LEN + 96];
} frame;

static void log_frame(const frame *f)
{
    obsd_stats_request(OBSD_STATS_BINARY, f->status, f->bytes_in, f->bytes_out);
    if (f->status == 200)
        obsd_stats_stage(OBSD_STAGE_TOTAL, obsd_now_ms() - f->t0);
    if (!obsd_log_enabled(OBSD_LOG_INFO))
        return;
    obsd_log(OBSD_LOG_INFO,
             "req=b%llu peer=%s BINARY id=%llu status=%d in=%zu out=%zu queue=%.1f decode=%.1f "
             "gl=%.1f encode=%.1f total=%.1f ms%s%s", (unsigned long long)f->rid, f->c->peer,
             (unsigned long long)f->id, f->status, f->bytes_in, f->bytes_out, f->ms_queue,
             f->ms_decode, f->ms_gl, f->ms_encode, obsd_now_ms() - f->t0, f->note[0] ? " " : "",
             f->note);
}

/* Sends a response; -1 when the connection is gone. */
static int send_response(frame *f, const obs_bin_response_desc *d)
{
    obs_bytes out;
    char err[OBS_ERR_LEN];
    obs_status s = obs_bin_response_encode(d, &out, err);
    if (s != OBS_OK) {
        obsd_log(OBSD_LOG_ERROR, "req=b%llu: cannot encode the response: %s",
                 (unsigned long long)f->rid, err);
        return -1;
    }
    f->status = d->status;
    f->bytes_out = out.size;
    int rc = write_all(f->c->srv, f->c->fd, out.data, out.size);
    obs_bytes_free(&out);
    if (d->status != 200)
        snprintf(f->note, sizeof f->note, "error=%s: %s", d->code, d->message);
    if (rc == -2)
        snprintf(f->note + strlen(f->note), sizeof f->note - strlen(f->note),
                 "%s(no byte of the answer went for %d s: the client does not read; gave up, closed)",
                 f->note[0] ? " " : "", f->c->srv->cfg->timeout);
    else if (rc != 0)
        snprintf(f->note + strlen(f->note), sizeof f->note - strlen(f->note),
                 "%s(client gone before the answer)", f->note[0] ? " " : "");
    log_frame(f);
    return rc;
}

static int send_error(frame *f, int status, const char *code, const char *msg)
{
    obs_bin_response_desc d = {.id = f->id, .status = status, .retry_after = status == 503 ? 1 : 0,
                                .code = code, .message = msg, .body = OBS_BIN_NONE};
    return send_response(f, &d);
}

static int send_status(frame *f, obs_status s, const char *msg)
{
    const char *code;
    int http = obs_http_status_of(s, &code);
    return send_error(f, http, code, msg && *msg ? msg : obs_status_message(s));
}

/* Runs a decoded request through the frame path and answers it. */
static int run_frame(frame *f, obs_bin_request *q)
{
    obsd_bin *b = f->c->srv;
    obs_limits lim = {.max_pixels = (uint64_t)b->cfg->max_pixels};
    char err[OBS_ERR_LEN] = "";
    obsd_fp fp;
    int rc;

    obsd_fp_init(&fp);
    if (q->body == OBS_BIN_EXR) {
        /* a deep EXR runs the deep chain, as on POST /v1/ao */
        obs_status s = obsd_fp_decode(&fp, q->exr, q->exr_len, &q->hr, &lim, NULL, err);
        f->ms_decode = fp.ms_decode;
        if (s == OBS_OK && !q->raw_out && q->hr.format == OBS_HTTP_EXR)
            obsd_fp_keep_source(&fp, q->exr, q->exr_len, obsd_fp_part(&fp)); /* the answer takes its header */
        if (s != OBS_OK) {
            rc = send_status(f, s, err);
            goto done;
        }
    } else {
        obsd_fp_use(&fp, &q->gf.gb, q->body == OBS_BIN_DEEP ? &q->deep : NULL);
    }
    obs_status cs = obsd_fp_check_output(&fp, &q->hr, err);
    if (cs != OBS_OK) {
        rc = send_status(f, cs, err);
        goto done;
    }
    if (atomic_load(&b->draining) ||
        obsd_fp_queue(&fp, b->queue, &q->hr.params, q->hr.outputs, NULL, NULL) != 0) {
        f->close_after = atomic_load(&b->draining);
        rc = f->close_after ? send_error(f, 503, "shutting_down", "the daemon is shutting down")
                            : send_error(f, 503, "queue_full", "the frame queue is full; retry later");
        goto done;
    }
    obsd_fp_wait(&fp);
    obs_status s = obsd_fp_finished(&fp);
    f->ms_queue = fp.ms_queue;
    f->ms_gl = fp.ms_gl;
    if (s != OBS_OK) {
        rc = send_status(f, s, fp.job.err);
        goto done;
    }

    /* Raw float32 images, an EXR or a PNG.  Deep input answers AO.Y (the
     * blended AO), AOFront.Y (raw output OBS_BIN_OUTPUT_AO_FRONT) and the
     * composite. */
    obsd_fp_images im;
    obsd_fp_images_of(&fp, q->hr.outputs, &im);
    obs_bytes blob;
    s = obsd_fp_encode(&fp, &im, &q->hr, q->raw_out, obsd_fp_camera(&fp), &blob, err);
    f->ms_encode = fp.ms_encode;
    obs_bin_response_desc d = {.id = f->id, .status = 200, .code = "ok", .message = "",
                               .blob = blob.data, .blob_len = blob.size};
    obs_bin_image images[3];
    int n = 0;
    if (q->raw_out) {
        if (im.ao)
            images[n++] = (obs_bin_image){OBS_OUTPUT_AO, *im.ao};
        if (im.ao_front)
            images[n++] = (obs_bin_image){OBS_BIN_OUTPUT_AO_FRONT, *im.ao_front};
        if (im.composite)
            images[n++] = (obs_bin_image){OBS_OUTPUT_COMPOSITE, *im.composite};
        d.body = OBS_BIN_RAW;
        d.images = images;
        d.image_count = n;
    } else {
        d.body = q->hr.format == OBS_HTTP_EXR ? OBS_BIN_EXR : OBS_BIN_PNG;
    }
    rc = s == OBS_INVALID_ARGUMENT || s == OBS_UNSUPPORTED ? send_status(f, s, err)
         : s != OBS_OK                                      ? send_error(f, 500, "encode_failed", err)
                                                            : send_response(f, &d);
    obs_bytes_free(&blob);
done:
    obsd_fp_free(&fp);
    return rc;
}

/* What serve_one() leaves the connection to. */
enum { NEXT_FRAME, CLOSE, CLOSE_LINGER };

/* Reads the head of a `len`-byte payload into *buf (malloc'd, *got
 * bytes): as many bytes as obs_bin_request_head() asks for, no more.
 * -1 when the client stops sending (timeout or EOF). */
static int read_head(obsd_bin *b, int fd, size_t len, const obs_limits *lim, obs_bin_head *hd,
                     unsigned char **buf, size_t *got, obs_status *s, char err[OBS_ERR_LEN])
{
    size_t need = 0, cap = 0;
    *buf = NULL;
    *got = 0;
    for (;;) {
        *s = obs_bin_request_head(*buf, *got, len, lim, hd, &need, err);
        if (*s != OBS_OK || need == 0)
            return 0;
        if (need > cap) {
            size_t ncap = need < 4096 ? 4096 : need;
            ncap = ncap < len ? ncap : len;
            unsigned char *nb = realloc(*buf, ncap);
            if (!nb) {
                *s = OBS_NO_MEMORY;
                snprintf(err, OBS_ERR_LEN, "no memory for the frame's head");
                return 0;
            }
            *buf = nb;
            cap = ncap;
        }
        if (read_all(b, fd, *buf + *got, need - *got, 0) != 1)
            return -1;
        *got = need;
    }
}

/* Reads and drops n bytes.  0 done, -1 cut short. */
static int discard(obsd_bin *b, int fd, size_t n)
{
    unsigned char scratch[16384];
    while (n > 0) {
        size_t k = n < sizeof scratch ? n : sizeof scratch;
        if (read_all(b, fd, scratch, k, 0) != 1)
            return -1;
        n -= k;
    }
    return 0;
}

static int token_ok(const obsd_bin *b, const char *token)
{
    char auth[sizeof ((obs_bin_head *)0)->token + 8];
    snprintf(auth, sizeof auth, "Bearer %s", token);
    return obs_http_bearer_ok(auth, b->token);
}

/* Reads and answers one frame: the header, the head, the checks that
 * need no G-buffer (token, drain, sizes, queue), then the rest. */
static int serve_one(conn *c)
{
    obsd_bin *b = c->srv;
    unsigned char hdr[OBS_BIN_HEADER_LEN];
    char err[OBS_ERR_LEN] = "";
    int r = read_all(b, c->fd, hdr, sizeof hdr, 1);
    if (r <= 0) {
        if (r < 0)
            obsd_log(OBSD_LOG_INFO, "peer=%s binary: connection closed in a frame header (timeout, "
                     "or a short frame)", c->peer);
        return CLOSE;
    }
    frame f = {.c = c, .rid = atomic_fetch_add(&b->next_id, 1) + 1, .t0 = obsd_now_ms(),
               .bytes_in = sizeof hdr};
    obs_bin_header h;
    obs_status s = obs_bin_header_parse(hdr, &h, (uint64_t)b->cfg->max_body, err);
    f.id = h.id;
    if (s == OBS_OK && h.kind != OBS_BIN_REQUEST)
        s = OBS_BAD_FILE, snprintf(err, sizeof err, "a client sends requests (kind 1), not responses");
    if (s != OBS_OK) {
        /* the stream cannot be resynchronised: answer and close */
        if (s == OBS_TOO_LARGE)
            send_error(&f, 413, "body_too_large", err);
        else
            send_status(&f, s == OBS_UNSUPPORTED ? OBS_UNSUPPORTED : OBS_BAD_FILE, err);
        return CLOSE_LINGER;
    }
    if (atomic_load(&b->draining)) {
        send_error(&f, 503, "shutting_down", "the daemon is shutting down");
        return CLOSE_LINGER;
    }

    /* The head: nothing of the G-buffer is read before it is allowed. */
    obs_limits lim = {.max_pixels = (uint64_t)b->cfg->max_pixels};
    obs_bin_head hd;
    unsigned char *payload = NULL;
    size_t got = 0;
    if (read_head(b, c->fd, (size_t)h.length, &lim, &hd, &payload, &got, &s, err) != 0) {
        obsd_log(OBSD_LOG_INFO, "req=b%llu peer=%s binary: frame of %llu bytes cut short in its head "
                 "(timeout or connection closed)", (unsigned long long)f.rid, c->peer,
                 (unsigned long long)h.length);
        free(payload);
        return CLOSE;
    }
    f.bytes_in += got;
    int rc = 0;
    if (b->token && (!hd.params_done || !token_ok(b, hd.token)))
        rc = 1, send_error(&f, 401, "unauthorized", "missing or wrong token parameter");
    else if (s == OBS_TOO_LARGE || s == OBS_NO_MEMORY)
        rc = 1, send_status(&f, s, err);
    else if (s != OBS_OK) {
        /* a malformed frame within the limits: as before the head was read
         * apart, its bytes are taken (dropped, not kept), it is answered
         * and the connection goes on; cut short, it is closed unanswered */
        free(payload);
        if (discard(b, c->fd, (size_t)h.length - got) != 0) {
            obsd_log(OBSD_LOG_INFO, "req=b%llu peer=%s binary: frame of %llu bytes cut short (timeout "
                     "or connection closed)", (unsigned long long)f.rid, c->peer,
                     (unsigned long long)h.length);
            return CLOSE;
        }
        f.bytes_in = sizeof hdr + (size_t)h.length;
        return send_status(&f, s, err) == 0 ? NEXT_FRAME : CLOSE;
    } else if (atomic_load(&b->draining))
        rc = 1, send_error(&f, 503, "shutting_down", "the daemon is shutting down");
    else {
        int full = 0;
        obsd_queue_stats(b->queue, NULL, NULL, &full);
        if (full)
            rc = 1, send_error(&f, 503, "queue_full", "the frame queue is full; retry later");
    }
    if (rc) {
        /* refused from the head: the G-buffer stays unread */
        free(payload);
        return got < h.length ? CLOSE_LINGER : CLOSE;
    }

    /* The G-buffer: the whole payload, in one buffer, the head first. */
    if (h.length > got) {
        unsigned char *whole = realloc(payload, (size_t)h.length);
        if (!whole) {
            free(payload);
            send_status(&f, OBS_NO_MEMORY, "no memory for the frame");
            return CLOSE_LINGER;
        }
        payload = whole;
        if (read_all(b, c->fd, payload + got, (size_t)h.length - got, 0) != 1) {
            obsd_log(OBSD_LOG_INFO, "req=b%llu peer=%s binary: frame of %llu bytes cut short (timeout "
                     "or connection closed)", (unsigned long long)f.rid, c->peer,
                     (unsigned long long)h.length);
            free(payload);
            return CLOSE;
        }
    }
    f.bytes_in = sizeof hdr + (size_t)h.length;
    obs_bin_request q;
    double t0 = obsd_now_ms();
    s = obs_bin_request_decode(payload, (size_t)h.length, &lim, &q, err);
    f.ms_decode = obsd_now_ms() - t0;
    if (s != OBS_OK)
        rc = send_status(&f, s, err);
    else
        rc = run_frame(&f, &q);
    obs_bin_request_free(&q);
    free(payload);
    return rc != 0 || f.close_after ? CLOSE : NEXT_FRAME;
}

static void conn_main_end(conn *c)
{
    obsd_bin *b = c->srv;
    pthread_mutex_lock(&b->lock);
    if (c->prev)
        c->prev->next = c->next;
    else
        b->conns = c->next;
    if (c->next)
        c->next->prev = c->prev;
    pthread_mutex_unlock(&b->lock);
}

static void *conn_main(void *arg)
{
    conn *c = arg;
    obsd_bin *b = c->srv;
    int r;
    while ((r = serve_one(c)) == NEXT_FRAME)
        ;
    if (r == CLOSE_LINGER)
        linger(c->fd); /* in the list still: obsd_bin_cut() ends it */
    /* out of the list before the close: obsd_bin_cut() never shuts a
     * closed (or reused) fd */
    conn_main_end(c);
    close(c->fd);
    free(c);
    atomic_fetch_sub(&b->connections, 1);
    return NULL;
}

/* ---- listeners ------------------------------------------------------------ */

/* The peer for the log, and the address max_per_client counts. */
static void describe_peer(const struct sockaddr_storage *ss, conn *c)
{
    char ip[INET6_ADDRSTRLEN] = "?";
    if (ss->ss_family == AF_INET) {
        const struct sockaddr_in *in = (const struct sockaddr_in *)(const void *)ss;
        inet_ntop(AF_INET, &in->sin_addr, ip, sizeof ip);
        snprintf(c->peer, sizeof c->peer, "%s:%u", ip, ntohs(in->sin_port));
        snprintf(c->addr, sizeof c->addr, "%s", ip);
    } else if (ss->ss_family == AF_INET6) {
        const struct sockaddr_in6 *in6 = (const struct sockaddr_in6 *)(const void *)ss;
        if (IN6_IS_ADDR_V4MAPPED(&in6->sin6_addr)) {
            /* an IPv4 client of a dual-stack [::] listener: its IPv4 address */
            inet_ntop(AF_INET, in6->sin6_addr.s6_addr + 12, ip, sizeof ip);
            snprintf(c->peer, sizeof c->peer, "%s:%u", ip, ntohs(in6->sin6_port));
        } else {
            inet_ntop(AF_INET6, &in6->sin6_addr, ip, sizeof ip);
            snprintf(c->peer, sizeof c->peer, "[%s]:%u", ip, ntohs(in6->sin6_port));
        }
        snprintf(c->addr, sizeof c->addr, "%s", ip);
    } else {
        snprintf(c->peer, sizeof c->peer, "unix");
        snprintf(c->addr, sizeof c->addr, "unix");
    }
}

static void refused_drop(obsd_bin *b, int i)
{
    close(b->refused[i].fd);
    b->refused[i] = b->refused[--b->nrefused];
}

/* Answers a connection over a limit (503 too_many_connections, id 0: it
 * has sent no frame yet), then lingers it in the accept thread. */
static void refuse(obsd_bin *b, int fd, const conn *c, const char *why)
{
    char msg[160];
    snprintf(msg, sizeof msg, "too many connections: %s; retry later", why);
    obs_bin_response_desc d = {.id = 0, .status = 503, .retry_after = 1, .code = "too_many_connections",
                               .message = msg, .body = OBS_BIN_NONE};
    obs_bytes out;
    char err[OBS_ERR_LEN];
    size_t sent = 0;
    if (obs_bin_response_encode(&d, &out, err) == OBS_OK) {
        /* a fresh socket's buffer takes these few bytes at once */
        ssize_t n = send(fd, out.data, out.size, MSG_NOSIGNAL | MSG_DONTWAIT);
        sent = n > 0 ? (size_t)n : 0;
        obs_bytes_free(&out);
    }
    obsd_stats_request(OBSD_STATS_BINARY, 503, 0, sent);
    b->refused_total++;
    double now = obsd_now_ms();
    if (now - b->refused_logged >= 1000) {
        /* at most a line a second, whatever a flood of clients does */
        obsd_log(OBSD_LOG_WARN, "peer=%s binary: refusing a connection: %s (%lu refused so far)", c->peer,
                 why, b->refused_total);
        b->refused_logged = now;
    }
    shutdown(fd, SHUT_WR);
    if (b->nrefused == REFUSED_MAX) {
        int oldest = 0;
        for (int i = 1; i < b->nrefused; i++)
            if (b->refused[i].until < b->refused[oldest].until)
                oldest = i;
        refused_drop(b, oldest);
    }
    b->refused[b->nrefused++] = (refused){fd, now + LINGER_MS, 0};
}

/* What refused connections send: read and dropped; closed on EOF, after
 * LINGER_MS or LINGER_BYTES. */
static void refused_poll(obsd_bin *b, const struct pollfd *p, int n)
{
    char scratch[4096];
    double now = obsd_now_ms();
    for (int i = n - 1; i >= 0; i--) {
        refused *r = &b->refused[i];
        int done = now >= r->until || r->dropped >= LINGER_BYTES;
        if (!done && (p[i].revents & (POLLIN | POLLHUP | POLLERR))) {
            ssize_t k = recv(r->fd, scratch, sizeof scratch, MSG_DONTWAIT);
            if (k > 0)
                r->dropped += (size_t)k;
            else if (k == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR))
                done = 1;
        }
        if (done)
            refused_drop(b, i);
    }
}

static void accept_one(obsd_bin *b, int lfd)
{
    struct sockaddr_storage ss;
    socklen_t sl = sizeof ss;
    int fd = accept(lfd, (struct sockaddr *)&ss, &sl);
    if (fd < 0)
        return;
    /* every wait is a poll() with a deadline: send() and recv() never block */
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    fcntl(fd, F_SETFD, FD_CLOEXEC);
    conn *c = calloc(1, sizeof *c);
    if (!c) {
        close(fd);
        return;
    }
    c->srv = b;
    c->fd = fd;
    describe_peer(&ss, c);
    if (ss.ss_family != AF_UNIX) {
        int one = 1;
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    }
    char why[128] = "";
    int open_now = 0, same = 0;
    pthread_mutex_lock(&b->lock);
    for (const conn *o = b->conns; o; o = o->next) {
        open_now++;
        same += !strcmp(o->addr, c->addr);
    }
    if (open_now >= b->cfg->bin_connections)
        snprintf(why, sizeof why, "%d open (bin_connections)", open_now);
    else if (b->cfg->max_per_client > 0 && same >= b->cfg->max_per_client)
        snprintf(why, sizeof why, "%d open from %s (max_per_client)", same, c->addr);
    else {
        c->next = b->conns;
        if (b->conns)
            b->conns->prev = c;
        b->conns = c;
        atomic_fetch_add(&b->connections, 1);
    }
    pthread_mutex_unlock(&b->lock);
    if (why[0]) {
        refuse(b, fd, c, why);
        free(c);
        return;
    }
    pthread_attr_t attr;
    pthread_t t;
    pthread_attr_init(&attr);
    pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
    if (pthread_create(&t, &attr, conn_main, c) != 0) {
        conn_main_end(c);
        atomic_fetch_sub(&b->connections, 1);
        close(fd);
        free(c);
    }
    pthread_attr_destroy(&attr);
}

static void *accept_main(void *arg)
{
    obsd_bin *b = arg;
    while (!atomic_load(&b->draining)) {
        struct pollfd p[2 + REFUSED_MAX];
        int n = 0, nr = b->nrefused;
        for (int i = 0; i < nr; i++)
            p[n++] = (struct pollfd){b->refused[i].fd, POLLIN, 0};
        int lst = n;
        if (b->unix_fd >= 0)
            p[n++] = (struct pollfd){b->unix_fd, POLLIN, 0};
        if (b->tcp_fd >= 0)
            p[n++] = (struct pollfd){b->tcp_fd, POLLIN, 0};
        int rc = poll(p, (nfds_t)n, nr ? 50 : TICK_MS);
        if (nr)
            refused_poll(b, p, nr);
        if (rc <= 0)
            continue;
        for (int i = lst; i < n; i++)
            if (p[i].revents & POLLIN)
                accept_one(b, p[i].fd);
    }
    while (b->nrefused > 0)
        refused_drop(b, b->nrefused - 1);
    return NULL;
}

static int listen_unix(const char *path, char err[OBS_ERR_LEN])
{
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    if (strlen(path) >= sizeof sa.sun_path) {
        snprintf(err, OBS_ERR_LEN, "--socket %s: path longer than %zu bytes", path,
                 sizeof sa.sun_path - 1);
        return -1;
    }
    memcpy(sa.sun_path, path, strlen(path) + 1);
    struct stat st;
    if (lstat(path, &st) == 0) {
        /* a socket left by a daemon that died may go; a live one, or
         * anything that is not a socket, stays */
        int probe = socket(AF_UNIX, SOCK_STREAM, 0);
        int live = probe >= 0 && connect(probe, (struct sockaddr *)&sa, sizeof sa) == 0;
        if (probe >= 0)
            close(probe);
        if (!S_ISSOCK(st.st_mode) || live) {
            snprintf(err, OBS_ERR_LEN, "--socket %s: %s", path,
                     live ? "another daemon listens there" : "exists and is not a socket");
            return -1;
        }
        unlink(path);
    }
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0 || listen(fd, 64) != 0) {
        snprintf(err, OBS_ERR_LEN, "--socket %s: %s", path, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    return fd;
}

/* "HOST:PORT" (IPv4), "[HOST]:PORT" (IPv6) or "PORT" (host 127.0.0.1). */
static int listen_tcp(const char *s, int *port_out, char err[OBS_ERR_LEN])
{
    char host[64] = "127.0.0.1";
    const char *ps = s;
    int v6 = 0;
    if (s[0] == '[') {
        const char *end = strchr(s, ']');
        if (!end || end[1] != ':' || end == s + 1 || (size_t)(end - s - 1) >= sizeof host)
            goto bad;
        snprintf(host, sizeof host, "%.*s", (int)(end - s - 1), s + 1);
        ps = end + 2;
        v6 = 1;
    } else {
        const char *colon = strrchr(s, ':');
        if (colon) {
            if ((size_t)(colon - s) >= sizeof host || memchr(s, ':', (size_t)(colon - s)))
                goto bad; /* an IPv6 address needs its brackets */
            if (colon > s)
                snprintf(host, sizeof host, "%.*s", (int)(colon - s), s);
            ps = colon + 1;
        }
    }
    char *end;
    long port = strtol(ps, &end, 10);
    struct sockaddr_storage ss;
    socklen_t sl;
    memset(&ss, 0, sizeof ss);
    if (!*ps || *end || port < 0 || port > 65535)
        goto bad;
    if (v6) {
        struct sockaddr_in6 *a = (struct sockaddr_in6 *)(void *)&ss;
        a->sin6_family = AF_INET6;
        a->sin6_port = htons((uint16_t)port);
        if (inet_pton(AF_INET6, host, &a->sin6_addr) != 1)
            goto bad;
        sl = sizeof *a;
    } else {
        struct sockaddr_in *a = (struct sockaddr_in *)(void *)&ss;
        a->sin_family = AF_INET;
        a->sin_port = htons((uint16_t)port);
        if (inet_pton(AF_INET, host, &a->sin_addr) != 1)
            goto bad;
        sl = sizeof *a;
    }
    int fd = socket(ss.ss_family, SOCK_STREAM | SOCK_CLOEXEC, 0), one = 1;
    if (fd >= 0)
        setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (fd < 0 || bind(fd, (struct sockaddr *)&ss, sl) != 0 || listen(fd, 64) != 0) {
        snprintf(err, OBS_ERR_LEN, "--tcp %s: %s", s, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    getsockname(fd, (struct sockaddr *)&ss, &sl);
    *port_out = ntohs(v6 ? ((struct sockaddr_in6 *)(void *)&ss)->sin6_port
                         : ((struct sockaddr_in *)(void *)&ss)->sin_port);
    return fd;
bad:
    snprintf(err, OBS_ERR_LEN, "--tcp '%s' is not [HOST:]PORT (an IPv4 host, or an IPv6 one in brackets: "
             "[::1]:PORT) with a port in 0..65535", s);
    return -1;
}

obs_status obsd_bin_start(const obsd_config *cfg, const char *token, obsd_queue *q,
                          obsd_gl_worker *gl, obsd_bin **out, char err[OBS_ERR_LEN])
{
    obsd_bin *b = calloc(1, sizeof *b);
    if (!b)
        return OBS_NO_MEMORY;
    b->cfg = cfg;
    b->token = token && *token ? token : NULL;
    b->queue = q;
    b->gl = gl;
    b->unix_fd = b->tcp_fd = -1;
    atomic_init(&b->draining, 0);
    atomic_init(&b->connections, 0);
    atomic_init(&b->next_id, 0);
    pthread_mutex_init(&b->lock, NULL);
    if (cfg->socket[0] && (b->unix_fd = listen_unix(cfg->socket, err)) < 0)
        goto fail;
    if (cfg->tcp[0] && (b->tcp_fd = listen_tcp(cfg->tcp, &b->tcp_port, err)) < 0)
        goto fail;
    if (pthread_create(&b->acceptor, NULL, accept_main, b) != 0) {
        snprintf(err, OBS_ERR_LEN, "cannot start the binary-protocol thread");
        goto fail;
    }
    b->accepting = 1;
    *out = b;
    return OBS_OK;
fail:
    if (b->unix_fd >= 0) {
        close(b->unix_fd);
        unlink(cfg->socket);
    }
    if (b->tcp_fd >= 0)
        close(b->tcp_fd);
    pthread_mutex_destroy(&b->lock);
    free(b);
    return OBS_IO;
}

int obsd_bin_tcp_port(const obsd_bin *b) { return b ? b->tcp_port : 0; }

void obsd_bin_quiesce(obsd_bin *b)
{
    if (!b)
        return;
    atomic_store(&b->draining, 1);
    if (b->accepting) {
        pthread_join(b->acceptor, NULL);
        b->accepting = 0;
    }
    if (b->unix_fd >= 0) {
        close(b->unix_fd);
        unlink(b->cfg->socket);
        b->unix_fd = -1;
    }
    if (b->tcp_fd >= 0) {
        close(b->tcp_fd);
        b->tcp_fd = -1;
    }
}

int obsd_bin_in_flight(obsd_bin *b) { return b ? atomic_load(&b->connections) : 0; }

int obsd_bin_cut(obsd_bin *b)
{
    if (!b)
        return 0;
    int n = 0;
    pthread_mutex_lock(&b->lock);
    for (conn *c = b->conns; c; c = c->next, n++)
        shutdown(c->fd, SHUT_RDWR); /* its thread's next recv/send fails, its poll wakes */
    pthread_mutex_unlock(&b->lock);
    if (n)
        obsd_log(OBSD_LOG_WARN, "binary: cut %d connection(s) still open", n);
    return n;
}

void obsd_bin_stop(obsd_bin *b)
{
    if (!b)
        return;
    obsd_bin_quiesce(b);
    obsd_bin_cut(b);
    /* each thread ends at its next wait; one with a frame on the GL worker
     * when that frame is finished */
    while (atomic_load(&b->connections) > 0) {
        struct timespec ts = {0, 10 * 1000000L};
        nanosleep(&ts, NULL);
    }
    pthread_mutex_destroy(&b->lock);
    free(b);
}
