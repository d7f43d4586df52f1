/* /v1/bakes: levels baked on the daemon's bake workers (bake_jobs.c).
 *
 *   GET    /v1/bakes                 the jobs (JSON)
 *   POST   /v1/bakes?PARAM=V...      a level as the body: 202, the job's id
 *   GET    /v1/bakes/ID              state, stage, progress, per-stage times
 *   GET    /v1/bakes/ID/events       text/event-stream: progress, then the end
 *   GET    /v1/bakes/ID/result       the baked .glb (409 until done)
 *   DELETE /v1/bakes/ID              cancel (queued, running) or drop (finished)
 *
 * The query takes the bake parameters (`obscura bake --params`) by name,
 * `distances=S,L`, and `format=EXT` (the level's file extension, else told
 * from its first bytes).  The body is the level itself, or a
 * multipart/form-data body (curl -F) with a part `level` and a part
 * `decorators`, a decorators file (obscura bake --decorators), checked
 * before the job is queued; libmicrohttpd's post processor copies the
 * parts out as the body arrives.
 * An event stream is http_events.c's, as the streams' are. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "http_internal.h"
#include "log.h"

typedef obsd__req req;

enum { OP_LIST = 1, OP_INFO, OP_RESULT, OP_EVENTS };

typedef struct parts parts; /* a multipart body's parts (below) */

/* A /v1/bakes request's own state (r->own), freed by obsd__bakes_done. */
typedef struct bake_req {
    int op;                       /* OP_* */
    char id[OBSD_BAKE_ID_LEN + 1];
    char ext[16];                 /* format=EXT */
    obs_bake_params params;
    obsd_bake_sub sub;            /* GET .../events */
    obsd__events events;
    struct MHD_PostProcessor *pp; /* a multipart body, split as it comes */
    parts *parts;                 /* its parts */
} bake_req;

#define ROUTES "GET|POST /v1/bakes, GET|DELETE /v1/bakes/ID, GET /v1/bakes/ID/result, GET /v1/bakes/ID/events"

static int id_ok(const char *s, size_t n)
{
    if (n == 0 || n > OBSD_BAKE_ID_LEN)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (!((s[i] >= '0' && s[i] <= '9') || (s[i] >= 'a' && s[i] <= 'f')))
            return 0;
    return 1;
}

/* 1: a route (bk->op, bk->id); 0: none; -1: not an id. */
static int parse_path(req *r, const char *url)
{
    bake_req *bk = r->own;
    const char *p = url + strlen("/v1/bakes");
    if (!*p || !strcmp(p, "/")) {
        bk->op = OP_LIST;
        return 1;
    }
    p++;
    size_t n = strcspn(p, "/");
    if (!id_ok(p, n))
        return -1;
    memcpy(bk->id, p, n);
    bk->id[n] = '\0';
    p += n;
    bk->op = !*p ? OP_INFO : !strcmp(p, "/result") ? OP_RESULT : !strcmp(p, "/events") ? OP_EVENTS : 0;
    return bk->op ? 1 : 0;
}

static enum MHD_Result unknown(req *r)
{
    bake_req *bk = r->own;
    char msg[160];
    snprintf(msg, sizeof msg, "no bake job '%s' (jobs live in the daemon's memory: a restart loses them; "
             "finished ones are dropped beyond --bake-keep)", bk->id);
    return obsd__answer_error(r, 404, "not_found", msg, NULL, NULL);
}

/* ---- POST: the query, then the body ------------------------------------ */

