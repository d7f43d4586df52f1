/* obscurad's bake jobs (bake_jobs.h): a list of jobs, oldest first, under
 * one lock; worker threads take the oldest queued one, write its level to
 * a temporary file (assimp reads files; the extension names the format),
 * load it, bake it with a progress callback that records the progress and
 * answers the cancel flag (the bake checks it between batches of rays),
 * write the .glb and keep its bytes.  Event streams are told of every
 * change of a job through its version. */
#include "bake_jobs.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "config.h"
#include "job.h"
#include "list.h"
#include "log.h"

#define MAX_WORKERS 16
#define KEEPALIVE_MS 15000.0
#define WAKE_MS 250.0 /* progress events at most this often */

typedef struct obsd_bake {
    struct obsd_bake *next;
    char id[OBSD_BAKE_ID_LEN + 1];
    obsd_bake_state state;
    atomic_int cancel;
    int refs;         /* the list's, and one per subscriber */
    int in_list;
    uint64_t version; /* moves on every change an event stream should see */
    unsigned char *level;
    size_t level_len;
    char ext[16];
    char *decorators; /* the text of a decorators file, or NULL */
    size_t decorator_rules;
    obs_bake_params params;
    const char *stage;
    size_t done, total;
    double t_submit, t_start, t_end, last_wake;
    double load_s, write_s;
    obs_bake_stats stats;
    int have_stats;
    unsigned char *result;
    size_t result_len;
    obs_status status;
    char err[OBS_ERR_LEN];
    obsd_bake_sub *subs;
} job;

struct obsd_bakes {
    pthread_mutex_t lock;
    pthread_cond_t cond;
    job *head;
    int max_active, keep, max_triangles, stopping, ended;
    pthread_t th[MAX_WORKERS];
    int nth;
    uint32_t nonce, counter;
};

static const char *const state_names[] = {"queued", "running", "done", "failed", "cancelled"};

const char *obsd_bake_state_name(obsd_bake_state s)
{
    return s >= OBSD_BAKE_QUEUED && s <= OBSD_BAKE_CANCELLED ? state_names[s] : "?";
}

static int finished(const job *j) { return j->state >= OBSD_BAKE_DONE; }

static void job_free(job *j)
{
    free(j->level);
    free(j->decorators);
    free(j->result);
    free(j);
}

/* Under the lock. */
static void unref(job *j)
{
    if (--j->refs == 0)
        job_free(j);
}

static void wake_subs(job *j)
{
    for (obsd_bake_sub *s = j->subs; s; s = s->next)
        if (s->parked) {
            s->parked = 0;
            s->wake(s->arg);
        }
}

/* Under the lock: the job changed. */
static void bump(job *j, int wake)
{
    j->version++;
    if (wake) {
        j->last_wake = obsd_now_ms();
        wake_subs(j);
    }
}

/* Under the lock: out of the list; its streams end. */
static void unlink_job(obsd_bakes *b, job *j)
{
    for (job **p = &b->head; *p; p = &(*p)->next)
        if (*p == j) {
            *p = j->next;
            break;
        }
    j->in_list = 0;
    for (obsd_bake_sub *s = j->subs; s; s = s->next)
        s->ended = 1;
    wake_subs(j);
    unref(j);
}

/* Under the lock: finished jobs beyond `keep`, oldest first, dropped. */
static void evict(obsd_bakes *b)
{
    int n = 0;
    for (job *j = b->head; j; j = j->next)
        n += finished(j);
    for (job *j = b->head, *next; j && n > b->keep; j = next) {
        next = j->next;
        if (finished(j)) {
            unlink_job(b, j);
            n--;
        }
    }
}

static job *find(obsd_bakes *b, const char *id)
{
    for (job *j = b->head; j; j = j->next)
        if (id && !strcmp(j->id, id))
            return j;
    return NULL;
}

/* ---- a job's run, on a worker -------------------------------------------- */

typedef struct run_ctx {
    obsd_bakes *b;
    job *j;
} run_ctx;

static int on_progress(void *user, size_t done, size_t total)
{
    run_ctx *c = user;
    job *j = c->j;
    pthread_mutex_lock(&c->b->lock);
    j->done = done;
    j->total = total;
    j->stage = done < total ? "trace" : "solve";
    bump(j, done >= total || obsd_now_ms() - j->last_wake >= WAKE_MS);
    pthread_mutex_unlock(&c->b->lock);
    return atomic_load(&j->cancel);
}

