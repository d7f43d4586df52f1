/* The HTTP side of a frame, POST /v1/ao and the streams' frames: the
 * query, the body, then the frame path (frame_path.c) with the
 * connection suspended while the GL worker has the job.
 *
 *   first call    query parameters, Content-Type, Content-Length (413
 *                 before any of the body is read), a full queue (503)
 *   body calls    append, 413 when it grows over --max-body
 *   last call     decode the EXR here (a network thread), suspend the
 *                 connection, queue the frame (503 when full)
 *   resumed       the GL worker is done: encode here, answer */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "http_internal.h"
#include "log.h"

typedef obsd__req req;

static int record_pair(req *r, const char *key, const char *value)
{
    obsd__frame_req *fr = r->fr;
    size_t kl = strlen(key) + 1, vl = strlen(value) + 1;
    if (fr->query_len + kl + vl > fr->query_cap) {
        size_t cap = (fr->query_cap ? fr->query_cap * 2 : 256) + kl + vl;
        char *p = realloc(fr->query, cap);
        if (!p)
            return -1;
        fr->query = p;
        fr->query_cap = cap;
    }
    memcpy(fr->query + fr->query_len, key, kl);
    memcpy(fr->query + fr->query_len + kl, value, vl);
    fr->query_len += kl + vl;
    return 0;
}

static int name_is(const char *name, const char *want)
{
    for (; *name && *want; name++, want++)
        if ((*name == '-' ? '_' : *name) != *want)
            return 0;
    return *name == *want;
}

/* One query argument of a frame's request (obsd__query_args). */
static obs_status frame_arg(req *r, const char *key, const char *value, char err[OBS_ERR_LEN])
{
    obsd__frame_req *fr = r->fr;
    if (fr->view) {
        /* a stored frame: the view options, and anything else re-runs it */
        if (name_is(key, "exposure")) {
            char *end;
            double ev = strtod(value, &end);
            if (end == value || *end || !(ev >= -20.0 && ev <= 20.0)) {
                snprintf(err, OBS_ERR_LEN, "parameter exposure: '%.100s' is not a number in [-20, 20] "
                         "(stops)", value);
                return OBS_INVALID_ARGUMENT;
            }
            fr->exposure = ev;
            return OBS_OK;
        }
        if (name_is(key, "output") && (!strcmp(value, "color") || !strcmp(value, "ao_front"))) {
            fr->want_color = value[0] == 'c';
            fr->want_front = value[0] == 'a';
            return OBS_OK;
        }
        if (name_is(key, "output"))
            fr->want_color = fr->want_front = 0;
        else if (!name_is(key, "format") && !name_is(key, "float") && !name_is(key, "compression") &&
                 !name_is(key, "png_bits") &&
                 !name_is(key, "png_transfer"))
            fr->rerun = 1;
    }
    obs_status s = obs_http_request_set(&fr->hr, key, value, err);
    if (s == OBS_OK && fr->kept && record_pair(r, key, value) != 0) {
        snprintf(err, OBS_ERR_LEN, "no memory for the query");
        s = OBS_NO_MEMORY;
    }
    return s;
}

int obsd__parse_query(req *r, enum MHD_Result *rc)
{
    obsd__frame_req *fr = r->fr;
    char err[OBS_ERR_LEN];
    obs_status s = obsd__query_args(r, frame_arg, err);
    if (s == OBS_OK)
        s = obs_http_request_check(&fr->hr, err);
    if (s == OBS_OK)
        return 1;
    *rc = s == OBS_INVALID_ARGUMENT ? obsd__answer_error(r, 400, "bad_parameter", err, NULL, NULL)
                                    : obsd__answer_status(r, s, err);
    return 0;
}

/* Called on the GL worker thread: give the connection back to MHD;
 * after the drain's cut, leave it, or free the request when its
 * connection is gone already (nothing of the server is touched then: it
 * may have stopped). */
static void job_done(void *user)
{
    req *r = user;
    for (;;) {
        int s = atomic_load(&r->job);
        if (s == JOB_PENDING) {
            /* Claimed, then resumed: once resumed, the request may be
             * answered and freed at once, so nothing of it after. */
            if (atomic_compare_exchange_strong(&r->job, &s, JOB_DONE)) {
                MHD_resume_connection(r->conn);
                return;
            }
        } else if (s == JOB_CUT) {
            if (atomic_compare_exchange_strong(&r->job, &s, JOB_CUT_DONE))
                return;
        } else {
            if (s == JOB_ORPHAN)
                obsd__req_free(r);
            return;
        }
    }
}

