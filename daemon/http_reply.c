/* obscurad's HTTP answers: every request ends here, so that each one is
 * logged once (the line the tests and operators grep for) and counted
 * once in the metrics.  Errors are the JSON of protocol/http.h; images
 * are written by the frame path (frame_path.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "http_internal.h"
#include "log.h"

typedef obsd__req req;

static void log_request(const req *r, const char *note)
{
    static const obsd_fp none; /* a request without a frame: its stages took 0 ms */
    if (!obsd_log_enabled(OBSD_LOG_INFO))
        return;
    const obsd_fp *fp = r->fr ? &r->fr->fp : &none;
    obsd_log(OBSD_LOG_INFO,
             "req=%llu peer=%s %s %s status=%d in=%zu out=%zu queue=%.1f decode=%.1f gl=%.1f "
             "encode=%.1f receive=%.1f total=%.1f ms%s%s",
             (unsigned long long)r->id, r->peer, r->method, r->path, r->status,
             r->len + r->discarded, r->bytes_out, fp->ms_queue, fp->ms_decode, fp->ms_gl, fp->ms_encode,
             fp->ms_receive,
             obsd_now_ms() - r->t0, note && *note ? " " : "", note ? note : "");
}

/* An answer while the client still sends its body: kept until the
 * body's end (obsd__answer_held), the rest of the body discarded. */
static enum MHD_Result hold(req *r, int status, struct MHD_Response *resp, size_t body_len, const char *note)
{
    if (r->held) /* one answer per request: the first one stands */
        MHD_destroy_response(resp);
    else {
        r->held = resp;
        r->held_status = status;
        r->held_len = body_len;
        r->held_note = note && *note ? strdup(note) : NULL;
    }
    r->state = REQ_HELD;
    return MHD_YES;
}

enum MHD_Result obsd__answer_held(req *r)
{
    struct MHD_Response *resp = r->held;
    char *note = r->held_note;
    r->held = NULL;
    r->held_note = NULL;
    enum MHD_Result rc = obsd__answer(r, r->held_status, resp, r->held_len, note);
    free(note);
    return rc;
}

enum MHD_Result obsd__answer(req *r, int status, struct MHD_Response *resp, size_t body_len,
                              const char *note)
{
    if (!resp)
        return MHD_NO;
    if (r->body_in)
        return hold(r, status, resp, body_len, note);
    if (!obsd__req_hold(r)) { /* cut (its deadline, the drain) while we worked */
        MHD_destroy_response(resp);
        return MHD_NO;
    }
    /* In the drain, and on a connection beyond --http-connections or
     * --max-per-client, the answer is the connection's last. */
    if (atomic_load(&r->srv->draining) || (r->cn && (r->cn->reserve || r->cn->over_client)))
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CONNECTION, "close");
    r->status = status;
    r->bytes_out = body_len;
    r->state = REQ_ANSWERED;
    MHD_add_response_header(resp, "Server", "obscurad/" OBS_VERSION);
    const char *origin = r->srv->front.cfg->cors;
    if (origin[0]) { /* --cors: a page from that origin may read every answer, its warnings and timings too */
        MHD_add_response_header(resp, "Access-Control-Allow-Origin", origin);
        MHD_add_response_header(resp, "Access-Control-Expose-Headers",
                                "X-Obscura-Warning, Server-Timing, Retry-After, Location");
        if (strcmp(origin, "*") != 0)
            MHD_add_response_header(resp, "Vary", "Origin");
    }
    enum MHD_Result rc = MHD_queue_response(r->conn, (unsigned)status, resp);
    MHD_destroy_response(resp);
    obsd_stats_request(r->slot, status, r->len + r->discarded, body_len);
    r->t_answered = obsd_now_ms();
    if (r->frame_total)
        obsd_stats_stage(OBSD_STAGE_TOTAL, r->t_answered - r->t0);
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
    obsd_stats_error_answer(status, code, r->peer, msg); /* over a limit: counted by reason */
    char note[OBS_ERR_LEN + 32];
    snprintf(note, sizeof note, "error=%s: %s", code, msg);
    return obsd__answer(r, status, resp, len, note);
}