/* One query argument of POST /v1/bakes (obsd__query_args). */
static obs_status bake_arg(req *r, const char *key, const char *value, char err[OBS_ERR_LEN])
{
    bake_req *bk = r->own;
    if (!strcmp(key, "format")) {
        size_t n = strlen(value);
        int ok = n > 0 && n < sizeof bk->ext;
        for (size_t i = 0; ok && i < n; i++)
            ok = (value[i] >= 'a' && value[i] <= 'z') || (value[i] >= '0' && value[i] <= '9');
        if (!ok) {
            snprintf(err, OBS_ERR_LEN, "format '%.40s' is not a file extension (glb, gltf, ac, obj, ...)",
                     value);
            return OBS_INVALID_ARGUMENT;
        }
        snprintf(bk->ext, sizeof bk->ext, "%s", value);
        return OBS_OK;
    }
    if (!strcmp(key, "distances")) {
        char s[64], l[64];
        const char *comma = strchr(value, ',');
        if (!comma || strchr(comma + 1, ',') || (size_t)(comma - value) >= sizeof s || strlen(comma + 1) >= sizeof l) {
            snprintf(err, OBS_ERR_LEN, "distances '%.40s': expected SHORT,LONG (e.g. 2,300)", value);
            return OBS_INVALID_ARGUMENT;
        }
        snprintf(s, sizeof s, "%.*s", (int)(comma - value), value);
        snprintf(l, sizeof l, "%s", comma + 1);
        obs_status st = obs_bake_param_set(&bk->params, "distance_short", s, err);
        return st != OBS_OK ? st : obs_bake_param_set(&bk->params, "distance_long", l, err);
    }
    obs_status st = obs_bake_param_set(&bk->params, key, value, err);
    if (st != OBS_OK && !obs_bake_param_find(key))
        snprintf(err, OBS_ERR_LEN, "unknown bake parameter '%.60s' (GET /v1/bakes lists none; "
                 "'obscura bake --params' lists them; also format=EXT, distances=S,L)", key);
    return st;
}

/* ---- a multipart/form-data body: the parts `level` and `decorators` ---- */

struct parts {
    unsigned char *buf[2]; /* level, decorators */
    size_t len[2], cap[2];
    size_t max;
    int seen[2];
    int too_large;    /* the error is a part over the limit: 413 */
    char err[200];
};

static const char *const part_name[2] = {"level", "decorators"};

static enum MHD_Result on_part(void *cls, enum MHD_ValueKind kind, const char *key,
                               const char *filename, const char *content_type,
                               const char *transfer_encoding, const char *data, uint64_t off,
                               size_t size)
{
    parts *pt = cls;
    (void)kind;
    (void)filename;
    (void)content_type;
    (void)transfer_encoding;
    int k = !key ? -1 : !strcmp(key, "level") ? 0 : !strcmp(key, "decorators") ? 1 : -1;
    if (k < 0) {
        snprintf(pt->err, sizeof pt->err, "unknown part '%.40s' (the parts are level and decorators)",
                 key ? key : "");
        return MHD_NO;
    }
    if (off == 0 && pt->seen[k] && pt->len[k] > 0) { /* a second part of that name */
        snprintf(pt->err, sizeof pt->err, "part %s given twice", part_name[k]);
        return MHD_NO;
    }
    pt->seen[k] = 1;
    if (size > pt->max - pt->len[k]) {
        snprintf(pt->err, sizeof pt->err, "part %s is over the limit of %zu bytes (--max-level)",
                 part_name[k], pt->max);
        pt->too_large = 1;
        return MHD_NO;
    }
    /* + 1: the decorators' NUL */
    if (obsd__reserve(&pt->buf[k], &pt->cap[k], pt->len[k] + size + 1, pt->max + 1) != 0) {
        snprintf(pt->err, sizeof pt->err, "no memory for part %s", part_name[k]);
        return MHD_NO;
    }
    memcpy(pt->buf[k] + pt->len[k], data, size);
    pt->len[k] += size;
    return MHD_YES;
}

/* The end of a multipart body: 0 with its parts checked, or -1 with
 * pt->err.  The post processor is destroyed. */
static int parts_end(req *r, parts *pt)
{
    bake_req *bk = r->own;
    enum MHD_Result done = MHD_destroy_post_processor(bk->pp);
    bk->pp = NULL;
    if (done != MHD_YES && !pt->err[0])
        snprintf(pt->err, sizeof pt->err, "the multipart/form-data body is cut short or malformed");
    if (!pt->err[0] && !pt->seen[0])
        snprintf(pt->err, sizeof pt->err, "a multipart/form-data body without a part 'level'");
    if (pt->err[0])
        return -1;
    if (pt->buf[1])
        pt->buf[1][pt->len[1]] = '\0';
    return 0;
}