static void set_stage(run_ctx *c, const char *stage)
{
    pthread_mutex_lock(&c->b->lock);
    c->j->stage = stage;
    bump(c->j, 1);
    pthread_mutex_unlock(&c->b->lock);
}

/* A temporary file name ending in `ext`, created empty; fd open. */
static int temp_file(char *path, size_t len, const char *ext)
{
    const char *dir = getenv("TMPDIR");
    snprintf(path, len, "%s/obscurad-bake-XXXXXX.%s", dir && *dir ? dir : "/tmp", ext);
    return mkstemps(path, (int)strlen(ext) + 1);
}

static obs_status write_all(int fd, const unsigned char *p, size_t n, char err[OBS_ERR_LEN])
{
    while (n) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            snprintf(err, OBS_ERR_LEN, "cannot write the level to a temporary file: %s", strerror(errno));
            return OBS_IO;
        }
        p += w;
        n -= (size_t)w;
    }
    return OBS_OK;
}

static obs_status read_file(const char *path, unsigned char **out, size_t *len, char err[OBS_ERR_LEN])
{
    FILE *f = fopen(path, "rb");
    struct stat sb;
    if (!f || fstat(fileno(f), &sb) != 0) {
        if (f)
            fclose(f);
        snprintf(err, OBS_ERR_LEN, "cannot read the baked level back: %s", strerror(errno));
        return OBS_IO;
    }
    unsigned char *p = malloc((size_t)sb.st_size + 1);
    int ok = p && fread(p, 1, (size_t)sb.st_size, f) == (size_t)sb.st_size;
    fclose(f);
    if (!ok) {
        free(p);
        snprintf(err, OBS_ERR_LEN, "cannot read the baked level back");
        return OBS_NO_MEMORY;
    }
    *out = p;
    *len = (size_t)sb.st_size;
    return OBS_OK;
}

static void run_job(obsd_bakes *b, job *j)
{
    run_ctx c = {b, j};
    char path[512], out[512], err[OBS_ERR_LEN] = "";
    obs_bake_scene sc;
    int loaded = 0;
    obs_bake_result r = {0};
    obs_status s;
    double t = obsd_now_ms();
    int fd = temp_file(path, sizeof path, j->ext);
    if (fd < 0) {
        snprintf(err, sizeof err, "cannot make a temporary file: %s", strerror(errno));
        s = OBS_IO;
        goto done;
    }
    s = write_all(fd, j->level, j->level_len, err);
    close(fd);
    if (s == OBS_OK) {
        obs_bake_params p;
        obs_bake_params_resolve(&j->params, &p);
        s = obs_bake_load(path, (size_t)p.max_triangles, &sc, err);
        loaded = s == OBS_OK;
        /* the loader names its file: the daemon's temporary copy means
         * nothing to the client, the level does */
        size_t n = strlen(path);
        if (s != OBS_OK && !strncmp(err, path, n)) {
            char rest[OBS_ERR_LEN];
            snprintf(rest, sizeof rest, "%s", err + n);
            snprintf(err, sizeof err, "the level (%.15s)%.*s", j->ext, (int)sizeof err - 32, rest);
        }
    }
    unlink(path);
    pthread_mutex_lock(&b->lock);
    free(j->level); /* the scene has it now */
    j->level = NULL;
    j->load_s = (obsd_now_ms() - t) / 1000.0;
    j->stage = "bake";
    bump(j, 1);
    pthread_mutex_unlock(&b->lock);
    if (s != OBS_OK)
        goto done;
    if (atomic_load(&j->cancel)) {
        s = OBS_CANCELLED;
        snprintf(err, sizeof err, "bake cancelled after the load");
        goto done;
    }
    obs_bake_desc d = {.params = j->params,
                       .progress = on_progress,
                       .progress_user = &c,
                       .decorators_json = j->decorators};
    s = obs_bake_run(&sc, &d, &r, err);
    pthread_mutex_lock(&b->lock);
    j->stats = r.stats;
    j->have_stats = 1;
    pthread_mutex_unlock(&b->lock);
    if (s != OBS_OK)
        goto done;
    set_stage(&c, "write");
    t = obsd_now_ms();
    if ((fd = temp_file(out, sizeof out, "glb")) < 0) {
        snprintf(err, sizeof err, "cannot make a temporary file: %s", strerror(errno));
        s = OBS_IO;
        goto done;
    }
    close(fd);
    s = obs_bake_write_glb(out, &sc, &r, 0, err);
    unsigned char *data = NULL;
    size_t len = 0;
    if (s == OBS_OK)
        s = read_file(out, &data, &len, err);
    unlink(out);
    pthread_mutex_lock(&b->lock);
    j->result = data;
    j->result_len = len;
    j->write_s = (obsd_now_ms() - t) / 1000.0;
    pthread_mutex_unlock(&b->lock);
done:
    obs_bake_result_free(&r);
    if (loaded)
        obs_bake_scene_free(&sc);
    pthread_mutex_lock(&b->lock);
    j->status = s;
    snprintf(j->err, sizeof j->err, "%s", s == OBS_OK ? "" : err[0] ? err : obs_status_message(s));
    j->state = s == OBS_OK ? OBSD_BAKE_DONE : s == OBS_CANCELLED ? OBSD_BAKE_CANCELLED : OBSD_BAKE_FAILED;
    j->stage = obsd_bake_state_name(j->state);
    j->t_end = obsd_now_ms();
    pthread_mutex_unlock(&b->lock);
}

