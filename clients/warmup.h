/* obscura warmup (clients/warmup.c): builds into the program cache every
 * program a configuration can need, by running small synthetic frames
 * through the real passes (so that Mesa's cache also gets the machine
 * code llvmpipe generates at the first draw):
 *
 *   obscura warmup [--methods all|LIST] [--cache-dir DIR] [--backend B] [-q|-v] [parameters]
 *
 * Returns the process exit code (0 ok, 1 failure or no writable cache,
 * 2 usage). */
#ifndef OBSCURA_CLIENT_WARMUP_H
#define OBSCURA_CLIENT_WARMUP_H

#include <stdio.h>

int cli_warmup(int argc, char **argv);

/* The usage lines, for obscura help. */
void cli_warmup_usage(FILE *f);

#endif