static enum MHD_Result post_start(req *r)
{
    bake_req *bk = r->own;
    obsd_http *h = r->srv;
    if (atomic_load(&h->draining))
        return obsd__answer_shutting_down(r);
    char err[OBS_ERR_LEN];
    if (obsd__query_args(r, bake_arg, err) != OBS_OK)
        return obsd__answer_error(r, 400, "bad_parameter", err, NULL, NULL);
    const char *ct = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_TYPE);
    int multipart = ct && !strncasecmp(ct, "multipart/form-data", strlen("multipart/form-data"));
    if (multipart) {
        /* the parts are copied out as the body comes: nothing is held twice */
        if (!(bk->parts = calloc(1, sizeof *bk->parts)))
            return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the parts");
        bk->parts->max = (size_t)h->front.cfg->max_level;
        bk->pp = MHD_create_post_processor(r->conn, 1 << 16, on_part, bk->parts);
        if (!bk->pp)
            return obsd__answer_error(r, 400, "bad_multipart",
                                      "a multipart/form-data body without a boundary", NULL, NULL);
    }
    enum MHD_Result rc;
    if (!obsd__body_expect(r, (size_t)h->front.cfg->max_level, "level", "--max-level", !multipart, &rc))
        return rc;
    r->state = REQ_BODY;
    return MHD_YES;
}

/* The level's format from its first bytes, or NULL. */
static const char *sniff(const unsigned char *p, size_t n)
{
    if (n >= 4 && !memcmp(p, "glTF", 4))
        return "glb";
    if (n >= 4 && !memcmp(p, "AC3D", 4))
        return "ac";
    if (n >= 4 && !memcmp(p, "ply", 3) && (p[3] == '\n' || p[3] == '\r'))
        return "ply";
    size_t i = 0;
    while (i < n && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' || p[i] == '\n'))
        i++;
    if (i < n && p[i] == '{')
        return "gltf";
    if (i + 1 < n && (p[i] == 'v' || p[i] == 'o' || p[i] == 'g' || p[i] == '#') &&
        (p[i + 1] == ' ' || p[i + 1] == '\t'))
        return "obj";
    if (n >= 6 && !memcmp(p + i, "mtllib", 6))
        return "obj";
    return NULL;
}

enum MHD_Result obsd__bakes_body(req *r, const char *data, size_t *size)
{
    bake_req *bk = r->own;
    obsd_http *h = r->srv;
    if (!obsd__req_alive(r))
        return MHD_NO;
    parts *pt = bk->parts;
    if (*size && pt) {
        size_t n = *size;
        *size = 0;
        if (pt->err[0]) /* answered at the end, as 413 is */
            return obsd__discard_body(r, n, pt->max);
        if (MHD_post_process(bk->pp, data, n) != MHD_YES && !pt->err[0])
            snprintf(pt->err, sizeof pt->err, "the multipart/form-data body is malformed");
        return MHD_YES;
    }
    if (*size)
        return obsd__append_body(r, data, size, (size_t)h->front.cfg->max_level);
    char msg[320];
    if (r->too_big) {
        snprintf(msg, sizeof msg, "level is over the limit of %lld bytes (--max-level)",
                 (long long)h->front.cfg->max_level);
        return obsd__answer_error(r, 413, "body_too_large", msg, NULL, NULL);
    }
    if (pt) {
        if (parts_end(r, pt) != 0)
            return pt->too_large ? obsd__answer_error(r, 413, "body_too_large", pt->err, NULL, NULL)
                                 : obsd__answer_error(r, 400, "bad_multipart", pt->err, NULL, NULL);
        free(r->body); /* the level part in its place */
        r->body = pt->buf[0];
        r->len = pt->len[0];
        r->cap = pt->cap[0];
        pt->buf[0] = NULL;
    }
    if (r->len == 0)
        return obsd__answer_error(r, 400, "empty_body",
                                  "POST /v1/bakes needs a level (glTF/GLB, AC3D, OBJ, ...) as its body", NULL, NULL);
    const char *ext = bk->ext[0] ? bk->ext : sniff(r->body, r->len);
    if (!ext)
        return obsd__answer_error(r, 415, "unsupported_media_type",
                                  "cannot tell the level's format from its first bytes: give format=EXT "
                                  "(glb, gltf, ac, obj, fbx, ... as assimp names them)", NULL, NULL);
    char *decor = NULL; /* the decorators part, checked as the bake reads it */
    size_t rules = 0;
    if (pt && pt->seen[1]) {
        decor = pt->buf[1] ? (char *)pt->buf[1] : strdup(""); /* an empty part: an empty file */
        pt->buf[1] = NULL;
        if (!decor)
            return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the decorators");
        char derr[OBS_ERR_LEN];
        if (obs_bake_decorators_check(decor, &rules, derr) != OBS_OK) {
            free(decor);
            return obsd__answer_error(r, 400, "bad_decorators", derr, NULL, NULL);
        }
    }
    char id[OBSD_BAKE_ID_LEN + 1];
    unsigned char *level = r->body;
    size_t len = r->len;
    r->body = NULL; /* the job has it */
    r->cap = 0;
    int rc = obsd_bakes_submit(h->bakes, level, len, ext, decor, rules, &bk->params, id);
    if (rc == -1) {
        snprintf(msg, sizeof msg, "%d bake jobs are queued or running (--max-bakes); retry later",
                 h->front.cfg->max_bakes);
        return obsd__answer_error(r, 503, "bake_queue_full", msg, MHD_HTTP_HEADER_RETRY_AFTER, "10");
    }
    if (rc == -2)
        return obsd__answer_shutting_down(r);
    if (rc != 0)
        return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the bake job");
    char *text = malloc(512);
    if (!text)
        return MHD_NO;
    int n = snprintf(text, 512,
                     "{\"id\":\"%s\",\"state\":\"queued\",\"format\":\"%s\",\"status\":\"/v1/bakes/%s\","
                     "\"events\":\"/v1/bakes/%s/events\",\"result\":\"/v1/bakes/%s/result\"}",
                     id, ext, id, id, id);
    struct MHD_Response *resp = MHD_create_response_from_buffer((size_t)n, text, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        free(text);
        return MHD_NO;
    }
    char loc[64];
    snprintf(loc, sizeof loc, "/v1/bakes/%s", id);
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, "application/json");
    MHD_add_response_header(resp, MHD_HTTP_HEADER_LOCATION, loc);
    char note[64];
    snprintf(note, sizeof note, "bake=%s", id);
    return obsd__answer(r, 202, resp, (size_t)n, note);
}

