/* Round trip through obscurad vs in-process, and frames per second with
 * concurrent clients.  bench/daemon_bench.sh starts the daemon and runs
 * this; see there.
 *
 *   daemon_bench [--frames N] [--per-client M] G-BUFFER.exr IN_PROCESS_ONLY|URL...
 *
 * The G-buffer must carry its camera in the header (tools/exr_upscale
 * with a camera JSON).  For every URL (http://, unix:, tcp://) the frame
 * goes through clients/remote.c, the code of `obscura ao --server`: HTTP
 * sends the EXR file and decodes a float EXR answer; the binary protocol
 * sends and receives raw float32 planes.  In-process is obs_run on a warm
 * context (what the daemon's GL worker does), and the same after an EXR
 * decode of the file.  Medians of N, all in one run.  Then, for the last
 * URL, 1, 2, 4 and 8 client processes send M frames each: frames per
 * second over the wall time.  Last, for the first http:// URL, small
 * frames (the G-buffer's depth at 64x36) one after another: over one
 * keep-alive connection, and on a new connection each, frames per second
 * and their ratio. */
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "obscura/io.h"
#include "obscura/obscura.h"
#include "remote.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *t, int n)
{
    qsort(t, (size_t)n, sizeof t[0], cmp);
    return n % 2 ? t[n / 2] : (t[n / 2 - 1] + t[n / 2]) / 2;
}

static void die(const char *what, const char *err)
{
    fprintf(stderr, "daemon_bench: %s: %s\n", what, err);
    exit(1);
}

/* One frame through the daemon; exits on failure. */
static void remote_frame(const char *url, const char *path, const obs_gbuffer *gb)
{
    char *argv[] = {NULL};
    obs_result r;
    if (cli_remote_run(url, 0, argv, path, gb, OBS_OUTPUT_AO, &r) != 0)
        die(url, "frame failed");
    obs_result_free(&r);
}

/* ---- small frames, keep-alive or not ---- */

/* The depth plane at w x h (nearest), as an EXR in memory. */
static void small_exr(const obs_gbuffer *gb, int w, int h, obs_bytes *out)
{
    static const char *const zn[] = {"Z"};
    obs_image img = {w, h, 1, malloc(sizeof(float) * (size_t)w * (size_t)h)};
    char err[OBS_ERR_LEN];
    if (!img.data)
        die("small frame", "no memory");
    size_t stride = gb->depth.row_stride ? gb->depth.row_stride
                                         : sizeof(float) * (size_t)gb->width * (size_t)gb->depth.channels;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            img.data[(size_t)y * w + x] =
                ((const float *)((const char *)gb->depth.data + (size_t)((long long)y * gb->height / h) * stride))
                    [(size_t)((long long)x * gb->width / w) * gb->depth.channels];
    obs_exr_layer layer = {&img, zn};
    if (obs_exr_write_mem(&layer, 1, OBS_EXR_FLOAT, &gb->camera, out, err) != OBS_OK)
        die("small frame", err);
    obs_image_free(&img);
}

static int http_connect(const char *url)
{
    char host[256], port[16];
    if (sscanf(url, "http://%255[^:/]:%15[0-9]", host, port) != 2)
        die(url, "not http://HOST:PORT");
    struct addrinfo hints = {.ai_socktype = SOCK_STREAM}, *ai;
    if (getaddrinfo(host, port, &hints, &ai) != 0)
        die(url, "cannot resolve");
    int fd = socket(ai->ai_family, ai->ai_socktype, ai->ai_protocol);
    if (fd < 0 || connect(fd, ai->ai_addr, ai->ai_addrlen) != 0)
        die(url, "cannot connect");
    /* as curl does: no Nagle delay between a request's head and its body */
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    freeaddrinfo(ai);
    return fd;
}

/* One POST /v1/ao on fd, its answer read whole; 0 when it was a 200
 * that leaves the connection open. */
static int http_frame(int fd, const obs_bytes *body, int keep)
{
    char head[256], buf[1 << 16];
    int n = snprintf(head, sizeof head, "POST /v1/ao HTTP/1.1\r\nHost: bench\r\nContent-Type: image/x-exr\r\n"
                     "Content-Length: %zu\r\n%s\r\n", body->size, keep ? "" : "Connection: close\r\n");
    if (send(fd, head, (size_t)n, MSG_NOSIGNAL | MSG_MORE) != n ||
        send(fd, body->data, body->size, MSG_NOSIGNAL) != (ssize_t)body->size)
        die("small frames", "send failed");
    size_t got = 0, need = 0, head_len = 0;
    for (;;) {
        ssize_t k = recv(fd, buf + got, sizeof buf - 1 - got, 0);
        if (k <= 0)
            die("small frames", "the daemon closed the connection early");
        got += (size_t)k;
        buf[got] = '\0';
        char *end = strstr(buf, "\r\n\r\n");
        if (!head_len && end) {
            head_len = (size_t)(end - buf) + 4;
            const char *cl = strstr(buf, "Content-Length: ");
            if (strncmp(buf, "HTTP/1.1 200", 12) != 0 || !cl)
                die("small frames", "not a 200 answer");
            need = head_len + strtoull(cl + 16, NULL, 10);
            if (need >= sizeof buf)
                die("small frames", "answer too large");
        }
        if (head_len && got >= need)
            break;
    }
    return strstr(buf, "Connection: close") != NULL;
}

