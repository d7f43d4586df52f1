/* Round trip through obscurad vs in-process, each stage of an HTTP
 * frame, the EXR encode per compression, and frames per second with
 * concurrent clients.  bench/daemon_bench.sh starts the daemon and runs
 * this; see there.
 *
 *   daemon_bench [--frames N] [--per-client M] [--max-clients C] [--daemon-pid PID]
 *                [--cpu] [--concurrency-only] G-BUFFER.exr URL...
 *
 * The G-buffer must carry its camera in the header (tools/exr_upscale
 * with a camera JSON).  In-process is obs_run on a warm context (what
 * the daemon's GL worker does; --cpu: obs_run_cpu, the CPU device), and
 * the same after an EXR decode of the file's bytes.  For an http:// URL:
 * this program's own client over one keep-alive connection, sending the
 * EXR bytes and decoding the answer's AO.Y, with the daemon's default
 * answer (half, compression auto) and with a float ZIP answer (the
 * answer before compression existed); then clients/remote.c, the code of
 * `obscura ao --server` (it asks for a half answer, as obscura ao writes half).  For unix: and
 * tcp:// URLs, the binary protocol's raw float32 planes through
 * clients/remote.c.  Medians of N rounds, each round every path once (a
 * load from outside falls on every path alike), all in one run.  Then 1, 2, 4 and 8
 * client processes send M frames each, over the first http:// URL (the
 * default answer) and over the last URL: frames per second over the wall
 * time (up to C clients, default 8), and the cores the daemon (its CPU
 * time from /proc, given its pid) and the clients kept busy.  Then, for the first http:// URL,
 * the daemon's stage means from GET /metrics (the big frames so far),
 * and small frames over one keep-alive connection and on a new
 * connection each. */
#include <math.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <sys/stat.h>
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
    if (cli_remote_run(url, 0, argv, path, gb, OBS_OUTPUT_AO, 1, &r) != 0)
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

/* ---- big frames over HTTP: this program's own client ---- */

typedef struct answer {
    unsigned char *data;
    size_t size, cap;
} answer;

/* One POST /v1/ao?QUERY of `body` on fd; the answer's body into *a.
 * Dies on anything but a 200 that keeps the connection. */
static void http_big(int fd, const char *query, const unsigned char *body, size_t len, answer *a)
{
    char head[512];
    int n = snprintf(head, sizeof head, "POST /v1/ao%s%s HTTP/1.1\r\nHost: bench\r\nContent-Type: image/x-exr\r\n"
                     "Content-Length: %zu\r\n\r\n", *query ? "?" : "", query, len);
    if (send(fd, head, (size_t)n, MSG_NOSIGNAL | MSG_MORE) != n)
        die("http", "send failed");
    for (size_t off = 0; off < len;) {
        ssize_t k = send(fd, body + off, len - off, MSG_NOSIGNAL);
        if (k <= 0)
            die("http", "send failed");
        off += (size_t)k;
    }
    size_t got = 0, need = 0, head_len = 0;
    for (;;) {
        if (a->cap - got < 65536) {
            a->cap = a->cap ? a->cap * 2 : 1 << 20;
            if (!(a->data = realloc(a->data, a->cap + 1)))
                die("http", "no memory");
        }
        ssize_t k = recv(fd, a->data + got, a->cap - got, 0);
        if (k <= 0)
            die("http", "the daemon closed the connection early");
        got += (size_t)k;
        if (!head_len) {
            a->data[got] = '\0';
            char *end = strstr((char *)a->data, "\r\n\r\n");
            if (!end)
                continue;
            head_len = (size_t)(end - (char *)a->data) + 4;
            const char *cl = strstr((char *)a->data, "Content-Length: ");
            if (strncmp((char *)a->data, "HTTP/1.1 200", 12) != 0 || !cl || (char *)cl > end) {
                end[0] = '\0';
                die("http: not a 200 answer", (char *)a->data);
            }
            need = head_len + strtoull(cl + 16, NULL, 10);
        }
        if (got >= need)
            break;
    }
    memmove(a->data, a->data + head_len, need - head_len);
    a->size = need - head_len;
}

