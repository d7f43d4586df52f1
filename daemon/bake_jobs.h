/* Bake jobs of obscurad (POST /v1/bakes): a level baked on worker
 * threads beside the GL worker (the bake is Embree and CHOLMOD, no GL),
 * bounded in number, cancellable, kept in memory only: a restart loses
 * them.  No HTTP here; http_bakes.c is the routes. */
#ifndef OBSD_BAKE_JOBS_H
#define OBSD_BAKE_JOBS_H

#include <stddef.h>
#include <stdint.h>

#include "obscura/bake.h"

#define OBSD_BAKE_ID_LEN 16

typedef enum obsd_bake_state {
    OBSD_BAKE_QUEUED,
    OBSD_BAKE_RUNNING,
    OBSD_BAKE_DONE,
    OBSD_BAKE_FAILED,
    OBSD_BAKE_CANCELLED
} obsd_bake_state;

const char *obsd_bake_state_name(obsd_bake_state s);

typedef struct obsd_bakes obsd_bakes;

/* Someone waiting for a job's news (an event stream): wake is called
 * under the store's lock when the job's version moves, and when the
 * waiter must end (shutdown, the job removed). */
typedef struct obsd_bake_sub {
    struct obsd_bake_sub *prev, *next; /* the job's subscribers (list.h) */
    void (*park)(void *arg); /* called under the lock when there is nothing to send */
    void (*wake)(void *arg);
    void *arg;
    uint64_t seen;   /* the job's version last sent */
    int parked;      /* waiting for wake */
    int keepalive;   /* woken for a keep-alive comment */
    int ended;       /* the stream must end */
    int final_sent;
    struct obsd_bake *job; /* referenced while subscribed */
} obsd_bake_sub;

/* max_active: jobs queued or running at once; workers: jobs run at once;
 * keep: finished jobs kept for their result (the oldest finished is
 * dropped beyond); max_triangles caps the bake's own limit.  NULL on no
 * memory or no thread. */
obsd_bakes *obsd_bakes_new(int max_active, int workers, int keep, int max_triangles);
/* Cancels every job, waits for the workers, frees everything. */
void obsd_bakes_free(obsd_bakes *b);
/* Cancels every queued and running job and ends every event stream (the
 * drain): the workers stop between batches of rays. */
void obsd_bakes_cancel_all(obsd_bakes *b);

/* Takes `level` and `decorators` (malloc'ed, freed by the store; the
 * text of a decorators file of decorator_rules rules, or NULL) and queues
 * a job; its id into id.  -1: the store is full (max_active), -2:
 * shutting down, -3: no memory (both are freed in every case). */
int obsd_bakes_submit(obsd_bakes *b, unsigned char *level, size_t len, const char *ext,
                      char *decorators, size_t decorator_rules, const obs_bake_params *p,
                      char id[OBSD_BAKE_ID_LEN + 1]);

/* The job as JSON (caller frees); NULL when there is no such job. */
char *obsd_bakes_json(obsd_bakes *b, const char *id);
/* Every job, id and state, as JSON (caller frees). */
char *obsd_bakes_list_json(obsd_bakes *b);
/* A copy of the result (caller frees) of a done job: 0 ok, -1 no such
 * job, 1 not done (*state says what it is), -3 no memory. */
int obsd_bakes_result(obsd_bakes *b, const char *id, unsigned char **data, size_t *len,
                      obsd_bake_state *state);
/* DELETE: a queued job is cancelled, a running one asked to stop (it
 * ends cancelled), a finished one removed.  *state: its state after;
 * *removed: it was removed.  -1: no such job. */
int obsd_bakes_delete(obsd_bakes *b, const char *id, obsd_bake_state *state, int *removed);

/* Event streams: subscribe to a job (-1: no such job, -2: shutting
 * down); the next event (n bytes into buf, 0: none yet, the sub is
 * parked, -1: the stream ends); unsubscribe (always, when the request
 * ends). */
int obsd_bakes_subscribe(obsd_bakes *b, const char *id, obsd_bake_sub *s);
int obsd_bakes_next_event(obsd_bakes *b, obsd_bake_sub *s, char *buf, size_t len);
void obsd_bakes_unsubscribe(obsd_bakes *b, obsd_bake_sub *s);
/* Wakes the parked streams for a keep-alive comment (a few times a
 * minute is enough; call a few times a second). */
void obsd_bakes_tick(obsd_bakes *b, double now_ms);

/* For /metrics and /v1/info: jobs by state. */
void obsd_bakes_counts(obsd_bakes *b, int counts[5]);

#endif
