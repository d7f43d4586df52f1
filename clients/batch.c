/* obscura batch (see batch.h): frame specs, path patterns and the run.
 *
 * The frames run in worker processes that each call the CLI's `ao` in a
 * loop: in-process there is one worker, so one GL context serves every
 * frame; with --server there are --jobs workers, each one connection at
 * a time.  Workers take the next frame from a shared counter and report
 * each frame's exit code over a pipe; the parent only keeps count and
 * draws the progress.  A worker that dies leaves its frame unreported,
 * which counts as a failure, never as a hang. */
#include "batch.h"
#include "cli.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

enum { RC_OK = 0, RC_FAIL = 1, RC_USAGE = 2, RC_BADINPUT = 3, RC_UNAVAILABLE = 4 };

#define MAX_FRAME 999999999L
#define MAX_JOBS 64

/* ---- frame specs ------------------------------------------------------------ */

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Reads a frame number at *p (digits only); -1 when there is none. */
static long read_num(const char **p)
{
    const char *s = *p;
    long v = 0;
    if (*s < '0' || *s > '9')
        return -1;
    while (*s >= '0' && *s <= '9') {
        v = v * 10 + (*s++ - '0');
        if (v > MAX_FRAME)
            return -1;
    }
    *p = s;
    return v;
}

int cli_batch_parse_frames(const char *spec, int **frames, int *count, char *err, size_t err_len)
{
    *frames = NULL;
    *count = 0;
    if (!spec || !*spec) {
        snprintf(err, err_len, "--frames: empty frame spec");
        return -1;
    }
    /* two passes: count (with an overflow-proof limit), then fill */
    int *out = NULL;
    long total = 0;
    for (int pass = 0; pass < 2; pass++) {
        long n = 0;
        const char *p = spec;
        for (;;) {
            const char *item = p;
            while (*p == ' ')
                p++;
            long a = read_num(&p), b, step = 1;
            if (a < 0)
                goto bad;
            b = a;
            if (*p == '-') {
                p++;
                if ((b = read_num(&p)) < 0)
                    goto bad;
                if (*p == 'x' || *p == ':') {
                    p++;
                    if ((step = read_num(&p)) < 1)
                        goto bad;
                }
                if (b < a) {
                    snprintf(err, err_len, "--frames: '%.*s' runs backwards", (int)strcspn(item, ","),
                             item);
                    free(out);
                    return -1;
                }
            }
            while (*p == ' ')
                p++;
            if (*p != ',' && *p != '\0')
                goto bad;
            long k = (b - a) / step + 1;
            if (pass == 0) {
                if (k > CLI_BATCH_MAX_FRAMES || (total += k) > CLI_BATCH_MAX_FRAMES) {
                    snprintf(err, err_len, "--frames: more than %d frames", CLI_BATCH_MAX_FRAMES);
                    return -1;
                }
            } else {
                for (long f = a; f <= b; f += step)
                    out[n++] = (int)f;
            }
            if (*p == '\0')
                break;
            p++;
            continue;
        bad:
            snprintf(err, err_len, "--frames: '%.*s' is not N, A-B or A-BxS (in '%s')",
                     (int)strcspn(item, ","), item, spec);
            free(out);
            return -1;
        }
        if (pass == 0 && !(out = malloc((size_t)total * sizeof *out))) {
            snprintf(err, err_len, "out of memory");
            return -1;
        }
    }
    qsort(out, (size_t)total, sizeof *out, cmp_int);
    int n = 0;
    for (long i = 0; i < total; i++)
        if (n == 0 || out[n - 1] != out[i])
            out[n++] = out[i];
    *frames = out;
    *count = n;
    return 0;
}

/* ---- patterns --------------------------------------------------------------- */

/* A placeholder at s: its length and padding width; 0 when none.  "%%"
 * is reported as a literal (width -1, length 2). */
