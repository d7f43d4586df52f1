/* The binary-protocol server (daemon/binary_server.c) without GL, on a
 * Unix socket: the connection limits answered with an error frame, frames
 * refused from their head (token, size, a full queue) before their
 * G-buffer is sent, the drain (no new frame starts), a client that never
 * reads its answer (the send gives up; obsd_bin_cut() ends it at once). */
#include <poll.h>
#include <pthread.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "testutil.h"

#include "binary.h"
#include "binary_server.h"
#include "job.h"
#include "../../../daemon/log.h" /* core/log.h shadows it: -Icore comes first */

static char dir[64], sock_path[96];

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

static obsd_bin *start(obsd_config *cfg, obsd_queue *q, const char *token)
{
    char err[OBS_ERR_LEN] = "";
    obsd_bin *b = NULL;
    snprintf(dir, sizeof dir, "/tmp/obsd-bin-XXXXXX");
    assert_non_null(mkdtemp(dir));
    snprintf(sock_path, sizeof sock_path, "%s/s.sock", dir);
    snprintf(cfg->socket, sizeof cfg->socket, "%s", sock_path);
    cfg->http[0] = '\0';
    assert_int_equal(obsd_queue_init(q, 1), 0);
    const obsd_front front = obsd_front_make(cfg, token, q, NULL);
    assert_int_equal(obsd_bin_start(&front, &b, err), OBS_OK);
    return b;
}

static void finish(obsd_bin *b, obsd_queue *q)
{
    obsd_bin_quiesce(b);
    obsd_bin_stop(b);
    obsd_queue_destroy(q);
    rmdir(dir);
}

static int dial(void)
{
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof sa.sun_path, "%s", sock_path);
    int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    assert_true(fd >= 0);
    assert_int_equal(connect(fd, (struct sockaddr *)&sa, sizeof sa), 0);
    return fd;
}

/* Waits (at most 3 s) until the server counts n connections. */
static void wait_in_flight(obsd_bin *b, int n)
{
    for (int i = 0; i < 300 && obsd_bin_in_flight(b) != n; i++)
        sleep_ms(10);
    assert_int_equal(obsd_bin_in_flight(b), n);
}

/* Reads one answer (at most 3 s): its status and code; -1 on EOF. */
static int answer(int fd, char code[64], uint64_t *id)
{
    unsigned char buf[8192];
    size_t got = 0, want = OBS_BIN_HEADER_LEN;
    obs_bin_header h = {0};
    char err[OBS_ERR_LEN];
    while (got < want) {
        struct pollfd p = {fd, POLLIN, 0};
        if (poll(&p, 1, 3000) <= 0)
            return -2;
        ssize_t n = recv(fd, buf + got, want - got, 0);
        if (n <= 0)
            return -1;
        got += (size_t)n;
        if (got == OBS_BIN_HEADER_LEN) {
            assert_int_equal(obs_bin_header_parse(buf, &h, sizeof buf - OBS_BIN_HEADER_LEN, err), OBS_OK);
            want += (size_t)h.length;
        }
    }
    obs_bin_response r;
    assert_int_equal(obs_bin_response_decode(buf + OBS_BIN_HEADER_LEN, (size_t)h.length, NULL, &r, err),
                     OBS_OK);
    int status = r.status;
    snprintf(code, 64, "%s", r.code);
    if (id)
        *id = h.id;
    obs_bin_response_free(&r);
    return status;
}

/* 1 when the server closes fd within 3 s. */
static int closed(int fd)
{
    char c;
    struct pollfd p = {fd, POLLIN, 0};
    return poll(&p, 1, 3000) == 1 && recv(fd, &c, 1, 0) == 0;
}

/* The header and head of a raw depth frame of w x h (its planes not
 * included), with a token parameter unless NULL.  Returns the bytes. */
static size_t raw_head(unsigned char *out, uint32_t w, uint32_t h, const char *token, uint64_t id)
{
    unsigned char *p = out + OBS_BIN_HEADER_LEN;
    size_t n = 0;
    uint32_t count = token ? 1 : 0;
    memcpy(p, &count, 4), n += 4;
    if (token) {
        uint16_t nl = 5;
        uint32_t vl = (uint32_t)strlen(token);
        memcpy(p + n, &nl, 2), n += 2;
        memcpy(p + n, "token", 5), n += 5;
        memcpy(p + n, &vl, 4), n += 4;
        memcpy(p + n, token, vl), n += vl;
    }
    p[n++] = OBS_BIN_RAW;
    while (n % 8)
        p[n++] = 0;
    memset(p + n, 0, 160);
    memcpy(p + n, &w, 4);
    memcpy(p + n + 4, &h, 4);
    n += 160;
    obs_bin_header_write(out, OBS_BIN_REQUEST, id, n + (uint64_t)w * h * 4);
    return OBS_BIN_HEADER_LEN + n;
}

