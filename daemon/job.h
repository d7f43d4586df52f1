/* A frame on its way through the daemon: decoded on a network thread,
 * queued, run on the GL worker, handed back through `done`. */
#ifndef OBSD_JOB_H
#define OBSD_JOB_H

#include <pthread.h>

#include "obscura/deep.h"
#include "obscura/obscura.h"

typedef struct obsd_job obsd_job;
struct obsd_job {
    /* in: owned by the submitter, valid until `done` runs; either a flat
     * G-buffer (gb, the VAO++ chain) or a deep one (deep, the multi-layer
     * chain of include/obscura/deep.h) */
    const obs_gbuffer *gb;
    const obs_deep_image *deep;
    const obs_params *params;
    unsigned outputs;
    /* out: filled by the GL worker before `done` (result for gb,
     * deep_result for deep) */
    obs_result result;
    obs_deep_result deep_result;
    /* output=deep on GL: every kept node's AO from the pass
     * (obs_deep_run_nodes); empty on the CPU device, where the encoder
     * computes them (obs_deep_ao_nodes) */
    obs_deep_ao deep_nodes;
    obs_status status;
    char err[OBS_ERR_LEN];
    double t_queued, t_started, t_finished; /* obsd_now_ms() */
    /* Called on the GL worker thread when the job is finished; it must not
     * block (the HTTP server resumes the connection here). */
    void (*done)(obsd_job *job, void *user);
    void *user;
};

/* A bounded FIFO of jobs: producers never wait (a full queue is refused),
 * the GL worker waits for work. */
typedef struct obsd_queue {
    pthread_mutex_t lock;
    pthread_cond_t nonempty;
    obsd_job **ring;
    int cap, head, count;
    int closed;
    int running; /* 1 while the worker runs a job it took */
} obsd_queue;

int obsd_queue_init(obsd_queue *q, int capacity); /* -1: out of memory */
void obsd_queue_destroy(obsd_queue *q);
/* 0: queued; -1: full or closed. */
int obsd_queue_push(obsd_queue *q, obsd_job *job);
/* Waits for a job; NULL once the queue is closed and empty.  Marks the
 * worker running until obsd_queue_done(). */
obsd_job *obsd_queue_pop(obsd_queue *q);
/* The same, waiting at most timeout_ms (< 0: no limit): NULL with
 * *timed_out set when the queue stayed empty and open that long. */
obsd_job *obsd_queue_pop_wait(obsd_queue *q, int timeout_ms, int *timed_out);
void obsd_queue_done(obsd_queue *q);
/* No more pushes; the worker drains what is queued, then pop gives NULL. */
void obsd_queue_close(obsd_queue *q);
/* Waiting jobs (not counting the running one), and whether it is full. */
void obsd_queue_stats(obsd_queue *q, int *waiting, int *running, int *full);

/* CLOCK_MONOTONIC in milliseconds. */
double obsd_now_ms(void);

#endif