static void *worker(void *arg)
{
    obsd_bakes *b = arg;
    pthread_mutex_lock(&b->lock);
    while (!b->stopping) {
        job *j = b->head;
        while (j && j->state != OBSD_BAKE_QUEUED)
            j = j->next;
        if (!j) {
            pthread_cond_wait(&b->cond, &b->lock);
            continue;
        }
        j->state = OBSD_BAKE_RUNNING;
        j->stage = "load";
        j->t_start = obsd_now_ms();
        j->refs++; /* ours while it runs: a DELETE cannot free it */
        bump(j, 1);
        pthread_mutex_unlock(&b->lock);
        obsd_log(OBSD_LOG_INFO, "bake=%s started (%zu bytes of .%s)", j->id, j->level_len, j->ext);
        run_job(b, j);
        obsd_log(j->state == OBSD_BAKE_DONE ? OBSD_LOG_INFO : OBSD_LOG_WARN, "bake=%s %s in %.1f s%s%s",
                 j->id, obsd_bake_state_name(j->state), (j->t_end - j->t_start) / 1000.0,
                 j->err[0] ? ": " : "", j->err);
        pthread_mutex_lock(&b->lock);
        bump(j, 1);
        unref(j);
        evict(b);
    }
    pthread_mutex_unlock(&b->lock);
    return NULL;
}

/* ---- the store ----------------------------------------------------------- */

obsd_bakes *obsd_bakes_new(int max_active, int workers, int keep, int max_triangles)
{
    obsd_bakes *b = calloc(1, sizeof *b);
    if (!b)
        return NULL;
    pthread_mutex_init(&b->lock, NULL);
    pthread_cond_init(&b->cond, NULL);
    b->max_active = max_active;
    b->keep = keep;
    b->max_triangles = max_triangles;
    /* ids differ from one run to the next: an id of a job lost in a
     * restart is unknown, never another's job */
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    b->nonce = (uint32_t)(ts.tv_nsec ^ ts.tv_sec * 2654435761u ^ (uint32_t)getpid() * 40503u);
    for (int i = 0; max_active > 0 && i < workers && i < MAX_WORKERS; i++) {
        if (pthread_create(&b->th[i], NULL, worker, b) != 0)
            break;
        b->nth++;
    }
    if (max_active > 0 && b->nth == 0) {
        obsd_bakes_free(b);
        return NULL;
    }
    return b;
}

void obsd_bakes_cancel_all(obsd_bakes *b)
{
    if (!b)
        return;
    pthread_mutex_lock(&b->lock);
    b->ended = 1;
    for (job *j = b->head; j; j = j->next) {
        if (j->state == OBSD_BAKE_QUEUED) {
            j->state = OBSD_BAKE_CANCELLED;
            j->stage = "cancelled";
            snprintf(j->err, sizeof j->err, "cancelled: the daemon is shutting down");
            j->status = OBS_CANCELLED;
        }
        atomic_store(&j->cancel, 1);
        for (obsd_bake_sub *s = j->subs; s; s = s->next)
            s->ended = 1;
        bump(j, 1);
    }
    pthread_mutex_unlock(&b->lock);
}

