/* The GL worker thread: creates the context, runs jobs, recreates the
 * context after a GL failure, destroys it. */
#include <malloc.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "gl_worker.h"
#include "config.h"
#include "log.h"

#define BACKOFF_FIRST_MS 100
#define BACKOFF_MAX_MS 5000

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* The program counters, over every context the worker made. */
static void count_programs(obsd_gl_worker *w, const obs_ctx *ctx, int destroying)
{
    obs_ctx_info ci;
    obs_ctx_get_info(ctx, &ci);
    unsigned long long n[3] = {w->programs_base[0] + ci.programs_compiled,
                               w->programs_base[1] + ci.programs_loaded,
                               w->programs_base[2] + ci.programs_rejected};
    atomic_store(&w->programs_compiled, n[0]);
    atomic_store(&w->programs_loaded, n[1]);
    atomic_store(&w->programs_rejected, n[2]);
    if (destroying)
        memcpy(w->programs_base, n, sizeof n);
}

/* Destroys the context and creates a new one with the same options,
 * retrying with backoff until it exists or the worker is stopped.
 * Returns the new context, or NULL when stopped before one existed. */
static obs_ctx *recreate(obsd_gl_worker *w, obs_ctx *ctx, obs_status why, const char *msg)
{
    atomic_store(&w->alive, 0);
    obsd_log(OBSD_LOG_WARN, "GL failure (%s: %s): destroying and recreating the GL context",
             obs_status_name(why), msg && *msg ? msg : obs_status_message(why));
    count_programs(w, ctx, 1);
    obs_ctx_destroy(ctx);
    ctx = NULL;
    int backoff = BACKOFF_FIRST_MS;
    for (int attempt = 1;; attempt++) {
        char err[OBS_ERR_LEN] = "";
        double t0 = obsd_now_ms();
        obs_status s = obs_ctx_create(&w->desc, &ctx, err);
        if (s == OBS_OK)
            s = obs_ctx_set_deadline(ctx, w->frame_deadline, err);
        if (s == OBS_OK) {
            atomic_fetch_add(&w->recreations, 1);
            atomic_store(&w->alive, 1);
            obsd_log(OBSD_LOG_WARN, "GL context recreated (attempt %d, %.0f ms)", attempt,
                     obsd_now_ms() - t0);
            return ctx;
        }
        ctx = NULL;
        obsd_log(OBSD_LOG_WARN, "GL context recreation failed (attempt %d): %s (%s); retrying in %d ms",
                 attempt, err, obs_status_name(s), backoff);
        /* Sleep in slices so that a stop is noticed soon. */
        for (int slept = 0; slept < backoff; slept += 50) {
            if (atomic_load(&w->stopping))
                return NULL;
            sleep_ms(50);
        }
        backoff = backoff * 2 > BACKOFF_MAX_MS ? BACKOFF_MAX_MS : backoff * 2;
    }
}

/* The CPU device's messages: warnings and errors as they are (a band
 * over --max-memory), the rest (each band's rows) at debug. */
static void cpu_log(void *user, obs_log_level level, const char *msg)
{
    obsd_gl_worker *w = user;
    if (level == OBS_LOG_WARN) {
        /* the same warning for every frame alike (a budget too small for
         * the frames a client sends) is said once, then at debug level */
        if (strcmp(msg, w->last_warn) == 0) {
            obsd_log(OBSD_LOG_DEBUG, "%s (again)", msg);
            return;
        }
        snprintf(w->last_warn, sizeof w->last_warn, "%s", msg);
    }
    obsd_log_core(NULL, level <= OBS_LOG_WARN ? level : OBS_LOG_DEBUG, msg);
}

/* The CPU device's cancel: the drain cut the requests. */
static int cut_asked(void *user)
{
    return atomic_load(&((obsd_gl_worker *)user)->cut);
}

/* 1 (and the job answered OBS_TOO_COSTLY) when the frame asks for more
 * work than --max-cost. */
static int too_costly(const obsd_gl_worker *w, obsd_job *job)
{
    if (!w->max_cost)
        return 0;
    int width = job->deep ? job->deep->width : job->gb->width;
    int height = job->deep ? job->deep->height : job->gb->height;
    /* deep: the nodes' pass, and with output=deep on the CPU device the
     * per-node AO the encoder computes apart */
    unsigned long long cost = job->deep ? obs_deep_frame_cost(job->deep, job->params, job->outputs, w->cpu)
                                        : obs_frame_cost(job->params, width, height, 0);
    if (cost <= w->max_cost)
        return 0;
    job->status = OBS_TOO_COSTLY;
    snprintf(job->err, OBS_ERR_LEN,
             "the frame asks for %llu samples (%dx%d, %llu per pixel), over --max-cost %llu: "
             "lower the samples or the size",
             cost, width, height, cost / ((unsigned long long)width * (unsigned long long)height),
             w->max_cost);
    return 1;
}

