/* What the CLI's commands share: see cli.h. */
#include "cli.h"

#include <dirent.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <string.h>
#include <errno.h>

#include "flags.h"
#include "obscura/obscura.h"

int cli_status_exit(obs_status s)
{
    switch (s) {
    case OBS_BAD_FILE:
    case OBS_UNSUPPORTED:
    case OBS_MISSING_CHANNEL:
    case OBS_TOO_LARGE:
    case OBS_NO_CAMERA:
    case OBS_INVALID_ARGUMENT: return EXIT_BADINPUT;
    default: return EXIT_FAIL;
    }
}

int cli_fail(obs_status s, const char *what, const char *err)
{
    const char *msg = err && *err ? err : obs_status_message(s);
    char shown[2 * OBS_ERR_LEN], name[1024];
    /* a damaged header's bytes reach the message: escaped, not sent to the terminal */
    cli_escape(msg, shown, sizeof shown);
    cli_escape(what, name, sizeof name);
    if (strncmp(msg, what, strlen(what)) == 0) /* the message names it already */
        fprintf(stderr, "obscura: error: %s (%s)\n", shown, obs_status_name(s));
    else
        fprintf(stderr, "obscura: error: %s: %s (%s)\n", name, shown, obs_status_name(s));
    return cli_status_exit(s);
}

void cli_escape(const char *in, char *out, size_t len)
{
    static const char hex[] = "0123456789abcdef";
    size_t o = 0;
    if (len == 0)
        return;
    for (const unsigned char *c = (const unsigned char *)in; *c && o + 1 < len; c++) {
        if (*c >= 0x20 && *c != 0x7f) {
            out[o++] = (char)*c;
            continue;
        }
        if (o + 4 >= len)
            break;
        out[o++] = '\\';
        out[o++] = 'x';
        out[o++] = hex[*c >> 4];
        out[o++] = hex[*c & 15];
    }
    out[o] = '\0';
}

void cli_progress_percent(int *last, long done, long total)
{
    int pct = total > 0 ? (int)(100 * done / total) : 100;
    if (pct == *last)
        return;
    *last = pct;
    printf("Progress: %d%%\n", pct);
    fflush(stdout);
}

int cli_input_fail(obs_status s, const char *what, const char *err)
{
    int rc = cli_fail(s, what, err);
    return s == OBS_IO ? EXIT_BADINPUT : rc;
}

void cli_die_usage(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "obscura: error: %s: ", cmd);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n(run 'obscura help' for usage)\n");
    va_end(ap);
    exit(EXIT_USAGE);
}

void cli_parse_shard(const char *cmd, const char *val, int *index, int *count)
{
    char *end, *end2;
    long si = strtol(val, &end, 10), n = 0;
    end2 = end;
    if (*end == '/')
        n = strtol(end + 1, &end2, 10);
    if (*end != '/' || end == val || *end2 || end2 == end + 1 || n < 1 || n > 1000000 || si < 0 ||
        si >= n)
        cli_die_usage(cmd, "--shard '%s': expected I/N with 0 <= I < N (e.g. 0/4)", val);
    *index = (int)si;
    *count = (int)n;
}

double cli_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

void cli_param_row(const obs_bake_param_info *pi, const char *def, int markdown)
{
    char flag[64], range[64];
    snprintf(flag, sizeof flag, "--%s", pi->name);
    for (char *c = flag; *c; c++)
        *c = *c == '_' ? '-' : *c;
    if (pi->type == OBS_BAKE_PARAM_ENUM)
        snprintf(range, sizeof range, "%s", pi->choices);
    else
        snprintf(range, sizeof range, "%g .. %g", pi->min, pi->max);
    if (markdown) {
        /* a '|' of the choices would end a cell */
        printf("| `%s` | %s | ", flag, def);
        for (const char *c = range; *c; c++)
            printf(*c == '|' ? "\\|" : "%c", *c);
        printf(" | %s |\n", pi->doc);
    } else {
        printf("%-24s %-10s %-22s %s\n", flag, def, range, pi->doc);
    }
}

/* A decorators file (obscura bake, bake-dynamic, obscura reference) in memory. */
obs_status cli_read_text(const char *path, char **out, char err[OBS_ERR_LEN])
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, OBS_ERR_LEN, "cannot open: %s", strerror(errno));
        return OBS_IO;
    }
    size_t cap = 4096, n = 0;
    char *b = malloc(cap);
    for (size_t got; b && (got = fread(b + n, 1, cap - n - 1, f)) > 0;) {
        n += got;
        if (n + 1 == cap) {
            char *nb = cap < ((size_t)1 << 30) ? realloc(b, cap * 2) : NULL;
            if (!nb) {
                free(b);
                b = NULL;
                break;
            }
            b = nb;
            cap *= 2;
        }
    }
    int bad = ferror(f);
    fclose(f);
    if (!b || bad) {
        free(b);
        snprintf(err, OBS_ERR_LEN, "%s", bad ? "read error" : "too large (1 GiB at most)");
        return bad ? OBS_IO : OBS_TOO_LARGE;
    }
    b[n] = 0;
    *out = b;
    return OBS_OK;
}