void obsd_bakes_free(obsd_bakes *b)
{
    if (!b)
        return;
    obsd_bakes_cancel_all(b);
    pthread_mutex_lock(&b->lock);
    b->stopping = 1;
    pthread_cond_broadcast(&b->cond);
    pthread_mutex_unlock(&b->lock);
    for (int i = 0; i < b->nth; i++)
        pthread_join(b->th[i], NULL);
    while (b->head)
        unlink_job(b, b->head);
    pthread_cond_destroy(&b->cond);
    pthread_mutex_destroy(&b->lock);
    free(b);
}

int obsd_bakes_submit(obsd_bakes *b, unsigned char *level, size_t len, const char *ext,
                      char *decorators, size_t decorator_rules, const obs_bake_params *p,
                      char id[OBSD_BAKE_ID_LEN + 1])
{
    job *j = calloc(1, sizeof *j);
    if (!j) {
        free(level);
        free(decorators);
        return -3;
    }
    j->level = level;
    j->level_len = len;
    j->decorators = decorators;
    j->decorator_rules = decorator_rules;
    snprintf(j->ext, sizeof j->ext, "%s", ext);
    j->params = *p;
    obs_bake_params r;
    obs_bake_params_resolve(p, &r);
    if (r.max_triangles > b->max_triangles) { /* the daemon's cap */
        char v[32];
        snprintf(v, sizeof v, "%d", b->max_triangles);
        char err[OBS_ERR_LEN];
        (void)obs_bake_param_set(&j->params, "max_triangles", v, err);
    }
    j->state = OBSD_BAKE_QUEUED;
    j->stage = "queued";
    j->refs = 1;
    j->in_list = 1;
    j->t_submit = obsd_now_ms();
    atomic_init(&j->cancel, 0);
    pthread_mutex_lock(&b->lock);
    int active = 0;
    for (job *k = b->head; k; k = k->next)
        active += !finished(k);
    int rc = b->ended ? -2 : active >= b->max_active ? -1 : 0;
    if (rc == 0) {
        snprintf(j->id, sizeof j->id, "%08x%08x", b->nonce, ++b->counter);
        job **p2 = &b->head;
        while (*p2)
            p2 = &(*p2)->next;
        *p2 = j;
        snprintf(id, OBSD_BAKE_ID_LEN + 1, "%s", j->id);
        pthread_cond_signal(&b->cond);
    }
    pthread_mutex_unlock(&b->lock);
    if (rc != 0)
        job_free(j);
    return rc;
}

/* ---- JSON ------------------------------------------------------------------ */

