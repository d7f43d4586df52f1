/* Shared by the parts of obscurad's HTTP server.  Not a public header.
 * Calls go one way: http_server.c dispatches through the route table
 * (routes.c) to http_frames.c, http_streams.c, http_bakes.c, http_info.c
 * and http_page.c; they all answer through
 * http_reply.c; http_streams.c also uses http_frames.c for its frames;
 * http_conn.c (the connections' records) is below them all. */
#ifndef OBSD_HTTP_INTERNAL_H
#define OBSD_HTTP_INTERNAL_H

#include <microhttpd.h>
#include <pthread.h>
#include <stdatomic.h>

#include "bake_jobs.h"
#include "frame_path.h"
#include "http.h"
#include "front.h"
#include "obscura/io.h"
#include "stats.h"
#include "stream_store.h"

/* Connections kept beyond --http-connections for /healthz and /readyz. */
#define OBSD_HTTP_RESERVE 16

/* Why a connection was shut down from outside its MHD thread. */
enum { CUT_NONE, CUT_DEADLINE, CUT_EVICTED, CUT_DRAIN, CUT_GONE /* an event stream's client left */ };

/* One open connection (http_server.c keeps the list, under obsd_http's
 * lock): its deadline, for the sweeper thread, and its request, for the
 * drain's cut. */
typedef struct obsd__conn {
    struct obsd__conn *prev, *next;
    struct MHD_Connection *mc;
    int fd;
    char peer[64];
    char ip[46];              /* the peer's address alone (INET6_ADDRSTRLEN), for --max-per-client */
    int over_client;          /* one more than --max-per-client from its address: answered 503, closed */
    double deadline;          /* obsd_now_ms() past which it is cut; 0: none */
    struct obsd__req *r;      /* the request under way; NULL before its headers, or idle */
    int reserve;              /* opened beyond --http-connections: probes only */
    atomic_int events;        /* answering an event stream: the sweeper watches for the client leaving */
    atomic_int cut;           /* CUT_*: shut down, MHD closes it next */
} obsd__conn;

/* The server (obsd_http in http_server.h, which only http_server.c and
 * obscurad.c include: the handlers reach the server through this
 * struct, and http_server.c reaches them through the route table). */
typedef struct obsd_http obsd_http;
struct obsd_http {
    struct MHD_Daemon *mhd;
    obsd_front front;
    obsd_streams *streams;
    obsd_bakes *bakes;
    int port;
    MHD_socket listen_fd;
    atomic_int in_flight;
    atomic_int draining;
    atomic_uint_fast64_t next_id;
    /* the open connections (oldest first), their count and the sweeper */
    pthread_mutex_t lock;
    obsd__conn *conns, *conns_tail;
    int open, evicting;
    pthread_t sweeper;
    int sweeper_running;
    atomic_int sweeper_stop;
    int family; /* AF_INET or AF_INET6 */
    char host[OBSD_STR_LEN]; /* as --http gave it, for the log */
};

/* A frame's trip to the GL worker, for the drain's cut (obsd_http_cut):
 * the one that moves a request out of JOB_PENDING resumes it. */
enum {
    JOB_NONE,
    JOB_PENDING,   /* queued, the connection suspended */
    JOB_DONE,      /* claimed by the worker, which resumes the connection */
    JOB_CUT,       /* resumed by the cut: the connection closes; the job runs on */
    JOB_CUT_DONE,  /* the job ended after the cut */
    JOB_ORPHAN     /* the connection is gone first: the worker frees the request */
};

typedef enum obsd__req_state {
    REQ_NEW,
    REQ_DEFERRED, /* no body: answered on the next call, so that the connection can stay open */
    REQ_BODY,     /* reading the body of a frame (POST /v1/ao, a stream's frames) */
    REQ_QUEUED,   /* suspended; the GL worker has the job */
    REQ_REFUSED,  /* suspended and resumed at once: the queue was full */
    REQ_EVENTS,   /* answering with Server-Sent Events */
    REQ_HELD,     /* answered while the client still sends its body: the body is
                     discarded and the answer queued at its end (obsd__answer) */
    REQ_ANSWERED
} obsd__req_state;