static size_t placeholder(const char *s, int *width)
{
    if (*s == '#') {
        size_t n = strspn(s, "#");
        *width = (int)n;
        return n;
    }
    if (*s != '%')
        return 0;
    if (s[1] == '%') {
        *width = -1;
        return 2;
    }
    if (s[1] == 'd') {
        *width = 0;
        return 2;
    }
    if (s[1] == '0') {
        size_t d = strspn(s + 2, "0123456789");
        if (d > 0 && d <= 2 && s[2 + d] == 'd') {
            *width = atoi(s + 2);
            return 2 + d + 1;
        }
    }
    return 0;
}

int cli_batch_check_pattern(const char *pattern, char *err, size_t err_len)
{
    int found = 0, w;
    for (const char *s = pattern; *s;) {
        size_t n = placeholder(s, &w);
        if (n == 0) {
            s++;
            continue;
        }
        found += w >= 0;
        s += n;
    }
    if (found == 1)
        return 0;
    snprintf(err, err_len, "'%s' %s: mark the frame number with #### or %%04d", pattern,
             found ? "has more than one frame placeholder" : "has no frame placeholder");
    return -1;
}

int cli_batch_expand(const char *pattern, int frame, char *buf, size_t len)
{
    char e[8];
    size_t o = 0;
    if (cli_batch_check_pattern(pattern, NULL, 0) != 0 || len == 0)
        return -1;
    for (const char *s = pattern; *s;) {
        int w;
        size_t n = placeholder(s, &w);
        char num[32];
        const char *put = num;
        size_t pl;
        if (n == 0) {
            e[0] = *s, e[1] = '\0';
            put = e;
            n = 1;
        } else if (w < 0) {
            put = "%";
        } else {
            snprintf(num, sizeof num, "%0*d", w, frame);
        }
        pl = strlen(put);
        if (o + pl >= len)
            return -1;
        memcpy(buf + o, put, pl);
        o += pl;
        s += n;
    }
    buf[o] = '\0';
    return 0;
}

/* ---- the run ---------------------------------------------------------------- */

typedef struct report {
    int index; /* into the frames to run */
    int rc;
    double seconds;
} report;

typedef struct shared {
    int next; /* the next frame to take */
    int stop; /* the server is gone: take no more */
} shared;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec / 1e9;
}

static int usage_error(const char *fmt, const char *arg)
{
    fprintf(stderr, "obscura: error: batch: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n(run 'obscura help' for usage)\n");
    return RC_USAGE;
}

/* A batch's flags and what the steps find: the frames, those with an
 * input, and the ao options handed to every frame. */
typedef struct batch_job {
    const char *in, *out, *spec, *server;
    int jobs, quiet_given;
    int allow_missing; /* missing inputs are not a failure (a batch that wrote nothing still is) */
    int quiet;         /* -q: no line per frame that went well */
    int percent;       /* --progress percent */
    int percent_last;  /* the last "Progress: N%" printed, -1 none */
    char **extra;      /* the ao options */
    int nextra, server_at;
    int *frames, nframes;
    int *todo, ntodo, missing;
} batch_job;

/* mkdir -p of the folder that holds `path`. */
static int make_parent(const char *path)
{
    char dir[PATH_MAX];
    const char *slash = strrchr(path, '/');
    if (!slash || slash == path)
        return 0;
    snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    for (char *p = dir + 1;; p++) {
        if (*p == '/' || *p == '\0') {
            char c = *p;
            *p = '\0';
            if (mkdir(dir, 0777) != 0 && errno != EEXIST)
                return -1;
            *p = c;
            if (!c)
                return 0;
        }
    }
}

/* One frame done: --progress percent's "Progress: N%" on stdout (what
 * Deadline's and OpenCue's parsers read); a failed frame's error line;
 * unless -q, the ok frame's line (stderr no terminal) or the bar. */
