/* /v1/streams: frames posted to named streams, kept for the preview page
 * (daemon/stream_store.c), fetched again or re-run with other
 * parameters, and announced to subscribers as Server-Sent Events.
 *
 *   GET  /v1/streams                    the streams (JSON)
 *   GET  /v1/streams/NAME               one stream and its kept frames (JSON)
 *   POST /v1/streams/NAME/frames        a frame, as POST /v1/ao (flat or
 *                                       deep); kept
 *   GET  /v1/streams/NAME/frames/N      a kept frame (N or "latest"):
 *                                       output=ao|composite|color|ao_front,
 *                                       format, exposure; other parameters
 *                                       re-run it
 *   GET  /v1/streams/NAME/events        text/event-stream: `frame` events
 *
 * An event stream is http_events.c's: the store parks and wakes it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "http_internal.h"
#include "log.h"

typedef obsd__req req;

/* What a /v1/streams request does. */
typedef enum stream_op {
    STREAM_NONE,
    STREAM_LIST,      /* GET /v1/streams */
    STREAM_INFO,      /* GET /v1/streams/NAME */
    STREAM_POST,      /* POST /v1/streams/NAME/frames */
    STREAM_FRAME,     /* GET /v1/streams/NAME/frames/N */
    STREAM_EVENTS     /* GET /v1/streams/NAME/events */
} stream_op;

/* A /v1/streams request's own state (r->own); its frame, when it posts
 * or re-runs one, is http_frames.c's (r->fr). */
typedef struct stream_req {
    stream_op op;
    char name[OBSD_STREAM_NAME_LEN + 1];
    obsd_frame *frame;   /* GET .../frames/N, or the posted frame once kept: a reference */
    obsd_sub sub;        /* GET .../events */
    obsd__events events;
} stream_req;

/* Splits the path after /v1/streams into sr->op and sr->name; 0 when it
 * is no route (404), -1 when the name is not valid. */
static int parse_path(req *r, const char *url, uint64_t *seq, int *latest)
{
    stream_req *sr = r->own;
    const char *p = url + strlen("/v1/streams");
    if (!*p || !strcmp(p, "/")) {
        sr->op = STREAM_LIST;
        return 1;
    }
    p++; /* the '/' */
    size_t n = strcspn(p, "/");
    if (n > OBSD_STREAM_NAME_LEN)
        return -1;
    memcpy(sr->name, p, n);
    sr->name[n] = '\0';
    if (!obsd_stream_name_ok(sr->name))
        return -1;
    p += n;
    if (!*p) {
        sr->op = STREAM_INFO;
        return 1;
    }
    if (!strcmp(p, "/events")) {
        sr->op = STREAM_EVENTS;
        return 1;
    }
    if (!strcmp(p, "/frames")) {
        sr->op = STREAM_POST;
        return 1;
    }
    if (!strncmp(p, "/frames/", 8)) {
        const char *s = p + 8;
        sr->op = STREAM_FRAME;
        if (!strcmp(s, "latest")) {
            *latest = 1;
            return 1;
        }
        char *end;
        unsigned long long v = strtoull(s, &end, 10);
        if (*s >= '0' && *s <= '9' && !*end && v > 0) {
            *seq = v;
            return 1;
        }
    }
    return 0;
}

/* ---- Server-Sent Events ----------------------------------------------- */

static int next_event(req *r, char *buf, size_t len)
{
    stream_req *sr = r->own;
    return obsd_streams_next_event(r->srv->streams, &sr->sub, buf, len, obsd_now_ms());
}

/* The stream's subscriber (obsd__events_open; the stream made when it
 * is not there yet). */
static int join(req *r, enum MHD_Result *rc)
{
    stream_req *sr = r->own;
    sr->sub = (obsd_sub){.park = obsd__events_park, .wake = obsd__events_wake, .arg = r};
    if (obsd_streams_subscribe(r->srv->streams, sr->name, &sr->sub, obsd_now_ms()) == 0)
        return 1;
    char msg[192];
    snprintf(msg, sizeof msg, "too many event subscribers (at most %d), or no stream '%s' and no room "
             "for a new one (--streams)", OBSD_STREAM_MAX_SUBS, sr->name);
    *rc = obsd__answer_error(r, 503, "too_many_subscribers", msg, MHD_HTTP_HEADER_RETRY_AFTER, "5");
    return 0;
}