/* ---- events -------------------------------------------------------------- */

static int next_event(req *r, char *buf, size_t len)
{
    bake_req *bk = r->own;
    return obsd_bakes_next_event(r->srv->bakes, &bk->sub, buf, len);
}

/* The job's subscriber (obsd__events_open): an unknown job is 404, one
 * the daemon is dropping (shutting down) 503. */
static int join(req *r, enum MHD_Result *rc)
{
    bake_req *bk = r->own;
    bk->sub = (obsd_bake_sub){.park = obsd__events_park, .wake = obsd__events_wake, .arg = r};
    int s = obsd_bakes_subscribe(r->srv->bakes, bk->id, &bk->sub);
    if (s != 0)
        *rc = s == -1 ? unknown(r) : obsd__answer_shutting_down(r);
    return s == 0;
}

static void leave(req *r)
{
    bake_req *bk = r->own;
    obsd_bakes_unsubscribe(r->srv->bakes, &bk->sub);
}

/* ---- the routes ------------------------------------------------------------- */

static enum MHD_Result result(req *r)
{
    bake_req *bk = r->own;
    unsigned char *data = NULL;
    size_t len = 0;
    obsd_bake_state st = OBSD_BAKE_QUEUED;
    int rc = obsd_bakes_result(r->srv->bakes, bk->id, &data, &len, &st);
    if (rc == -1)
        return unknown(r);
    if (rc == -3)
        return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the result");
    if (rc == 1) {
        char msg[192];
        snprintf(msg, sizeof msg, "bake %s is %s%s (GET /v1/bakes/%s says more)", bk->id,
                 obsd_bake_state_name(st), st == OBSD_BAKE_FAILED || st == OBSD_BAKE_CANCELLED ? ": no result" : "",
                 bk->id);
        return obsd__answer_error(r, 409,
                                  st == OBSD_BAKE_FAILED      ? "bake_failed"
                                  : st == OBSD_BAKE_CANCELLED ? "bake_cancelled"
                                                              : "bake_not_done",
                                  msg, NULL, NULL);
    }
    struct MHD_Response *resp = MHD_create_response_from_buffer(len, data, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        free(data);
        return MHD_NO;
    }
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, "model/gltf-binary");
    return obsd__answer(r, 200, resp, len, NULL);
}