static void progress(batch_job *b, int tty, int done, double t0, int frame, int rc, double secs)
{
    int total = b->ntodo;
    double el = now_s() - t0;
    double fps = el > 0 ? done / el : 0;
    if (b->percent)
        cli_progress_percent(&b->percent_last, done, total);
    if (rc != RC_OK || (!tty && !b->quiet && !b->percent)) {
        char what[32] = "ok";
        if (rc != RC_OK)
            snprintf(what, sizeof what, "failed (exit %d)", rc);
        fprintf(stderr, "%sobscura: %sbatch: [%d/%d] frame %d %s (%.2f s, %.2f frames/s)\n",
                tty ? "\r\033[K" : "", rc != RC_OK ? "error: " : "", done, total, frame, what, secs, fps);
        return;
    }
    if (!tty || b->quiet || b->percent)
        return;
    enum { BAR = 30 };
    char bar[BAR + 1];
    int fill = total ? done * BAR / total : BAR;
    for (int i = 0; i < BAR; i++)
        bar[i] = i < fill ? '#' : '.';
    bar[BAR] = '\0';
    double eta = fps > 0 ? (total - done) / fps : 0;
    fprintf(stderr, "\r\033[K[%s] %d/%d  %.2f frames/s  ETA %d:%02d", bar, done, total, fps, (int)eta / 60,
            (int)eta % 60);
    if (done == total)
        fputc('\n', stderr);
}

int cli_batch_rotate(const char *list, int k, char *buf, size_t len)
{
    int n = 1;
    for (const char *p = list; *p; p++)
        n += *p == ',';
    k = ((k % n) + n) % n;
    const char *start = list;
    for (int i = 0; i < k; i++)
        start = strchr(start, ',') + 1;
    size_t total = strlen(list);
    if (total >= len)
        return -1;
    /* "c,d" + "," + "a,b" */
    size_t tail = strlen(start);
    memcpy(buf, start, tail);
    if (k > 0) {
        buf[tail] = ',';
        memcpy(buf + tail + 1, list, (size_t)(start - list) - 1);
    }
    buf[total] = '\0';
    return 0;
}

/* One frame's `obscura ao` arguments into av (room for nextra + 4):
 * INPUT -o OUTPUT, then the ao options.  Returns the count. */
static int frame_argv(char **av, char *inp, char *outp, char **extra, int nextra)
{
    int n = 0;
    av[n++] = inp;
    av[n++] = "-o";
    av[n++] = outp;
    for (int k = 0; k < nextra; k++)
        av[n++] = extra[k];
    av[n] = NULL;
    return n;
}

/* One worker: frames from the shared counter until none are left.  With
 * a list of servers, frame i starts at server i (round robin). */
static void worker(int fd, shared *sh, const batch_job *b, const cli_batch_ops *ops)
{
    char **av = malloc((size_t)(b->nextra + 4) * sizeof *av);
    char inp[PATH_MAX], outp[PATH_MAX], servers[4096];
    for (;;) {
        int i = __atomic_fetch_add(&sh->next, 1, __ATOMIC_SEQ_CST);
        if (i >= b->ntodo || __atomic_load_n(&sh->stop, __ATOMIC_SEQ_CST))
            break;
        report r = {i, RC_FAIL, 0};
        double t0 = now_s();
        if (av && cli_batch_expand(b->in, b->todo[i], inp, sizeof inp) == 0 &&
            cli_batch_expand(b->out, b->todo[i], outp, sizeof outp) == 0) {
            int n = frame_argv(av, inp, outp, b->extra, b->nextra);
            if (b->server_at >= 0 &&
                cli_batch_rotate(b->extra[b->server_at], i, servers, sizeof servers) == 0)
                av[3 + b->server_at] = servers;
            r.rc = ops->ao(n, av);
        }
        r.seconds = now_s() - t0;
        if (r.rc == RC_UNAVAILABLE)
            __atomic_store_n(&sh->stop, 1, __ATOMIC_SEQ_CST);
        fflush(stderr);
        if (write(fd, &r, sizeof r) != (ssize_t)sizeof r)
            break;
    }
    free(av);
    if (ops->finish)
        ops->finish();
}

/* The batch's own flags; the rest are ao options (b->extra, room for
 * argc + 4).  Returns RC_OK or the usage error's code. */