/* A thread count as the user wrote it: digits only, in [0, 64] (0: every
 * core, the bakes' threads parameter's meaning); else -1. */
static int threads_value(const char *v)
{
    char *end;
    errno = 0;
    long n = strtol(v, &end, 10);
    if (!*v || *end || errno || v[0] == '+' || v[0] == ' ' || n < 0 || n > 64)
        return -1;
    return (int)n;
}

/* Takes every --NAME VALUE (or --NAME=VALUE) out of argv, the last
 * value in *given (NULL: none); a missing value is a usage error of cmd
 * saying what the value is.  The new argc. */
static int take_flag(const char *cmd, int argc, char **argv, const char *name, const char *what,
                     const char **given)
{
    const char *v;
    int n = 0;
    *given = NULL;
    for (int i = 0; i < argc; i++) {
        int k = cli_flag_value(argc, argv, &i, name, &v);
        if (k < 0)
            cli_die_usage(cmd, "option --%s needs a value (%s)", name, what);
        if (k > 0)
            *given = v;
        else
            argv[n++] = argv[i];
    }
    return n;
}

int cli_take_threads(const char *cmd, int argc, char **argv)
{
    const char *given, *from = "--threads";
    int n = take_flag(cmd, argc, argv, "threads", "a whole number in [0, 64], 0: every core", &given);
    if (!given) {
        given = getenv("OBSCURA_THREADS");
        from = "OBSCURA_THREADS";
        if (!given || !*given) /* set empty: as unset, as OBSCURA_BACKEND */
            return n;
    }
    char shown[64], err[OBS_ERR_LEN];
    int t = threads_value(given);
    cli_escape(given, shown, sizeof shown);
    if (t < 0)
        cli_die_usage(cmd, "%s: '%s' is not a whole number in [0, 64] (the threads this process may "
                      "run: llvmpipe's and every worker pool's; 0: every core)", from, shown);
    if (obs_threads_set(t, err) != OBS_OK)
        cli_die_usage(cmd, "%s: %s", from, err);
    return n;
}

/* The budget of this process's CPU frames: bytes (0: the default), the
 * name the band warning gives it, the -v text. */
static struct {
    size_t bytes;
    char name[96], text[160];
} max_memory;

int cli_take_max_memory(const char *cmd, int argc, char **argv)
{
    const char *given, *from = "--max-memory";
    int n = take_flag(cmd, argc, argv, "max-memory", "MiB the CPU device's frames may hold", &given);
    max_memory.bytes = 0;
    max_memory.name[0] = 0;
    max_memory.text[0] = 0;
    if (!given) {
        given = getenv("OBSCURA_MAX_MEMORY");
        from = "OBSCURA_MAX_MEMORY";
        if (!given || !*given) /* set empty: as unset, as OBSCURA_THREADS */
            return n;
    }
    const size_t phys_mib = obs_cpu_memory_usable() >> 20;
    const long hi = phys_mib ? (long)phys_mib : 1L << 30;
    char shown[64], *end;
    cli_escape(given, shown, sizeof shown);
    errno = 0;
    long mib = strtol(given, &end, 10);
    if (!*given || *end || errno || given[0] == '+' || given[0] == ' ' || mib < 1)
        cli_die_usage(cmd, "%s: '%s' is not a whole number of MiB from 1 to %ld (the memory the CPU "
                      "device's frames may hold; over it a frame runs in bands of rows)", from, shown, hi);
    if (mib > hi)
        cli_die_usage(cmd, "%s: %s MiB is more than the usable memory (%ld MiB)", from, shown, hi);
    max_memory.bytes = (size_t)mib << 20;
    if (from[0] == '-')
        snprintf(max_memory.name, sizeof max_memory.name, "--max-memory %ld MiB", mib);
    else
        snprintf(max_memory.name, sizeof max_memory.name, "OBSCURA_MAX_MEMORY=%ld MiB", mib);
    snprintf(max_memory.text, sizeof max_memory.text, "%ld MiB (%s)", mib, from);
    return n;
}

void cli_max_memory(obs_cpu_options *o)
{
    o->max_memory = max_memory.bytes;
    o->max_memory_name = max_memory.bytes ? max_memory.name : NULL; /* the default's: bands_run.c */
}

int cli_max_memory_given(void) { return max_memory.name[0] == '-'; }

const char *cli_max_memory_text(void)
{
    if (!max_memory.bytes)
        obs_cpu_memory_default_text(max_memory.text, sizeof max_memory.text);
    return max_memory.text;
}

int cli_process_threads(void)
{
    DIR *d = opendir("/proc/self/task");
    struct dirent *e;
    int n = 0;
    if (!d)
        return -1;
    while ((e = readdir(d)))
        n += e->d_name[0] != '.';
    closedir(d);
    return n;
}