static enum MHD_Result delete_job(req *r)
{
    bake_req *bk = r->own;
    obsd_bake_state st;
    int removed = 0;
    if (obsd_bakes_delete(r->srv->bakes, bk->id, &st, &removed) != 0)
        return unknown(r);
    char *text = malloc(160);
    if (!text)
        return MHD_NO;
    int n = snprintf(text, 160, "{\"id\":\"%s\",\"state\":\"%s\",\"removed\":%s%s}", bk->id,
                     obsd_bake_state_name(st), removed ? "true" : "false",
                     st == OBSD_BAKE_RUNNING ? ",\"cancel_requested\":true" : "");
    return obsd__answer_text(r, 200, "application/json", text, (size_t)n, NULL);
}

enum MHD_Result obsd__bakes_start(req *r, const char *url)
{
    obsd_http *h = r->srv;
    bake_req *bk = r->own = calloc(1, sizeof *bk);
    if (!bk)
        return obsd__answer_status(r, OBS_NO_MEMORY, "no memory for the request");
    int ok = parse_path(r, url);
    if (h->front.cfg->max_bakes < 1)
        return obsd__answer_error(r, 404, "bakes_off", "bake jobs are off (--max-bakes 0)", NULL, NULL);
    if (ok < 0)
        return obsd__answer_error(r, 404, "not_found", "a bake job's id is 16 hex digits, as POST /v1/bakes "
                                  "answered it", NULL, NULL);
    if (ok == 0)
        return obsd__answer_error(r, 404, "not_found", "no such route (" ROUTES ")", NULL, NULL);
    const char *allowed = bk->op == OP_LIST ? "GET, POST" : bk->op == OP_INFO ? "GET, DELETE" : "GET";
    int get = !strcmp(r->method, "GET") || !strcmp(r->method, "HEAD");
    if (!get && !(bk->op == OP_LIST && !strcmp(r->method, "POST")) &&
        !(bk->op == OP_INFO && !strcmp(r->method, "DELETE"))) {
        char msg[96];
        snprintf(msg, sizeof msg, "this /v1/bakes route takes %s", allowed);
        return obsd__answer_error(r, 405, "method_not_allowed", msg, MHD_HTTP_HEADER_ALLOW, allowed);
    }
    switch (bk->op) {
    case OP_LIST: {
        if (!get)
            return post_start(r);
        char *text = obsd_bakes_list_json(h->bakes);
        return text ? obsd__answer_text(r, 200, "application/json", text, strlen(text), NULL) : MHD_NO;
    }
    case OP_INFO: {
        if (!get)
            return delete_job(r);
        char *text = obsd_bakes_json(h->bakes, bk->id);
        return text ? obsd__answer_text(r, 200, "application/json", text, strlen(text), NULL) : unknown(r);
    }
    case OP_RESULT:
        return result(r);
    default:
        return obsd__events_open(r, &bk->events, join, next_event, leave);
    }
}

void obsd__bakes_done(req *r)
{
    bake_req *bk = r->own;
    if (!bk)
        return;
    obsd__events_close(r, &bk->events);
    if (bk->pp)
        MHD_destroy_post_processor(bk->pp);
    if (bk->parts) {
        free(bk->parts->buf[0]);
        free(bk->parts->buf[1]);
        free(bk->parts);
    }
    free(bk);
    r->own = NULL;
}
