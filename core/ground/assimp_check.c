/* What obscura checks around assimp (assimp_read.h): a file before it is
 * handed over, assimp's failure as a status and message.  C, so that
 * core/level/load.c, which reads through assimp's C API, needs no C++. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ground/assimp_read.h"
#include "internal.h"

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

/* How much of a PLY file is searched for the end of its header. */
#define PLY_HEADER_MAX ((size_t)1 << 20)

obs_status obs__assimp_precheck(const char *path, char err[OBS_ERR_LEN])
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return obs__fail(err, OBS_IO, "%s: cannot open: %s", path, strerror(errno));
    char head[5] = "";
    size_t n = fread(head, 1, 4, f);
    if (n < 4 || memcmp(head, "ply", 3) != 0 || (head[3] != '\n' && head[3] != '\r')) {
        fclose(f);
        return OBS_OK; /* not PLY */
    }
    /* assimp 5.2's PLY reader, given a header without its end_header
     * line, reads past its buffer (binary) or never returns (ASCII). */
    char *buf = malloc(PLY_HEADER_MAX + 1);
    if (!buf) {
        fclose(f);
        return obs__fail(err, OBS_NO_MEMORY, "%s: PLY header", path);
    }
    n = fread(buf, 1, PLY_HEADER_MAX, f);
    fclose(f);
    buf[n] = '\0';
    int found = 0;
    for (char *line = buf; !found && line < buf + n;) {
        char *end = memchr(line, '\n', (size_t)(buf + n - line));
        size_t len = end ? (size_t)(end - line) : (size_t)(buf + n - line);
        while (len > 0 && (line[len - 1] == '\r' || line[len - 1] == ' ' || line[len - 1] == '\t'))
            len--;
        found = len == 10 && memcmp(line, "end_header", 10) == 0;
        if (!end)
            break;
        line = end + 1;
    }
    free(buf);
    if (!found)
        return obs__fail(err, OBS_BAD_FILE, "%s: a PLY header without its end_header line%s "
                                            "(damaged or truncated)",
                         path, n == PLY_HEADER_MAX ? " in its first MiB" : "");
    return OBS_OK;
}