static void leave(req *r)
{
    stream_req *sr = r->own;
    obsd_streams_unsubscribe(r->srv->streams, &sr->sub);
}

/* ---- frames ------------------------------------------------------------ */

/* The stored frame's parameters first (its camera, its channel map), so
 * that the request's own override them; its output and format do not
 * carry over. */
static void apply_stored(req *r, const obsd_frame *f)
{
    obsd__frame_req *fr = r->fr;
    char err[OBS_ERR_LEN];
    for (size_t k = 0; k + 1 < f->query_len;) {
        const char *key = f->query + k, *val = key + strlen(key) + 1;
        (void)obs_http_request_set(&fr->hr, key, val, err); /* they were valid when posted */
        k = (size_t)(val - f->query) + strlen(val) + 1;
    }
    fr->hr.outputs = OBS_OUTPUT_AO;
    fr->hr.format = OBS_HTTP_EXR;
    fr->hr.float_exr = 0;
    fr->hr.compression = 0;
    fr->hr.png_bits = 8;
}

/* A kept frame's images that the request asks for; a deep frame's as
 * POST /v1/ao writes them (AO.Y, AOFront.Y, R,G,B,A). */
static obsd_fp_images kept_images(const req *r, const obsd_frame *f)
{
    obsd__frame_req *fr = r->fr;
    const int ao = (fr->hr.outputs & OBS_OUTPUT_AO) != 0;
    return (obsd_fp_images){.ao = ao ? &f->ao : NULL, .ao_front = ao && f->deep ? &f->ao_front : NULL,
                            .composite = (fr->hr.outputs & OBS_OUTPUT_COMPOSITE) ? &f->composite : NULL,
                            .deep = f->deep};
}

/* output=ao_front: a deep frame's front layer's AO alone, as its AO (the
 * preview page's AO view of deep input); 400 for a flat frame. */
static enum MHD_Result answer_front(req *r, const obs_image *front, const obs_camera *cam, int timing,
                                    uint64_t seq)
{
    char num[32];
    snprintf(num, sizeof num, "%llu", (unsigned long long)seq);
    if (!front || !front->data)
        return obsd__answer_error(r, 400, "not_deep",
                                  "output=ao_front is the front layer's AO of a deep frame; this frame is "
                                  "flat (ask for output=ao)", NULL, NULL);
    obsd_fp_images im = {.ao = front};
    return obsd__answer_images(r, &im, cam, timing, "X-Obscura-Frame", num);
}

static enum MHD_Result get_frame(req *r, uint64_t seq)
{
    stream_req *sr = r->own;
    obsd_http *h = r->srv;
    int found = 0;
    enum MHD_Result rc;
    char msg[320];
    sr->frame = obsd_streams_get(h->streams, sr->name, seq, &found);
    if (!sr->frame) {
        if (found && seq)
            snprintf(msg, sizeof msg, "stream '%s' has no frame %llu (GET /v1/streams/%s lists the kept ones)",
                     sr->name, (unsigned long long)seq, sr->name);
        else
            snprintf(msg, sizeof msg, found ? "stream '%s' has no frame yet" : "no stream '%s'", sr->name);
        return obsd__answer_error(r, 404, "not_found", msg, NULL, NULL);
    }
    obsd__frame_req *fr = obsd__frame_req_new(r);
    if (!fr)
        return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the request");
    fr->view = 1;
    apply_stored(r, sr->frame);
    if (!obsd__parse_query(r, &rc))
        return rc;
    const obsd_frame *f = sr->frame;
    char num[32];
    snprintf(num, sizeof num, "%llu", (unsigned long long)f->seq);
    /* a kept frame's EXR takes its body's header, as its POST's did */
    if (fr->hr.format == OBS_HTTP_EXR)
        obsd_fp_keep_source(&fr->fp, f->body, f->body_len, f->part);
    if (fr->want_color) {
        if (!f->color.data)
            return obsd__answer_error(r, 404, "no_color",
                                      f->deep ? "a deep frame has no flat colour plane (output=composite is its "
                                                "samples' composite, output=ao_front its front layer's AO)"
                                              : "the frame's G-buffer has no colour plane",
                                      NULL, NULL);
        obsd_fp_images color = {.composite = &f->color};
        return obsd__answer_images(r, &color, NULL, 0, "X-Obscura-Frame", num);
    }
    if (fr->want_front && (!f->deep || !fr->rerun))
        return answer_front(r, f->deep ? &f->ao_front : NULL, f->written.has_projection ? &f->written : NULL, 0,
                            f->seq);
    if (!fr->rerun) {
        obsd_fp_images im = kept_images(r, f);
        return obsd__answer_images(r, &im, f->written.has_projection ? &f->written : NULL, 0, "X-Obscura-Frame",
                                   num);
    }
    /* other parameters: the frame runs again (not kept) */
    fr->before_drain = !atomic_load(&h->draining);
    if (!fr->before_drain)
        return obsd__answer_shutting_down(r);
    int full;
    obsd_queue_stats(h->front.queue, NULL, NULL, &full);
    if (full)
        return obsd__answer_error(r, 503, "queue_full", "the frame queue is full; retry later",
                                  MHD_HTTP_HEADER_RETRY_AFTER, "1");
    return obsd__queue_frame(r, f->body, f->body_len, fr->hr.outputs);
}

