/* The routes a request is counted and dispatched under: the HTTP API's
 * paths, the preview page, and the binary protocol (not a URL). */
#ifndef OBSD_ROUTES_H
#define OBSD_ROUTES_H

typedef enum obsd_route {
    OBSD_ROUTE_AO,
    OBSD_ROUTE_PARAMS,
    OBSD_ROUTE_INFO,
    OBSD_ROUTE_HEALTHZ,
    OBSD_ROUTE_READYZ,
    OBSD_ROUTE_METRICS,
    OBSD_ROUTE_STREAMS, /* /v1/streams and everything under it */
    OBSD_ROUTE_BAKES,   /* /v1/bakes and everything under it */
    OBSD_ROUTE_PAGE,    /* the preview page: / and /preview/... */
    OBSD_ROUTE_BINARY, /* the binary protocol (socket / TCP), not a URL */
    OBSD_ROUTE_OTHER,
    OBSD_ROUTE_COUNT
} obsd_route;

/* "/v1/ao", ... ; "other" for OBSD_ROUTE_OTHER. */
const char *obsd_route_path(obsd_route r);
/* The route of a URL path (exact match; /v1/streams/..., /v1/bakes/... and /preview/...
 * by prefix), OBSD_ROUTE_OTHER if none. */
obsd_route obsd_route_of(const char *path);

#endif
