/* The GL worker thread: creates the context, runs jobs, destroys it. */
#include <stdio.h>
#include <string.h>

#include "gl_worker.h"

static void *worker_main(void *arg)
{
    obsd_gl_worker *w = arg;
    obs_ctx *ctx = NULL;
    char err[OBS_ERR_LEN] = "";
    double t0 = obsd_now_ms();
    obs_status s = obs_ctx_create(&w->desc, &ctx, err);

    pthread_mutex_lock(&w->lock);
    w->start_status = s;
    if (s == OBS_OK) {
        obs_ctx_info info;
        obs_ctx_get_info(ctx, &info);
        snprintf(w->backend, sizeof w->backend, "%s", obs_backend_name(info.backend));
        snprintf(w->gl_version, sizeof w->gl_version, "%s", info.gl_version ? info.gl_version : "");
        snprintf(w->gl_vendor, sizeof w->gl_vendor, "%s", info.gl_vendor ? info.gl_vendor : "");
        snprintf(w->gl_renderer, sizeof w->gl_renderer, "%s", info.gl_renderer ? info.gl_renderer : "");
        w->create_ms = obsd_now_ms() - t0;
        w->alive = 1;
    } else {
        snprintf(w->err, sizeof w->err, "%s", err);
    }
    w->started = 1;
    pthread_cond_signal(&w->ready);
    pthread_mutex_unlock(&w->lock);
    if (s != OBS_OK)
        return NULL;

    obsd_job *job;
    while ((job = obsd_queue_pop(w->queue)) != NULL) {
        job->t_started = obsd_now_ms();
        job->err[0] = '\0';
        job->status = obs_run(ctx, job->gb, job->params, job->outputs, &job->result, job->err);
        job->t_finished = obsd_now_ms();
        obsd_queue_done(w->queue);
        job->done(job, job->user); /* the job is not ours after this */
    }
    obs_ctx_destroy(ctx);
    return NULL;
}

obs_status obsd_gl_start(obsd_gl_worker *w, obsd_queue *q, const obs_ctx_desc *desc,
                         char err[OBS_ERR_LEN])
{
    memset(w, 0, sizeof *w);
    w->queue = q;
    w->desc = *desc;
    pthread_mutex_init(&w->lock, NULL);
    pthread_cond_init(&w->ready, NULL);
    if (pthread_create(&w->thread, NULL, worker_main, w) != 0) {
        snprintf(err, OBS_ERR_LEN, "cannot start the GL thread");
        return OBS_NO_MEMORY;
    }
    pthread_mutex_lock(&w->lock);
    while (!w->started)
        pthread_cond_wait(&w->ready, &w->lock);
    obs_status s = w->start_status;
    pthread_mutex_unlock(&w->lock);
    if (s != OBS_OK) {
        pthread_join(w->thread, NULL);
        snprintf(err, OBS_ERR_LEN, "%s", w->err);
    }
    return s;
}

void obsd_gl_stop(obsd_gl_worker *w)
{
    if (!w->alive)
        return;
    obsd_queue_close(w->queue);
    pthread_join(w->thread, NULL);
    w->alive = 0;
}
