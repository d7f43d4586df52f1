/* The HTTP routes, one row each (routes.c): the path a request is found
 * by, what http_server.c checks before the route's handler runs (method,
 * token, room on a reserve connection), whether the first call reads a
 * body, and the handlers of the request's life.  A row's index is its
 * slot in the request counters (stats.h), so /metrics lists the routes in
 * the table's order.  Adding a route: a row here, its handler file, its
 * handlers' declarations (http_internal.h) and protocol/HTTP.md. */
#ifndef OBSD_ROUTES_H
#define OBSD_ROUTES_H

#include <stddef.h>

#include <microhttpd.h>

struct obsd__req;

/* The flags of a row. */
enum {
    OBSD_ROUTE_OPEN = 1,       /* no bearer token needed (probes, the static page) */
    OBSD_ROUTE_PROBE = 2,      /* served on a connection beyond --http-connections */
    OBSD_ROUTE_FRAME_TOTAL = 4, /* every answer is a frame's end: timed as the `total` stage */
    OBSD_ROUTE_LEVEL_BODY = 8   /* its body is a level: --max-level bounds it, not --max-body */
};

typedef struct obsd__route {
    const char *path;  /* matched exactly; also the metrics' route label and the 405 message's */
    const char *under; /* with it, every path that starts so matches too ("/v1/streams/") */
    /* "GET" (HEAD too) or "POST": any other method is 405 before `start`;
     * NULL: the handler checks the method itself */
    const char *methods;
    /* Which methods' first call goes to `start` at once, reading the
     * body: "*" every method, else one method; NULL: none.  The others
     * are answered on the next call, once libmicrohttpd has the whole
     * request, so that the connection stays open. */
    const char *reads_body;
    unsigned flags;    /* OBSD_ROUTE_* */
    /* The first call with the checks passed (the answer, or the body's
     * start: r->state = REQ_BODY). */
    enum MHD_Result (*start)(struct obsd__req *r, const char *url);
    /* A call in REQ_BODY: `size` bytes of the body, or (size 0) its end. */
    enum MHD_Result (*body)(struct obsd__req *r, const char *data, size_t *size);
    /* The call after the GL worker resumed the connection (REQ_QUEUED). */
    enum MHD_Result (*finish)(struct obsd__req *r);
    /* The request's end, answered or not: the handler frees its state. */
    void (*done)(struct obsd__req *r);
} obsd__route;

extern const obsd__route obsd__routes[];
extern const int obsd__route_count;

/* The row of a URL path (its index), -1 when none (404). */
int obsd__route_find(const char *path);

#endif