obsd__frame_req *obsd__frame_req_new(req *r)
{
    if (r->fr)
        return r->fr;
    if (!(r->fr = calloc(1, sizeof *r->fr)))
        return NULL;
    obsd_fp_init(&r->fr->fp);
    obs_http_request_init(&r->fr->hr);
    return r->fr;
}

enum MHD_Result obsd__frame_start(req *r, const char *url)
{
    obsd_http *h = r->srv;
    obsd__frame_req *fr = obsd__frame_req_new(r);
    const char *v;
    enum MHD_Result rc;
    (void)url;
    if (!fr)
        return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the request");
    fr->before_drain = !atomic_load(&h->draining);
    if (!fr->before_drain)
        return obsd__answer_shutting_down(r);
    obs_http_request_init(&fr->hr);
    if (!obsd__parse_query(r, &rc))
        return rc;
    v = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_TYPE);
    if (v && strncmp(v, "image/x-exr", 11) != 0 && strncmp(v, "application/octet-stream", 24) != 0)
        return obsd__answer_error(r, 415, "unsupported_media_type",
                            "the body must be a G-buffer EXR (Content-Type: image/x-exr)", NULL, NULL);
    if (!obsd__body_expect(r, (size_t)h->front.cfg->max_body, "body", "--max-body", 1, &rc))
        return rc;
    /* Refuse early when the queue is already full: no need for the body. */
    int full;
    obsd_queue_stats(h->front.queue, NULL, NULL, &full);
    if (full)
        return obsd__answer_error(r, 503, "queue_full", "the frame queue is full; retry later",
                            MHD_HTTP_HEADER_RETRY_AFTER, "1");
    r->state = REQ_BODY;
    return MHD_YES;
}

int obsd__body_expect(req *r, size_t max, const char *what, const char *flag, int keep, enum MHD_Result *rc)
{
    const char *v = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
    if (!v)
        return 1;
    char *end, msg[160];
    errno = 0;
    unsigned long long n = strtoull(v, &end, 10);
    if (errno == ERANGE || n > (unsigned long long)max) {
        r->body_in = 0; /* not held: the client waits for 100 Continue, or sends more than we would read */
        snprintf(msg, sizeof msg, "%s of %s bytes is over the limit of %lld bytes (%s)", what, v,
                 (long long)max, flag);
        *rc = obsd__answer_error(r, 413, "body_too_large", msg, NULL, NULL);
        return 0;
    }
    /* Sized by the claim, which is within the limit; grows if it lied. */
    r->cap = keep ? (size_t)n : 0;
    if (r->cap && !(r->body = malloc(r->cap))) {
        snprintf(msg, sizeof msg, "no memory for the %s", what);
        *rc = obsd__answer_status(r, OBS_NO_MEMORY, msg);
        return 0;
    }
    return 1;
}

int obsd__reserve(unsigned char **buf, size_t *cap, size_t need, size_t max)
{
    if (need <= *cap)
        return 0;
    size_t c = *cap ? *cap : 1 << 16;
    while (c < need)
        c = c > max / 2 ? (max > need ? max : need) : c * 2;
    unsigned char *p = realloc(*buf, c);
    if (!p)
        return -1;
    *buf = p;
    *cap = c;
    return 0;
}

enum MHD_Result obsd__discard_body(req *r, size_t n, size_t max)
{
    r->discarded += n;
    if (r->discarded > max) {
        obsd_log(OBSD_LOG_INFO, "req=%llu peer=%s %s %s: over %zu bytes of an unread body, "
                 "connection closed", (unsigned long long)r->id, r->peer, r->method,
                 r->label, max);
        return MHD_NO;
    }
    return MHD_YES;
}

enum MHD_Result obsd__append_body(req *r, const char *data, size_t *size, size_t max)
{
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
        return obsd__discard_body(r, n, max);
    }
    if (obsd__reserve(&r->body, &r->cap, r->len + n, max) != 0)
        return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the body");
    memcpy(r->body + r->len, data, n);
    r->len += n;
    return MHD_YES;
}