static cJSON *job_json(const job *j, int full)
{
    cJSON *o = cJSON_CreateObject();
    double now = obsd_now_ms();
    cJSON_AddStringToObject(o, "id", j->id);
    cJSON_AddStringToObject(o, "state", obsd_bake_state_name(j->state));
    cJSON_AddStringToObject(o, "stage", j->stage);
    double prog = j->state == OBSD_BAKE_DONE ? 1.0 : j->total ? (double)j->done / (double)j->total : 0.0;
    cJSON_AddNumberToObject(o, "progress", prog);
    cJSON_AddNumberToObject(o, "samples_done", (double)j->done);
    cJSON_AddNumberToObject(o, "samples", (double)j->total);
    if (atomic_load(&j->cancel) && !finished(j))
        cJSON_AddBoolToObject(o, "cancel_requested", 1);
    if (j->err[0]) {
        const char *code = obs_status_name(j->status);
        cJSON *e = cJSON_AddObjectToObject(o, "error");
        cJSON_AddStringToObject(e, "status", code);
        cJSON_AddStringToObject(e, "message", j->err);
    }
    if (!full)
        return o;
    cJSON *sec = cJSON_AddObjectToObject(o, "seconds");
    double start = j->t_start ? j->t_start : now;
    cJSON_AddNumberToObject(sec, "queued", (start - j->t_submit) / 1000.0);
    if (j->t_start) {
        cJSON_AddNumberToObject(sec, "load", j->load_s);
        for (int i = 0; j->have_stats && i < OBS_BAKE_STAGE_COUNT; i++)
            cJSON_AddNumberToObject(sec, obs_bake_stage_name(i), j->stats.seconds[i]);
        if (j->state == OBSD_BAKE_DONE)
            cJSON_AddNumberToObject(sec, "write", j->write_s);
        cJSON_AddNumberToObject(sec, "running", ((j->t_end ? j->t_end : now) - j->t_start) / 1000.0);
    }
    if (j->have_stats) {
        cJSON *c = cJSON_AddObjectToObject(o, "counts");
        cJSON_AddNumberToObject(c, "instances", (double)j->stats.instances);
        cJSON_AddNumberToObject(c, "triangles", (double)j->stats.triangles);
        cJSON_AddNumberToObject(c, "samples", (double)j->stats.samples);
        cJSON_AddNumberToObject(c, "rays", (double)j->stats.rays);
        /* the decorators' classes (section 2.2): none, shrub, tree, small */
        static const char *const cls[4] = {"none", "shrub", "tree", "small"};
        cJSON *dn = cJSON_AddObjectToObject(o, "decorator_nodes");
        for (int k = 0; k < 4; k++)
            cJSON_AddNumberToObject(dn, cls[k], (double)j->stats.decorator_nodes[k]);
        if (j->stats.decorator_warning[0])
            cJSON_AddStringToObject(o, "decorator_warning", j->stats.decorator_warning);
        if (j->state == OBSD_BAKE_DONE)
            cJSON_AddNumberToObject(o, "ao_mean", j->stats.ao_mean);
    }
    if (j->decorators) /* the job's decorators file: its rules */
        cJSON_AddNumberToObject(o, "decorator_rules", (double)j->decorator_rules);
    cJSON *par = cJSON_AddObjectToObject(o, "params");
    obs_bake_params p;
    obs_bake_params_resolve(&j->params, &p);
    for (int i = 0; i < obs_bake_param_count(); i++) {
        const obs_bake_param_info *pi = obs_bake_param_at(i);
        char v[64];
        obs_bake_param_format(&p, pi, v, sizeof v);
        if (pi->type == OBS_BAKE_PARAM_ENUM)
            cJSON_AddStringToObject(par, pi->name, v);
        else
            cJSON_AddNumberToObject(par, pi->name, strtod(v, NULL));
    }
    if (j->state == OBSD_BAKE_DONE) {
        char url[64];
        snprintf(url, sizeof url, "/v1/bakes/%s/result", j->id);
        cJSON_AddStringToObject(o, "result", url);
        cJSON_AddNumberToObject(o, "result_bytes", (double)j->result_len);
    }
    return o;
}

static char *print(cJSON *o)
{
    char *s = o ? cJSON_PrintUnformatted(o) : NULL;
    cJSON_Delete(o);
    return s;
}

char *obsd_bakes_json(obsd_bakes *b, const char *id)
{
    pthread_mutex_lock(&b->lock);
    job *j = find(b, id);
    char *s = j ? print(job_json(j, 1)) : NULL;
    pthread_mutex_unlock(&b->lock);
    return s;
}

char *obsd_bakes_list_json(obsd_bakes *b)
{
    cJSON *o = cJSON_CreateObject(), *a = cJSON_AddArrayToObject(o, "bakes");
    pthread_mutex_lock(&b->lock);
    for (job *j = b->head; j; j = j->next)
        cJSON_AddItemToArray(a, job_json(j, 0));
    cJSON_AddNumberToObject(o, "max_active", b->max_active);
    pthread_mutex_unlock(&b->lock);
    return print(o);
}

int obsd_bakes_result(obsd_bakes *b, const char *id, unsigned char **data, size_t *len,
                      obsd_bake_state *state)
{
    int rc;
    pthread_mutex_lock(&b->lock);
    job *j = find(b, id);
    if (!j) {
        rc = -1;
    } else if (j->state != OBSD_BAKE_DONE) {
        *state = j->state;
        rc = 1;
    } else {
        *state = j->state;
        *data = malloc(j->result_len ? j->result_len : 1);
        rc = *data ? 0 : -3;
        if (*data) {
            memcpy(*data, j->result, j->result_len);
            *len = j->result_len;
        }
    }
    pthread_mutex_unlock(&b->lock);
    return rc;
}

