/* The route table: one row per HTTP route (routes.h says what a row
 * holds).  The order is the metrics' order; keep new rows after
 * /v1/bakes so that existing scrapes keep their order. */
#include <string.h>

#include "http_internal.h"
#include "routes.h"

const obsd__route obsd__routes[] = {
    {"/v1/ao", NULL, "POST", "*", OBSD_ROUTE_FRAME_TOTAL, obsd__frame_start, obsd__frame_body, obsd__ao_finish, NULL},
    {"/v1/params", NULL, "GET", NULL, 0, obsd__params_get, NULL, NULL, NULL},
    {"/v1/info", NULL, "GET", NULL, 0, obsd__info_get, NULL, NULL, NULL},
    {"/healthz", NULL, "GET", NULL, OBSD_ROUTE_OPEN | OBSD_ROUTE_PROBE, obsd__healthz_get, NULL, NULL, NULL},
    {"/readyz", NULL, "GET", NULL, OBSD_ROUTE_OPEN | OBSD_ROUTE_PROBE, obsd__readyz_get, NULL, NULL, NULL},
    {"/metrics", NULL, "GET", NULL, 0, obsd__metrics_get, NULL, NULL, NULL},
    {"/v1/streams", "/v1/streams/", NULL, "POST", 0, obsd__streams_start, obsd__frame_body, obsd__streams_finish,
     obsd__streams_done},
    {"/v1/bakes", "/v1/bakes/", NULL, "POST", 0, obsd__bakes_start, obsd__bakes_body, NULL, obsd__bakes_done},
    {"/", "/preview/", NULL, NULL, OBSD_ROUTE_OPEN, obsd__page, NULL, NULL, NULL},
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

