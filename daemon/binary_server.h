/* obscurad's binary-protocol listeners (protocol/PROTOCOL.md): a Unix
 * socket and/or a TCP port, one accept thread, one small thread per
 * connection.  Frames go through the same queue and GL worker as HTTP. */
#ifndef OBSD_BINARY_SERVER_H
#define OBSD_BINARY_SERVER_H

#include "front.h"

typedef struct obsd_bin obsd_bin;

/* Listens on f->cfg->socket and/or f->cfg->tcp (whichever is set). */
obs_status obsd_bin_start(const obsd_front *f, obsd_bin **out, char err[OBS_ERR_LEN]);

/* The bound TCP port (useful with port 0); 0 when there is no TCP. */
int obsd_bin_tcp_port(const obsd_bin *b);

/* Stops accepting; idle connections close, a frame that comes is
 * answered 503 shutting_down (its connection closed), a frame under way
 * is finished and answered. */
void obsd_bin_quiesce(obsd_bin *b);

/* Connections still open. */
int obsd_bin_in_flight(obsd_bin *b);

/* Closes every connection still open at once (shutdown(SHUT_RDWR) on its
 * socket: its thread's next read or send fails, and it ends; one with a
 * frame on the GL worker when that frame is finished, its answer
 * dropped).  Returns how many it cut.  For the drain's deadline: call
 * after obsd_bin_quiesce(), then obsd_bin_stop(). NULL-safe. */
int obsd_bin_cut(obsd_bin *b);

/* Joins the accept thread, cuts the connections still open
 * (obsd_bin_cut), waits for their threads, removes the socket file and
 * frees b; whatever the clients do, it takes at most the frames under way
 * on the GL worker.  Call after obsd_bin_quiesce(). NULL-safe. */
void obsd_bin_stop(obsd_bin *b);

#endif
