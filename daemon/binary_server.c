/* The binary protocol's listeners: a Unix socket and/or a TCP port, one
 * accept thread, a thread per connection (binary_conn.c), the limits, the
 * drain.
 *
 *   accept thread   poll() on the Unix and TCP listeners (200 ms ticks, so
 *                   it sees the drain), a detached thread per connection;
 *                   over --bin-connections, or --max-per-client from one
 *                   address, a connection is answered 503
 *                   too_many_connections and closed (what it sends is read
 *                   and dropped for a moment, so that the answer arrives)
 *   drain           no new connection; obsd_bin_cut() shuts every
 *                   connection's socket down at once. */
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "addr.h"
#include "binary.h"
#include "binary_internal.h"
#include "binary_server.h"
#include "list.h"
#include "log.h"
#include "stats.h"

/* The peer for the log, and the address max_per_client counts. */
static void describe_peer(const struct sockaddr_storage *ss, conn *c)
{
    char ip[INET6_ADDRSTRLEN] = "?";
    if (ss->ss_family == AF_INET) {
        const struct sockaddr_in *in = (const struct sockaddr_in *)(const void *)ss;
        inet_ntop(AF_INET, &in->sin_addr, ip, sizeof ip);
        snprintf(c->peer, sizeof c->peer, "%s:%u", ip, ntohs(in->sin_port));
        snprintf(c->addr, sizeof c->addr, "%s", ip);
    } else if (ss->ss_family == AF_INET6) {
        const struct sockaddr_in6 *in6 = (const struct sockaddr_in6 *)(const void *)ss;
        if (IN6_IS_ADDR_V4MAPPED(&in6->sin6_addr)) {
            /* an IPv4 client of a dual-stack [::] listener: its IPv4 address */
            inet_ntop(AF_INET, in6->sin6_addr.s6_addr + 12, ip, sizeof ip);
            snprintf(c->peer, sizeof c->peer, "%s:%u", ip, ntohs(in6->sin6_port));
        } else {
            inet_ntop(AF_INET6, &in6->sin6_addr, ip, sizeof ip);
            snprintf(c->peer, sizeof c->peer, "[%s]:%u", ip, ntohs(in6->sin6_port));
        }
        snprintf(c->addr, sizeof c->addr, "%s", ip);
    } else {
        snprintf(c->peer, sizeof c->peer, "unix");
        snprintf(c->addr, sizeof c->addr, "unix");
    }
}

static void refused_drop(obsd_bin *b, int i)
{
    close(b->refused[i].fd);
    b->refused[i] = b->refused[--b->nrefused];
}

/* Answers a connection over a limit (503 too_many_connections, id 0: it
 * has sent no frame yet), then lingers it in the accept thread. */
static void refuse(obsd_bin *b, int fd, const conn *c, const char *why)
{
    char msg[160];
    snprintf(msg, sizeof msg, "too many connections: %s; retry later", why);
    obs_bin_response_desc d = {.id = 0, .status = 503, .retry_after = 1, .code = "too_many_connections",
                               .message = msg, .body = OBS_BIN_NONE};
    obs_bytes out;
    char err[OBS_ERR_LEN];
    size_t sent = 0;
    if (obs_bin_response_encode(&d, &out, err) == OBS_OK) {
        /* a fresh socket's buffer takes these few bytes at once */
        ssize_t n = send(fd, out.data, out.size, MSG_NOSIGNAL | MSG_DONTWAIT);
        sent = n > 0 ? (size_t)n : 0;
        obs_bytes_free(&out);
    }
    obsd_stats_request(OBSD_STATS_BINARY, 503, 0, sent);
    b->refused_total++;
    double now = obsd_now_ms();
    /* counted by reason; at most a line a second, whatever a flood of clients does */
    obsd_stats_refusal("too_many_connections", c->peer, msg);
    shutdown(fd, SHUT_WR);
    if (b->nrefused == REFUSED_MAX) {
        int oldest = 0;
        for (int i = 1; i < b->nrefused; i++)
            if (b->refused[i].until < b->refused[oldest].until)
                oldest = i;
        refused_drop(b, oldest);
    }
    b->refused[b->nrefused++] = (refused){fd, now + LINGER_MS, 0};
}

/* What refused connections send: read and dropped; closed on EOF, after
 * LINGER_MS or LINGER_BYTES. */
static void refused_poll(obsd_bin *b, const struct pollfd *p, int n)
{
    char scratch[4096];
    double now = obsd_now_ms();
    for (int i = n - 1; i >= 0; i--) {
        refused *r = &b->refused[i];
        int done = now >= r->until || r->dropped >= LINGER_BYTES;
        if (!done && (p[i].revents & (POLLIN | POLLHUP | POLLERR))) {
            ssize_t k = recv(r->fd, scratch, sizeof scratch, MSG_DONTWAIT);
            if (k > 0)
                r->dropped += (size_t)k;
            else if (k == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR))
                done = 1;
        }
        if (done)
            refused_drop(b, i);
    }
}

