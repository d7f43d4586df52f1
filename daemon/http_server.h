/* obscurad's HTTP front end (libmicrohttpd, internal thread pool with
 * epoll).  Network threads parse, decode and encode; frames go to the GL
 * worker through the queue while their connection is suspended. */
#ifndef OBSD_HTTP_SERVER_H
#define OBSD_HTTP_SERVER_H

#include "front.h"

typedef struct obsd_http obsd_http;

/* Starts listening on f->cfg->http. */
obs_status obsd_http_start(const obsd_front *f, obsd_http **out, char err[OBS_ERR_LEN]);
/* The port it listens on (useful with port 0). */
int obsd_http_port(const obsd_http *h);
/* "http://HOST:PORT" as --http named the host ("[::1]" for IPv6), with
 * the port it listens on: the log's "listening on" line. */
void obsd_http_url(const obsd_http *h, char *buf, size_t len);
/* Stops accepting connections (a new one is refused at once); requests
 * under way go on.  New frames on open connections are answered 503, and
 * every answer closes its connection; event streams (SSE) end. */
void obsd_http_quiesce(obsd_http *h);
/* Requests between their first byte and their answer being sent. */
int obsd_http_in_flight(obsd_http *h);
/* Wakes event streams whose keep-alive is due; call a few times a second. */
void obsd_http_tick(obsd_http *h);
/* Closes every remaining connection at once, whatever it is doing (a
 * request being read or answered, an event stream, a frame the GL worker
 * still has: that one's connection closes, the job runs on and is freed
 * when it ends); returns how many it cut.  For the drain's deadline. */
int obsd_http_cut(obsd_http *h);
/* Closes every connection (obsd_http_cut) and frees the server, in
 * bounded time; frames still with the GL worker are freed by it. */
void obsd_http_stop(obsd_http *h);

#endif