/* Freed heap goes back to the system (malloc_trim, which walks the whole
 * heap) once the queue has stayed empty this long: not after every frame
 * of a client that sends them one after another, and only after the
 * network threads have freed the last frames' decoded G-buffers and
 * encoded answers, which they do once the worker is done with them. */
#define TRIM_IDLE_MS 1000

/* When the queue has run empty: the kept targets over --keep-memory are
 * released. */
static void idle(obsd_gl_worker *w, obs_ctx *ctx)
{
    int waiting, running, full;
    obsd_queue_stats(w->queue, &waiting, &running, &full);
    if (waiting > 0)
        return;
    char err[OBS_ERR_LEN] = "";
    if (ctx && obs_ctx_trim(ctx, w->keep_memory, err) != OBS_OK)
        obsd_log(OBSD_LOG_WARN, "releasing frame targets: %s", err);
    if (w->cpu) /* the CPU device's planes, as a context's targets */
        obs_cpu_trim(w->keep_memory);
    atomic_store(&w->kept_bytes, ctx ? obs_ctx_kept_bytes(ctx) : w->cpu ? obs_cpu_kept_bytes() : 0);
}

static void *worker_main(void *arg)
{
    obsd_gl_worker *w = arg;
    obs_ctx *ctx = NULL;
    char err[OBS_ERR_LEN] = "";
    double t0 = obsd_now_ms();
    /* the CPU device (backend cpu) needs no context */
    obs_status s = w->cpu ? OBS_OK : obs_ctx_create(&w->desc, &ctx, err);
    if (s == OBS_OK && ctx)
        s = obs_ctx_set_deadline(ctx, w->frame_deadline, err);

    pthread_mutex_lock(&w->lock);
    w->start_status = s;
    if (s == OBS_OK && w->cpu) {
        snprintf(w->backend, sizeof w->backend, "cpu");
        snprintf(w->gl_renderer, sizeof w->gl_renderer, "the CPU device (no GL context)");
        w->create_ms = obsd_now_ms() - t0;
        atomic_store(&w->alive, 1);
    } else if (s == OBS_OK) {
        obs_ctx_info info;
        obs_ctx_get_info(ctx, &info);
        snprintf(w->backend, sizeof w->backend, "%s", obs_backend_name(info.backend));
        snprintf(w->gl_version, sizeof w->gl_version, "%s", info.gl_version ? info.gl_version : "");
        snprintf(w->gl_vendor, sizeof w->gl_vendor, "%s", info.gl_vendor ? info.gl_vendor : "");
        snprintf(w->gl_renderer, sizeof w->gl_renderer, "%s", info.gl_renderer ? info.gl_renderer : "");
        snprintf(w->cache_dir, sizeof w->cache_dir, "%s", info.cache_dir ? info.cache_dir : "");
        w->cache_writable = info.cache_writable;
        w->create_ms = obsd_now_ms() - t0;
        atomic_store(&w->alive, 1);
    } else {
        snprintf(w->err, sizeof w->err, "%s", err);
    }
    w->started = 1;
    pthread_cond_signal(&w->ready);
    pthread_mutex_unlock(&w->lock);
    if (s != OBS_OK)
        return NULL;

    long frame = 0;
    int trim_pending = 0; /* frames ran since the last malloc_trim */
    for (;;) {
        int idle_long;
        obsd_job *job = obsd_queue_pop_wait(w->queue, trim_pending ? TRIM_IDLE_MS : -1, &idle_long);
        if (idle_long) {
            malloc_trim(0);
            atomic_fetch_add(&w->heap_trims, 1);
            trim_pending = 0;
            continue;
        }
        if (!job)
            break; /* closed and drained */
        frame++;
        job->t_started = obsd_now_ms();
        job->err[0] = '\0';
        if (!ctx && !w->cpu) {
            /* Stopped while the context could not be recreated. */
            job->status = OBS_GL_UNAVAILABLE;
            snprintf(job->err, OBS_ERR_LEN, "the GL context was lost and could not be recreated");
        } else if (w->fail_after > 0 && frame == w->fail_after) {
            job->status = OBS_GL_ERROR;
            snprintf(job->err, OBS_ERR_LEN, "injected GL failure on frame %ld (--fail-gl-after)", frame);
        } else if (atomic_load(&w->cut)) {
            job->status = OBS_CANCELLED;
            snprintf(job->err, OBS_ERR_LEN, "not run: the drain's deadline passed");
        } else if (too_costly(w, job)) {
            /* answered without running */
        } else if (w->cpu) {
            obs_cpu_options o = {.deadline = w->frame_deadline, /* as the GL context's */
                                 .cancel = cut_asked, .cancel_user = w, .log = cpu_log, .log_user = w,
                                 .max_memory = w->max_memory,
                                 .max_memory_name = w->max_memory_name[0] ? w->max_memory_name : NULL};
            job->status = job->deep ? obs_deep_run_cpu_opts(job->deep, job->params, &o,
                                                            &job->deep_result, job->err)
                                    : obs_run_cpu_opts(job->gb, job->params, job->outputs,
                                                       &job->result, &o, job->err);
        } else if (job->deep) {
            job->status = (job->outputs & OBS_OUTPUT_DEEP)
                              ? obs_deep_run_nodes(ctx, job->deep, job->params, &job->deep_result,
                                                   &job->deep_nodes, job->err)
                              : obs_deep_run(ctx, job->deep, job->params, &job->deep_result, job->err);
        } else {
            job->status = obs_run(ctx, job->gb, job->params, job->outputs, &job->result, job->err);
        }
        job->t_finished = obsd_now_ms();
        if (job->status == OBS_DEADLINE) /* name the option that set it */
            snprintf(job->err + strlen(job->err), OBS_ERR_LEN - strlen(job->err),
                     " (--frame-deadline)");
        if (job->status == OBS_CANCELLED) /* by the drain's cut: its request is gone */
            obsd_log(OBSD_LOG_INFO, "frame %ld: %s", frame, job->err);
        obs_status st = job->status;
        char msg[OBS_ERR_LEN];
        snprintf(msg, sizeof msg, "%s", job->err);
        if (ctx) {
            atomic_store(&w->kept_bytes, obs_ctx_kept_bytes(ctx));
            count_programs(w, ctx, 0);
        } else if (w->cpu) {
            atomic_store(&w->kept_bytes, obs_cpu_kept_bytes());
        }
        obsd_queue_done(w->queue);
        job->done(job, job->user); /* the job is not ours after this */
        if (ctx && (st == OBS_GL_ERROR || st == OBS_GL_UNAVAILABLE))
            ctx = recreate(w, ctx, st, msg);
        idle(w, ctx);
        trim_pending = 1;
    }
    atomic_store(&w->alive, 0);
    if (ctx)
        obs_ctx_destroy(ctx);
    return NULL;
}