int obsd_bakes_delete(obsd_bakes *b, const char *id, obsd_bake_state *state, int *removed)
{
    pthread_mutex_lock(&b->lock);
    job *j = find(b, id);
    if (!j) {
        pthread_mutex_unlock(&b->lock);
        return -1;
    }
    *removed = 0;
    if (j->state == OBSD_BAKE_QUEUED) {
        j->state = OBSD_BAKE_CANCELLED;
        j->stage = "cancelled";
        j->status = OBS_CANCELLED;
        snprintf(j->err, sizeof j->err, "cancelled before it ran");
        j->t_end = obsd_now_ms();
        bump(j, 1);
    } else if (j->state == OBSD_BAKE_RUNNING) {
        atomic_store(&j->cancel, 1); /* the worker stops between batches of rays */
        bump(j, 1);
    } else {
        *removed = 1;
    }
    *state = j->state;
    if (*removed)
        unlink_job(b, j);
    else
        evict(b);
    pthread_mutex_unlock(&b->lock);
    return 0;
}

/* ---- event streams --------------------------------------------------------- */

int obsd_bakes_subscribe(obsd_bakes *b, const char *id, obsd_bake_sub *s)
{
    pthread_mutex_lock(&b->lock);
    job *j = find(b, id);
    int rc = !j ? -1 : b->ended ? -2 : 0;
    if (rc == 0) {
        s->job = j;
        s->seen = UINT64_MAX; /* its state is the first event */
        s->parked = s->ended = s->final_sent = s->keepalive = 0;
        OBSD_LIST_PUSH(j->subs, s);
        j->refs++;
    }
    pthread_mutex_unlock(&b->lock);
    return rc;
}

int obsd_bakes_next_event(obsd_bakes *b, obsd_bake_sub *s, char *buf, size_t len)
{
    int n = 0;
    pthread_mutex_lock(&b->lock);
    job *j = s->job;
    if (!j || s->final_sent) {
        n = -1;
    } else if (j->version != s->seen || finished(j)) {
        s->seen = j->version;
        s->final_sent = finished(j);
        char *data = print(job_json(j, 0));
        n = snprintf(buf, len, "event: %s\ndata: %s\n\n", finished(j) ? obsd_bake_state_name(j->state) : "progress",
                     data ? data : "{}");
        free(data);
        if (n > 0 && (size_t)n >= len) { /* a long error message: the event without it */
            n = snprintf(buf, len, "event: %s\ndata: {\"id\":\"%s\",\"state\":\"%s\"}\n\n",
                         finished(j) ? obsd_bake_state_name(j->state) : "progress", j->id,
                         obsd_bake_state_name(j->state));
        }
    } else if (s->ended) {
        n = snprintf(buf, len, "event: end\ndata: {\"id\":\"%s\",\"reason\":\"%s\"}\n\n", j->id,
                     j->in_list ? "shutting down" : "job removed");
        s->final_sent = 1;
    } else if (s->keepalive) {
        s->keepalive = 0;
        n = snprintf(buf, len, ": keep-alive\n\n");
    } else {
        s->parked = 1;
        if (s->park)
            s->park(s->arg);
    }
    pthread_mutex_unlock(&b->lock);
    return n;
}

void obsd_bakes_unsubscribe(obsd_bakes *b, obsd_bake_sub *s)
{
    pthread_mutex_lock(&b->lock);
    job *j = s->job;
    if (j) {
        OBSD_LIST_UNLINK(j->subs, s);
        s->job = NULL;
        unref(j);
    }
    pthread_mutex_unlock(&b->lock);
}

void obsd_bakes_tick(obsd_bakes *b, double now_ms)
{
    static double last;
    if (!b || now_ms - last < KEEPALIVE_MS)
        return;
    last = now_ms;
    pthread_mutex_lock(&b->lock);
    for (job *j = b->head; j; j = j->next)
        for (obsd_bake_sub *s = j->subs; s; s = s->next)
            if (s->parked) {
                s->parked = 0;
                s->keepalive = 1;
                s->wake(s->arg);
            }
    pthread_mutex_unlock(&b->lock);
}

void obsd_bakes_counts(obsd_bakes *b, int counts[5])
{
    memset(counts, 0, 5 * sizeof *counts);
    if (!b)
        return;
    pthread_mutex_lock(&b->lock);
    for (job *j = b->head; j; j = j->next)
        counts[j->state]++;
    pthread_mutex_unlock(&b->lock);
}