/* One frame over fd with the answer's AO decoded, as a client uses it. */
static void http_big_frame(int fd, const char *query, const obs_bytes *file, answer *a)
{
    char err[OBS_ERR_LEN];
    obs_image ao = {0};
    http_big(fd, query, file->data, file->size, a);
    if (obs_exr_read_channel_mem(a->data, a->size, "AO.Y", NULL, &ao, err) != OBS_OK)
        die("the answer", err);
    obs_image_free(&ao);
}

/* One frame of a concurrent client: over HTTP (this program's client,
 * the default answer; fd kept per client) or clients/remote.c. */
static void client_frames(const char *url, const char *path, const obs_gbuffer *gb, const obs_bytes *file,
                          int count)
{
    if (!strncmp(url, "http://", 7)) {
        answer a = {0};
        int fd = http_connect(url);
        for (int k = 0; k < count; k++)
            http_big_frame(fd, "", file, &a);
        close(fd);
        free(a.data);
        return;
    }
    for (int k = 0; k < count; k++)
        remote_frame(url, path, gb);
}

static int max_clients = 8;
#define STAGES 7
static void metrics_read(const char *url, double sum[STAGES], double count[STAGES]);
static void stage_header(const char *first);
static void stage_row(const char *first, const double s0[STAGES], const double c0[STAGES],
                      const double s1[STAGES], const double c1[STAGES]);
static long daemon_pid; /* --daemon-pid: its CPU time, from /proc */

/* CPU seconds (user + system) the daemon used so far; -1 unknown. */
static double daemon_cpu_s(void)
{
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%ld/stat", daemon_pid);
    FILE *f = daemon_pid > 0 ? fopen(path, "r") : NULL;
    if (!f)
        return -1;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    const char *p = strrchr(buf, ')'); /* the name may hold spaces */
    unsigned long long ut = 0, st = 0;
    if (!p || sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &ut, &st) != 2)
        return -1;
    return (double)(ut + st) / (double)sysconf(_SC_CLK_TCK);
}

/* CPU seconds the finished client processes used so far. */
static double children_cpu_s(void)
{
    struct rusage ru;
    getrusage(RUSAGE_CHILDREN, &ru);
    return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) / 1e6;
}

/* `metrics`: the daemon's http:// URL, for each client count's stage
 * means (NULL: none). */
