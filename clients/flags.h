/* How the CLI's commands read their flags (clients/flags.c), and the
 * flags of the request options: `obscura ao --output ... --png-bits ...`
 * are parsed by the rows of obs_http_options (protocol/http.c), the same
 * code that parses obscurad's query parameters. */
#ifndef OBSCURA_CLIENT_FLAGS_H
#define OBSCURA_CLIENT_FLAGS_H

#include "http.h"

/* Matches argv[*i] against the flag NAME, spelled -NAME or --NAME, its
 * value after '=' or in the next argument (*i moves past it).  Returns 1
 * with *value set, 0 when argv[*i] is not this flag, -1 when the value
 * is missing (NAME is the last argument). */
int cli_flag_value(int argc, char **argv, int *i, const char *name, const char **value);

/* Levenshtein distance of a and b (the "did you mean" of an unknown
 * option); a large number for words of 64 bytes or more. */
int cli_edit_distance(const char *a, const char *b);

/* argv is exactly --NAME (a switch takes no value).  0 / 1. */
int cli_is_switch(const char *arg, const char *name);

/* The request options' flags: each row's name with '-' for '_'
 * (--output, --format, --png-bits, --preset, --depth, --normal,
 * --color: a value; --float: a switch).  When argv[*i] is one, sets it
 * in r through obs_http_option_set() with OBS_HTTP_CLI and returns 1,
 * *which the row; 0 when it is none of them; -1 with a message in err
 * when its value is bad or missing. */
int cli_request_flag(int argc, char **argv, int *i, obs_http_request *r,
                     const obs_http_option **which, char err[OBS_ERR_LEN]);

/* The "did you mean" of an unknown option: start with the argument as
 * typed, try every option name the command knows (a table's '_' read as
 * '-'); best is the nearest at most two edits away and fewer edits than
 * the word has letters, spelled --name (-n for one letter), or "". */
typedef struct cli_suggest {
    char word[64];
    char best[80];
    int best_d;
} cli_suggest;
void cli_suggest_start(cli_suggest *s, const char *arg);
void cli_suggest_try(cli_suggest *s, const char *name);

#endif
