/* The route table: one row per HTTP route (routes.h says what a row
 * holds).  The order is the metrics' order; keep new rows after
 * /v1/bakes so that existing scrapes keep their order. */
#include <string.h>

#include "http_internal.h"
#include "routes.h"

const obsd__route obsd__routes[] = {
    {.path = "/v1/ao", .methods = "POST", .reads_body = "*", .flags = OBSD_ROUTE_FRAME_TOTAL,
     .start = obsd__frame_start, .body = obsd__frame_body, .finish = obsd__ao_finish},
    {.path = "/v1/params", .methods = "GET", .start = obsd__params_get},
    {.path = "/v1/info", .methods = "GET", .start = obsd__info_get},
    {.path = "/healthz", .methods = "GET", .flags = OBSD_ROUTE_OPEN | OBSD_ROUTE_PROBE, .start = obsd__healthz_get},
    {.path = "/readyz", .methods = "GET", .flags = OBSD_ROUTE_OPEN | OBSD_ROUTE_PROBE, .start = obsd__readyz_get},
    {.path = "/metrics", .methods = "GET", .start = obsd__metrics_get},
    /* the methods of each sub-route are http_streams.c's and http_bakes.c's to check */
    {.path = "/v1/streams", .under = "/v1/streams/", .reads_body = "POST", .start = obsd__streams_start,
     .body = obsd__frame_body, .finish = obsd__streams_finish, .done = obsd__streams_done},
    {.path = "/v1/bakes", .under = "/v1/bakes/", .reads_body = "POST", .flags = OBSD_ROUTE_LEVEL_BODY, .start = obsd__bakes_start,
     .body = obsd__bakes_body, .done = obsd__bakes_done},
    {.path = "/", .under = "/preview/", .flags = OBSD_ROUTE_OPEN, .start = obsd__page}, /* static: no token */
};
const int obsd__route_count = (int)(sizeof obsd__routes / sizeof obsd__routes[0]);

_Static_assert(sizeof obsd__routes / sizeof obsd__routes[0] <= OBSD_STATS_ROUTES,
               "more routes than the request counters have slots (stats.h)");

int obsd__route_find(const char *path)
{
    if (!path)
        return -1;
    for (int i = 0; i < obsd__route_count; i++) {
        const obsd__route *rt = &obsd__routes[i];
        if (!strcmp(path, rt->path) || (rt->under && !strncmp(path, rt->under, strlen(rt->under))))
            return i;
    }
    return -1;
}

