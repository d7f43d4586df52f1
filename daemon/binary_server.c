/* The binary protocol's listeners and connections.
 *
 *   accept thread   poll() on the Unix and TCP listeners (200 ms ticks, so
 *                   it sees the drain), a detached thread per connection
 *   connection      read a header (idle --timeout), check it, read the
 *                   payload (a bad size is answered and the connection
 *                   closed: the stream cannot be resynchronised), decode
 *                   the request, then the frame path (frame_path.c: the
 *                   EXR, the GL worker, the encode), answer; then the
 *                   next frame.  Answers go in request order. */
#include <arpa/inet.h>
#include <errno.h>
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

#define MAX_CONNECTIONS 256
#define TICK_MS 200

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
};

typedef struct conn {
    obsd_bin *srv;
    int fd;
    char peer[80];
} conn;

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

static int write_all(obsd_bin *b, int fd, const void *buf, size_t len)
{
    const int timeout = b->cfg->timeout;
    double deadline = timeout ? obsd_now_ms() + timeout * 1000.0 : 0;
    size_t put = 0;
    while (put < len) {
        if (wait_fd(b, fd, POLLOUT, deadline, 0) <= 0)
            return -1;
        ssize_t n = send(fd, (const char *)buf + put, len - put, MSG_NOSIGNAL);
        if (n < 0) {
            if (errno == EINTR || errno == EAGAIN)
                continue;
            return -1;
        }
        put += (size_t)n;
    }
    return 0;
}

/* ---- one frame ------------------------------------------------------------ */

typedef struct frame {
    conn *c;
    uint64_t id, rid;
    double t0;
    size_t bytes_in, bytes_out;
    double ms_decode, ms_queue, ms_gl, ms_encode;
    int status;
    const char *code;
    char note[OBS_ERR_LEN + 64];
} frame;

static void log_frame(const frame *f)
{
    obsd_stats_request(OBSD_ROUTE_BINARY, f->status, f->bytes_in, f->bytes_out);
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
    if (rc != 0)
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
        obs_status s = obsd_fp_decode(&fp, q->exr, q->exr_len, &q->hr.map, &lim, NULL, err);
        f->ms_decode = fp.ms_decode;
        if (s != OBS_OK) {
            rc = send_status(f, s, err);
            goto done;
        }
    } else {
        obsd_fp_use(&fp, &q->gf.gb, q->body == OBS_BIN_DEEP ? &q->deep : NULL);
    }
    if (obsd_fp_queue(&fp, b->queue, &q->hr.params, q->hr.outputs, NULL, NULL) != 0) {
        rc = send_error(f, 503, atomic_load(&b->draining) ? "shutting_down" : "queue_full",
                        "the frame queue is full; retry later");
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
    rc = s != OBS_OK ? send_error(f, 500, "encode_failed", err) : send_response(f, &d);
    obs_bytes_free(&blob);
done:
    obsd_fp_free(&fp);
    return rc;
}

/* Reads and answers one frame.  1: go on, 0: close (EOF, drain, bad
 * framing, I/O error). */
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
        return 0;
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
        return 0;
    }
    unsigned char *payload = h.length ? malloc((size_t)h.length) : NULL;
    if (h.length && !payload) {
        send_status(&f, OBS_NO_MEMORY, "no memory for the frame");
        return 0;
    }
    if (read_all(b, c->fd, payload, (size_t)h.length, 0) != 1) {
        obsd_log(OBSD_LOG_INFO, "req=b%llu peer=%s binary: frame of %llu bytes cut short (timeout "
                 "or connection closed)", (unsigned long long)f.rid, c->peer,
                 (unsigned long long)h.length);
        free(payload);
        return 0;
    }
    f.bytes_in += (size_t)h.length;
    obs_bin_request q;
    obs_limits lim = {.max_pixels = (uint64_t)b->cfg->max_pixels};
    double t0 = obsd_now_ms();
    s = obs_bin_request_decode(payload, (size_t)h.length, &lim, &q, err);
    f.ms_decode = obsd_now_ms() - t0;
    int rc;
    if (s != OBS_OK) {
        rc = send_status(&f, s, err);
    } else if (b->token) {
        char auth[sizeof q.token + 8];
        snprintf(auth, sizeof auth, "Bearer %s", q.token);
        rc = obs_http_bearer_ok(auth, b->token) ? run_frame(&f, &q)
                                                 : send_error(&f, 401, "unauthorized",
                                                              "missing or wrong token parameter");
    } else if (atomic_load(&b->draining)) {
        rc = send_error(&f, 503, "shutting_down", "the daemon is shutting down");
    } else {
        rc = run_frame(&f, &q);
    }
    obs_bin_request_free(&q);
    free(payload);
    return rc == 0;
}

