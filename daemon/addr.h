/* A listener's address: a host as text and a port into a socket address,
 * for both servers' option parsing (--http, --tcp). */
#ifndef OBSD_ADDR_H
#define OBSD_ADDR_H

#include <stdint.h>
#include <sys/socket.h>

/* *ss (and *len) for an IPv4 host, or with v6 an IPv6 host, and port:
 * 0, or -1 when host is not such an address. */
int obsd_addr_fill(int v6, const char *host, uint16_t port, struct sockaddr_storage *ss, socklen_t *len);

#endif