obs_status obsd_gl_start(obsd_gl_worker *w, obsd_queue *q, const obs_ctx_desc *desc, int cpu,
                         const obsd_config *cfg, char err[OBS_ERR_LEN])
{
    memset(w, 0, sizeof *w);
    w->cpu = cpu;
    w->queue = q;
    w->desc = *desc;
    w->fail_after = cfg->fail_gl_after;
    w->max_cost = (unsigned long long)cfg->max_cost;
    w->keep_memory = (unsigned long long)cfg->keep_memory;
    w->frame_deadline = cfg->frame_deadline;
    w->max_memory = (size_t)cfg->max_memory << 20;
    const obsd_opt_info *mo = obsd_opt_find("max_memory");
    w->max_memory_name[0] = 0; /* the default's name: the library's (bands_run.c) */
    if (cfg->max_memory)
        snprintf(w->max_memory_name, sizeof w->max_memory_name, cfg->set[mo - obsd_opt_at(0)]
                 ? "--max-memory %d MiB" : "OBSCURA_MAX_MEMORY=%d MiB", cfg->max_memory);
    atomic_init(&w->alive, 0);
    atomic_init(&w->recreations, 0);
    atomic_init(&w->heap_trims, 0);
    atomic_init(&w->stopping, 0);
    atomic_init(&w->cut, 0);
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
    } else {
        w->running = 1;
    }
    return s;
}

void obsd_gl_stop(obsd_gl_worker *w)
{
    if (!w->running)
        return;
    atomic_store(&w->stopping, 1);
    obsd_queue_close(w->queue);
    pthread_join(w->thread, NULL);
    w->running = 0;
}

void obsd_gl_cut(obsd_gl_worker *w)
{
    atomic_store(&w->cut, 1);
}