enum MHD_Result obsd__answer_preflight(req *r, const char *methods)
{
    struct MHD_Response *resp = MHD_create_response_from_buffer(0, NULL, MHD_RESPMEM_PERSISTENT);
    if (!resp)
        return MHD_NO;
    MHD_add_response_header(resp, "Access-Control-Allow-Methods",
                            !strcmp(methods, "GET") ? "GET, HEAD" : methods);
    MHD_add_response_header(resp, "Access-Control-Allow-Headers", "Authorization, Content-Type");
    MHD_add_response_header(resp, "Access-Control-Max-Age", "600");
    return obsd__answer(r, 204, resp, 0, "preflight (--cors)");
}

enum MHD_Result obsd__answer_shutting_down(req *r)
{
    return obsd__answer_error(r, 503, "shutting_down", "the daemon is shutting down", MHD_HTTP_HEADER_RETRY_AFTER,
                              "5");
}

enum MHD_Result obsd__answer_status(req *r, obs_status s, const char *msg)
{
    const char *code;
    int http = obs_http_status_of(s, &code);
    return obsd__answer_error(r, http, code, msg && *msg ? msg : obs_status_message(s),
                        http == 503 ? MHD_HTTP_HEADER_RETRY_AFTER : NULL, "1");
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
    obsd__frame_req *fr = r->fr;
    struct MHD_Response *resp = MHD_create_response_from_buffer(out->size, out->data, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        obs_bytes_free(out);
        return MHD_NO;
    }
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    if (timing) {
        /* send is not known yet: it is in /metrics (obscurad_stage_seconds) */
        char t[224];
        snprintf(t, sizeof t, "queue;dur=%.2f, decode;dur=%.2f, gl;dur=%.2f, encode;dur=%.2f, receive;dur=%.2f",
                 fr->fp.ms_queue, fr->fp.ms_decode, fr->fp.ms_gl, fr->fp.ms_encode, fr->fp.ms_receive);
        MHD_add_response_header(resp, "Server-Timing", t);
    }
    if (extra_name)
        MHD_add_response_header(resp, extra_name, extra_value);
    /* the input's sanity warnings (strict=1 makes them a 422 instead) */
    for (int i = 0; i < fr->fp.gf.info.warning_count; i++)
        MHD_add_response_header(resp, "X-Obscura-Warning", fr->fp.gf.info.warnings[i]);
    return obsd__answer(r, 200, resp, out->size, NULL);
}

enum MHD_Result obsd__answer_images(req *r, const obsd_fp_images *im, const obs_camera *cam, int timing,
                                    const char *extra_name, const char *extra_value)
{
    obsd__frame_req *fr = r->fr;
    char err[OBS_ERR_LEN] = "";
    obsd_fp_images shown = *im;
    obs_image exposed = {0};
    /* exposure is a view of a colour PNG; the AO is never exposed */
    const obs_image *img = obsd_fp_png_image(im);
    if (fr->hr.format != OBS_HTTP_EXR && img != im->ao && fr->exposure != 0.0) {
        if (expose(img, fr->exposure, &exposed) != 0)
            return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the image");
        shown.composite = &exposed;
    }
    obs_bytes out;
    obs_status s = obsd_fp_encode(&fr->fp, &shown, &fr->hr, 0, cam, &out, err);
    obs_image_free(&exposed);
    /* what the request asked for and the input cannot give (append=1: a
     * channel named like the AO layer) is the request's fault */
    if (s == OBS_INVALID_ARGUMENT || s == OBS_UNSUPPORTED)
        return obsd__answer_status(r, s, err);
    if (s != OBS_OK)
        return obsd__answer_error(r, 500, "encode_failed", err, NULL, NULL);
    return answer_bytes(r, &out, fr->hr.format == OBS_HTTP_EXR ? "image/x-exr" : "image/png", timing,
                        extra_name, extra_value);
}
