/* obscurad: keeps one GL context alive and serves AO frames over HTTP and
 * the binary protocol (Unix socket, TCP).
 *
 *   obscurad [--config FILE] [--http 127.0.0.1:8420] [--socket PATH]
 *            [--tcp HOST:PORT] [--queue 8] ...
 *
 * Threads: main (signals, start and drain), the GL worker (the only one
 * that touches GL), libmicrohttpd's pool and the binary protocol's
 * connection threads (parse, decode, encode); bake jobs' threads.  The
 * work's own threads (llvmpipe's, the worker pools') are bounded by
 * --render-threads (obs_threads_set), the HTTP pool by --threads.
 * SIGTERM/SIGINT: stop accepting, finish every queued and running frame,
 * answer it, exit 0; a second SIGINT exits at once.
 * Exit codes: 0 ok, 1 failure (GL, listen), 2 usage. */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "config.h"
#include "binary_server.h"
#include "gl_worker.h"
#include "http_server.h"
#include "log.h"
#include "stats.h"

static volatile sig_atomic_t stop_requested;
static volatile sig_atomic_t interrupts;

/* Only sets flags: the main loop acts on them. */
static void on_signal(int sig)
{
    if (sig == SIGINT)
        interrupts = interrupts + 1;
    stop_requested = 1;
}

static int install_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    if (sigaction(SIGTERM, &sa, NULL) != 0 || sigaction(SIGINT, &sa, NULL) != 0)
        return -1;
    sa.sa_handler = SIG_IGN;
    return sigaction(SIGPIPE, &sa, NULL);
}

/* Blocks or unblocks SIGTERM/SIGINT on the calling thread; threads made
 * while blocked inherit it, so the signals reach the main thread. */
static void mask_signals(int how)
{
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGINT);
    pthread_sigmask(how, &set, NULL);
}

static int read_token(const char *path, char *buf, size_t len)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        obsd_log(OBSD_LOG_ERROR, "--token-file %s: %s", path, strerror(errno));
        return -1;
    }
    size_t n = fread(buf, 1, len - 1, f);
    int more = fgetc(f) != EOF;
    fclose(f);
    buf[n] = '\0';
    while (n && (buf[n - 1] == '\n' || buf[n - 1] == '\r' || buf[n - 1] == ' ' || buf[n - 1] == '\t'))
        buf[--n] = '\0';
    if (more || n == 0 || strpbrk(buf, "\r\n")) {
        obsd_log(OBSD_LOG_ERROR, "--token-file %s: expected one line of 1 to %zu characters", path, len - 2);
        return -1;
    }
    return 0;
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL); /* a signal cuts it short, which is what we want */
}

/* The GL context's backend (--backend, else OBSCURA_BACKEND, else auto)
 * and program cache (an explicit --cache-dir, even empty, wins); 1 for
 * the CPU device (backend cpu: no context), -1 on a backend that is none
 * (logged). */
static int context_desc(const obsd_config *cfg, obs_ctx_desc *desc)
{
    const obsd_opt_info *bo = obsd_opt_find("backend");
    const char *env = getenv("OBSCURA_BACKEND");
    char bname[32];
    obsd_config_format(cfg, bo, bname, sizeof bname);
    int named = cfg->set[bo - obsd_opt_at(0)];
    if (!named && env && *env) {
        snprintf(bname, sizeof bname, "%s", env);
        named = 1;
    }
    int cpu = !strcmp(bname, "cpu");
    if (!cpu && obs_backend_parse(bname, &desc->backend) != OBS_OK) {
        obsd_log(OBSD_LOG_ERROR, "backend '%s' is not one of " OBSD_CHOICES_backend, bname);
        return -1;
    }
    const obsd_opt_info *co = obsd_opt_find("cache_dir");
    static char cache[OBSD_STR_LEN + 64];
    char why[OBS_ERR_LEN];
    desc->cache_dir = obs_cache_dir_default(cfg->set[co - obsd_opt_at(0)] ? cfg->cache_dir : NULL, cache,
                                           sizeof cache, why);
    if (why[0])
        obsd_log(OBSD_LOG_WARN, "%s", why);
    if (!cpu && desc->backend == OBS_BACKEND_AUTO) {
        /* auto: a GPU, else the faster device for the default chain,
         * measured when auto was named and kept in the cache folder */
        obs_device_choice ch;
        char err[OBS_ERR_LEN] = "";
        if (obs_device_choose(desc->cache_dir, NULL, named, &ch, err) != OBS_OK) {
            obsd_log(OBSD_LOG_WARN, "backend auto: %s; a GL context", err);
        } else {
            obsd_log(named ? OBSD_LOG_INFO : OBSD_LOG_DEBUG, "backend auto: %s", ch.why);
            cpu = ch.cpu;
            if (ch.backend == OBS_BACKEND_EGL_DEVICE)
                desc->backend = OBS_BACKEND_EGL_DEVICE;
        }
    }
    return cpu;
}

/* --render-threads, else OBSCURA_THREADS (as obscura's --threads), made
 * the process's thread limit before the GL context and any thread exist
 * (obs_threads_set may set LP_NUM_THREADS); -1 on a bad value (logged). */
