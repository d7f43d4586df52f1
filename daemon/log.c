/* Log lines to stderr: each formatted whole, then written with one call,
 * so lines from different threads do not interleave; one call is one
 * line, whatever its text holds (control characters escaped). */
#include <stdarg.h>
#include <stdio.h>
#include <time.h>
#include <unistd.h>

#include "config.h"
#include "log.h"

static volatile int log_level = OBSD_LOG_INFO;

void obsd_log_set_level(int level) { log_level = level; }

int obsd_log_enabled(int level) { return level <= log_level; }

/* Control characters (a newline or a carriage return from a client's
 * query, path or parameter) would forge lines: written as \xNN.  Returns
 * the length written into out (at most cap - 1). */
size_t obsd_log_escape(const char *in, size_t n, char *out, size_t cap)
{
    static const char hex[] = "0123456789abcdef";
    size_t o = 0;
    for (size_t i = 0; i < n && o + 1 < cap; i++) {
        unsigned char c = (unsigned char)in[i];
        if (c >= 0x20 && c != 0x7f) {
            out[o++] = (char)c;
        } else if (o + 4 < cap) {
            out[o++] = '\\';
            out[o++] = 'x';
            out[o++] = hex[c >> 4];
            out[o++] = hex[c & 15];
        } else {
            break;
        }
    }
    out[o] = '\0';
    return o;
}

void obsd_log(int level, const char *fmt, ...)
{
    static const char *const names[] = {"error", "warn", "info", "debug"};
    char msg[2048], line[2048];
    struct timespec ts;
    struct tm tm;
    if (!obsd_log_enabled(level))
        return;
    clock_gettime(CLOCK_REALTIME, &ts);
    gmtime_r(&ts.tv_sec, &tm);
    int n = snprintf(line, sizeof line, "%04d-%02d-%02dT%02d:%02d:%02d.%03ldZ obscurad %s: ",
                     tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                     ts.tv_nsec / 1000000, names[level < 0 ? 0 : level > 3 ? 3 : level]);
    va_list ap;
    va_start(ap, fmt);
    int m = vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    size_t mlen = m < 0 ? 0 : (size_t)m >= sizeof msg ? sizeof msg - 1 : (size_t)m;
    size_t len = (size_t)n + obsd_log_escape(msg, mlen, line + n, sizeof line - (size_t)n - 1);
    line[len++] = '\n';
    ssize_t w = write(STDERR_FILENO, line, len);
    (void)w;
}

void obsd_log_core(void *user, obs_log_level level, const char *msg)
{
    (void)user;
    obsd_log((int)level, "%s", msg); /* OBS_LOG_* and OBSD_LOG_* agree */
}