static int parse_args(int argc, char **argv, batch_job *b)
{
#define VALUE(name)                                                                              \
    (!strcmp(a, name) ? (i + 1 < argc ? argv[++i] : NULL)                                        \
                      : (!strncmp(a, name "=", sizeof name) ? a + sizeof name : (const char *)0))
#define MATCHES(name) (!strcmp(a, name) || !strncmp(a, name "=", sizeof name))
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        int has = MATCHES("--frames") || MATCHES("-o") || MATCHES("--output-file") || MATCHES("--server") ||
                  MATCHES("--jobs") || MATCHES("-j");
        if (has) {
            const char *name = a;
            const char *v = MATCHES("--frames") ? VALUE("--frames")
                            : MATCHES("-o")     ? VALUE("-o")
                            : MATCHES("--output-file") ? VALUE("--output-file")
                            : MATCHES("--server")      ? VALUE("--server")
                            : MATCHES("--jobs")        ? VALUE("--jobs")
                                                       : VALUE("-j");
            if (!v)
                return usage_error("option %s needs a value", name);
            if (!strncmp(name, "--frames", 8))
                b->spec = v;
            else if (!strncmp(name, "-o", 2) || !strncmp(name, "--output-file", 13))
                b->out = v;
            else if (!strncmp(name, "--server", 8))
                b->server = v;
            else {
                char *end;
                long j = strtol(v, &end, 10);
                if (*end || j < 1 || j > MAX_JOBS)
                    return usage_error("--jobs: '%s' is not in [1, 64]", v);
                b->jobs = (int)j;
            }
        } else if (!strcmp(a, "--allow-missing")) {
            b->allow_missing = 1;
        } else if (MATCHES("--progress")) {
            const char *v = VALUE("--progress");
            if (!v || (strcmp(v, "plain") && strcmp(v, "percent")))
                return usage_error("--progress: '%s' is not plain or percent", v ? v : "");
            b->percent = !strcmp(v, "percent");
        } else if (!b->in && a[0] != '-' && (i == 0 || cli_batch_check_pattern(a, NULL, 0) == 0)) {
            b->in = a; /* the input pattern: first, or the first word with a placeholder */
        } else {
            int q = !strcmp(a, "-q") || !strcmp(a, "--quiet");
            b->quiet |= q;
            b->quiet_given |= q || !strcmp(a, "-v") || !strcmp(a, "--verbose");
            b->extra[b->nextra++] = argv[i];
        }
    }
#undef VALUE
#undef MATCHES
    return RC_OK;
}

/* The patterns, the frames, --jobs against --server; then --server and
 * -q join the ao options.  Returns RC_OK or the usage error's code. */
static int check_job(batch_job *b)
{
    char err[512];
    if (!b->in)
        return usage_error("%s", "no input pattern (e.g. 'shot/frame.####.exr')");
    if (!b->out)
        return usage_error("%s", "no output pattern (-o 'out/ao.####.exr')");
    if (!b->spec)
        return usage_error("%s", "no frames (--frames 1-100, 1-100x2, 1,5,9)");
    if (cli_batch_check_pattern(b->in, err, sizeof err) != 0 ||
        cli_batch_check_pattern(b->out, err, sizeof err) != 0)
        return usage_error("%s", err);
    if (cli_batch_parse_frames(b->spec, &b->frames, &b->nframes, err, sizeof err) != 0)
        return usage_error("%s", err);
    if (!b->server && b->jobs > 1)
        return usage_error("%s", "--jobs > 1 needs --server: in-process, every frame runs on the one GL "
                                 "context (for parallel frames run obscurad and pass --server)");
    if (b->server) {
        b->extra[b->nextra++] = "--server";
        b->server_at = b->nextra;
        b->extra[b->nextra++] = (char *)b->server;
    }
    if (!b->quiet_given)
        b->extra[b->nextra++] = "-q"; /* the progress replaces ao's per-frame lines */
    return RC_OK;
}