enum MHD_Result obsd__streams_start(req *r, const char *url)
{
    obsd_http *h = r->srv;
    stream_req *sr = r->own = calloc(1, sizeof *sr);
    if (!sr)
        return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the request");
    uint64_t seq = 0;
    int latest = 0;
    int ok = parse_path(r, url, &seq, &latest);
    if (ok < 0)
        return obsd__answer_error(r, 400, "bad_stream_name",
                                  "a stream name is 1 to 64 characters of A-Z a-z 0-9 . _ -", NULL, NULL);
    if (ok == 0)
        return obsd__answer_error(r, 404, "not_found",
                                  "no such route (GET /v1/streams, GET|POST /v1/streams/NAME/frames[/N], "
                                  "GET /v1/streams/NAME/events)", NULL, NULL);
    if (h->front.cfg->streams < 1)
        return obsd__answer_error(r, 404, "streams_off", "streams are off (--streams 0)", NULL, NULL);
    const char *allowed = sr->op == STREAM_POST ? "POST" : "GET";
    if (strcmp(r->method, allowed) != 0 && !(sr->op != STREAM_POST && !strcmp(r->method, "HEAD"))) {
        char msg[96];
        snprintf(msg, sizeof msg, "this /v1/streams route takes %s", allowed);
        return obsd__answer_error(r, 405, "method_not_allowed", msg, MHD_HTTP_HEADER_ALLOW, allowed);
    }
    switch (sr->op) {
    case STREAM_LIST: {
        char *text = obsd_streams_list_json(h->streams);
        return text ? obsd__answer_text(r, 200, "application/json", text, strlen(text), NULL) : MHD_NO;
    }
    case STREAM_INFO: {
        int found;
        char *text = obsd_streams_stream_json(h->streams, sr->name, &found);
        if (!found) {
            char msg[96];
            snprintf(msg, sizeof msg, "no stream '%s'", sr->name);
            return obsd__answer_error(r, 404, "not_found", msg, NULL, NULL);
        }
        return text ? obsd__answer_text(r, 200, "application/json", text, strlen(text), NULL) : MHD_NO;
    }
    case STREAM_POST:
        if (!obsd__frame_req_new(r))
            return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the request");
        r->fr->kept = 1;
        r->frame_total = 1;
        return obsd__frame_start(r, url);
    case STREAM_FRAME:
        return get_frame(r, latest ? 0 : seq);
    case STREAM_EVENTS:
        return obsd__events_open(r, &sr->events, join, next_event, leave);
    default:
        return obsd__answer_error(r, 404, "not_found", "no such route", NULL, NULL);
    }
}

/* The G-buffer's colour as an RGBA image (alpha 1 when it has none). */
static int copy_color(const obs_gbuffer *gb, obs_image *out)
{
    const obs_plane *p = &gb->color;
    if (!p->data || p->channels < 3)
        return 0;
    size_t w = (size_t)gb->width, hgt = (size_t)gb->height;
    size_t stride = p->row_stride ? p->row_stride / sizeof(float) : w * (size_t)p->channels;
    if (!(out->data = malloc(w * hgt * 4 * sizeof(float))))
        return -1;
    out->width = gb->width;
    out->height = gb->height;
    out->channels = 4;
    for (size_t y = 0; y < hgt; y++)
        for (size_t x = 0; x < w; x++) {
            const float *s = p->data + y * stride + x * (size_t)p->channels;
            float *d = out->data + (y * w + x) * 4;
            d[0] = s[0];
            d[1] = s[1];
            d[2] = s[2];
            d[3] = p->channels >= 4 ? s[3] : 1.0f;
        }
    return 0;
}

