/* obscurad's HTTP front end (libmicrohttpd, internal thread pool with
 * epoll).  Network threads parse, decode and encode; frames go to the GL
 * worker through the queue while their connection is suspended. */
#ifndef OBSD_HTTP_SERVER_H
#define OBSD_HTTP_SERVER_H

#include "config.h"
#include "gl_worker.h"

typedef struct obsd_http obsd_http;

/* Starts listening on cfg->http.  `token` (may be NULL) is the bearer
 * token; cfg, q and gl must outlive the server. */
obs_status obsd_http_start(const obsd_config *cfg, const char *token, obsd_queue *q,
                           obsd_gl_worker *gl, obsd_http **out, char err[OBS_ERR_LEN]);
/* The port it listens on (useful with port 0). */
int obsd_http_port(const obsd_http *h);
/* Stops accepting connections; requests under way go on.  New frames on
 * open connections are answered 503; event streams (SSE) end. */
void obsd_http_quiesce(obsd_http *h);
/* Requests between their first byte and their answer being sent. */
int obsd_http_in_flight(obsd_http *h);
/* Wakes event streams whose keep-alive is due; call a few times a second. */
void obsd_http_tick(obsd_http *h);
/* Closes every connection and frees the server; call when in_flight is 0. */
void obsd_http_stop(obsd_http *h);

#endif