static int render_threads(const obsd_config *cfg)
{
    int n = cfg->render_threads;
    const char *env = getenv("OBSCURA_THREADS");
    char err[OBS_ERR_LEN];
    if (!n && env && *env) {
        obsd_config tmp;
        obsd_config_defaults(&tmp);
        if (obsd_config_set(&tmp, "render_threads", env, err) != OBS_OK) {
            obsd_log(OBSD_LOG_ERROR, "OBSCURA_THREADS: %s", err);
            return -1;
        }
        n = tmp.render_threads;
    }
    if (obs_threads_set(n, err) != OBS_OK) {
        obsd_log(OBSD_LOG_ERROR, "render threads: %s", err);
        return -1;
    }
    return 0;
}

/* --max-memory, else OBSCURA_MAX_MEMORY (as obscura's --max-memory),
 * into cfg->max_memory (MiB; 0: the library's default): at most the
 * machine's memory.  -1 on a bad value (logged, naming where it came
 * from). */
static int max_memory(obsd_config *cfg)
{
    const char *env = getenv("OBSCURA_MAX_MEMORY"), *from = "max_memory";
    char err[OBS_ERR_LEN];
    if (!cfg->max_memory && env && *env) {
        obsd_config tmp;
        obsd_config_defaults(&tmp);
        from = "OBSCURA_MAX_MEMORY";
        obs_status st = obsd_config_set(&tmp, "max_memory", env, err);
        if (st != OBS_OK || !tmp.max_memory) {
            obsd_log(OBSD_LOG_ERROR, "OBSCURA_MAX_MEMORY: %s", st != OBS_OK ? err :
                     "'0' is not a budget (MiB from 1 to the usable memory)");
            return -1;
        }
        cfg->max_memory = tmp.max_memory;
    }
    const long long phys = (long long)(obs_cpu_memory_usable() >> 20);
    if (phys && cfg->max_memory > phys) {
        obsd_log(OBSD_LOG_ERROR, "%s: %d MiB is more than the usable memory (%lld MiB)", from,
                 cfg->max_memory, phys);
        return -1;
    }
    return 0;
}

/* The CPU device's budget and where it came from. */
static void log_max_memory(const obsd_config *cfg)
{
    const obsd_opt_info *o = obsd_opt_find("max_memory");
    char text[160];
    if (cfg->max_memory)
        snprintf(text, sizeof text, "%d MiB (%s)", cfg->max_memory,
                 cfg->set[o - obsd_opt_at(0)] ? "--max-memory" : "OBSCURA_MAX_MEMORY");
    else
        obs_cpu_memory_default_text(text, sizeof text);
    obsd_log(OBSD_LOG_INFO, "memory budget of a frame on the CPU device: %s", text);
}

/* The threads line: a farm slot's limit is kept only when it reached
 * llvmpipe and the pools, so the log says where each count came from. */
static void log_threads(const obsd_config *cfg, int llvmpipe)
{
    obs_threads_info ti;
    char lp[96] = "not in use";
    obs_threads_get(&ti);
    if (llvmpipe && ti.llvmpipe < 0)
        snprintf(lp, sizeof lp, "one per core (LP_NUM_THREADS unset)");
    else if (llvmpipe)
        snprintf(lp, sizeof lp, "%d (LP_NUM_THREADS %s)", ti.llvmpipe,
                 ti.llvmpipe_from_user ? "from the environment, kept" : "set from the render threads");
    if (ti.limit)
        obsd_log(OBSD_LOG_INFO, "threads: render %d (--render-threads or OBSCURA_THREADS), llvmpipe %s, "
                 "HTTP %d", ti.limit, lp, cfg->threads);
    else
        obsd_log(OBSD_LOG_INFO, "threads: render every core (%d; --render-threads bounds them), "
                 "llvmpipe %s, HTTP %d", ti.pool, lp, cfg->threads);
}

/* The log's lines that say where obscurad listens. */
static void log_listeners(const obsd_config *cfg, obsd_http *http, obsd_bin *bin, int token)
{
    if (cfg->socket[0])
        obsd_log(OBSD_LOG_INFO, "binary protocol on unix:%s", cfg->socket);
    if (cfg->tcp[0]) {
        char host[OBSD_STR_LEN] = "127.0.0.1";
        const char *colon = strrchr(cfg->tcp, ':');
        if (colon && colon > cfg->tcp)
            snprintf(host, sizeof host, "%.*s", (int)(colon - cfg->tcp), cfg->tcp);
        obsd_log(OBSD_LOG_INFO, "binary protocol on tcp://%s:%d", host, obsd_bin_tcp_port(bin));
    }
    if (http) {
        char url[OBSD_STR_LEN + 16];
        obsd_http_url(http, url, sizeof url);
        obsd_log(OBSD_LOG_INFO, "listening on %s (queue %d, %d threads, max %lld pixels, "
                 "max body %lld bytes%s)", url, cfg->queue, cfg->threads,
                 (long long)cfg->max_pixels, (long long)cfg->max_body, token ? ", token required" : "");
    }
}