/* The finished job's images and camera into the frame (the job keeps
 * none of them): a deep frame's blended AO, front AO and composite, a
 * flat one's AO and composite. */
static void take_result(obsd_fp *fp, obsd_frame *f)
{
    const obs_camera *written = obsd_fp_camera(fp);
    if (written)
        f->written = *written;
    if (fp->deep) {
        obs_deep_result *dr = &fp->job.deep_result;
        f->deep = 1;
        f->width = fp->deep->width;
        f->height = fp->deep->height;
        f->camera = fp->deep->camera;
        f->ao = dr->ao_blend;
        f->ao_front = dr->ao_front;
        f->composite = dr->composite;
        *dr = (obs_deep_result){0};
        return;
    }
    obs_result *res = &fp->job.result;
    f->width = fp->gb->width;
    f->height = fp->gb->height;
    f->camera = fp->gb->camera;
    f->ao = res->ao;
    f->composite = res->composite;
    res->ao = (obs_image){0};
    res->composite = (obs_image){0};
    obs_result_free(res);
}

/* POST .../frames, the GL worker done: keep the frame, answer like /v1/ao. */
static enum MHD_Result post_finish(req *r)
{
    obsd__frame_req *fr = r->fr;
    stream_req *sr = r->own;
    obsd_http *h = r->srv;
    const obs_gbuffer *gb = &fr->fp.gf.gb;
    obsd_frame *f = obsd_frame_new();
    if (!f || (!fr->fp.deep && copy_color(gb, &f->color) != 0)) {
        obsd_frame_release(f);
        return obsd__answer_status(r, OBS_NO_MEMORY, "no memory to keep the frame");
    }
    f->body = r->body;
    f->body_len = r->len;
    r->body = NULL;
    r->cap = 0;
    f->query = fr->query;
    f->query_len = fr->query_len;
    fr->query = NULL;
    fr->query_len = fr->query_cap = 0;
    take_result(&fr->fp, f);
    f->part = obsd_fp_part(&fr->fp);
    f->ms_queue = fr->fp.ms_queue;
    f->ms_decode = fr->fp.ms_decode;
    f->ms_gl = fr->fp.ms_gl;
    atomic_fetch_add(&f->refs, 1); /* ours, to answer with */
    uint64_t seq = obsd_streams_add(h->streams, sr->name, f);
    if (!seq) {
        obsd_frame_release(f);
        return obsd__answer_status(r, OBS_NO_MEMORY, "no memory to keep the frame");
    }
    char num[32];
    snprintf(num, sizeof num, "%llu", (unsigned long long)seq);
    sr->frame = f; /* released when the request ends */
    obsd_fp_images im = kept_images(r, f);
    return obsd__answer_images(r, &im, f->written.has_projection ? &f->written : NULL, 1, "X-Obscura-Frame", num);
}

enum MHD_Result obsd__streams_finish(req *r)
{
    obsd__frame_req *fr = r->fr;
    stream_req *sr = r->own;
    obs_status s = obsd_fp_finished(&fr->fp);
    if (s != OBS_OK)
        return obsd__answer_status(r, s, fr->fp.job.err);
    if (sr->op == STREAM_POST)
        return post_finish(r);
    /* a re-run of a kept frame */
    if (fr->want_front)
        return answer_front(r, &fr->fp.job.deep_result.ao_front, obsd_fp_camera(&fr->fp), 1, sr->frame->seq);
    char num[32];
    snprintf(num, sizeof num, "%llu", (unsigned long long)sr->frame->seq);
    obsd_fp_images im;
    obsd_fp_images_of(&fr->fp, fr->hr.outputs, &im);
    return obsd__answer_images(r, &im, obsd_fp_camera(&fr->fp), 1, "X-Obscura-Frame", num);
}

void obsd__streams_done(req *r)
{
    stream_req *sr = r->own;
    if (!sr)
        return;
    obsd__events_close(r, &sr->events);
    obsd_frame_release(sr->frame);
    free(sr);
    r->own = NULL;
}
