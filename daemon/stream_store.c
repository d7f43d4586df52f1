/* The stream store behind /v1/streams (see stream_store.h). */
#include "stream_store.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "list.h"
#include "obscura/mask.h"

typedef struct obsd_stream obsd_stream;
struct obsd_stream {
    char name[OBSD_STREAM_NAME_LEN + 1];
    obsd_frame **frames;   /* oldest first */
    int count;
    uint64_t next_seq;
    size_t bytes;
    uint64_t touched;      /* store clock at the last post (LRU) */
    double updated_unix;
    int dropped;           /* out of the list; freed with its last subscriber */
    obsd_sub *subs;
    int nsubs;
    obsd_stream *next;
};

struct obsd_streams {
    pthread_mutex_t lock;
    obsd_stream *list;
    int nstreams, nsubs;
    int max_streams, max_frames;
    int64_t max_bytes;
    uint64_t clock;
    int ended;
};

/* ---- frames ---------------------------------------------------------- */

obsd_frame *obsd_frame_new(void)
{
    obsd_frame *f = calloc(1, sizeof *f);
    if (f)
        atomic_init(&f->refs, 1);
    return f;
}

void obsd_frame_release(obsd_frame *f)
{
    if (!f || atomic_fetch_sub(&f->refs, 1) != 1)
        return;
    free(f->body);
    free(f->query);
    obs_image_free(&f->ao);
    obs_image_free(&f->ao_front);
    obs_image_free(&f->composite);
    obs_image_free(&f->color);
    free(f);
}

static size_t image_bytes(const obs_image *im)
{
    return im->data ? (size_t)im->width * (size_t)im->height * (size_t)im->channels * sizeof(float) : 0;
}

size_t obsd_frame_bytes(const obsd_frame *f)
{
    return sizeof *f + f->body_len + f->query_len + image_bytes(&f->ao) + image_bytes(&f->ao_front) +
           image_bytes(&f->composite) +
           image_bytes(&f->color);
}

/* ---- streams --------------------------------------------------------- */

int obsd_stream_name_ok(const char *name)
{
    size_t n = name ? strlen(name) : 0;
    if (n == 0 || n > OBSD_STREAM_NAME_LEN)
        return 0;
    for (size_t i = 0; i < n; i++) {
        char c = name[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
              c == '_' || c == '-'))
            return 0;
    }
    return 1;
}

obsd_streams *obsd_streams_new(int max_streams, int max_frames, int64_t max_bytes)
{
    obsd_streams *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    pthread_mutex_init(&s->lock, NULL);
    s->max_streams = max_streams;
    s->max_frames = max_frames < 1 ? 1 : max_frames;
    s->max_bytes = max_bytes;
    return s;
}

static void stream_free(obsd_stream *st)
{
    for (int i = 0; i < st->count; i++)
        obsd_frame_release(st->frames[i]);
    free(st->frames);
    free(st);
}

void obsd_streams_free(obsd_streams *s)
{
    if (!s)
        return;
    for (obsd_stream *st = s->list, *next; st; st = next) {
        next = st->next;
        stream_free(st);
    }
    pthread_mutex_destroy(&s->lock);
    free(s);
}

static double unix_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

static obsd_stream *find(obsd_streams *s, const char *name)
{
    for (obsd_stream *st = s->list; st; st = st->next)
        if (!strcmp(st->name, name))
            return st;
    return NULL;
}

static void wake_all(obsd_stream *st)
{
    for (obsd_sub *u = st->subs; u; u = u->next)
        if (u->parked) {
            u->parked = 0;
            u->wake(u->arg);
        }
}

/* Takes `st` out of the list: its frames go, its subscribers are told. */
static void drop(obsd_streams *s, obsd_stream *st)
{
    obsd_stream **pp = &s->list;
    while (*pp && *pp != st)
        pp = &(*pp)->next;
    if (*pp)
        *pp = st->next;
    s->nstreams--;
    st->dropped = 1;
    for (obsd_sub *u = st->subs; u; u = u->next)
        u->ended = 1;
    wake_all(st);
    if (st->nsubs == 0)
        stream_free(st);
}

/* The stream named, created when new (when full, dropping the least
 * recently posted-to stream if may_drop); NULL when out of memory, full or
 * streams are off. */
static obsd_stream *get_or_create(obsd_streams *s, const char *name, int may_drop)
{
    obsd_stream *st = find(s, name);
    if (st || s->max_streams < 1 || (!may_drop && s->nstreams >= s->max_streams))
        return st;
    while (s->nstreams >= s->max_streams && s->list) {
        obsd_stream *lru = s->list;
        for (obsd_stream *t = s->list; t; t = t->next)
            if (t->touched < lru->touched)
                lru = t;
        drop(s, lru);
    }
    if (!(st = calloc(1, sizeof *st)) || !(st->frames = calloc((size_t)s->max_frames, sizeof *st->frames))) {
        free(st);
        return NULL;
    }
    snprintf(st->name, sizeof st->name, "%s", name);
    st->next_seq = 1;
    st->touched = ++s->clock;
    st->next = s->list;
    s->list = st;
    s->nstreams++;
    return st;
}

