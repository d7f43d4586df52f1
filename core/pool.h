/* One parallel-for over every fan-out of the library: the bake's samples,
 * probes, volume points and LOD instances, the reference's rows, an EXR
 * part's chunks. pthreads: the caller's thread works too, ranges are handed
 * out in order from one counter, and what a range computes depends on its
 * indices only, so the output is the same bytes for any thread count. */
#ifndef OBS_POOL_H
#define OBS_POOL_H

#include <stddef.h>

/* The most threads one loop starts. */
#define OBS__POOL_MAX_THREADS 64

/* The one rule for a thread count: the caller's, else (0 or less) the
 * machine's cores; then no more than the process's limit (obs_threads_set:
 * obscura --threads, obscurad --render-threads, OBSCURA_THREADS) and the
 * maximum; at least 1. */
int obs__pool_threads(int requested);

/* The process's limit (0: none); obs_threads_set sets it. */
void obs__pool_set_limit(int n);
int obs__pool_limit(void);

/* Embree's device configuration under the limit: "threads=N" in buf (its
 * BVH builds run on TBB's threads, one per core unless told), NULL
 * without a limit (Embree's defaults, as before). */
const char *obs__pool_embree_config(char buf[32]);

typedef struct obs__pool_for {
    size_t first, end; /* the items [first, end) */
    size_t chunk;      /* items per range handed out (0: 1) */
    int threads;       /* through obs__pool_threads */
    /* Runs the items [i0, i1) on one thread with that thread's local
     * state; nonzero stops handing out ranges (a failure). */
    int (*range)(void *ctx, void *local, size_t i0, size_t i1);
    void *ctx;
    /* Optional: bytes of zeroed state per thread, with a hook at the
     * thread's start and one at its end (the end one runs under the pool's
     * lock, so it may merge the local state into ctx without one of its
     * own). */
    size_t local_size;
    void (*begin)(void *ctx, void *local);
    void (*end_thread)(void *ctx, void *local);
    /* Optional: after each range, under the pool's lock, with the items
     * done so far of end - first; nonzero stops (a cancel). */
    int (*progress)(void *user, size_t done, size_t total);
    void *progress_user;
} obs__pool_for;

/* Runs the loop; returns 1 when a range or progress stopped it, -1 when
 * the threads' local state could not be allocated (nothing ran), else 0;
 * *done (when not NULL) the items finished. */
int obs__pool_run(const obs__pool_for *f, size_t *done);

/* The plain form: fn(ctx, i) for every i in [0, n), in ranges of chunk. */
void obs__pool_each(size_t n, size_t chunk, int threads, void (*fn)(void *ctx, size_t i),
                    void *ctx);

#endif
