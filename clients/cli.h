/* What the CLI's commands share (clients/cli.c): exit codes and how a
 * failed status is reported. */
#ifndef OBSCURA_CLIENT_CLI_H
#define OBSCURA_CLIENT_CLI_H

#include "obscura/bake.h"
#include "obscura/obscura.h"
#include "obscura/status.h"

/* Process exit codes of every command: 3 is bad input (retrying will not
 * help), 1 any other failure. */
enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_USAGE = 2, EXIT_BADINPUT = 3 };

/* The exit code for a failed status: bad input is 3, the rest 1. */
int cli_status_exit(obs_status s);

/* Prints "obscura: error: WHAT: message (STATUS)" (WHAT left out when the message
 * names it already) and returns cli_status_exit(s). */
int cli_fail(obs_status s, const char *what, const char *err);

/* The same for reading an input: a file that cannot be read is bad input
 * too. */
int cli_input_fail(obs_status s, const char *what, const char *err);

/* "obscura CMD: MESSAGE" and the pointer to help on stderr, then exit
 * EXIT_USAGE. */
void cli_die_usage(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3), noreturn));

/* One row of a parameter table (obscura bake --params, bake-dynamic
 * --params; README's tables with markdown): flag, default, range (an
 * enum's choices), doc. */
void cli_param_row(const obs_bake_param_info *pi, const char *def, int markdown);
/* The whole of a text file, NUL-terminated, in *out (caller frees); the
 * message in err. */
obs_status cli_read_text(const char *path, char **out, char err[OBS_ERR_LEN]);

/* `in` with its control bytes (below 0x20, 0x7f) as \xNN, truncated to
 * fit len: a name or message read from a file cannot drive the terminal. */
void cli_escape(const char *in, char *out, size_t len);

/* --progress percent: "Progress: N%" on stdout (the line Deadline's and
 * OpenCue's progress parsers read) when N differs from *last. */
void cli_progress_percent(int *last, long done, long total);

/* --threads N (else OBSCURA_THREADS) of a command that renders, bakes or
 * reads: taken out of argv (the new argc returned) and made the process's
 * thread limit (obs_threads_set: every worker pool and llvmpipe's
 * LP_NUM_THREADS, unless the user set that).  N is a whole number in
 * [0, 64] (0: every core); anything else is a usage error of cmd (exit 2). */
int cli_take_threads(const char *cmd, int argc, char **argv);

/* --max-memory MIB (else OBSCURA_MAX_MEMORY) of a command whose frames
 * may run on the CPU device, taken out of argv as cli_take_threads takes
 * --threads (the new argc returned): the budget of every such frame
 * (obs_cpu_options.max_memory; over it a frame runs in bands of rows).
 * MIB is a whole number from 1 to the usable memory in MiB; anything
 * else is a usage error of cmd naming the option (exit 2).  Neither
 * given: the library's default, a quarter of the usable memory. */
int cli_take_max_memory(const char *cmd, int argc, char **argv);

/* The budget taken (0: the default) and its name in o (max_memory,
 * max_memory_name: the band warning says what set it). */
void cli_max_memory(obs_cpu_options *o);

/* The budget in use and where it came from, for -v and obscura info:
 * "256 MiB (--max-memory)", "... (OBSCURA_MAX_MEMORY)", or the default's
 * "6038 MiB (default: a quarter of 23.6 GiB; --max-memory MIB sets it)". */
const char *cli_max_memory_text(void);

/* 1 when the budget came from --max-memory (not the environment). */
int cli_max_memory_given(void);

/* The threads this process runs now (/proc/self/task); -1 unknown. */
int cli_process_threads(void);

/* Seconds of CLOCK_MONOTONIC (progress, stage times). */
double cli_now_s(void);
/* --shard I/N of obscura bake and bake-dynamic: 0 <= I < N <= 10^6, else
 * a usage error of cmd. */
void cli_parse_shard(const char *cmd, const char *val, int *index, int *count);

#endif