static void accept_one(obsd_bin *b, int lfd)
{
    struct sockaddr_storage ss;
    socklen_t sl = sizeof ss;
    int fd = accept(lfd, (struct sockaddr *)&ss, &sl);
    if (fd < 0)
        return;
    /* every wait is a poll() with a deadline: send() and recv() never block */
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    fcntl(fd, F_SETFD, FD_CLOEXEC);
    conn *c = calloc(1, sizeof *c);
    if (!c) {
        close(fd);
        return;
    }
    c->srv = b;
    c->fd = fd;
    describe_peer(&ss, c);
    if (ss.ss_family != AF_UNIX) {
        int one = 1;
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    }
    char why[128] = "";
    int open_now = 0, same = 0;
    pthread_mutex_lock(&b->lock);
    for (const conn *o = b->conns; o; o = o->next) {
        open_now++;
        same += !strcmp(o->addr, c->addr);
    }
    if (open_now >= b->front.cfg->bin_connections)
        snprintf(why, sizeof why, "%d open (bin_connections)", open_now);
    else if (b->front.cfg->max_per_client > 0 && same >= b->front.cfg->max_per_client)
        snprintf(why, sizeof why, "%d open from %s (max_per_client)", same, c->addr);
    else {
        OBSD_LIST_PUSH(b->conns, c);
        atomic_fetch_add(&b->connections, 1);
    }
    pthread_mutex_unlock(&b->lock);
    if (why[0]) {
        refuse(b, fd, c, why);
        free(c);
        return;
    }
    pthread_attr_t attr;
    pthread_t t;
    pthread_attr_init(&attr);
    pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
    if (pthread_create(&t, &attr, obsd__bin_conn_main, c) != 0) {
        obsd__bin_conn_unlink(c);
        atomic_fetch_sub(&b->connections, 1);
        close(fd);
        free(c);
    }
    pthread_attr_destroy(&attr);
}

static void *accept_main(void *arg)
{
    obsd_bin *b = arg;
    while (!atomic_load(&b->draining)) {
        struct pollfd p[2 + REFUSED_MAX];
        int n = 0, nr = b->nrefused;
        for (int i = 0; i < nr; i++)
            p[n++] = (struct pollfd){b->refused[i].fd, POLLIN, 0};
        int lst = n;
        if (b->unix_fd >= 0)
            p[n++] = (struct pollfd){b->unix_fd, POLLIN, 0};
        if (b->tcp_fd >= 0)
            p[n++] = (struct pollfd){b->tcp_fd, POLLIN, 0};
        int rc = poll(p, (nfds_t)n, nr ? 50 : TICK_MS);
        if (nr)
            refused_poll(b, p, nr);
        if (rc <= 0)
            continue;
        for (int i = lst; i < n; i++)
            if (p[i].revents & POLLIN)
                accept_one(b, p[i].fd);
    }
    while (b->nrefused > 0)
        refused_drop(b, b->nrefused - 1);
    return NULL;
}

