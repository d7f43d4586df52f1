/* obscura inspect (clients/inspect.c). */
#ifndef OBSCURA_CLIENT_INSPECT_H
#define OBSCURA_CLIENT_INSPECT_H

/* obscura inspect FILE [--json] [reading options]: argv after the
 * command word.  Returns the exit code. */
int cli_inspect(int argc, char **argv);

#endif