uint64_t obsd_streams_add(obsd_streams *s, const char *name, obsd_frame *f)
{
    uint64_t seq = 0;
    pthread_mutex_lock(&s->lock);
    obsd_stream *st = obsd_stream_name_ok(name) ? get_or_create(s, name, 1) : NULL;
    if (!st) {
        pthread_mutex_unlock(&s->lock);
        obsd_frame_release(f);
        return 0;
    }
    f->seq = seq = st->next_seq++;
    f->posted_unix = unix_now();
    size_t fb = obsd_frame_bytes(f);
    /* oldest out while over either bound; the new frame always stays */
    while (st->count > 0 &&
           (st->count >= s->max_frames || (int64_t)(st->bytes + fb) > s->max_bytes)) {
        obsd_frame *old = st->frames[0];
        st->bytes -= obsd_frame_bytes(old);
        memmove(st->frames, st->frames + 1, (size_t)(st->count - 1) * sizeof *st->frames);
        st->count--;
        obsd_frame_release(old);
    }
    st->frames[st->count++] = f;
    st->bytes += fb;
    st->touched = ++s->clock;
    st->updated_unix = f->posted_unix;
    wake_all(st);
    pthread_mutex_unlock(&s->lock);
    return seq;
}

obsd_frame *obsd_streams_get(obsd_streams *s, const char *name, uint64_t seq, int *stream_found)
{
    obsd_frame *f = NULL;
    pthread_mutex_lock(&s->lock);
    obsd_stream *st = find(s, name);
    if (stream_found)
        *stream_found = st != NULL;
    if (st && st->count > 0) {
        if (seq == 0) {
            f = st->frames[st->count - 1];
        } else {
            for (int i = 0; i < st->count; i++)
                if (st->frames[i]->seq == seq)
                    f = st->frames[i];
        }
        if (f)
            atomic_fetch_add(&f->refs, 1);
    }
    pthread_mutex_unlock(&s->lock);
    return f;
}

/* ---- JSON ------------------------------------------------------------ */

static void add_timings(cJSON *o, const obsd_frame *f)
{
    cJSON *t = cJSON_AddObjectToObject(o, "timings");
    if (!t)
        return;
    cJSON_AddNumberToObject(t, "queue", f->ms_queue);
    cJSON_AddNumberToObject(t, "decode", f->ms_decode);
    cJSON_AddNumberToObject(t, "gl", f->ms_gl);
}

/* The query the frame was posted with, keyed by the table's snake_case
 * names ('fov-y' and 'fov_y' are one parameter; the last given wins, as
 * the request parser reads them). */
static void add_params(cJSON *o, const obsd_frame *f)
{
    cJSON *q = cJSON_AddObjectToObject(o, "params");
    for (size_t k = 0; q && k + 1 < f->query_len;) {
        const char *key = f->query + k, *val = key + strlen(key) + 1;
        char name[64];
        snprintf(name, sizeof name, "%s", key);
        for (char *c = name; *c; c++)
            if (*c == '-')
                *c = '_';
        cJSON_DeleteItemFromObjectCaseSensitive(q, name);
        cJSON_AddStringToObject(q, name, val);
        k = (size_t)(val - f->query) + strlen(val) + 1;
    }
}

/* Six significant digits: what a control shows, not 49.99999809. */
static double rounded(double v)
{
    char buf[32];
    snprintf(buf, sizeof buf, "%.6g", v);
    return strtod(buf, NULL);
}

/* fov_y (degrees), near and far of the perspective projection the frame
 * ran with, whichever gave it (the parameters, the file's worldToNDC, a
 * camera JSON), inverted from the OpenGL matrix as clients/remote.c
 * does: P[5] = 1/tan(fov/2), P[10] = -(f+n)/(f-n), P[11] = -2fn/(f-n).
 * Left out for no projection or an orthographic one (P[14] = 0). */
static void add_camera(cJSON *o, const obs_camera *c)
{
    const float *p = c->projection;
    if (!c->has_projection || p[14] != -1.0f || p[5] <= 0.0f || p[10] == 1.0f || p[10] == -1.0f)
        return;
    cJSON *cam = cJSON_AddObjectToObject(o, "camera");
    if (!cam)
        return;
    cJSON_AddNumberToObject(cam, "fov_y", rounded(2.0 * atan(1.0 / p[5]) * 180.0 / M_PI));
    cJSON_AddNumberToObject(cam, "near", rounded(p[11] / (p[10] - 1.0)));
    cJSON_AddNumberToObject(cam, "far", rounded(p[11] / (p[10] + 1.0)));
}

