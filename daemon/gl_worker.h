/* The GL worker: the one thread that owns the GL context, for the whole
 * life of the process.  It takes jobs from the queue, runs obs_run (or
 * obs_deep_run for deep input) and hands each back through its `done`
 * callback.  When a frame fails with
 * OBS_GL_ERROR or OBS_GL_UNAVAILABLE (a lost context), that frame is
 * answered with the failure, then the worker destroys the context and
 * creates a new one with the same options (retrying with backoff) before
 * it takes the next frame; `alive` is 0 meanwhile. */
#ifndef OBSD_GL_WORKER_H
#define OBSD_GL_WORKER_H

#include <stdatomic.h>

#include "config.h"
#include "job.h"

typedef struct obsd_gl_worker {
    pthread_t thread;
    obsd_queue *queue;
    obs_ctx_desc desc;
    int fail_after; /* testing: frame number treated as a GL failure (0: none) */
    unsigned long long max_cost;    /* --max-cost (0: none) */
    unsigned long long keep_memory; /* --keep-memory */
    int frame_deadline;             /* --frame-deadline, seconds (0: none) */
    size_t max_memory;              /* --max-memory in bytes (0: the library's default) */
    char max_memory_name[96];       /* what set it, as the band warning names it */
    char last_warn[320];            /* the CPU device's last warning (worker only): a
                                     * frame repeating it logs it at debug level */
    atomic_ullong kept_bytes;       /* obs_ctx_kept_bytes after the last frame */
    atomic_ullong heap_trims;       /* malloc_trim calls, once idle after frames */
    /* programs built from source, loaded from the program cache, cache
     * entries rejected: over every context, after the last frame */
    atomic_ullong programs_compiled, programs_loaded, programs_rejected;
    unsigned long long programs_base[3]; /* of the contexts destroyed (worker only) */
    char cache_dir[4096];          /* the program cache in use ("" none), set with backend */
    int cache_writable;
    /* set once the first context exists (read-only afterwards; a
     * recreated context uses the same options) */
    char backend[32], gl_version[128], gl_vendor[128], gl_renderer[256];
    int cpu;                       /* backend cpu: no context, the CPU device */
    double create_ms;
    atomic_int alive;              /* a context exists */
    atomic_ullong recreations;     /* contexts recreated after a GL failure */
    atomic_int stopping;           /* obsd_gl_stop() was called */
    atomic_int cut;                /* obsd_gl_cut() was called */
    int running;                   /* the thread runs (main thread only) */
    /* start-up handshake */
    pthread_mutex_t lock;
    pthread_cond_t ready;
    int started;
    obs_status start_status;
    char err[OBS_ERR_LEN];
} obsd_gl_worker;

/* Starts the thread and waits until it has created the context; on
 * failure the thread has ended and err says why.  From cfg: max_cost
 * (a frame asking more is answered OBS_TOO_COSTLY without running),
 * keep_memory (what the context may keep when the queue runs empty),
 * max_memory (the CPU device's budget, resolved: obscurad.c) and
 * fail_gl_after (testing: frame N is failed with OBS_GL_ERROR without
 * running it, as if the context were lost; 0: never).  cpu: the jobs run
 * on the CPU device (obs_run_cpu, obs_deep_run_cpu) and no context is
 * made; backend reads "cpu". */
obs_status obsd_gl_start(obsd_gl_worker *w, obsd_queue *q, const obs_ctx_desc *desc, int cpu,
                         const obsd_config *cfg, char err[OBS_ERR_LEN]);

/* Closes the queue, lets the worker finish every queued job, joins it
 * (the context is destroyed on the worker thread). */
void obsd_gl_stop(obsd_gl_worker *w);

/* The drain's cut (its deadline passed, the requests cut): the frame
 * running on the CPU device stops at its next tile, and every job still
 * queued is answered OBS_CANCELLED without running, so that the stop
 * that follows does not wait for frames nobody waits for. */
void obsd_gl_cut(obsd_gl_worker *w);

#endif
