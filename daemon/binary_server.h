/* obscurad's binary-protocol listeners (protocol/PROTOCOL.md): a Unix
 * socket and/or a TCP port, one accept thread, one small thread per
 * connection.  Frames go through the same queue and GL worker as HTTP. */
#ifndef OBSD_BINARY_SERVER_H
#define OBSD_BINARY_SERVER_H

#include "config.h"
#include "gl_worker.h"

typedef struct obsd_bin obsd_bin;

/* Listens on cfg->socket and/or cfg->tcp (whichever is set).  `token`
 * may be NULL or "" (no token required). */
obs_status obsd_bin_start(const obsd_config *cfg, const char *token, obsd_queue *q,
                          obsd_gl_worker *gl, obsd_bin **out, char err[OBS_ERR_LEN]);

/* The bound TCP port (useful with port 0); 0 when there is no TCP. */
int obsd_bin_tcp_port(const obsd_bin *b);

/* Stops accepting; idle connections close, a frame under way is
 * finished and answered. */
void obsd_bin_quiesce(obsd_bin *b);

/* Connections still open. */
int obsd_bin_in_flight(obsd_bin *b);

/* Joins the accept thread, waits for the connections, removes the
 * socket file and frees b.  Call after obsd_bin_quiesce(). NULL-safe. */
void obsd_bin_stop(obsd_bin *b);

#endif
