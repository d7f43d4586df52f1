/* Shared by the binary protocol's two parts: binary_server.c (the
 * listeners, the accept thread, the connection limits, the drain) and
 * binary_conn.c (one connection's loop).  Not a public header.  Calls go
 * one way: binary_server.c starts obsd__bin_conn_main on a thread per
 * connection. */
#ifndef OBSD_BINARY_INTERNAL_H
#define OBSD_BINARY_INTERNAL_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>

#include "front.h"

#define TICK_MS 200
/* Before closing a connection that was answered without reading all it
 * sent, what it still sends is read and dropped for so long (or so many
 * bytes): closing with unread bytes resets the connection, and the
 * client could lose the answer. */
#define LINGER_MS 2000
#define LINGER_BYTES ((size_t)64 << 20)
/* Refused connections lingering in the accept thread at once. */
#define REFUSED_MAX 64

typedef struct conn conn;

struct conn {
    struct obsd_bin *srv;
    int fd;
    char peer[80]; /* for the log: IP:port, [IPv6]:port or unix */
    char addr[64]; /* for max_per_client: the IP, or "unix" */
    conn *prev, *next;
};

/* A refused connection, answered, its sends dropped until `until`. */
typedef struct refused {
    int fd;
    double until;
    size_t dropped;
} refused;

typedef struct obsd_bin obsd_bin; /* as binary_server.h, which only the listeners include */
struct obsd_bin {
    obsd_front front;
    int unix_fd, tcp_fd, tcp_port;
    pthread_t acceptor;
    int accepting;
    atomic_int draining;
    atomic_int connections;
    atomic_uint_fast64_t next_id;
    pthread_mutex_t lock; /* guards conns (obsd_bin_cut shuts their sockets) */
    conn *conns;
    /* the accept thread's own */
    refused refused[REFUSED_MAX];
    int nrefused;
    unsigned long refused_total;
    double refused_logged;
};

/* A connection's thread (arg: its conn, in b->conns): frames until the
 * client closes, the drain, or an error; then out of the list, closed,
 * freed. */
void *obsd__bin_conn_main(void *arg);
/* Takes c out of its server's list (under the lock). */
void obsd__bin_conn_unlink(conn *c);

#endif