static void keepalive_bench(const char *url, const obs_gbuffer *gb, int count)
{
    obs_bytes body;
    small_exr(gb, 64, 36, &body);
    int fd = http_connect(url);
    http_frame(fd, &body, 1); /* warm-up: the daemon's textures at this size */
    double t0 = now_ms();
    for (int k = 0; k < count; k++)
        if (http_frame(fd, &body, 1) != 0)
            die("keep-alive", "the daemon closed a keep-alive connection");
    double keep_s = (now_ms() - t0) / 1e3;
    close(fd);
    t0 = now_ms();
    for (int k = 0; k < count; k++) {
        fd = http_connect(url);
        http_frame(fd, &body, 0);
        close(fd);
    }
    double new_s = (now_ms() - t0) / 1e3;
    size_t size = body.size;
    obs_bytes_free(&body);
    printf("\nSmall frames (64x36 depth, %zu-byte EXR, AO EXR answer), %d one after another (%s):\n\n", size,
           count, url);
    printf("| connection | wall s | frames/s |\n|---|---|---|\n");
    printf("| one keep-alive connection | %.2f | %.1f |\n", keep_s, count / keep_s);
    printf("| a new connection per frame | %.2f | %.1f |\n", new_s, count / new_s);
    printf("\nkeep-alive / new connection: %.2f x the frames per second\n", new_s / keep_s);
    fflush(stdout);
}

int main(int argc, char **argv)
{
    int frames = 7, per_client = 3, i = 1;
    for (; i + 1 < argc && argv[i][0] == '-'; i += 2) {
        if (!strcmp(argv[i], "--frames"))
            frames = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--per-client"))
            per_client = atoi(argv[i + 1]);
    }
    if (argc - i < 2 || frames < 1 || frames > 64 || per_client < 1) {
        fprintf(stderr, "usage: daemon_bench [--frames N] [--per-client M] G-BUFFER.exr URL...\n");
        return 2;
    }
    const char *path = argv[i++];
    char err[OBS_ERR_LEN];
    obs_gbuffer_file gf = {0};
    if (obs_gbuffer_read_exr(path, NULL, NULL, &gf, err) != OBS_OK)
        die(path, err);
    if (gf.gb.camera.source == OBS_CAMERA_NONE)
        die(path, "no camera in the header (make it with tools/exr_upscale ... CAMERA.json)");

    /* in-process: a warm context, as the daemon's GL worker */
    obs_ctx_desc desc = {0};
    obs_ctx *ctx;
    if (obs_ctx_create(&desc, &ctx, err) != OBS_OK)
        die("context", err);
    obs_result r;
    double t[64], t_dec[64];
    if (obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &r, err) != OBS_OK) /* compiles the shaders */
        die("obs_run", err);
    obs_result_free(&r);
    for (int k = 0; k < frames; k++) {
        obs_gbuffer_file g2 = {0};
        double t0 = now_ms();
        if (obs_gbuffer_read_exr(path, NULL, NULL, &g2, err) != OBS_OK)
            die(path, err);
        double t1 = now_ms();
        if (obs_run(ctx, &g2.gb, NULL, OBS_OUTPUT_AO, &r, err) != OBS_OK)
            die("obs_run", err);
        double t2 = now_ms();
        obs_result_free(&r);
        obs_gbuffer_free(&g2);
        t[k] = t2 - t1;
        t_dec[k] = t2 - t0;
    }
    obs_ctx_destroy(ctx);
    double in_proc = median(t, frames), in_proc_dec = median(t_dec, frames);
    printf("G-buffer %s: %dx%d; median of %d frames each, after one warm-up\n\n", path, gf.gb.width,
           gf.gb.height, frames);
    printf("| path | round trip ms | x in-process obs_run |\n|---|---|---|\n");
    printf("| in-process: obs_run, warm context (upload + passes + readback) | %.1f | 1.00 |\n", in_proc);
    printf("| in-process: EXR decode + obs_run | %.1f | %.2f |\n", in_proc_dec, in_proc_dec / in_proc);
    fflush(stdout);

    const char *last = NULL;
    for (int u = i; u < argc; u++) {
        const char *url = argv[u];
        remote_frame(url, path, &gf.gb); /* warm-up: the daemon's shaders, textures */
        for (int k = 0; k < frames; k++) {
            double t0 = now_ms();
            remote_frame(url, path, &gf.gb);
            t[k] = now_ms() - t0;
        }
        double m = median(t, frames);
        const char *what = !strncmp(url, "http", 4) ? "HTTP, EXR body, float EXR answer"
                           : !strncmp(url, "unix:", 5) ? "binary protocol, raw planes, Unix socket"
                                                       : "binary protocol, raw planes, TCP loopback";
        printf("| %s | %.1f | %.2f |\n", what, m, m / in_proc);
        fflush(stdout);
        last = url;
    }

    printf("\nConcurrent clients (%s, %d frames per client, one process each):\n\n", last, per_client);
    printf("| clients | frames | wall s | frames/s |\n|---|---|---|---|\n");
    fflush(stdout);
    for (int n = 1; n <= 8; n *= 2) {
        double t0 = now_ms();
        pid_t pids[8];
        for (int c = 0; c < n; c++) {
            pids[c] = fork();
            if (pids[c] == 0) {
                for (int k = 0; k < per_client; k++)
                    remote_frame(last, path, &gf.gb);
                _exit(0);
            }
            if (pids[c] < 0)
                die("fork", "failed");
        }
        int bad = 0;
        for (int c = 0; c < n; c++) {
            int st;
            if (waitpid(pids[c], &st, 0) < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0)
                bad++;
        }
        double s = (now_ms() - t0) / 1e3;
        if (bad)
            die("concurrent clients", "a client failed");
        printf("| %d | %d | %.2f | %.2f |\n", n, n * per_client, s, n * per_client / s);
        fflush(stdout);
    }
    for (int u = i; u < argc; u++)
        if (!strncmp(argv[u], "http://", 7)) {
            keepalive_bench(argv[u], &gf.gb, 200);
            break;
        }
    obs_gbuffer_free(&gf);
    return 0;
}
