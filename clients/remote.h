/* obscura ao --server URL: the AO chain run by obscurad instead of
 * in-process.  The CLI reads and decodes its input as always, this runs
 * the frame remotely and hands back the same obs_result, so the CLI
 * writes the same files.
 *
 *   unix:/path, tcp://host:port   the binary protocol (protocol/PROTOCOL.md),
 *                                 raw float32 planes both ways (deep input:
 *                                 a deep G-buffer, counts and samples)
 *   http://host:port              POST /v1/ao with the input EXR, the
 *                                 answer asked as a float EXR
 *
 * URL may be a comma-separated list of servers: a frame goes to the
 * first, and to the next when one is busy (503) or unreachable; a server
 * found unreachable is passed over for 30 s (`obscura batch` rotates the
 * list frame by frame, so frames are spread round robin).  With
 * `--stream NAME` (HTTP only) the frame is posted to the daemon's stream
 * NAME (POST /v1/streams/NAME/frames) for the preview page.
 *
 * OBSCURA_TOKEN, when set, is sent as the bearer token.  OBSCURA_RETRIES
 * (0..100, default 4) is how often the servers, all unreachable or busy,
 * are tried again. */
#ifndef OBSCURA_CLIENT_REMOTE_H
#define OBSCURA_CLIENT_REMOTE_H

#include "obscura/deep.h"
#include "obscura/io.h"
#include "obscura/obscura.h"

#define CLI_REMOTE_MAX_SERVERS 16

/* Takes "--server URL" / "--server=URL" and "--stream NAME" out of
 * argv[0..argc-1] (argv is compacted); returns the new argc.  *server is
 * NULL when absent.  A --stream without --server, or with a bad name, is
 * a usage error: it prints why and exits 2. */
int cli_remote_take_server(int argc, char **argv, const char **server);

/* Runs the frame on the daemon at `server`.  argv are the ao arguments
 * (the parameters of the table are forwarded by name); in_path is the
 * input EXR (sent as is over HTTP); gb its decoded G-buffer with the
 * camera the CLI chose (sent as planes over the binary protocol).
 * Prints its own message on failure.  Returns an exit code: 0 ok, 1
 * failure, 2 usage, 3 bad input (the server said 4xx other than 503), 4
 * server unreachable or busy (after bounded retries with Retry-After).
 * `half`: the caller writes the images as a half EXR as they come (no
 * combination first), so an HTTP answer in half is enough and gives the
 * same file; 0 asks for float (PNG, --float).  Raw planes are float.
 * On 0 the caller frees *out with obs_result_free(). */
int cli_remote_run(const char *server, int argc, char **argv, const char *in_path,
                   const obs_gbuffer *gb, unsigned outputs, int half, obs_result *out);

/* The same for deep input: over the binary protocol the A-buffer goes as
 * a deep G-buffer (per-pixel counts and samples), over HTTP the deep EXR
 * as it is; the answer is the deep chain's result (AO.Y, AOFront.Y, the
 * composite, as `outputs` asks).  On 0 the caller frees *out with
 * obs_deep_result_free(). */
int cli_remote_run_deep(const char *server, int argc, char **argv, const char *in_path,
                        const obs_deep_image *deep, unsigned outputs, int half, obs_deep_result *out);
/* --output deep: the daemon's answer, the two-part deep EXR, as it came
 * into *file (the caller frees it with obs_bytes_free()). */
int cli_remote_run_deep_file(const char *server, int argc, char **argv, const char *in_path,
                             const obs_deep_image *deep, obs_bytes *file);

/* The warnings the last answer carried (X-Obscura-Warning over HTTP,
 * the 200's warnings over the binary protocol: the daemon's checks of
 * the input and of the result), appended to info, those already there
 * (the input's, which the CLI checked itself) left out; the caller
 * prints them as it prints its own.  Returns how many were added. */
int cli_remote_take_warnings(obs_exr_info *info);

/* Splits a comma-separated server list into urls (each < 256 bytes);
 * returns how many, or -1 when an entry is empty or too long or there
 * are more than max. */
int cli_remote_split(const char *list, char urls[][256], int max);

#endif
