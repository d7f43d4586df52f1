/* One binary-protocol connection (protocol/PROTOCOL.md): its thread's
 * loop, frame after frame, on a non-blocking socket.
 *
 *   a frame    read a header (idle --timeout), check it; read the
 *              request's head (its parameters and the G-buffer's fixed
 *              fields, obs_bin_request_head) and check the token, the
 *              drain, the sizes and the queue before a byte of the
 *              G-buffer is read (a refusal is answered and the connection
 *              closed: the stream cannot be resynchronised); read the
 *              rest, decode the request, then the frame path
 *              (frame_path.c: the EXR, the GL worker, the encode),
 *              answer; then the next frame.  Answers go in request
 *              order.  A send that makes no progress for --timeout
 *              seconds gives up and closes.
 *   drain      a frame that comes is answered 503 shutting_down and the
 *              connection closed; the frame under way is answered.
 *
 * The listeners, the limits and the drain's cut are binary_server.c's. */
#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "binary.h"
#include "binary_internal.h"
#include "list.h"
#include "frame_path.h"
#include "log.h"
#include "stats.h"

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
    const int timeout = b->front.cfg->timeout;
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
    const int timeout = b->front.cfg->timeout;
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
    double ms_receive, ms_send; /* the payload's arrival after its header; the answer's write */
    int status;
    int close_after; /* answered shutting_down: no frame follows */
    char note[OBS_ERR_LEN + 96];
} frame;

static void log_frame(const frame *f)
{
    obsd_stats_request(OBSD_STATS_BINARY, f->status, f->bytes_in, f->bytes_out);
    if (f->status == 200) {
        obsd_stats_stage(OBSD_STAGE_TOTAL, obsd_now_ms() - f->t0);
        obsd_stats_stage(OBSD_STAGE_SEND, f->ms_send);
    }
    if (!obsd_log_enabled(OBSD_LOG_INFO))
        return;
    /* receive= and send= after encode=, as HTTP's line has receive= */
    obsd_log(OBSD_LOG_INFO,
             "req=b%llu peer=%s BINARY id=%llu status=%d in=%zu out=%zu queue=%.1f decode=%.1f "
             "gl=%.1f encode=%.1f receive=%.1f send=%.1f total=%.1f ms%s%s", (unsigned long long)f->rid,
             f->c->peer, (unsigned long long)f->id, f->status, f->bytes_in, f->bytes_out, f->ms_queue,
             f->ms_decode, f->ms_gl, f->ms_encode, f->ms_receive, f->ms_send, obsd_now_ms() - f->t0,
             f->note[0] ? " " : "", f->note);
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
    double t0 = obsd_now_ms();
    int rc = write_all(f->c->srv, f->c->fd, out.data, out.size);
    f->ms_send = obsd_now_ms() - t0;
    obs_bytes_free(&out);
    if (d->status != 200)
        snprintf(f->note, sizeof f->note, "error=%s: %s", d->code, d->message);
    if (rc == -2)
        snprintf(f->note + strlen(f->note), sizeof f->note - strlen(f->note),
                 "%s(no byte of the answer went for %d s: the client does not read; gave up, closed)",
                 f->note[0] ? " " : "", f->c->srv->front.cfg->timeout);
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
    obsd_stats_error_answer(status, code, f->c->peer, msg); /* over a limit: counted by reason */
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
    obs_limits lim = {.max_pixels = (uint64_t)b->front.cfg->max_pixels};
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
        obsd_fp_queue(&fp, b->front.queue, &q->hr.params, q->hr.outputs, NULL, NULL) != 0) {
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
    /* the input's sanity warnings and the result's, as HTTP's
     * X-Obscura-Warning headers: the 200's message, one a line */
    const char *said[OBS_EXR_WARNINGS];
    for (int i = 0; i < fp.gf.info.warning_count; i++)
        said[i] = fp.gf.info.warnings[i];
    obs_bin_response_desc d = {.id = f->id, .status = 200, .code = "ok", .message = "",
                               .warnings = said, .warning_count = fp.gf.info.warning_count,
                               .blob = blob.data, .blob_len = blob.size};
    /* the raw images, in the order the answer carries them */
    const struct {
        unsigned output;
        const obs_image *image;
    } raw[] = {{OBS_OUTPUT_AO, im.ao},
               {OBS_BIN_OUTPUT_AO_FRONT, im.ao_front},
               {OBS_OUTPUT_COMPOSITE, im.composite},
               {OBS_OUTPUT_MULTIBOUNCE, im.multibounce},
               {OBS_OUTPUT_SAMPLE_COUNT, im.samples},
               {OBS_OUTPUT_BENT, im.bent}};
    obs_bin_image images[sizeof raw / sizeof raw[0]];
    int n = 0;
    if (q->raw_out) {
        for (size_t i = 0; i < sizeof raw / sizeof raw[0]; i++)
            if (raw[i].image)
                images[n++] = (obs_bin_image){raw[i].output, *raw[i].image};
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
    return obs_http_bearer_ok(auth, b->front.token);
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
    obs_status s = obs_bin_header_parse(hdr, &h, (uint64_t)b->front.cfg->max_body, err);
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
    obs_limits lim = {.max_pixels = (uint64_t)b->front.cfg->max_pixels};
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
    if (b->front.token && (!hd.params_done || !token_ok(b, hd.token)))
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
        obsd_queue_stats(b->front.queue, NULL, NULL, &full);
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
    f.ms_receive = obsd_now_ms() - f.t0;
    obsd_stats_stage(OBSD_STAGE_RECEIVE, f.ms_receive);
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

void obsd__bin_conn_unlink(conn *c)
{
    obsd_bin *b = c->srv;
    pthread_mutex_lock(&b->lock);
    OBSD_LIST_UNLINK(b->conns, c);
    pthread_mutex_unlock(&b->lock);
}

void *obsd__bin_conn_main(void *arg)
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
    obsd__bin_conn_unlink(c);
    close(c->fd);
    free(c);
    atomic_fetch_sub(&b->connections, 1);
    return NULL;
}