static cJSON *stream_summary(const obsd_stream *st)
{
    cJSON *o = cJSON_CreateObject(), *fr;
    if (!o)
        return NULL;
    cJSON_AddStringToObject(o, "name", st->name);
    fr = cJSON_AddArrayToObject(o, "frames");
    for (int i = 0; fr && i < st->count; i++)
        cJSON_AddItemToArray(fr, cJSON_CreateNumber((double)st->frames[i]->seq));
    const obsd_frame *last = st->count ? st->frames[st->count - 1] : NULL;
    cJSON_AddNumberToObject(o, "latest", last ? (double)last->seq : 0);
    cJSON_AddNumberToObject(o, "width", last ? last->width : 0);
    cJSON_AddNumberToObject(o, "height", last ? last->height : 0);
    cJSON_AddNumberToObject(o, "updated", st->updated_unix);
    cJSON_AddNumberToObject(o, "subscribers", st->nsubs);
    cJSON_AddNumberToObject(o, "bytes", (double)st->bytes);
    return o;
}

char *obsd_streams_list_json(obsd_streams *s)
{
    cJSON *root = cJSON_CreateObject(), *arr;
    char *out = NULL;
    if (!root)
        return NULL;
    pthread_mutex_lock(&s->lock);
    if ((arr = cJSON_AddArrayToObject(root, "streams")))
        for (obsd_stream *st = s->list; st; st = st->next)
            cJSON_AddItemToArray(arr, stream_summary(st));
    cJSON_AddNumberToObject(root, "max_streams", s->max_streams);
    cJSON_AddNumberToObject(root, "max_frames", s->max_frames);
    cJSON_AddNumberToObject(root, "max_bytes", (double)s->max_bytes);
    pthread_mutex_unlock(&s->lock);
    out = cJSON_Print(root);
    cJSON_Delete(root);
    return out;
}

/* What the object-mask selectors of a frame can name (the preview page's
 * receivers/occluders control): each Cryptomatte layer's names and the ID
 * channels, from the body's header (no pixel is decoded); neither key
 * when the frame has none. */
static void add_objects(cJSON *fo, const obsd_frame *f)
{
    obs_crypto_info ci;
    char err[OBS_ERR_LEN];
    if (!f->body || obs_crypto_describe(NULL, f->body, f->body_len, &ci, err) != OBS_OK)
        return;
    if (!ci.layer_count && !ci.id_count) { /* nothing to name: no keys */
        obs_crypto_info_free(&ci);
        return;
    }
    cJSON *layers = cJSON_AddArrayToObject(fo, "cryptomatte");
    for (int i = 0; layers && i < ci.layer_count; i++) {
        cJSON *l = cJSON_CreateObject(), *names = cJSON_CreateArray();
        cJSON_AddItemToArray(layers, l);
        cJSON_AddStringToObject(l, "name", ci.layers[i].name);
        cJSON_AddStringToObject(l, "manifest_error", ci.layers[i].manifest_error);
        for (int k = 0; k < ci.layers[i].entry_count; k++)
            cJSON_AddItemToArray(names, cJSON_CreateString(ci.layers[i].names[k]));
        cJSON_AddItemToObject(l, "names", names);
    }
    cJSON *ids = cJSON_AddArrayToObject(fo, "id_channels");
    for (int i = 0; ids && i < ci.id_count; i++)
        cJSON_AddItemToArray(ids, cJSON_CreateString(ci.id_channels[i]));
    obs_crypto_info_free(&ci);
}

char *obsd_streams_stream_json(obsd_streams *s, const char *name, int *found)
{
    char *out = NULL;
    pthread_mutex_lock(&s->lock);
    obsd_stream *st = find(s, name);
    *found = st != NULL;
    cJSON *o = st ? stream_summary(st) : NULL, *list = o ? cJSON_AddArrayToObject(o, "frame_info") : NULL;
    for (int i = 0; list && i < st->count; i++) {
        const obsd_frame *f = st->frames[i];
        cJSON *fo = cJSON_CreateObject();
        if (!fo)
            break;
        cJSON_AddItemToArray(list, fo);
        cJSON_AddNumberToObject(fo, "frame", (double)f->seq);
        cJSON_AddNumberToObject(fo, "width", f->width);
        cJSON_AddNumberToObject(fo, "height", f->height);
        cJSON_AddBoolToObject(fo, "color", f->color.data != NULL);
        cJSON_AddBoolToObject(fo, "deep", f->deep);
        cJSON_AddNumberToObject(fo, "posted", f->posted_unix);
        add_timings(fo, f);
        add_params(fo, f);
        add_camera(fo, &f->camera);
        add_objects(fo, f);
    }
    pthread_mutex_unlock(&s->lock);
    if (o) {
        out = cJSON_Print(o);
        cJSON_Delete(o);
    }
    return out;
}