static int listen_unix(const char *path, char err[OBS_ERR_LEN])
{
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    if (strlen(path) >= sizeof sa.sun_path) {
        snprintf(err, OBS_ERR_LEN, "--socket %s: path longer than %zu bytes", path,
                 sizeof sa.sun_path - 1);
        return -1;
    }
    memcpy(sa.sun_path, path, strlen(path) + 1);
    struct stat st;
    if (lstat(path, &st) == 0) {
        /* a socket left by a daemon that died may go; a live one, or
         * anything that is not a socket, stays */
        int probe = socket(AF_UNIX, SOCK_STREAM, 0);
        int live = probe >= 0 && connect(probe, (struct sockaddr *)&sa, sizeof sa) == 0;
        if (probe >= 0)
            close(probe);
        if (!S_ISSOCK(st.st_mode) || live) {
            snprintf(err, OBS_ERR_LEN, "--socket %s: %s", path,
                     live ? "another daemon listens there" : "exists and is not a socket");
            return -1;
        }
        unlink(path);
    }
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0 || listen(fd, 64) != 0) {
        snprintf(err, OBS_ERR_LEN, "--socket %s: %s", path, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    return fd;
}

/* "HOST:PORT" (IPv4), "[HOST]:PORT" (IPv6) or "PORT" (host 127.0.0.1). */
static int listen_tcp(const char *s, int *port_out, char err[OBS_ERR_LEN])
{
    char host[64] = "127.0.0.1";
    const char *ps = s;
    int v6 = 0;
    if (s[0] == '[') {
        const char *end = strchr(s, ']');
        if (!end || end[1] != ':' || end == s + 1 || (size_t)(end - s - 1) >= sizeof host)
            goto bad;
        snprintf(host, sizeof host, "%.*s", (int)(end - s - 1), s + 1);
        ps = end + 2;
        v6 = 1;
    } else {
        const char *colon = strrchr(s, ':');
        if (colon) {
            if ((size_t)(colon - s) >= sizeof host || memchr(s, ':', (size_t)(colon - s)))
                goto bad; /* an IPv6 address needs its brackets */
            if (colon > s)
                snprintf(host, sizeof host, "%.*s", (int)(colon - s), s);
            ps = colon + 1;
        }
    }
    char *end;
    long port = strtol(ps, &end, 10);
    struct sockaddr_storage ss;
    socklen_t sl;
    if (!*ps || *end || port < 0 || port > 65535 || obsd_addr_fill(v6, host, (uint16_t)port, &ss, &sl) != 0)
        goto bad;
    int fd = socket(ss.ss_family, SOCK_STREAM | SOCK_CLOEXEC, 0), one = 1;
    if (fd >= 0)
        setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (fd < 0 || bind(fd, (struct sockaddr *)&ss, sl) != 0 || listen(fd, 64) != 0) {
        snprintf(err, OBS_ERR_LEN, "--tcp %s: %s", s, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    getsockname(fd, (struct sockaddr *)&ss, &sl);
    *port_out = ntohs(v6 ? ((struct sockaddr_in6 *)(void *)&ss)->sin6_port
                         : ((struct sockaddr_in *)(void *)&ss)->sin_port);
    return fd;
bad:
    snprintf(err, OBS_ERR_LEN, "--tcp '%s' is not [HOST:]PORT (an IPv4 host, or an IPv6 one in brackets: "
             "[::1]:PORT) with a port in 0..65535", s);
    return -1;
}

obs_status obsd_bin_start(const obsd_front *f, obsd_bin **out, char err[OBS_ERR_LEN])
{
    const obsd_config *cfg = f->cfg;
    obsd_bin *b = calloc(1, sizeof *b);
    if (!b)
        return OBS_NO_MEMORY;
    b->front = *f;
    b->unix_fd = b->tcp_fd = -1;
    atomic_init(&b->draining, 0);
    atomic_init(&b->connections, 0);
    atomic_init(&b->next_id, 0);
    pthread_mutex_init(&b->lock, NULL);
    if (cfg->socket[0] && (b->unix_fd = listen_unix(cfg->socket, err)) < 0)
        goto fail;
    if (cfg->tcp[0] && (b->tcp_fd = listen_tcp(cfg->tcp, &b->tcp_port, err)) < 0)
        goto fail;
    if (pthread_create(&b->acceptor, NULL, accept_main, b) != 0) {
        snprintf(err, OBS_ERR_LEN, "cannot start the binary-protocol thread");
        goto fail;
    }
    b->accepting = 1;
    *out = b;
    return OBS_OK;
fail:
    if (b->unix_fd >= 0) {
        close(b->unix_fd);
        unlink(cfg->socket);
    }
    if (b->tcp_fd >= 0)
        close(b->tcp_fd);
    pthread_mutex_destroy(&b->lock);
    free(b);
    return OBS_IO;
}

int obsd_bin_tcp_port(const obsd_bin *b) { return b ? b->tcp_port : 0; }

void obsd_bin_quiesce(obsd_bin *b)
{
    if (!b)
        return;
    atomic_store(&b->draining, 1);
    if (b->accepting) {
        pthread_join(b->acceptor, NULL);
        b->accepting = 0;
    }
    if (b->unix_fd >= 0) {
        close(b->unix_fd);
        unlink(b->front.cfg->socket);
        b->unix_fd = -1;
    }
    if (b->tcp_fd >= 0) {
        close(b->tcp_fd);
        b->tcp_fd = -1;
    }
}

int obsd_bin_in_flight(obsd_bin *b) { return b ? atomic_load(&b->connections) : 0; }

int obsd_bin_cut(obsd_bin *b)
{
    if (!b)
        return 0;
    int n = 0;
    pthread_mutex_lock(&b->lock);
    for (conn *c = b->conns; c; c = c->next, n++)
        shutdown(c->fd, SHUT_RDWR); /* its thread's next recv/send fails, its poll wakes */
    pthread_mutex_unlock(&b->lock);
    if (n)
        obsd_log(OBSD_LOG_WARN, "binary: cut %d connection(s) still open", n);
    return n;
}

void obsd_bin_stop(obsd_bin *b)
{
    if (!b)
        return;
    obsd_bin_quiesce(b);
    obsd_bin_cut(b);
    /* each thread ends at its next wait; one with a frame on the GL worker
     * when that frame is finished */
    while (atomic_load(&b->connections) > 0) {
        struct timespec ts = {0, 10 * 1000000L};
        nanosleep(&ts, NULL);
    }
    pthread_mutex_destroy(&b->lock);
    free(b);
}
