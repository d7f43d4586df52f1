/* What the CLI's commands share: see cli.h. */
#include "cli.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <string.h>

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
    if (strncmp(msg, what, strlen(what)) == 0) /* the message names it already */
        fprintf(stderr, "obscura: %s (%s)\n", msg, obs_status_name(s));
    else
        fprintf(stderr, "obscura: %s: %s (%s)\n", what, msg, obs_status_name(s));
    return cli_status_exit(s);
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
    fprintf(stderr, "obscura: %s: ", cmd);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n(run 'obscura help' for usage)\n");
    va_end(ap);
    exit(EXIT_USAGE);
}

double cli_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}