static void test_connection_limits(void **state)
{
    (void)state;
    obsd_config cfg;
    obsd_queue q;
    obsd_config_defaults(&cfg);
    assert_int_equal(cfg.bin_connections, 256);
    assert_int_equal(cfg.max_per_client, 64);
    cfg.bin_connections = 2;
    cfg.max_per_client = 0;
    obsd_bin *b = start(&cfg, &q, NULL);
    int a = dial(), c = dial();
    wait_in_flight(b, 2);
    int d = dial();
    char code[64];
    uint64_t id = 99;
    assert_int_equal(answer(d, code, &id), 503);
    assert_string_equal(code, "too_many_connections");
    assert_true(id == 0);
    assert_true(closed(d));
    close(d);
    assert_int_equal(obsd_bin_in_flight(b), 2);
    /* one closes: a new one is taken */
    close(a);
    wait_in_flight(b, 1);
    a = dial();
    wait_in_flight(b, 2);
    close(a);
    close(c);
    wait_in_flight(b, 0);
    finish(b, &q);

    /* Unix-socket clients are one address */
    obsd_config_defaults(&cfg);
    cfg.max_per_client = 1;
    b = start(&cfg, &q, NULL);
    a = dial();
    wait_in_flight(b, 1);
    d = dial();
    assert_int_equal(answer(d, code, NULL), 503);
    assert_string_equal(code, "too_many_connections");
    close(d);
    close(a);
    wait_in_flight(b, 0);
    finish(b, &q);
}

static void test_head_refusals(void **state)
{
    (void)state;
    obsd_config cfg;
    obsd_queue q;
    obsd_config_defaults(&cfg);
    cfg.max_pixels = 1 << 20;
    obsd_bin *b = start(&cfg, &q, "tok");
    unsigned char f[1024];
    char code[64];
    /* no token, a 4096 x 4096 frame (64 MB): 401 from the head alone */
    int fd = dial();
    size_t n = raw_head(f, 4096, 4096, NULL, 3);
    assert_int_equal(send(fd, f, n, 0), (ssize_t)n);
    uint64_t id = 0;
    assert_int_equal(answer(fd, code, &id), 401);
    assert_string_equal(code, "unauthorized");
    assert_true(id == 3);
    assert_true(closed(fd));
    close(fd);
    /* a wrong token, an allowed size: 401 */
    fd = dial();
    n = raw_head(f, 16, 16, "nope", 4);
    send(fd, f, n, 0);
    assert_int_equal(answer(fd, code, NULL), 401);
    close(fd);
    /* the token, a size over max_pixels: 413 from the head */
    fd = dial();
    n = raw_head(f, 4096, 4096, "tok", 5);
    send(fd, f, n, 0);
    assert_int_equal(answer(fd, code, NULL), 413);
    assert_string_equal(code, "too_large");
    assert_true(closed(fd));
    close(fd);
    /* the queue full (one job no worker takes): 503 queue_full from the head */
    obsd_job job;
    memset(&job, 0, sizeof job);
    assert_int_equal(obsd_queue_push(&q, &job), 0);
    fd = dial();
    n = raw_head(f, 16, 16, "tok", 6);
    send(fd, f, n, 0);
    assert_int_equal(answer(fd, code, NULL), 503);
    assert_string_equal(code, "queue_full");
    assert_true(closed(fd));
    close(fd);
    wait_in_flight(b, 0);
    finish(b, &q);
}

static void test_drain_and_cut(void **state)
{
    (void)state;
    obsd_config cfg;
    obsd_queue q;
    obsd_config_defaults(&cfg);
    obsd_bin *b = start(&cfg, &q, NULL);
    unsigned char f[1024];
    char code[64];
    size_t n = raw_head(f, 16, 16, NULL, 8);
    int idle = dial(), half = dial(), head = dial();
    wait_in_flight(b, 3);
    send(half, f, 10, 0);                     /* in a header */
    send(head, f, OBS_BIN_HEADER_LEN + 2, 0); /* in a head */
    sleep_ms(100);
    obsd_bin_quiesce(b);
    /* the idle connection closes at the drain */
    assert_true(closed(idle));
    /* a frame that comes now does not start: 503 shutting_down, closed */
    send(head, f + OBS_BIN_HEADER_LEN + 2, n - OBS_BIN_HEADER_LEN - 2, 0);
    assert_int_equal(answer(head, code, NULL), 503);
    assert_string_equal(code, "shutting_down");
    assert_true(closed(head));
    wait_in_flight(b, 1);
    /* the one in a header would wait --timeout (60 s): cut it */
    assert_int_equal(obsd_bin_cut(b), 1);
    assert_true(closed(half));
    wait_in_flight(b, 0);
    assert_int_equal(obsd_bin_cut(b), 0);
    close(idle);
    close(half);
    close(head);
    finish(b, &q);

    /* stop itself cuts what is left, in bounded time */
    b = start(&cfg, &q, NULL);
    half = dial();
    wait_in_flight(b, 1);
    send(half, f, 10, 0);
    obsd_bin_quiesce(b);
    double t0 = obsd_now_ms();
    obsd_bin_stop(b);
    assert_true(obsd_now_ms() - t0 < 2000);
    assert_true(closed(half));
    close(half);
    obsd_queue_destroy(&q);
    rmdir(dir);
}

