/* Logging: the library never prints; it hands messages to the callback
 * the caller installed (obs_ctx_desc.log), or drops them. */
#include <stdio.h>

#include "log.h"

static void vlogf(obs_log_fn fn, void *user, obs_log_level level, const char *fmt, va_list ap)
{
    if (!fn)
        return;
    char msg[1024];
    vsnprintf(msg, sizeof msg, fmt, ap);
    fn(user, level, msg);
}

void obs__logf(obs_log_fn fn, void *user, obs_log_level level, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vlogf(fn, user, level, fmt, ap);
    va_end(ap);
}

void obs__log(obs_ctx *ctx, obs_log_level level, const char *fmt, ...)
{
    if (!ctx)
        return;
    va_list ap;
    va_start(ap, fmt);
    /* the sink is the context's first member (log.h, context.h) */
    const obs__log_sink *sink = (const obs__log_sink *)(const void *)ctx;
    vlogf(sink->fn, sink->user, level, fmt, ap);
    va_end(ap);
}
