/* Streams of frames for the preview page: a renderer posts frames to a
 * named stream, the daemon keeps the last few results of each in memory
 * and tells subscribers (Server-Sent Events) when a new one is there.
 *
 * Bounded: at most max_streams streams (the least recently posted-to one
 * is dropped to make room), at most max_frames frames per stream and
 * about max_bytes of frame data per stream (oldest frames dropped first;
 * the newest frame is always kept, and is itself bounded by --max-body and
 * --max-pixels).  A frame handed out with obsd_streams_get() stays valid
 * until released, even when the stream drops it meanwhile.
 *
 * No sockets here: a subscriber is parked and woken through callbacks
 * (the HTTP server suspends and resumes its connection).  Thread-safe. */
#ifndef OBSD_STREAM_STORE_H
#define OBSD_STREAM_STORE_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "obscura/obscura.h"

#define OBSD_STREAM_NAME_LEN 64   /* longest name, in characters */
#define OBSD_STREAM_MAX_SUBS 256  /* event subscribers over all streams */
#define OBSD_SSE_KEEPALIVE_MS 15000

/* One stored frame.  Filled by the poster, then owned by the store. */
typedef struct obsd_frame {
    atomic_int refs;
    uint64_t seq;          /* 1, 2, ... per stream; set by obsd_streams_add() */
    int width, height;
    unsigned char *body;   /* the G-buffer EXR as posted (for re-runs) */
    size_t body_len;
    char *query;           /* its query parameters: "name\0value\0" pairs */
    size_t query_len;      /* bytes of query */
    obs_image ao;          /* the AO (1 channel; deep input: the blended AO, AO.Y) */
    obs_image ao_front;    /* deep input: the front layer's AO (AOFront.Y); else empty */
    obs_image composite;   /* colour x AO (RGBA) */
    obs_image color;       /* the G-buffer's colour (RGBA); empty without one (and for deep input) */
    int deep;              /* the body is a deep EXR: it ran the multi-layer chain */
    obs_camera camera;
    obs_camera written;    /* the camera its EXR answers carry: the one it ran with (obsd_fp_camera) */
    int part;              /* the body's part the G-buffer was read from */
    double ms_queue, ms_decode, ms_gl; /* the stages of its run */
    double posted_unix;    /* seconds since the epoch */
} obsd_frame;

/* A zeroed frame holding one reference; NULL when out of memory. */
obsd_frame *obsd_frame_new(void);
/* Drops one reference; the last frees everything the frame holds. */
void obsd_frame_release(obsd_frame *f);
/* Bytes a frame holds (what max_bytes counts). */
size_t obsd_frame_bytes(const obsd_frame *f);

typedef struct obsd_streams obsd_streams;

/* An event subscriber.  The caller owns it (zeroed before subscribing)
 * and must unsubscribe before freeing it.  `park` is called, under the
 * store's lock, when there is nothing to send; `wake` later, under the
 * same lock, once there is (a new frame, the stream dropped, shutdown, a
 * keep-alive due).  Neither may call back into the store. */
typedef struct obsd_sub obsd_sub;
struct obsd_sub {
    void (*park)(void *arg);
    void (*wake)(void *arg);
    void *arg;
    /* the store's */
    struct obsd_stream *stream;
    uint64_t sent;      /* the newest frame announced */
    int parked, ended, said_end;
    double last_write_ms;
    obsd_sub *prev, *next;
};

obsd_streams *obsd_streams_new(int max_streams, int max_frames, int64_t max_bytes);
/* Every subscriber must have unsubscribed. */
void obsd_streams_free(obsd_streams *s);

/* 1 when `name` is 1..64 characters of [A-Za-z0-9._-]. */
int obsd_stream_name_ok(const char *name);

/* Adds the frame (the store takes the caller's reference) to stream
 * `name`, created when new; sets f->seq and returns it.  Subscribers are
 * woken. */
uint64_t obsd_streams_add(obsd_streams *s, const char *name, obsd_frame *f);

/* Frame `seq` (0: the newest) of stream `name`, with a reference the
 * caller releases; NULL when there is none.  *stream_found tells whether
 * the stream exists. */
obsd_frame *obsd_streams_get(obsd_streams *s, const char *name, uint64_t seq, int *stream_found);

/* JSON: {"streams": [{"name", "frames": [seq...], "latest", "width",
 * "height", "updated", "subscribers"}]}.  Caller frees with free(). */
char *obsd_streams_list_json(obsd_streams *s);
/* JSON of one stream with each kept frame's size, timings, whether it
 * is deep, its parameters (the query it was posted with) and its camera
 * (fov_y, near, far as the projection it ran with says, when it had one:
 * a camera from the file shows there, not as a parameter); NULL when it
 * does not exist (or out of memory). */
char *obsd_streams_stream_json(obsd_streams *s, const char *name, int *found);

/* Subscribes to stream `name` (created, empty, when new and there is
 * room: a subscriber never drops a stream).  -1: too many subscribers
 * (OBSD_STREAM_MAX_SUBS), no room for a new stream, or out of memory. */
int obsd_streams_subscribe(obsd_streams *s, const char *name, obsd_sub *sub, double now_ms);
void obsd_streams_unsubscribe(obsd_streams *s, obsd_sub *sub);

/* The next event text for `sub` into buf (at most len bytes; 512 are
 * always enough): the newest frame when it has not been announced, a
 * keep-alive comment when nothing was written for OBSD_SSE_KEEPALIVE_MS,
 * an `end` event once the stream was dropped or the store ended.
 * Returns its length; 0 after parking the subscriber (nothing to send);
 * -1 when the end was said (close the stream). */
int obsd_streams_next_event(obsd_streams *s, obsd_sub *sub, char *buf, size_t len, double now_ms);

/* Wakes parked subscribers whose keep-alive is due. */
void obsd_streams_tick(obsd_streams *s, double now_ms);
/* Shutdown: every subscriber gets its `end` and is woken; no new ones. */
void obsd_streams_end_all(obsd_streams *s);

/* For /metrics. */
void obsd_streams_gauges(obsd_streams *s, int *streams, int *frames, uint64_t *bytes, int *subscribers);

#endif