/* A frame's request (http_frames.c's: POST /v1/ao, and the streams'
 * frames posted, viewed or re-run): its query, its trip through the frame
 * path, the view of its answer.  Freed with the request (the GL worker
 * may outlive the connection). */
typedef struct obsd__frame_req {
    obs_http_request hr;
    obsd_fp fp;          /* the frame: its input, job, result and stage times */
    int before_drain;    /* started before SIGTERM: finished in the drain */
    int kept;            /* a stream's frame (flat or deep): its body and query are kept with it */
    int view;            /* a kept frame's GET: exposure, output=color|ao_front view it, other parameters re-run it */
    char *query;         /* kept: the query as "name\0value\0" pairs */
    size_t query_len, query_cap;
    int want_color;      /* output=color */
    int want_front;      /* output=ao_front: a deep frame's front layer's AO */
    int rerun;           /* view with parameters: run the frame again */
    double exposure;     /* stops applied to colour PNGs */
} obsd__frame_req;

/* An event stream's answer (http_events.c): `next` writes the source's
 * next event into buf and returns its length; 0: none yet (the source
 * parked the connection, obsd__events_park, and wakes it); -1: the end.
 * `leave` unsubscribes the request from its source (set while it is
 * subscribed). */
typedef struct obsd__events {
    int (*next)(struct obsd__req *r, char *buf, size_t len);
    void (*leave)(struct obsd__req *r);
    struct obsd__req *r;
    char buf[512];
    int len, off;
} obsd__events;

/* One request: what every route has (its connection, route, state, body,
 * answer and times); what only one route needs is behind `fr` and `own`. */
typedef struct obsd__req {
    obsd_http *srv;
    struct MHD_Connection *conn;
    obsd__conn *cn;      /* its connection's record */
    atomic_int job;      /* JOB_* */
    uint64_t id;
    const struct obsd__route *route; /* its row of the route table; NULL: no such route */
    int slot;            /* its counters' slot (stats.h) */
    const char *label;   /* the route's label in the log and the metrics ("other": none) */
    int frame_total;     /* its answer ends a frame: timed as the `total` stage */
    obsd__req_state state;
    char method[8];
    char peer[64];
    char path[128];      /* the URL's path, for the log */
    double t0;
    double t_answered;   /* its answer queued (obsd_now_ms()), for the `send` stage */
    /* its body (a frame's, a level's) */
    unsigned char *body;
    size_t len, cap;
    int too_big;
    size_t discarded;    /* bytes thrown away after too_big, or under a held answer */
    /* The client is sending a body that MHD has not all handed over: an
     * answer queued now would close the connection with unread input,
     * and the kernel's reset would destroy the answer at the client.  So
     * the answer is held (REQ_HELD) until the body's end, discarding it up
     * to hold_max bytes and within --request-timeout. */
    int body_in;
    size_t hold_max;
    struct MHD_Response *held;
    int held_status;
    size_t held_len;
    char *held_note;
    obsd__frame_req *fr; /* the frame it carries (http_frames.c), or NULL */
    void *own;           /* its route's own state (http_streams.c, http_bakes.c), freed by the row's done */
    /* answer */
    int status;
    size_t bytes_out;
} obsd__req;

/* ---- http_conn.c: the open connections ---- */

/* MHD_OPTION_NOTIFY_CONNECTION: a connection's record made, or freed. */
void obsd__conn_notify(void *cls, struct MHD_Connection *mc, void **socket_context,
                       enum MHD_ConnectionNotificationCode toe);
/* The thread that cuts connections past their deadline (until
 * h->sweeper_stop). */
void *obsd__conn_sweeper(void *arg);
/* A request's first call: it is the connection's request now; 1 when
 * the deadline passed already (the caller answers 408). */
