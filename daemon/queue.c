/* The bounded job queue between the network threads and the GL worker. */
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
    pthread_cond_init(&q->nonempty, NULL);
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
    obsd_job *job = NULL;
    pthread_mutex_lock(&q->lock);
    while (q->count == 0 && !q->closed)
        pthread_cond_wait(&q->nonempty, &q->lock);
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