/* ---- subscribers ----------------------------------------------------- */

int obsd_streams_subscribe(obsd_streams *s, const char *name, obsd_sub *sub, double now_ms)
{
    int rc = -1;
    pthread_mutex_lock(&s->lock);
    obsd_stream *st = NULL;
    if (!s->ended && s->nsubs < OBSD_STREAM_MAX_SUBS && obsd_stream_name_ok(name))
        st = get_or_create(s, name, 0); /* a subscriber makes room for no one */
    if (st) {
        sub->stream = st;
        sub->sent = 0;
        sub->parked = sub->ended = sub->said_end = 0;
        sub->last_write_ms = now_ms;
        OBSD_LIST_PUSH(st->subs, sub);
        st->nsubs++;
        s->nsubs++;
        rc = 0;
    }
    pthread_mutex_unlock(&s->lock);
    return rc;
}

void obsd_streams_unsubscribe(obsd_streams *s, obsd_sub *sub)
{
    pthread_mutex_lock(&s->lock);
    obsd_stream *st = sub->stream;
    if (st) {
        OBSD_LIST_UNLINK(st->subs, sub);
        st->nsubs--;
        s->nsubs--;
        sub->stream = NULL;
        if (st->dropped && st->nsubs == 0)
            stream_free(st);
    }
    pthread_mutex_unlock(&s->lock);
}

int obsd_streams_next_event(obsd_streams *s, obsd_sub *sub, char *buf, size_t len, double now_ms)
{
    int n = 0;
    pthread_mutex_lock(&s->lock);
    obsd_stream *st = sub->stream;
    const obsd_frame *last = st && st->count ? st->frames[st->count - 1] : NULL;
    if (sub->said_end || !st) {
        n = -1;
    } else if (last && last->seq > sub->sent && !sub->ended) {
        sub->sent = last->seq;
        n = snprintf(buf, len,
                     "event: frame\nid: %llu\ndata: {\"stream\":\"%s\",\"frame\":%llu,\"width\":%d,"
                     "\"height\":%d,\"color\":%s,\"deep\":%s,\"timings\":{\"queue\":%.2f,\"decode\":%.2f,\"gl\":%.2f}}"
                     "\n\n",
                     (unsigned long long)last->seq, st->name, (unsigned long long)last->seq, last->width,
                     last->height, last->color.data ? "true" : "false", last->deep ? "true" : "false", last->ms_queue, last->ms_decode,
                     last->ms_gl);
    } else if (sub->ended || s->ended) {
        sub->said_end = 1;
        n = snprintf(buf, len, "event: end\ndata: {\"stream\":\"%s\",\"reason\":\"%s\"}\n\n", st->name,
                     s->ended ? "shutting down" : "stream dropped");
    } else if (now_ms - sub->last_write_ms >= OBSD_SSE_KEEPALIVE_MS) {
        n = snprintf(buf, len, ": keep-alive\n\n");
    } else {
        sub->parked = 1;
        sub->park(sub->arg);
    }
    if (n > 0) {
        if ((size_t)n >= len)
            n = (int)len - 1;
        sub->last_write_ms = now_ms;
    }
    pthread_mutex_unlock(&s->lock);
    return n;
}

void obsd_streams_tick(obsd_streams *s, double now_ms)
{
    pthread_mutex_lock(&s->lock);
    for (obsd_stream *st = s->list; st; st = st->next)
        for (obsd_sub *u = st->subs; u; u = u->next)
            if (u->parked && now_ms - u->last_write_ms >= OBSD_SSE_KEEPALIVE_MS) {
                u->parked = 0;
                u->wake(u->arg);
            }
    pthread_mutex_unlock(&s->lock);
}

void obsd_streams_end_all(obsd_streams *s)
{
    pthread_mutex_lock(&s->lock);
    s->ended = 1;
    for (obsd_stream *st = s->list; st; st = st->next) {
        for (obsd_sub *u = st->subs; u; u = u->next)
            u->ended = 1;
        wake_all(st);
    }
    pthread_mutex_unlock(&s->lock);
}

void obsd_streams_gauges(obsd_streams *s, int *streams, int *frames, uint64_t *bytes, int *subscribers)
{
    int nf = 0;
    uint64_t nb = 0;
    pthread_mutex_lock(&s->lock);
    for (obsd_stream *st = s->list; st; st = st->next) {
        nf += st->count;
        nb += st->bytes;
    }
    *streams = s->nstreams;
    *frames = nf;
    *bytes = nb;
    *subscribers = s->nsubs;
    pthread_mutex_unlock(&s->lock);
}
