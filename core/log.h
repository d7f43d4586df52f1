/* Where a context's log lines go: the callback obs_ctx_desc.log installed.
 * The first member of struct obs_ctx (context.h), so that obs__log
 * (log.c) reads it through the context pointer without the context's
 * definition and the GL types it pulls in.  Not installed. */
#ifndef OBSCURA_LOG_H
#define OBSCURA_LOG_H

#include "internal.h"

typedef struct obs__log_sink {
    obs_log_fn fn; /* NULL: lines are dropped */
    void *user;
} obs__log_sink;

#endif
