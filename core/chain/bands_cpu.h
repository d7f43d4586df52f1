/* The CPU device's parallel-for: a pass's rows in bands on the one worker
 * pool (core/pool.h).  Every pixel is computed by the same arithmetic
 * whichever band and thread it falls to, so a pass's output is the same
 * bytes for any thread count.  No GL.  Not installed. */
#ifndef OBSCURA_BANDS_CPU_H
#define OBSCURA_BANDS_CPU_H

/* Rows per band: a few rows of a 1080p frame's planes stay in a core's
 * cache, and a frame has enough bands for the pool to even out. */
#define OBS__CPU_BAND_ROWS 8

/* fn(ctx, y0, y1) for the rows [y0, y1) of [0, height), in bands of
 * `rows` (0: OBS__CPU_BAND_ROWS), on obs__cpu_threads() threads. */
void obs__cpu_rows(int height, int rows, void (*fn)(void *ctx, int y0, int y1), void *ctx);

/* fn(ctx, x0, x1, y0, y1) for the tiles of tw x th pixels of a width x
 * height frame (the last ones cut), row of tiles by row of tiles, on
 * obs__cpu_threads() threads.  For the passes whose samples reach
 * around the pixel: a tile's neighbourhood stays in a core's cache where
 * a band of whole rows does not. */
void obs__cpu_tiles(int width, int height, int tw, int th,
                    void (*fn)(void *ctx, int x0, int x1, int y0, int y1), void *ctx);

/* A frame run in bands (bands_run.c): the rows each pass computes.  While
 * a window is set on the calling thread, obs__cpu_rows and obs__cpu_tiles
 * over a height the window names run only its rows [lo, hi) of that
 * height (every pixel's arithmetic unchanged: the frame keeps its whole
 * size and coordinates).  Heights it does not name run whole. */
#define OBS__CPU_WINDOWS 3
typedef struct obs__cpu_window {
    int height[OBS__CPU_WINDOWS]; /* 0: an unused entry */
    int lo[OBS__CPU_WINDOWS], hi[OBS__CPU_WINDOWS];
} obs__cpu_window;

/* Sets the calling thread's window (NULL: none); returns the previous. */
const obs__cpu_window *obs__cpu_window_set(const obs__cpu_window *w);

/* The thread count of the CPU chain: the pool's one rule
 * (obs__pool_threads) on the count set below, 0 by default. */
int obs__cpu_threads(void);

/* Sets the count passed to the pool's rule (0: its default); for tests
 * that compare thread counts.  Returns the previous value. */
int obs__cpu_set_threads(int requested);

#endif