/* The ao options: checked once, before any frame (exits 2 when wrong). */
static int check_ao_options(const batch_job *b, const cli_batch_ops *ops)
{
    char inp[PATH_MAX], outp[PATH_MAX];
    char **av = malloc((size_t)(b->nextra + 4) * sizeof *av);
    if (!av || cli_batch_expand(b->in, b->frames[0], inp, sizeof inp) != 0 ||
        cli_batch_expand(b->out, b->frames[0], outp, sizeof outp) != 0) {
        free(av);
        return usage_error("%s", "a pattern expands to a path that is too long");
    }
    ops->check(frame_argv(av, inp, outp, b->extra, b->nextra), av);
    free(av);
    return RC_OK;
}

/* The frames whose input exists (b->todo), their output folders made;
 * missing inputs reported (an error unless --allow-missing): the run
 * still does the others, summarise() says what the gaps cost. */
static int find_inputs(batch_job *b)
{
    b->todo = malloc((size_t)b->nframes * sizeof *b->todo);
    if (!b->todo)
        return RC_FAIL;
    for (int i = 0; i < b->nframes; i++) {
        char p[PATH_MAX];
        cli_batch_expand(b->in, b->frames[i], p, sizeof p);
        if (access(p, R_OK) != 0) {
            char shown[PATH_MAX * 4];
            cli_escape(p, shown, sizeof shown);
            fprintf(stderr, "obscura: %s: batch: frame %d: missing input %s (%s)\n",
                    b->allow_missing ? "warning" : "error", b->frames[i], shown, strerror(errno));
            b->missing++;
            continue;
        }
        cli_batch_expand(b->out, b->frames[i], p, sizeof p);
        if (make_parent(p) != 0) {
            fprintf(stderr, "obscura: error: batch: cannot create the folder of %s: %s\n", p, strerror(errno));
            return RC_FAIL;
        }
        b->todo[b->ntodo++] = b->frames[i];
    }
    return RC_OK;
}

/* Forks up to --jobs workers writing to fd; returns how many started.
 * A worker frees what the parent holds and exits 0. */
static int start_workers(batch_job *b, const cli_batch_ops *ops, shared *sh, int fds[2],
                         int *code, pid_t *pids)
{
    int want = b->jobs < b->ntodo ? b->jobs : b->ntodo, n = 0;
    fflush(NULL);
    for (; n < want; n++) {
        pid_t p = fork();
        if (p < 0)
            break;
        if (p == 0) {
            close(fds[0]);
            worker(fds[1], sh, b, ops);
            close(fds[1]);
            free(b->extra);
            free(b->frames);
            free(b->todo);
            free(code);
            munmap(sh, sizeof *sh);
            exit(0);
        }
        pids[n] = p;
    }
    return n;
}

/* Each frame's code from the workers' reports (code[i] -1 until then),
 * the progress drawn as they come; then the workers reaped. */
static void collect(batch_job *b, int fd, int *code, const pid_t *pids, int nworkers,
                    double t0)
{
    int tty = isatty(2), done_n = 0;
    report r;
    for (;;) {
        ssize_t got = read(fd, &r, sizeof r);
        if (got < 0 && errno == EINTR)
            continue;
        if (got != (ssize_t)sizeof r)
            break;
        if (r.index < 0 || r.index >= b->ntodo || code[r.index] != -1)
            continue;
        code[r.index] = r.rc;
        progress(b, tty, ++done_n, t0, b->todo[r.index], r.rc, r.seconds);
    }
    close(fd);
    for (int k = 0; k < nworkers; k++) {
        int st;
        while (waitpid(pids[k], &st, 0) < 0 && errno == EINTR)
            ;
        if (!WIFEXITED(st) || WEXITSTATUS(st) != 0)
            fprintf(stderr, "obscura: error: batch: a worker %s %d\n", WIFSIGNALED(st) ? "died of signal" : "exited",
                    WIFSIGNALED(st) ? WTERMSIG(st) : WEXITSTATUS(st));
    }
    if (tty && !b->quiet && !b->percent && done_n < b->ntodo)
        fputc('\n', stderr);
}

