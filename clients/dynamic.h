/* obscura bake-dynamic (clients/dynamic.c): the dynamic-object model of a
 * level (section 2.3), and its evaluation.  Returns the exit code. */
#ifndef OBSCURA_CLIENT_DYNAMIC_H
#define OBSCURA_CLIENT_DYNAMIC_H

#include <stdio.h>

int cli_dynamic(int argc, char **argv);
void cli_dynamic_usage(FILE *f);

#endif
