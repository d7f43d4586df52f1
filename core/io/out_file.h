/* Frame outputs written whole or not at all (core/io/out_file.c).
 *
 * A render-farm task can be killed at any moment (scancel, a pre-empted
 * node, a full disk): the next step of the pipeline must never find a
 * truncated EXR or PNG under the frame's name.  So a writer opens
 * obs__out_begin()'s temporary path, DIR/.NAME.PID.tmp (same folder, so
 * the rename is atomic; hidden, so frame patterns do not match it; the
 * pid, so a wrapper that killed the process knows what to remove), and
 * obs__out_end() renames it over the final path when the write succeeded
 * or removes it when it failed.  Devices and pipes (/dev/stdout) and names
 * too long for a temporary sibling are written directly, as before. */
#ifndef OBSCURA_IO_OUT_FILE_H
#define OBSCURA_IO_OUT_FILE_H

#include "obscura/obscura.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct obs__out_file {
    const char *path; /* the final path (the caller's string) */
    char tmp[4096];   /* what the writer opens: a temporary sibling or path itself */
    int direct;       /* 1: tmp is path (a device, a pipe, a name too long) */
} obs__out_file;

/* Fills o; returns the path the writer must create (o->tmp). */
const char *obs__out_begin(obs__out_file *o, const char *path);

/* st == OBS_OK: renames the temporary file over the final path (a failed
 * rename is an OBS_IO with its reason in err); otherwise removes it and
 * returns st.  Direct writes: a failed one is removed when it is a regular
 * file, never a device or pipe. */
obs_status obs__out_end(obs__out_file *o, obs_status st, char err[OBS_ERR_LEN]);

#ifdef __cplusplus
}
#endif

#endif
