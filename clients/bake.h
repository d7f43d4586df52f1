/* obscura bake (clients/bake.c): ambient obscurance baked onto a level's
 * vertices.  Returns the process exit code. */
#ifndef OBSCURA_CLIENT_BAKE_H
#define OBSCURA_CLIENT_BAKE_H

#include <stdio.h>

int cli_bake(int argc, char **argv);
void cli_bake_usage(FILE *f);

#endif
