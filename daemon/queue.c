/* The bounded job queue between the network threads and the GL worker. */
#include <errno.h>
#include <stdlib.h>
#include <time.h>

#include "job.h"

double obsd_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

int obsd_queue_init(obsd_queue *q, int capacity)
{
    q->ring = calloc((size_t)capacity, sizeof *q->ring);
    if (!q->ring)
        return -1;
    q->cap = capacity;
    q->head = q->count = q->closed = q->running = 0;
    pthread_mutex_init(&q->lock, NULL);
    /* obsd_queue_pop_wait's timeout runs on the monotonic clock */
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&q->nonempty, &attr);
    pthread_condattr_destroy(&attr);
    return 0;
}

void obsd_queue_destroy(obsd_queue *q)
{
    if (!q->ring)
        return;
    pthread_cond_destroy(&q->nonempty);
    pthread_mutex_destroy(&q->lock);
    free(q->ring);
    q->ring = NULL;
}

int obsd_queue_push(obsd_queue *q, obsd_job *job)
{
    int rc = -1;
    pthread_mutex_lock(&q->lock);
    if (!q->closed && q->count < q->cap) {
        job->t_queued = obsd_now_ms();
        q->ring[(q->head + q->count) % q->cap] = job;
        q->count++;
        rc = 0;
        pthread_cond_signal(&q->nonempty);
    }
    pthread_mutex_unlock(&q->lock);
    return rc;
}

obsd_job *obsd_queue_pop(obsd_queue *q)
{
    int timed_out;
    return obsd_queue_pop_wait(q, -1, &timed_out);
}

obsd_job *obsd_queue_pop_wait(obsd_queue *q, int timeout_ms, int *timed_out)
{
    obsd_job *job = NULL;
    struct timespec until;
    clock_gettime(CLOCK_MONOTONIC, &until);
    if (timeout_ms >= 0) {
        until.tv_sec += timeout_ms / 1000;
        until.tv_nsec += (long)(timeout_ms % 1000) * 1000000L;
        if (until.tv_nsec >= 1000000000L) {
            until.tv_sec++;
            until.tv_nsec -= 1000000000L;
        }
    }
    *timed_out = 0;
    pthread_mutex_lock(&q->lock);
    while (q->count == 0 && !q->closed && !*timed_out) {
        if (timeout_ms < 0)
            pthread_cond_wait(&q->nonempty, &q->lock);
        else if (pthread_cond_timedwait(&q->nonempty, &q->lock, &until) == ETIMEDOUT)
            *timed_out = q->count == 0 && !q->closed;
    }
    if (q->count > 0) {
        job = q->ring[q->head];
        q->head = (q->head + 1) % q->cap;
        q->count--;
        q->running = 1;
    }
    pthread_mutex_unlock(&q->lock);
    return job;
}

void obsd_queue_done(obsd_queue *q)
{
    pthread_mutex_lock(&q->lock);
    q->running = 0;
    pthread_mutex_unlock(&q->lock);
}

void obsd_queue_close(obsd_queue *q)
{
    pthread_mutex_lock(&q->lock);
    q->closed = 1;
    pthread_cond_broadcast(&q->nonempty);
    pthread_mutex_unlock(&q->lock);
}

void obsd_queue_stats(obsd_queue *q, int *waiting, int *running, int *full)
{
    pthread_mutex_lock(&q->lock);
    if (waiting)
        *waiting = q->count;
    if (running)
        *running = q->running;
    if (full)
        *full = q->closed || q->count >= q->cap;
    pthread_mutex_unlock(&q->lock);
}
