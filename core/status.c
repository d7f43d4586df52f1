/* Status names and messages, generated from OBS_STATUS_MAP. */
#include <stdarg.h>
#include <stdio.h>

#include "obscura/obscura.h"

const char *obs_status_name(obs_status s)
{
    switch (s) {
#define X(name, msg) case OBS_##name: return #name;
        OBS_STATUS_MAP(X)
#undef X
    default: return "UNKNOWN";
    }
}

const char *obs_status_message(obs_status s)
{
    switch (s) {
#define X(name, msg) case OBS_##name: return msg;
        OBS_STATUS_MAP(X)
#undef X
    default: return "unknown status";
    }
}

obs_status obs_status_fail(char err[OBS_ERR_LEN], obs_status s, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, OBS_ERR_LEN, fmt, ap);
        va_end(ap);
    }
    return s;
}