enum MHD_Result obsd__queue_frame(req *r, const unsigned char *body, size_t len, unsigned outputs)
{
    obsd__frame_req *fr = r->fr;
    obsd_http *h = r->srv;
    char err[OBS_ERR_LEN] = "";
    obs_limits lim = {.max_pixels = (uint64_t)h->front.cfg->max_pixels};
    obs_status s = obsd_fp_decode(&fr->fp, body, len, &fr->hr, &lim, NULL, err);
    /* An EXR answer takes the body's header (its windows and attributes;
     * append=1: the body itself), which lives until the answer: r->body,
     * freed with the request, or a stream frame's, which it holds. */
    if (s == OBS_OK && fr->hr.format == OBS_HTTP_EXR)
        obsd_fp_keep_source(&fr->fp, body, len, obsd_fp_part(&fr->fp));
    if (s == OBS_OK)
        s = obsd_fp_check_output(&fr->fp, &fr->hr, err);
    if (s != OBS_OK)
        return obsd__answer_status(r, s, err);
    /* The request is whole: its deadline stops (the GL worker's time is
     * not the client's).  Suspend before queueing: the worker may finish
     * and resume at once.  The job is pending only once the connection is
     * suspended, and the drain's cut (obsd_http_cut: the connection's
     * `cut` set, then the job looked at) is checked after: one of the two
     * sees the other, so a cut connection is never left suspended. */
    if (!obsd__req_hold(r))
        return MHD_NO;
    r->state = REQ_QUEUED;
    MHD_suspend_connection(r->conn);
    atomic_store(&r->job, JOB_PENDING);
    if ((r->cn && atomic_load(&r->cn->cut)) || (atomic_load(&h->draining) && !fr->before_drain) ||
        obsd_fp_queue(&fr->fp, h->front.queue, &fr->hr.params, outputs, job_done, r) != 0) {
        int pending = JOB_PENDING;
        if (atomic_compare_exchange_strong(&r->job, &pending, JOB_NONE)) {
            r->state = REQ_REFUSED;
            MHD_resume_connection(r->conn);
        } else {
            atomic_store(&r->job, JOB_CUT_DONE); /* the cut resumed it; no job runs */
        }
    }
    return MHD_YES;
}

static enum MHD_Result queue_body(req *r)
{
    obsd__frame_req *fr = r->fr;
    fr->fp.ms_receive = obsd_now_ms() - r->t0;
    obsd_stats_stage(OBSD_STAGE_RECEIVE, fr->fp.ms_receive);
    if (r->len == 0) {
        char msg[128];
        snprintf(msg, sizeof msg, "%s %s needs a G-buffer EXR as its body", r->method,
                 fr->kept ? "/v1/streams/NAME/frames" : "/v1/ao");
        return obsd__answer_error(r, 400, "empty_body", msg, NULL, NULL);
    }
    if (fr->kept) /* the body is kept with the frame: re-runs decode it again */
        return obsd__queue_frame(r, r->body, r->len, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE);
    enum MHD_Result rc = obsd__queue_frame(r, r->body, r->len, fr->hr.outputs);
    if (!fr->fp.src) { /* else the answer needs it; freed with the request */
        free(r->body);
        r->body = NULL;
        r->cap = 0;
    }
    return rc;
}

enum MHD_Result obsd__frame_body(req *r, const char *data, size_t *size)
{
    if (!obsd__req_alive(r))
        return MHD_NO;
    if (*size)
        return obsd__append_body(r, data, size, (size_t)r->srv->front.cfg->max_body);
    if (r->too_big) {
        char msg[160];
        snprintf(msg, sizeof msg, "body is over the limit of %lld bytes (--max-body)",
                 (long long)r->srv->front.cfg->max_body);
        return obsd__answer_error(r, 413, "body_too_large", msg, NULL, NULL);
    }
    return queue_body(r);
}

/* Called again once the GL worker resumed the connection.  Deep input
 * answers an EXR of AO.Y, AOFront.Y and R,G,B,A as `obscura ao` writes
 * it, or a PNG of the blended AO or the composite. */
enum MHD_Result obsd__ao_finish(req *r)
{
    obsd__frame_req *fr = r->fr;
    obs_status s = obsd_fp_finished(&fr->fp);
    if (s != OBS_OK)
        return obsd__answer_status(r, s, fr->fp.job.err);
    obsd_fp_images im;
    obsd_fp_images_of(&fr->fp, fr->hr.outputs, &im);
    return obsd__answer_images(r, &im, obsd_fp_camera(&fr->fp), 1, NULL, NULL);
}
