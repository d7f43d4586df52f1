/* The route table: a URL path to its route, a route to its name (the
 * metrics' route label). */
#include <string.h>

#include "routes.h"

static const char *const route_paths[OBSD_ROUTE_COUNT] = {
    "/v1/ao", "/v1/params", "/v1/info", "/healthz", "/readyz", "/metrics", "/v1/streams", "/v1/bakes", "/",
    "binary", "other"};

const char *obsd_route_path(obsd_route r)
{
    return r >= 0 && r < OBSD_ROUTE_COUNT ? route_paths[r] : "other";
}

obsd_route obsd_route_of(const char *path)
{
    for (int r = 0; r < OBSD_ROUTE_BINARY; r++)
        if (path && !strcmp(path, route_paths[r]))
            return (obsd_route)r;
    if (path && !strncmp(path, "/v1/streams/", 12))
        return OBSD_ROUTE_STREAMS;
    if (path && !strncmp(path, "/v1/bakes/", 10))
        return OBSD_ROUTE_BAKES;
    if (path && !strncmp(path, "/preview/", 9))
        return OBSD_ROUTE_PAGE;
    return OBSD_ROUTE_OTHER;
}
