/* obscurad's HTTP server (daemon/http_server.c) against a GL worker that
 * never runs: a frame posted stays queued, its connection suspended.
 * obsd_http_cut() closes it at once (the client sees the end) and
 * obsd_http_stop() returns (libmicrohttpd aborts when stopped with a
 * connection suspended); the job finished afterwards frees the request,
 * with the server gone (ASan checks that nothing is touched after). */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <pthread.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "testutil.h"

#include "http_server.h"
#include "job.h"

typedef struct client {
    int port;
    unsigned char *body;
    size_t len;
    int got;         /* bytes of an answer read */
    int ended;       /* the connection ended */
    double ended_ms;
} client;

static void *post_frame(void *arg)
{
    client *c = arg;
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)c->port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    struct timeval tv = {20, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    if (connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        close(fd);
        return NULL;
    }
    char head[256];
    int n = snprintf(head, sizeof head, "POST /v1/ao?fov_y=50 HTTP/1.1\r\nHost: x\r\nContent-Type: image/x-exr\r\n"
                     "Content-Length: %zu\r\n\r\n", c->len);
    if (send(fd, head, (size_t)n, MSG_NOSIGNAL) == n && send(fd, c->body, c->len, MSG_NOSIGNAL) == (ssize_t)c->len) {
        char buf[512];
        ssize_t k;
        while ((k = recv(fd, buf, sizeof buf, 0)) > 0)
            c->got += (int)k;
        c->ended = k == 0 || k < 0;
        c->ended_ms = obsd_now_ms();
    }
    close(fd);
    return NULL;
}

static int wait_queued(obsd_queue *q)
{
    for (int i = 0; i < 200; i++) {
        int waiting;
        obsd_queue_stats(q, &waiting, NULL, NULL);
        if (waiting == 1)
            return 1;
        struct timespec t = {0, 50 * 1000 * 1000};
        nanosleep(&t, NULL);
    }
    return 0;
}

static void run(int cut_first)
{
    obsd_config cfg;
    char err[OBS_ERR_LEN] = "";
    obsd_config_defaults(&cfg);
    snprintf(cfg.http, sizeof cfg.http, "127.0.0.1:0");
    cfg.threads = 2;
    obsd_queue q;
    assert_int_equal(obsd_queue_init(&q, 4), 0);
    obsd_gl_worker gl;
    memset(&gl, 0, sizeof gl);
    obsd_http *h = NULL;
    const obsd_front front = obsd_front_make(&cfg, NULL, &q, &gl);
    assert_int_equal(obsd_http_start(&front, &h, err), OBS_OK);

    client c = {.port = obsd_http_port(h)};
    c.body = obs_test_slurp(TESTDATA "/room_small.exr", &c.len);
    assert_non_null(c.body);
    pthread_t t;
    assert_int_equal(pthread_create(&t, NULL, post_frame, &c), 0);
    assert_true(wait_queued(&q)); /* decoded, queued, suspended: nobody runs it */
    assert_int_equal(obsd_http_in_flight(h), 1);

    double t0 = obsd_now_ms();
    if (cut_first) {
        assert_int_equal(obsd_http_cut(h), 1);
        pthread_join(t, NULL);
        assert_true(c.ended);
        assert_int_equal(c.got, 0); /* closed, not answered */
        assert_true(c.ended_ms - t0 < 5000.0);
        for (int i = 0; i < 100 && obsd_http_in_flight(h) > 0; i++) {
            struct timespec s = {0, 20 * 1000 * 1000};
            nanosleep(&s, NULL);
        }
        assert_int_equal(obsd_http_in_flight(h), 0);
        obsd_http_stop(h);
    } else {
        obsd_http_stop(h); /* a suspended connection: still bounded */
        pthread_join(t, NULL);
        assert_true(c.ended);
    }
    assert_true(obsd_now_ms() - t0 < 10000.0);

    /* the GL worker finishes the frame after the server is gone */
    obsd_job *job = obsd_queue_pop(&q);
    assert_non_null(job);
    job->status = OBS_GL_ERROR;
    job->done(job, job->user);
    obsd_queue_done(&q);
    obsd_queue_destroy(&q);
    free(c.body);
}

static void test_cut(void **state)
{
    (void)state;
    run(1);
}

static void test_stop_suspended(void **state)
{
    (void)state;
    run(0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_cut), cmocka_unit_test(test_stop_suspended)};
    return cmocka_run_group_tests_name("daemon_http_server", tests, NULL, NULL);
}