/* The closing line and the batch's exit code from the frames' codes. */
static int summarise(const batch_job *b, const int *code, double el)
{
    int ok = 0, failed = 0, not_run = 0, n3 = 0, n1 = 0, n4 = 0, n2 = 0;
    for (int i = 0; i < b->ntodo; i++) {
        switch (code[i]) {
        case RC_OK: ok++; break;
        case -1: not_run++; break;
        default:
            failed++;
            n1 += code[i] == RC_FAIL || code[i] > RC_UNAVAILABLE;
            n2 += code[i] == RC_USAGE;
            n3 += code[i] == RC_BADINPUT;
            n4 += code[i] == RC_UNAVAILABLE;
        }
    }
    /* a permanent failure first (a retry cannot help), the server last */
    int rc = n2 ? RC_USAGE : n3 ? RC_BADINPUT : n1 ? RC_FAIL : (n4 || not_run) ? RC_UNAVAILABLE : RC_OK;
    if (not_run && !n4 && !n1 && !n3 && !n2)
        rc = RC_FAIL; /* a worker died */
    /* A farm reads only the code: a gap is bad input (3: rerunning will
     * not help until the frame is there) unless --allow-missing, and a
     * batch that wrote nothing is never a success. */
    if (rc == RC_OK && ((b->missing && !b->allow_missing) || ok == 0))
        rc = RC_BADINPUT;
    if (b->quiet && rc == RC_OK)
        return rc;
    fprintf(stderr, "obscura: %sbatch: %d frames: %d ok, %d failed, %d missing, %d not run; %.1f s, %.2f frames/s%s\n",
            rc == RC_OK ? "" : "error: ", b->nframes, ok, failed, b->missing, not_run, el, el > 0 ? ok / el : 0.0,
            ok == 0 && rc != RC_USAGE ? "; nothing written" : "");
    return rc;
}

/* The frames in the workers, their codes collected, the summary. */
static int run_frames(batch_job *b, const cli_batch_ops *ops)
{
    int rc = RC_OK, fds[2] = {-1, -1};
    pid_t pids[MAX_JOBS];
    int *code = malloc((size_t)(b->ntodo ? b->ntodo : 1) * sizeof *code);
    shared *sh = mmap(NULL, sizeof *sh, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (!code || sh == MAP_FAILED || pipe(fds) != 0) {
        fprintf(stderr, "obscura: error: batch: %s\n", strerror(errno));
        rc = RC_FAIL;
        goto done;
    }
    sh->next = sh->stop = 0;
    for (int i = 0; i < b->ntodo; i++)
        code[i] = -1;
    int nworkers = start_workers(b, ops, sh, fds, code, pids);
    close(fds[1]);
    double t0 = now_s();
    if (nworkers == 0 && b->ntodo > 0)
        fprintf(stderr, "obscura: error: batch: cannot start a worker: %s\n", strerror(errno));
    collect(b, fds[0], code, pids, nworkers, t0);
    rc = summarise(b, code, now_s() - t0);
done:
    if (sh != MAP_FAILED)
        munmap(sh, sizeof *sh);
    free(code);
    return rc;
}

int cli_batch(int argc, char **argv, const cli_batch_ops *ops)
{
    batch_job b = {.jobs = 1, .server_at = -1, .percent_last = -1};
    b.extra = malloc((size_t)(argc + 4) * sizeof *b.extra);
    if (!b.extra)
        return RC_FAIL;
    int rc = parse_args(argc, argv, &b);
    if (rc == RC_OK)
        rc = check_job(&b);
    if (rc == RC_OK)
        rc = check_ao_options(&b, ops);
    if (rc == RC_OK)
        rc = find_inputs(&b);
    if (rc == RC_OK)
        rc = run_frames(&b, ops);
    free(b.todo);
    free(b.frames);
    free(b.extra);
    return rc;
}
