/* OpenEXR's messages and statuses, for every EXR file of core/io: the
 * library reports through a callback (obs__exr_error_handler) into a
 * per-thread buffer, which the failing call's message then quotes; the
 * threads and the failure of a loop over a part's chunks; and
 * the output compressions by name, with what this build's library can
 * code (the request parser checks them without the writer).  Below the
 * readers and writers, so that each can use it. */
#include <stdio.h>
#include <string.h>

#include "io/exr_internal.h"
#include "internal.h"
#include "pool.h"

static _Thread_local char exr_msg[384];

void obs__exr_msg_reset(void)
{
    exr_msg[0] = '\0';
}

const char *obs__exr_msg(void)
{
    return exr_msg;
}

void obs__exr_error_handler(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    size_t n = strlen(exr_msg);
    (void)ctxt;
    if (!msg || !*msg)
        msg = exr_get_default_error_message(code);
    /* The first message names the cause; later ones add context. */
    if (n == 0)
        snprintf(exr_msg, sizeof exr_msg, "%s", msg);
    else if (n + 3 < sizeof exr_msg)
        snprintf(exr_msg + n, sizeof exr_msg - n, "; %s", msg);
}

obs_status obs__exr_status(exr_result_t rv)
{
    switch (rv) {
    case EXR_ERR_SUCCESS: return OBS_OK;
    case EXR_ERR_OUT_OF_MEMORY: return OBS_NO_MEMORY;
    case EXR_ERR_FILE_ACCESS:
    case EXR_ERR_WRITE_IO: return OBS_IO;
    case EXR_ERR_FEATURE_NOT_IMPLEMENTED: return OBS_UNSUPPORTED;
    /* The reader passes valid arguments, so anything else (out of range,
     * bad header, corrupt chunk, short read) comes from the file. */
    default: return OBS_BAD_FILE;
    }
}

obs_status obs__exr_fail(char err[OBS_ERR_LEN], exr_result_t rv, const char *what)
{
    const char *msg = exr_msg[0] ? exr_msg : exr_get_default_error_message(rv);
    return obs__fail(err, obs__exr_status(rv), "%s: %s", what, msg);
}

/* ---- output compressions ------------------------------------------------ */

static const char *const compression_names[] = {"zip", "none", "rle", "zips", "zip", "piz", "dwaa"};
#define COMPRESSIONS ((int)(sizeof compression_names / sizeof compression_names[0]))

const char *obs_exr_compression_name(obs_exr_compression c)
{
    return (int)c >= 0 && (int)c < COMPRESSIONS ? compression_names[c] : "?";
}

int obs_exr_compression_parse(const char *name)
{
    for (int c = 1; name && c < COMPRESSIONS; c++)
        if (!strcmp(name, compression_names[c]))
            return c;
    return -1;
}

obs_status obs_exr_compression_check(obs_exr_compression c, char err[OBS_ERR_LEN])
{
    if ((int)c < 0 || (int)c >= COMPRESSIONS)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "unknown EXR compression %d", (int)c);
    if (c != OBS_EXR_DWAA)
        return OBS_OK;
    /* OpenEXR's C API codes DWAA from 3.2 on; 3.1's says "not yet
     * implemented in C" for both directions. */
    int maj = 0, min = 0, patch = 0;
    exr_get_library_version(&maj, &min, &patch, NULL);
    if (maj > 3 || (maj == 3 && min >= 2))
        return OBS_OK;
    return obs__fail(err, OBS_UNSUPPORTED,
                     "compression dwaa needs OpenEXR 3.2 or later (this build has %d.%d.%d, whose C API neither "
                     "writes nor reads DWAA); use none, rle, zips, zip or piz", maj, min, patch);
}

int obs__exr_chunk_threads(int threads, int64_t chunks)
{
    int n = obs__pool_threads(threads);
    if (n > chunks / 4)
        n = (int)(chunks / 4);
    return n < 1 ? 1 : n;
}

void obs__exr_chunk_fail_keep(obs__exr_chunk_fail *part, const obs__exr_chunk_fail *thread)
{
    if (thread->code != 0 && thread->chunk < part->chunk)
        *part = *thread;
}
