/* obscura batch: one `obscura ao` per frame of a sequence, as a render
 * farm's task runs it.
 *
 *   obscura batch 'shot/frame.####.exr' --frames 1-100x2 -o 'out/ao.####.exr'
 *                 [--server URL] [--jobs N] [--allow-missing]
 *                 [--progress plain|percent] [-q] [ao options]
 *
 * The frame-spec and pattern parsers are pure functions (unit tests in
 * tests/unit/clients/test_batch.c); cli_batch() runs the frames through
 * the CLI's own `ao` (handed in as cli_batch_ops), so a batch frame
 * writes the same file as a single `obscura ao`. */
#ifndef OBSCURA_CLIENT_BATCH_H
#define OBSCURA_CLIENT_BATCH_H

#include <stddef.h>

#define CLI_BATCH_MAX_FRAMES 1000000

/* Parses a frame spec: comma-separated items, each N, A-B or A-BxS
 * (inclusive, step S >= 1, A <= B), frames 0 .. 999999999.  The frames
 * come back ascending, each once.  Returns 0 and *frames (caller frees
 * with free()) and *count; -1 with a message in err. */
int cli_batch_parse_frames(const char *spec, int **frames, int *count, char *err, size_t err_len);

/* Checks a path pattern: exactly one frame placeholder, a run of '#'
 * (width = the run's length) or printf's %d / %0Nd.  Returns 0, or -1
 * with a message in err. */
int cli_batch_check_pattern(const char *pattern, char *err, size_t err_len);

/* The pattern with its placeholder replaced by `frame`, zero-padded to
 * the placeholder's width ("%%" stays a '%' only inside a printf-style
 * pattern).  Returns 0, or -1 when the result does not fit in buf or the
 * pattern is not valid. */
int cli_batch_expand(const char *pattern, int frame, char *buf, size_t len);

/* The comma-separated list rotated to start at its k-th entry (modulo
 * its length): ("a,b,c", 1) -> "b,c,a".  Returns 0, or -1 when it does
 * not fit in buf. */
int cli_batch_rotate(const char *list, int k, char *buf, size_t len);

typedef struct cli_batch_ops {
    /* Validates `obscura ao` arguments (exits 2 on a usage error). */
    void (*check)(int argc, char **argv);
    /* Runs `obscura ao ARGV` (argv has room: it may be reordered) with a
     * GL context kept from one call to the next; returns its exit code. */
    int (*ao)(int argc, char **argv);
    /* Frees what ao kept (the context). */
    void (*finish)(void);
} cli_batch_ops;

/* `obscura batch ARGS`; returns the exit code: 0 every frame written, 1
 * failure, 2 usage, 3 bad input (permanent: a frame's input missing
 * without --allow-missing, or damaged; or nothing written at all), 4
 * server unreachable or busy (retryable). */
int cli_batch(int argc, char **argv, const cli_batch_ops *ops);

#endif