/* A stand-in GL worker: finishes one job with an AO image of the
 * G-buffer's size. */
static void *worker(void *arg)
{
    obsd_queue *q = arg;
    obsd_job *job = obsd_queue_pop(q);
    if (!job)
        return NULL;
    size_t n = (size_t)job->gb->width * (size_t)job->gb->height;
    job->t_started = job->t_finished = obsd_now_ms();
    job->result.ao = (obs_image){job->gb->width, job->gb->height, 1, calloc(n, sizeof(float))};
    job->status = OBS_OK;
    obsd_queue_done(q);
    job->done(job, job->user);
    return NULL;
}

/* A 1024 x 1024 format=raw frame: a 4 MB answer, never read. */
static int send_big_raw(void)
{
    const uint32_t w = 1024, h = 1024;
    size_t plen = 4 + 2 + 6 + 4 + 3 + 1, n = 0;
    while (plen % 8)
        plen++;
    plen += 160 + (size_t)w * h * 4;
    unsigned char *f = calloc(1, OBS_BIN_HEADER_LEN + plen), *p = f + OBS_BIN_HEADER_LEN;
    obs_bin_header_write(f, OBS_BIN_REQUEST, 1, plen);
    uint32_t count = 1, vl = 3;
    uint16_t nl = 6;
    memcpy(p, &count, 4), n += 4;
    memcpy(p + n, &nl, 2), n += 2;
    memcpy(p + n, "format", 6), n += 6;
    memcpy(p + n, &vl, 4), n += 4;
    memcpy(p + n, "raw", 3), n += 3;
    p[n++] = OBS_BIN_RAW;
    while (n % 8)
        n++;
    memcpy(p + n, &w, 4);
    memcpy(p + n + 4, &h, 4);
    int fd = dial();
    for (size_t put = 0; put < OBS_BIN_HEADER_LEN + plen;) {
        ssize_t k = send(fd, f + put, OBS_BIN_HEADER_LEN + plen - put, 0);
        assert_true(k > 0);
        put += (size_t)k;
    }
    free(f);
    return fd;
}

static void test_stuck_send(void **state)
{
    (void)state;
    obsd_config cfg;
    obsd_queue q;
    pthread_t t;
    obsd_config_defaults(&cfg); /* --timeout 60 */
    obsd_bin *b = start(&cfg, &q, NULL);
    pthread_create(&t, NULL, worker, &q);
    int fd = send_big_raw();
    sleep_ms(500); /* answered as far as the socket takes it */
    assert_int_equal(obsd_bin_in_flight(b), 1);
    double t0 = obsd_now_ms();
    assert_int_equal(obsd_bin_cut(b), 1);
    wait_in_flight(b, 0);
    assert_true(obsd_now_ms() - t0 < 1000);
    pthread_join(t, NULL);
    close(fd);
    finish(b, &q);

    /* --timeout 1: the send gives up by itself */
    obsd_config_defaults(&cfg);
    cfg.timeout = 1;
    b = start(&cfg, &q, NULL);
    pthread_create(&t, NULL, worker, &q);
    fd = send_big_raw();
    t0 = obsd_now_ms();
    wait_in_flight(b, 0);
    assert_true(obsd_now_ms() - t0 > 500);
    pthread_join(t, NULL);
    close(fd);
    finish(b, &q);
}

int main(void)
{
    obsd_log_set_level(OBSD_LOG_ERROR);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_connection_limits),
        cmocka_unit_test(test_head_refusals),
        cmocka_unit_test(test_drain_and_cut),
        cmocka_unit_test(test_stuck_send),
    };
    return cmocka_run_group_tests_name("daemon_binary_server", tests, NULL, NULL);
}
