/* obscura's ground-truth commands (clients/ground.c):
 *
 *   obscura gbuffer SCENE -o OUT.exr --camera CAM.json [--width W] [--height H] [--baked]
 *   obscura reference SCENE -o REF.(exr|png) --camera CAM.json [--distance D]
 *                     [--spp N] [--seed N] [--threads N] [--gbuffer G.exr]
 *                     [--obscurance SHORT,LONG [--blend B]]
 *
 * Each returns the process exit code (0 ok, 1 failure, 2 usage, 3 bad
 * input). */
#ifndef OBSCURA_CLIENT_GROUND_H
#define OBSCURA_CLIENT_GROUND_H

#include <stdio.h>

int cli_gbuffer(int argc, char **argv);
int cli_reference(int argc, char **argv);

/* The usage lines of both commands, for obscura help. */
void cli_ground_usage(FILE *f);

#endif
