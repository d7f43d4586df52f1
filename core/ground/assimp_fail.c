/* assimp's failure as a status and message (assimp_read.h); C, so that
 * core/level/load.c, which reads through assimp's C API, needs no C++. */
#include <stdio.h>
#include <string.h>

#include "ground/assimp_read.h"

obs_status obs__assimp_fail(const char *path, const char *what, const char *msg,
                            char err[OBS_ERR_LEN])
{
    if (msg && strstr(msg, "bad_alloc")) {
        if (err)
            snprintf(err, OBS_ERR_LEN, "%s: assimp ran out of memory reading it (a count in the "
                                       "file larger than the file holds?)", path);
        return OBS_TOO_LARGE;
    }
    if (err)
        snprintf(err, OBS_ERR_LEN, "%s: not %s assimp can read: %s", path, what,
                 msg && *msg ? msg : "unknown error");
    return OBS_BAD_FILE;
}