static void *conn_main(void *arg)
{
    conn *c = arg;
    obsd_bin *b = c->srv;
    while (serve_one(c))
        ;
    close(c->fd);
    free(c);
    atomic_fetch_sub(&b->connections, 1);
    return NULL;
}

/* ---- listeners ------------------------------------------------------------ */

static void accept_one(obsd_bin *b, int lfd)
{
    struct sockaddr_storage ss;
    socklen_t sl = sizeof ss;
    int fd = accept(lfd, (struct sockaddr *)&ss, &sl);
    if (fd < 0)
        return;
    if (atomic_load(&b->connections) >= MAX_CONNECTIONS) {
        obsd_log(OBSD_LOG_WARN, "binary: %d connections open; refusing one", MAX_CONNECTIONS);
        close(fd);
        return;
    }
    conn *c = calloc(1, sizeof *c);
    if (!c) {
        close(fd);
        return;
    }
    c->srv = b;
    c->fd = fd;
    if (ss.ss_family == AF_INET) {
        const struct sockaddr_in *in = (const struct sockaddr_in *)(const void *)&ss;
        char ip[INET_ADDRSTRLEN] = "?";
        inet_ntop(AF_INET, &in->sin_addr, ip, sizeof ip);
        snprintf(c->peer, sizeof c->peer, "%s:%u", ip, ntohs(in->sin_port));
        int one = 1;
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    } else {
        snprintf(c->peer, sizeof c->peer, "unix");
    }
    atomic_fetch_add(&b->connections, 1);
    pthread_attr_t attr;
    pthread_t t;
    pthread_attr_init(&attr);
    pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
    if (pthread_create(&t, &attr, conn_main, c) != 0) {
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
        struct pollfd p[2];
        int n = 0;
        if (b->unix_fd >= 0)
            p[n++] = (struct pollfd){b->unix_fd, POLLIN, 0};
        if (b->tcp_fd >= 0)
            p[n++] = (struct pollfd){b->tcp_fd, POLLIN, 0};
        if (poll(p, (nfds_t)n, TICK_MS) <= 0)
            continue;
        for (int i = 0; i < n; i++)
            if (p[i].revents & POLLIN)
                accept_one(b, p[i].fd);
    }
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

/* "HOST:PORT" or "PORT" (host 127.0.0.1), IPv4. */
static int listen_tcp(const char *s, int *port_out, char err[OBS_ERR_LEN])
{
    const char *colon = strrchr(s, ':');
    char host[64] = "127.0.0.1";
    const char *ps = s;
    if (colon) {
        if ((size_t)(colon - s) >= sizeof host)
            goto bad;
        if (colon > s)
            snprintf(host, sizeof host, "%.*s", (int)(colon - s), s);
        ps = colon + 1;
    }
    char *end;
    long port = strtol(ps, &end, 10);
    struct sockaddr_in sa = {.sin_family = AF_INET};
    if (!*ps || *end || port < 0 || port > 65535 || inet_pton(AF_INET, host, &sa.sin_addr) != 1)
        goto bad;
    sa.sin_port = htons((uint16_t)port);
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0), one = 1;
    if (fd >= 0)
        setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (fd < 0 || bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0 || listen(fd, 64) != 0) {
        snprintf(err, OBS_ERR_LEN, "--tcp %s: %s", s, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    socklen_t sl = sizeof sa;
    getsockname(fd, (struct sockaddr *)&sa, &sl);
    *port_out = ntohs(sa.sin_port);
    return fd;
bad:
    snprintf(err, OBS_ERR_LEN, "--tcp '%s' is not [IPv4-HOST:]PORT with a port in 0..65535", s);
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

void obsd_bin_stop(obsd_bin *b)
{
    if (!b)
        return;
    obsd_bin_quiesce(b);
    while (atomic_load(&b->connections) > 0) {
        struct timespec ts = {0, 10 * 1000000L};
        nanosleep(&ts, NULL);
    }
    free(b);
}