int obsd__conn_attach(obsd_http *h, obsd__conn *c, obsd__req *r, double now);
/* The request ended: the connection's next one gets its deadline. */
void obsd__conn_detach(obsd_http *h, obsd__conn *c);
/* The request is whole (or answered): its deadline no longer runs.  0
 * when the connection was cut already (the caller returns MHD_NO). */
int obsd__req_hold(obsd__req *r);
/* A call with more of the body: 0 when the connection was cut, or is
 * now, past its deadline (the caller returns MHD_NO). */
int obsd__req_alive(obsd__req *r);
/* Frees a request (not its connection's record). */
void obsd__req_free(obsd__req *r);

/* ---- http_reply.c: answers, each logged and counted ---- */


/* Queues `resp` (taking it) with status; logs and counts the request.
 * While the client still sends its body (r->body_in), the answer is held
 * instead (REQ_HELD) and the caller goes on as if it were queued. */
enum MHD_Result obsd__answer(obsd__req *r, int status, struct MHD_Response *resp, size_t body_len,
                             const char *note);
/* The held answer queued, at the end of the discarded body. */
enum MHD_Result obsd__answer_held(obsd__req *r);
/* A body of `len` bytes that the answer frees. */
enum MHD_Result obsd__answer_text(obsd__req *r, int status, const char *type, char *text, size_t len,
                                  const char *note);
/* The JSON error; one extra header (name, value) when hname is set. */
enum MHD_Result obsd__answer_error(obsd__req *r, int status, const char *code, const char *msg,
                                   const char *hname, const char *hvalue);
/* 204 to a browser's OPTIONS preflight (--cors): the route's methods,
 * the headers a page may send, how long the browser may keep it. */
enum MHD_Result obsd__answer_preflight(obsd__req *r, const char *methods);
/* 503 shutting_down (Retry-After: 5): the drain refuses what would start. */
enum MHD_Result obsd__answer_shutting_down(obsd__req *r);
/* The error of a core status (503 with Retry-After). */
enum MHD_Result obsd__answer_status(obsd__req *r, obs_status s, const char *msg);
/* Answers with images as r->fr->hr asks (format, float, png_bits), a colour
 * PNG exposed by r->fr->exposure.  With `timing`, a Server-Timing header. */
enum MHD_Result obsd__answer_images(obsd__req *r, const obsd_fp_images *im, const obs_camera *cam, int timing,
                                    const char *extra_name, const char *extra_value);

/* ---- http_query.c: a request's query arguments ------------------------ */

/* A route's reader of one query argument (value "" when it has none):
 * OBS_OK, or an error with its message in err. */
typedef obs_status (*obsd__arg_fn)(obsd__req *r, const char *key, const char *value,
                                   char err[OBS_ERR_LEN]);
/* Every query argument of r through fn, in order, up to the first error
 * (one with a NUL byte is an error before fn sees it): OBS_OK or that
 * error, its message in err. */
obs_status obsd__query_args(obsd__req *r, obsd__arg_fn fn, char err[OBS_ERR_LEN]);

/* ---- http_frames.c: a frame's query, body and trip to the GL worker ---- */

/* The start of a frame's request: query, Content-Type, Content-Length,
 * a full queue; then the body is read (REQ_BODY). */
enum MHD_Result obsd__frame_start(obsd__req *r, const char *url);
/* A call in REQ_BODY: `size` bytes of the body, or (size 0) its end,
 * when the frame is decoded and queued. */
enum MHD_Result obsd__frame_body(obsd__req *r, const char *data, size_t *size);
/* The request's Content-Length, when it has one, against max: over it
 * (or unreadable), 413 naming the `what` and its option `flag` is
 * answered (returns 0, *rc set); else the body's buffer is sized by it
 * when `keep` (a body kept whole; a multipart one is not).  1: go on. */
int obsd__body_expect(obsd__req *r, size_t max, const char *what, const char *flag, int keep,
                      enum MHD_Result *rc);
