/* The worker pool (pool.h): one counter hands out ranges, the caller's
 * thread is one of the workers, and threads that fail to start are not
 * needed (the others take their ranges). */
#include "pool.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

typedef struct run {
    const obs__pool_for *f;
    size_t chunk;
    atomic_size_t next;
    atomic_int stop;
    pthread_mutex_t lock; /* guards done and the hooks' merges */
    size_t done;
} run;

/* Set once at the start (obs_threads_set), read by every loop: atomic,
 * so a loop already running on another thread reads a whole value. */
static atomic_int limit;

void obs__pool_set_limit(int n)
{
    atomic_store(&limit, n > 0 ? n : 0);
}

int obs__pool_limit(void)
{
    return atomic_load(&limit);
}

const char *obs__pool_embree_config(char buf[32])
{
    int lim = atomic_load(&limit);
    if (lim <= 0)
        return NULL;
    snprintf(buf, 32, "threads=%d", lim);
    return buf;
}

int obs__pool_threads(int requested)
{
    long n = requested, lim = atomic_load(&limit);
    if (n <= 0)
        n = sysconf(_SC_NPROCESSORS_ONLN);
    if (lim > 0 && n > lim)
        n = lim;
    return n < 1 ? 1 : n > OBS__POOL_MAX_THREADS ? OBS__POOL_MAX_THREADS : (int)n;
}

static void take_ranges(run *r, void *local)
{
    const obs__pool_for *f = r->f;
    size_t i0;
    while (!atomic_load(&r->stop) && (i0 = atomic_fetch_add(&r->next, r->chunk)) < f->end) {
        size_t i1 = f->end - i0 > r->chunk ? i0 + r->chunk : f->end;
        int failed = f->range(f->ctx, local, i0, i1);
        pthread_mutex_lock(&r->lock);
        r->done += i1 - i0;
        if (f->progress && f->progress(f->progress_user, r->done, f->end - f->first))
            failed = 1; /* between ranges: cancelled */
        pthread_mutex_unlock(&r->lock);
        if (failed)
            atomic_store(&r->stop, 1);
    }
}

typedef struct thread {
    run *r;
    void *local;
} thread;

static void *worker(void *arg)
{
    thread *t = arg;
    run *r = t->r;
    const obs__pool_for *f = r->f;
    if (f->begin)
        f->begin(f->ctx, t->local);
    take_ranges(r, t->local);
    if (f->end_thread) {
        pthread_mutex_lock(&r->lock);
        f->end_thread(f->ctx, t->local);
        pthread_mutex_unlock(&r->lock);
    }
    return NULL;
}

int obs__pool_run(const obs__pool_for *f, size_t *done)
{
    int nt = obs__pool_threads(f->threads), started = 0;
    unsigned char *local = NULL;
    if (f->local_size && !(local = calloc((size_t)nt, f->local_size)))
        return -1;
    run r = {.f = f, .chunk = f->chunk ? f->chunk : 1};
    atomic_init(&r.next, f->first < f->end ? f->first : f->end);
    atomic_init(&r.stop, 0);
    pthread_mutex_init(&r.lock, NULL);
    pthread_t th[OBS__POOL_MAX_THREADS];
    thread t[OBS__POOL_MAX_THREADS];
    for (int k = 0; k < nt; k++)
        t[k] = (thread){&r, local ? local + (size_t)k * f->local_size : NULL};
    while (started < nt - 1 && pthread_create(&th[started], NULL, worker, &t[started + 1]) == 0)
        started++;
    worker(&t[0]); /* the caller's thread is one of the workers */
    for (int k = 0; k < started; k++)
        pthread_join(th[k], NULL);
    pthread_mutex_destroy(&r.lock);
    free(local);
    if (done)
        *done = r.done;
    return atomic_load(&r.stop);
}

typedef struct each {
    void (*fn)(void *, size_t);
    void *ctx;
} each;

static int each_range(void *ctx, void *local, size_t i0, size_t i1)
{
    (void)local;
    const each *e = ctx;
    for (size_t i = i0; i < i1; i++)
        e->fn(e->ctx, i);
    return 0;
}

void obs__pool_each(size_t n, size_t chunk, int threads, void (*fn)(void *ctx, size_t i),
                    void *ctx)
{
    each e = {fn, ctx};
    obs__pool_for f = {.end = n, .chunk = chunk, .threads = threads, .range = each_range, .ctx = &e};
    obs__pool_run(&f, NULL);
}