/* Drain: no new connections; every frame taken is finished and answered
 * before the server stops, within --drain-timeout: past it what is left
 * is cut (logged), and the worker skips the frames still queued and stops
 * the CPU device's frame under way, so the drain ends whatever the clients
 * do. */
static void drain(const obsd_config *cfg, obsd_http *http, obsd_bin *bin, obsd_gl_worker *gl)
{
    obsd_log(OBSD_LOG_INFO, "stopping: finishing %d request(s) and %d binary connection(s) under way "
             "(SIGINT again to quit now)", http ? obsd_http_in_flight(http) : 0, obsd_bin_in_flight(bin));
    if (http)
        obsd_http_quiesce(http);
    obsd_bin_quiesce(bin);
    const double drain_end = obsd_now_ms() + 1000.0 * cfg->drain_timeout;
    while ((http && obsd_http_in_flight(http) > 0) || obsd_bin_in_flight(bin) > 0) {
        if (interrupts >= 2) {
            obsd_log(OBSD_LOG_WARN, "second SIGINT: exiting now");
            _exit(130);
        }
        if (cfg->drain_timeout > 0 && obsd_now_ms() >= drain_end) {
            int requests = http ? obsd_http_in_flight(http) : 0, conns = obsd_bin_in_flight(bin);
            obsd_log(OBSD_LOG_WARN, "drain deadline (%d s) passed: cutting %d request(s) and %d "
                     "binary connection(s)", cfg->drain_timeout, requests, conns);
            obsd_gl_cut(gl);
            if (http)
                obsd_http_cut(http);
            obsd_bin_cut(bin);
            break;
        }
        sleep_ms(20);
    }
}

int main(int argc, char **argv)
{
    obsd_config cfg;
    char err[OBS_ERR_LEN] = "", token[512] = "";
    int help = 0;

    obsd_config_defaults(&cfg);
    obs_status s = obsd_config_args(&cfg, argc, argv, &help, err);
    if (s != OBS_OK) {
        fprintf(stderr, "obscurad: %s\n(run 'obscurad --help' for usage)\n", err);
        return 2;
    }
    if (help) {
        obsd_config_help(stdout);
        return 0;
    }
    obsd_log_set_level(cfg.log_level);
    if (!cfg.http[0] && !cfg.socket[0] && !cfg.tcp[0]) {
        obsd_log(OBSD_LOG_ERROR, "no listener: --http, --socket and --tcp are all empty");
        return 2;
    }
    if (cfg.token_file[0] && read_token(cfg.token_file, token, sizeof token) != 0)
        return 2;

    obs_ctx_desc desc = {.log = obsd_log_core};
    int cpu = context_desc(&cfg, &desc);
    if (cpu < 0 || render_threads(&cfg) != 0 || max_memory(&cfg) != 0)
        return 2;
    if (install_signals() != 0) {
        obsd_log(OBSD_LOG_ERROR, "cannot install signal handlers: %s", strerror(errno));
        return 1;
    }

    obsd_queue queue;
    obsd_gl_worker gl;
    obsd_http *http = NULL;
    obsd_bin *bin = NULL;
    if (obsd_queue_init(&queue, cfg.queue) != 0) {
        obsd_log(OBSD_LOG_ERROR, "out of memory");
        return 1;
    }
    obsd_stats_init();
    mask_signals(SIG_BLOCK);
    s = obsd_gl_start(&gl, &queue, &desc, cpu, &cfg, err);
    if (s != OBS_OK) {
        obsd_log(OBSD_LOG_ERROR, "OpenGL: %s (%s)", err, obs_status_name(s));
        obsd_queue_destroy(&queue);
        return 1;
    }
    obsd_log(OBSD_LOG_INFO, "GL context: backend %s, %s, %s (created in %.0f ms)", gl.backend,
             gl.gl_renderer, gl.gl_version, gl.create_ms);
    log_threads(&cfg, strstr(gl.gl_renderer, "llvmpipe") != NULL);
    if (cpu)
        log_max_memory(&cfg);
    const obsd_front front = obsd_front_make(&cfg, token, &queue, &gl);
    s = cfg.http[0] ? obsd_http_start(&front, &http, err) : OBS_OK;
    if (s == OBS_OK && (cfg.socket[0] || cfg.tcp[0]))
        s = obsd_bin_start(&front, &bin, err);
    mask_signals(SIG_UNBLOCK);
    if (s != OBS_OK) {
        obsd_log(OBSD_LOG_ERROR, "%s", err);
        if (http) {
            obsd_http_quiesce(http);
            obsd_http_stop(http);
        }
        obsd_gl_stop(&gl);
        obsd_queue_destroy(&queue);
        return 1;
    }
    log_listeners(&cfg, http, bin, token[0] != 0);

    while (!stop_requested) {
        sleep_ms(200);
        obsd_http_tick(http); /* event streams' keep-alives */
    }

    drain(&cfg, http, bin, &gl);
    obsd_http_stop(http);
    obsd_bin_stop(bin);
    obsd_gl_stop(&gl);
    obsd_queue_destroy(&queue);
    obsd_log(OBSD_LOG_INFO, "stopped");
    return 0;
}