/* Appends `size` bytes of a body up to max bytes (then r->too_big, the
 * rest discarded, the connection closed past twice max). */
enum MHD_Result obsd__append_body(obsd__req *r, const char *data, size_t *size, size_t max);
/* n more bytes of a body thrown away after an error that is answered at
 * its end (libmicrohttpd cannot answer in the middle of a body): MHD_NO,
 * closing the connection, once they are over max. */
enum MHD_Result obsd__discard_body(obsd__req *r, size_t n, size_t max);
/* *buf of *cap bytes grown (doubling from 64 KiB, at most max unless need
 * is more) to hold need bytes: 0, or -1 on no memory (*buf unchanged). */
int obsd__reserve(unsigned char **buf, size_t *cap, size_t need, size_t max);
/* The request's query parameters into r->fr->hr (recorded into its query
 * when kept); 400 answered on a bad one (returns 0, *rc set). */
int obsd__parse_query(obsd__req *r, enum MHD_Result *rc);
/* The request's frame state (r->fr), made on the first call; NULL on no
 * memory. */
obsd__frame_req *obsd__frame_req_new(obsd__req *r);
/* Decodes `body` into r->fr's frame with its query's channel map (a deep EXR on
 * POST /v1/ao only), queues the frame (outputs) and suspends the
 * connection; answers the error itself. */
enum MHD_Result obsd__queue_frame(obsd__req *r, const unsigned char *body, size_t len, unsigned outputs);
/* POST /v1/ao, resumed by the GL worker: the answer. */
enum MHD_Result obsd__ao_finish(obsd__req *r);

/* ---- http_streams.c: /v1/streams ---- */

/* The first call of a request (token checked); the call after the GL
 * worker resumed it; the end of a request. */
enum MHD_Result obsd__streams_start(obsd__req *r, const char *url);
enum MHD_Result obsd__streams_finish(obsd__req *r);
void obsd__streams_done(obsd__req *r);

/* ---- http_bakes.c: /v1/bakes ---- */

/* The first call (token checked); a call with the body of a POST; the
 * end of a request. */
enum MHD_Result obsd__bakes_start(obsd__req *r, const char *url);
enum MHD_Result obsd__bakes_body(obsd__req *r, const char *data, size_t *size);
void obsd__bakes_done(obsd__req *r);

/* ---- http_events.c: Server-Sent Events ---- */

/* A subscriber's park and wake callbacks (arg: the request): suspend and
 * resume its connection. */
void obsd__events_park(void *arg);
void obsd__events_wake(void *arg);
/* An event route's answer (ev lives as long as the request): 503 while
 * the daemon drains; else join subscribes the request to its source
 * (with obsd__events_park and _wake; 0 and its own answer in *rc when it
 * cannot), and the answer is 200 text/event-stream with the events of
 * next (REQ_EVENTS), until obsd__events_close calls leave. */
enum MHD_Result obsd__events_open(obsd__req *r, obsd__events *ev,
                                  int (*join)(obsd__req *r, enum MHD_Result *rc),
                                  int (*next)(obsd__req *r, char *buf, size_t len),
                                  void (*leave)(obsd__req *r));
/* The request's subscription ended, when it has one (its route's done). */
void obsd__events_close(obsd__req *r, obsd__events *ev);

/* ---- http_info.c, http_page.c ---- */

/* GET /v1/params, /v1/info, /healthz, /readyz, /metrics. */
enum MHD_Result obsd__params_get(obsd__req *r, const char *url);
enum MHD_Result obsd__info_get(obsd__req *r, const char *url);
enum MHD_Result obsd__healthz_get(obsd__req *r, const char *url);
enum MHD_Result obsd__readyz_get(obsd__req *r, const char *url);
enum MHD_Result obsd__metrics_get(obsd__req *r, const char *url);
/* GET / and /preview/...: the embedded page. */
enum MHD_Result obsd__page(obsd__req *r, const char *url);

#endif
