/* What obscurad's front ends (http_server.c, binary_server.c) serve
 * frames from, the same for both: the configuration, the bearer token
 * (NULL: none required), the frames' queue and the GL worker.  obscurad.c
 * makes one; each server keeps a copy; what it points to outlives them. */
#ifndef OBSD_FRONT_H
#define OBSD_FRONT_H

#include "config.h"
#include "gl_worker.h"

typedef struct obsd_front {
    const obsd_config *cfg;
    const char *token;
    obsd_queue *queue;
    obsd_gl_worker *gl;
} obsd_front;

/* token "" is no token, as NULL. */
static inline obsd_front obsd_front_make(const obsd_config *cfg, const char *token, obsd_queue *q,
                                         obsd_gl_worker *gl)
{
    obsd_front f = {cfg, token && *token ? token : NULL, q, gl};
    return f;
}

#endif
