/* The CPU device's parallel-for over row bands (bands_cpu.h). */
#include <stdatomic.h>

#include "chain/bands_cpu.h"
#include "pool.h"

static atomic_int requested_threads;

int obs__cpu_threads(void) { return obs__pool_threads(atomic_load(&requested_threads)); }

int obs__cpu_set_threads(int requested) { return atomic_exchange(&requested_threads, requested); }

typedef struct rows_job {
    void (*fn)(void *ctx, int y0, int y1);
    void *ctx;
} rows_job;

static int rows_range(void *ctx, void *local, size_t i0, size_t i1)
{
    const rows_job *j = ctx;
    (void)local;
    j->fn(j->ctx, (int)i0, (int)i1);
    return 0;
}

void obs__cpu_rows(int height, int rows, void (*fn)(void *ctx, int y0, int y1), void *ctx)
{
    if (height <= 0)
        return;
    rows = rows > 0 ? rows : OBS__CPU_BAND_ROWS;
    int threads = obs__cpu_threads();
    if (threads <= 1 || height <= rows) { /* one band: no thread to start */
        fn(ctx, 0, height);
        return;
    }
    rows_job j = {fn, ctx};
    obs__pool_for f = {.end = (size_t)height, .chunk = (size_t)rows, .threads = threads,
                       .range = rows_range, .ctx = &j};
    obs__pool_run(&f, NULL);
}
