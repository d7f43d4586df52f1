/* Where a context's log lines go: the callback obs_ctx_desc.log installed.
 * The first member of struct obs_ctx (context.h), so that obs__log
 * (log.c) reads it through the context pointer without the context's
 * definition and the GL types it pulls in.  A bare sink may stand in for
 * a context where only logging reads it (obs__log_only_ctx: the CPU
 * device's frame setup, run_cpu.c).  Not installed. */
#ifndef OBSCURA_LOG_H
#define OBSCURA_LOG_H

#include "internal.h"

typedef struct obs__log_sink {
    obs_log_fn fn; /* NULL: lines are dropped */
    void *user;
} obs__log_sink;

/* The sink as the obs_ctx pointer obs__log reads; for code that takes a
 * context only to log (the frame setup), never for GL work. */
static inline obs_ctx *obs__log_only_ctx(obs__log_sink *sink)
{
    return (obs_ctx *)(void *)sink;
}

#endif
