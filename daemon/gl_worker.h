/* The GL worker: the one thread that owns the GL context, for the whole
 * life of the process.  It takes jobs from the queue, runs obs_run and
 * hands each back through its `done` callback. */
#ifndef OBSD_GL_WORKER_H
#define OBSD_GL_WORKER_H

#include "job.h"

typedef struct obsd_gl_worker {
    pthread_t thread;
    obsd_queue *queue;
    obs_ctx_desc desc;
    /* set once the context exists (read-only afterwards) */
    char backend[32], gl_version[128], gl_vendor[128], gl_renderer[256];
    double create_ms;
    int alive; /* the context exists and the thread runs */
    /* start-up handshake */
    pthread_mutex_t lock;
    pthread_cond_t ready;
    int started;
    obs_status start_status;
    char err[OBS_ERR_LEN];
} obsd_gl_worker;

/* Starts the thread and waits until it has created the context; on
 * failure the thread has ended and err says why. */
obs_status obsd_gl_start(obsd_gl_worker *w, obsd_queue *q, const obs_ctx_desc *desc,
                         char err[OBS_ERR_LEN]);

/* Closes the queue, lets the worker finish every queued job, joins it
 * (the context is destroyed on the worker thread). */
void obsd_gl_stop(obsd_gl_worker *w);

#endif
