/* Temporary sibling + rename for frame outputs (see out_file.h). */
#include "out_file.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "internal.h"

const char *obs__out_begin(obs__out_file *o, const char *path)
{
    struct stat sb;
    const char *slash = strrchr(path, '/');
    const char *name = slash ? slash + 1 : path;
    int dir_len = slash ? (int)(slash - path + 1) : 0;

    o->path = path;
    o->direct = 1;
    snprintf(o->tmp, sizeof o->tmp, "%s", path);
    if (stat(path, &sb) == 0 && !S_ISREG(sb.st_mode))
        return o->tmp;
    /* 255: NAME_MAX of the common file systems; 24 for ".", ".PID.tmp" */
    if (!*name || strlen(name) > 255 - 24)
        return o->tmp;
    int n = snprintf(o->tmp, sizeof o->tmp, "%.*s.%s.%ld.tmp", dir_len, path, name, (long)getpid());
    if (n < 0 || (size_t)n >= sizeof o->tmp) {
        snprintf(o->tmp, sizeof o->tmp, "%s", path);
        return o->tmp;
    }
    o->direct = 0;
    return o->tmp;
}

obs_status obs__out_end(obs__out_file *o, obs_status st, char err[OBS_ERR_LEN])
{
    struct stat sb;
    if (st == OBS_OK && !o->direct && rename(o->tmp, o->path) != 0)
        st = obs__fail(err, OBS_IO, "renaming the finished file into place: %s", strerror(errno));
    if (st != OBS_OK && stat(o->tmp, &sb) == 0 && S_ISREG(sb.st_mode))
        remove(o->tmp);
    return st;
}