static void concurrency(const char *url, const char *what, const char *path, const obs_gbuffer *gb,
                        const obs_bytes *file, int per_client, const char *metrics)
{
    double ms0[4][STAGES], mc0[4][STAGES], ms1[4][STAGES], mc1[4][STAGES];
    int rows = 0;
    printf("\nConcurrent clients (%s, %s, %d frames per client, one process each):\n\n", url, what, per_client);
    printf("| clients | frames | wall s | frames/s | x one client | cores busy: daemon + clients "
           "| frames per daemon core-second |\n|---|---|---|---|---|---|---|\n");
    fflush(stdout);
    double one = 0;
    for (int n = 1; n <= max_clients; n *= 2) {
        if (metrics)
            metrics_read(metrics, ms0[rows], mc0[rows]);
        double d0 = daemon_cpu_s(), c0 = children_cpu_s();
        double t0 = now_ms();
        pid_t pids[8];
        for (int c = 0; c < n; c++) {
            pids[c] = fork();
            if (pids[c] == 0) {
                client_frames(url, path, gb, file, per_client);
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
        double sec = (now_ms() - t0) / 1e3;
        if (bad)
            die("concurrent clients", "a client failed");
        double fps = n * per_client / sec, d1 = daemon_cpu_s(), c1 = children_cpu_s();
        if (n == 1)
            one = fps;
        /* frames per CPU-second of the daemon: the work a frame costs it,
         * whatever share of the cores a loaded machine leaves it */
        char busy[64] = "-", per_core[32] = "-";
        if (d0 >= 0 && d1 >= 0) {
            snprintf(busy, sizeof busy, "%.2f + %.2f", (d1 - d0) / sec, (c1 - c0) / sec);
            if (d1 > d0)
                snprintf(per_core, sizeof per_core, "%.2f", n * per_client / (d1 - d0));
        }
        printf("| %d | %d | %.2f | %.2f | %.2f | %s | %s |\n", n, n * per_client, sec, fps, fps / one, busy,
               per_core);
        fflush(stdout);
        if (metrics)
            metrics_read(metrics, ms1[rows], mc1[rows]);
        rows++;
    }
    if (!metrics)
        return;
    printf("\nThe daemon's stages per client count (GET /metrics before and after: mean ms of those frames; "
           "decode: the EXR's, on the connection's thread; gl: the chain, on the worker):\n\n");
    stage_header("clients");
    for (int r = 0, n = 1; r < rows; r++, n *= 2) {
        char c[16];
        snprintf(c, sizeof c, "%d", n);
        stage_row(c, ms0[r], mc0[r], ms1[r], mc1[r]);
    }
    fflush(stdout);
}

/* ---- the EXR encode and decode, in process ---- */

static double encode_ms(const obs_exr_layer *layer, const obs_exr_options *o, int reps, size_t *bytes)
{
    double t[16];
    char err[OBS_ERR_LEN];
    for (int k = 0; k < reps; k++) {
        obs_bytes b;
        double t0 = now_ms();
        if (obs_exr_write_ex_mem(layer, 1, o, &b, err) != OBS_OK)
            die("encode", err);
        t[k] = now_ms() - t0;
        *bytes = b.size;
        obs_bytes_free(&b);
    }
    return median(t, reps);
}

/* The AO's encode per compression, half and float, one thread and the
 * pool's; the decode of the G-buffer the same; the half answer's error. */
static void codec_bench(const obs_image *ao, const obs_bytes *file, int reps)
{
    static const char *const names[] = {"AO.Y"};
    obs_exr_layer layer = {ao, names};
    int cores = (int)sysconf(_SC_NPROCESSORS_ONLN);
    char err[OBS_ERR_LEN];
    printf("\nEXR encode of the %dx%d AO (median of %d; threads: 1, and %d = the cores; the daemon's answer "
           "uses the cores):\n\n", ao->width, ao->height, reps, cores);
    printf("| compression | pixel | bytes | ms, 1 thread | ms, %d threads |\n|---|---|---|---|---|\n", cores);
    for (int c = OBS_EXR_NONE; c <= OBS_EXR_DWAA; c++) {
        if (obs_exr_compression_check((obs_exr_compression)c, err) != OBS_OK) {
            printf("| %s | - | - | not written: %s | |\n", obs_exr_compression_name((obs_exr_compression)c), err);
            continue;
        }
        for (int px = 0; px < 2; px++) {
            obs_exr_options o = {.pixel = px ? OBS_EXR_FLOAT : OBS_EXR_HALF,
                                 .compression = (obs_exr_compression)c, .threads = 1};
            size_t bytes = 0;
            double one = encode_ms(&layer, &o, reps, &bytes);
            o.threads = cores;
            double all = encode_ms(&layer, &o, reps, &bytes);
            printf("| %s | %s | %zu | %.1f | %.1f |\n", obs_exr_compression_name((obs_exr_compression)c),
                   px ? "float" : "half", bytes, one, all);
        }
    }
    /* the half answer's error against the float AO */
    obs_exr_options o = {.pixel = OBS_EXR_HALF, .compression = OBS_EXR_NONE};
    obs_bytes b;
    obs_image back = {0};
    if (obs_exr_write_ex_mem(&layer, 1, &o, &b, err) != OBS_OK ||
        obs_exr_read_channel_mem(b.data, b.size, "AO.Y", NULL, &back, err) != OBS_OK)
        die("half", err);
    double max_err = 0, lo = 1e30, hi = -1e30;
    for (size_t i = 0; i < (size_t)ao->width * (size_t)ao->height; i++) {
        double e = fabs((double)back.data[i] - ao->data[i]);
        max_err = e > max_err ? e : max_err;
        lo = ao->data[i] < lo ? ao->data[i] : lo;
        hi = ao->data[i] > hi ? ao->data[i] : hi;
    }
    obs_image_free(&back);
    obs_bytes_free(&b);
    printf("\nHalf answer: AO in [%.4f, %.4f]; max |half - float| = %.2e (half's spacing in [0.5, 1) is "
           "2^-11 = 4.9e-4, so rounding errs by at most 2.4e-4)\n", lo, hi, max_err);

    double td[16];
    printf("\nEXR decode of the G-buffer (%zu bytes, in memory; median of %d):\n\n", file->size, reps);
    printf("| threads | ms |\n|---|---|\n");
    for (int th = 1; th <= cores; th = th < cores ? cores : th + 1) {
        obs_limits lim = {.threads = th};
        for (int k = 0; k < reps; k++) {
            obs_gbuffer_file g = {0};
            double t0 = now_ms();
            if (obs_gbuffer_read_exr_mem(file->data, file->size, NULL, &lim, &g, err) != OBS_OK)
                die("decode", err);
            td[k] = now_ms() - t0;
            obs_gbuffer_free(&g);
        }
        printf("| %d | %.1f |\n", th, median(td, reps));
    }
    fflush(stdout);
}

/* The daemon's stages, GET /metrics obscurad_stage_seconds: each one's
 * sum (s) and count so far, in the order of `stages`. */
static const char *const stages[STAGES] = {"receive", "decode", "queue", "gl", "encode", "send", "total"};

static void metrics_read(const char *url, double sum[STAGES], double count[STAGES])
{
    int fd = http_connect(url);
    const char *req = "GET /metrics HTTP/1.1\r\nHost: bench\r\nConnection: close\r\n\r\n";
    if (send(fd, req, strlen(req), MSG_NOSIGNAL) < 0)
        die("metrics", "send failed");
    size_t cap = 1 << 20, got = 0;
    char *buf = malloc(cap + 1);
    ssize_t k;
    while (buf && (k = recv(fd, buf + got, cap - got, 0)) > 0)
        if ((got += (size_t)k) == cap && !(buf = realloc(buf, (cap *= 2) + 1)))
            break;
    close(fd);
    if (!buf)
        die("metrics", "no memory");
    buf[got] = '\0';
    for (int s = 0; s < STAGES; s++) {
        char key[96];
        sum[s] = count[s] = 0;
        snprintf(key, sizeof key, "obscurad_stage_seconds_sum{stage=\"%s\"} ", stages[s]);
        const char *p = strstr(buf, key);
        if (p)
            sum[s] = strtod(p + strlen(key), NULL);
        snprintf(key, sizeof key, "obscurad_stage_seconds_count{stage=\"%s\"} ", stages[s]);
        if ((p = strstr(buf, key)))
            count[s] = strtod(p + strlen(key), NULL);
    }
    free(buf);
}

static void stage_header(const char *first)
{
    printf("| %s |", first);
    for (int s = 0; s < STAGES; s++)
        printf(" %s |", stages[s]);
    printf("\n|---|");
    for (int s = 0; s < STAGES; s++)
        printf("---|");
    printf("\n");
}

/* One row: the mean ms of each stage between two reads. */
static void stage_row(const char *first, const double s0[STAGES], const double c0[STAGES],
                      const double s1[STAGES], const double c1[STAGES])
{
    printf("| %s |", first);
    for (int s = 0; s < STAGES; s++)
        printf(" %.1f |", c1[s] > c0[s] ? (s1[s] - s0[s]) / (c1[s] - c0[s]) * 1e3 : 0.0);
    printf("\n");
}

/* The daemon's stage means so far (the big frames above). */
static void metrics_means(const char *url)
{
    double sum[STAGES], count[STAGES], zero[STAGES] = {0};
    metrics_read(url, sum, count);
    printf("\nDaemon's stages of the 1080p frames above (GET /metrics obscurad_stage_seconds: mean ms over "
           "every protocol, warm-ups included; total: a request's arrival to its answer queued, every "
           "protocol):\n\n");
    stage_header("frames");
    char n[32];
    snprintf(n, sizeof n, "%.0f", count[STAGES - 1]);
    stage_row(n, zero, zero, sum, count);
    fflush(stdout);
}

static int file_bytes(const char *path, obs_bytes *out)
{
    FILE *f = fopen(path, "rb");
    struct stat st;
    if (!f || fstat(fileno(f), &st) != 0 || !(out->data = malloc((size_t)st.st_size ? (size_t)st.st_size : 1)))
        return -1;
    out->size = fread(out->data, 1, (size_t)st.st_size, f);
    fclose(f);
    return out->size == (size_t)st.st_size ? 0 : -1;
}

int main(int argc, char **argv)
{
    int frames = 7, per_client = 3, cpu = 0, only_conc = 0, i = 1;
    for (; i < argc && argv[i][0] == '-'; i++) {
        if (!strcmp(argv[i], "--cpu"))
            cpu = 1;
        else if (!strcmp(argv[i], "--concurrency-only"))
            only_conc = 1;
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc)
            frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--per-client") && i + 1 < argc)
            per_client = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--max-clients") && i + 1 < argc)
            max_clients = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--daemon-pid") && i + 1 < argc)
            daemon_pid = atol(argv[++i]);
        else
            break;
    }
    if (argc - i < 2 || frames < 1 || frames > 64 || per_client < 1 || max_clients < 1 || max_clients > 8) {
        fprintf(stderr, "usage: daemon_bench [--frames N] [--per-client M] [--max-clients 1..8] [--daemon-pid PID] [--cpu] "
                        "[--concurrency-only] "
                        "G-BUFFER.exr URL...\n");
        return 2;
    }
    const char *path = argv[i++];
    char err[OBS_ERR_LEN];
    obs_gbuffer_file gf = {0};
    obs_bytes file = {0};
    if (file_bytes(path, &file) != 0)
        die(path, "cannot read it");
    if (obs_gbuffer_read_exr(path, NULL, NULL, &gf, err) != OBS_OK)
        die(path, err);
    if (gf.gb.camera.source == OBS_CAMERA_NONE)
        die(path, "no camera in the header (make it with tools/exr_upscale ... CAMERA.json)");
    const char *http = NULL;
    for (int u = i; u < argc; u++)
        if (!http && !strncmp(argv[u], "http://", 7))
            http = argv[u];
    if (only_conc) {
        if (http)
            concurrency(http, "HTTP, default answer", path, &gf.gb, &file, per_client, http);
        if (argv[argc - 1] != http)
            concurrency(argv[argc - 1], "binary protocol, raw planes", path, &gf.gb, &file, per_client, http);
        obs_gbuffer_free(&gf);
        obs_bytes_free(&file);
        return 0;
    }

    /* in-process: a warm context, as the daemon's worker (or the CPU device) */
    obs_ctx_desc desc = {0};
    obs_ctx *ctx = NULL;
    if (!cpu && obs_ctx_create(&desc, &ctx, err) != OBS_OK)
        die("context", err);
    obs_result r;
    if ((cpu ? obs_run_cpu(&gf.gb, NULL, OBS_OUTPUT_AO, &r, err) /* warm-up (GL: compiles the shaders) */
             : obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &r, err)) != OBS_OK)
        die("obs_run", err);
    obs_result kept = r; /* its AO for the encode table */

    /* The paths, measured in rounds: each round runs every path once, so
     * that load from outside falls on all of them alike. */
    enum { MAX_PATHS = 16 };
    struct path {
        const char *url, *query, *what;
        int kind; /* 0: this client over fd, 1: clients/remote.c */
        int fd;
        answer a;
        double t[64];
    } paths[MAX_PATHS];
    int np = 0;
    for (int u = i; u < argc && np + 3 <= MAX_PATHS; u++) {
        const char *url = argv[u];
        if (!strncmp(url, "http://", 7)) {
            paths[np++] = (struct path){url, "",
                "HTTP, EXR body, default answer (half, compression auto = rle), answer decoded, keep-alive", 0};
            paths[np++] = (struct path){url, "float=1&compression=zip",
                "HTTP, EXR body, float ZIP answer (the answer before compression=), answer decoded", 0};
        }
        paths[np++] = (struct path){url, NULL,
            !strncmp(url, "http", 4) ? "HTTP through obscura ao --server's client (file read, half answer)"
            : !strncmp(url, "unix:", 5) ? "binary protocol, raw planes, Unix socket"
                                        : "binary protocol, raw planes, TCP loopback", 1};
    }
    for (int q = 0; q < np; q++) { /* warm-ups: the daemon's shaders, textures */
        if (paths[q].kind == 0) {
            paths[q].fd = http_connect(paths[q].url);
            paths[q].a = (answer){0};
            http_big_frame(paths[q].fd, paths[q].query, &file, &paths[q].a);
        } else {
            remote_frame(paths[q].url, path, &gf.gb);
        }
    }
    double t[64], t_dec[64];
    for (int k = 0; k < frames; k++) {
        obs_gbuffer_file g2 = {0};
        double t0 = now_ms();
        if (obs_gbuffer_read_exr_mem(file.data, file.size, NULL, NULL, &g2, err) != OBS_OK)
            die(path, err);
        double t1 = now_ms();
        if ((cpu ? obs_run_cpu(&g2.gb, NULL, OBS_OUTPUT_AO, &r, err)
                 : obs_run(ctx, &g2.gb, NULL, OBS_OUTPUT_AO, &r, err)) != OBS_OK)
            die("obs_run", err);
        double t2 = now_ms();
        obs_result_free(&r);
        obs_gbuffer_free(&g2);
        t[k] = t2 - t1;
        t_dec[k] = t2 - t0;
        for (int q = 0; q < np; q++) {
            t0 = now_ms();
            if (paths[q].kind == 0)
                http_big_frame(paths[q].fd, paths[q].query, &file, &paths[q].a);
            else
                remote_frame(paths[q].url, path, &gf.gb);
            paths[q].t[k] = now_ms() - t0;
        }
    }
    if (ctx)
        obs_ctx_destroy(ctx);
    double in_proc = median(t, frames), in_proc_dec = median(t_dec, frames);
    printf("G-buffer %s: %dx%d; median of %d rounds, each path once a round (in-process first), after one "
           "warm-up each\n\n", path, gf.gb.width, gf.gb.height, frames);
    printf("| path | round trip ms | answer bytes | x in-process run | x in-process decode + run |\n"
           "|---|---|---|---|---|\n");
    printf("| in-process: %s, warm (%s) | %.1f | | 1.00 | |\n", cpu ? "obs_run_cpu" : "obs_run",
           cpu ? "the CPU device" : "upload + passes + readback", in_proc);
    printf("| in-process: EXR decode (in memory) + run | %.1f | | %.2f | 1.00 |\n", in_proc_dec,
           in_proc_dec / in_proc);
    for (int q = 0; q < np; q++) {
        double m = median(paths[q].t, frames);
        if (paths[q].kind == 0)
            printf("| %s | %.1f | %zu | %.2f | %.2f |\n", paths[q].what, m, paths[q].a.size, m / in_proc,
                   m / in_proc_dec);
        else
            printf("| %s | %.1f | | %.2f | %.2f |\n", paths[q].what, m, m / in_proc, m / in_proc_dec);
        if (paths[q].kind == 0) {
            close(paths[q].fd);
            free(paths[q].a.data);
        }
    }
    fflush(stdout);

    if (http)
        metrics_means(http);
    codec_bench(&kept.ao, &file, frames < 5 ? 5 : frames > 16 ? 16 : frames);
    obs_result_free(&kept);

    if (http)
        concurrency(http, "HTTP, default answer", path, &gf.gb, &file, per_client, http);
    if (argv[argc - 1] != http)
        concurrency(argv[argc - 1], "binary protocol, raw planes", path, &gf.gb, &file, per_client, http);
    if (http)
        keepalive_bench(http, &gf.gb, 200);
    obs_gbuffer_free(&gf);
    obs_bytes_free(&file);
    return 0;
}
