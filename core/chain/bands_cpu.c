/* The CPU device's parallel-for over row bands (bands_cpu.h). */
#include <stdatomic.h>

#include "chain/bands_cpu.h"
#include "pool.h"

static atomic_int requested_threads;

static _Thread_local const obs__cpu_window *window;

const obs__cpu_window *obs__cpu_window_set(const obs__cpu_window *w)
{
    const obs__cpu_window *old = window;
    window = w;
    return old;
}

/* The rows of [0, height) the window runs: [*lo, *hi). */
static void window_rows(int height, int *lo, int *hi)
{
    *lo = 0;
    *hi = height;
    for (int i = 0; window && i < OBS__CPU_WINDOWS; i++)
        if (window->height[i] == height) {
            *lo = window->lo[i] > 0 ? window->lo[i] : 0;
            *hi = window->hi[i] < height ? window->hi[i] : height;
            return;
        }
}

int obs__cpu_threads(void) { return obs__pool_threads(atomic_load(&requested_threads)); }

int obs__cpu_set_threads(int requested) { return atomic_exchange(&requested_threads, requested); }

typedef struct rows_job {
    void (*fn)(void *ctx, int y0, int y1);
    void *ctx;
    int lo; /* the first row (a window's) */
} rows_job;

static int rows_range(void *ctx, void *local, size_t i0, size_t i1)
{
    const rows_job *j = ctx;
    (void)local;
    j->fn(j->ctx, j->lo + (int)i0, j->lo + (int)i1);
    return 0;
}

void obs__cpu_rows(int height, int rows, void (*fn)(void *ctx, int y0, int y1), void *ctx)
{
    int lo, hi;
    window_rows(height, &lo, &hi);
    if (hi <= lo)
        return;
    rows = rows > 0 ? rows : OBS__CPU_BAND_ROWS;
    int threads = obs__cpu_threads();
    if (threads <= 1 || hi - lo <= rows) { /* one band: no thread to start */
        fn(ctx, lo, hi);
        return;
    }
    rows_job j = {fn, ctx, lo};
    obs__pool_for f = {.end = (size_t)(hi - lo), .chunk = (size_t)rows, .threads = threads,
                       .range = rows_range, .ctx = &j};
    obs__pool_run(&f, NULL);
}

typedef struct tiles_job {
    void (*fn)(void *ctx, int x0, int x1, int y0, int y1);
    void *ctx;
    int width, height, tw, th, across, lo; /* lo: the first row (a window's) */
} tiles_job;

static int tiles_range(void *ctx, void *local, size_t i0, size_t i1)
{
    const tiles_job *j = ctx;
    (void)local;
    for (size_t i = i0; i < i1; i++) {
        int x0 = (int)(i % (size_t)j->across) * j->tw;
        int y0 = j->lo + (int)(i / (size_t)j->across) * j->th;
        int x1 = j->width - x0 > j->tw ? x0 + j->tw : j->width;
        int y1 = j->height - y0 > j->th ? y0 + j->th : j->height;
        j->fn(j->ctx, x0, x1, y0, y1);
    }
    return 0;
}

void obs__cpu_tiles(int width, int height, int tw, int th,
                    void (*fn)(void *ctx, int x0, int x1, int y0, int y1), void *ctx)
{
    int lo, hi;
    window_rows(height, &lo, &hi);
    if (width <= 0 || hi <= lo)
        return;
    tiles_job j = {fn, ctx, width, hi, tw, th, (width + tw - 1) / tw, lo};
    size_t n = (size_t)j.across * (size_t)((hi - lo + th - 1) / th);
    int threads = obs__cpu_threads();
    if (threads <= 1) {
        tiles_range(&j, NULL, 0, n);
        return;
    }
    obs__pool_for f = {.end = n, .chunk = 1, .threads = threads, .range = tiles_range, .ctx = &j};
    obs__pool_run(&f, NULL);
}
