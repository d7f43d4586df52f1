/* The process's thread settings (obs_threads_set): the worker pools' limit
 * (kept by core/pool.c, where the one thread-count rule is) and llvmpipe's
 * thread count, which Mesa takes from LP_NUM_THREADS when a context is
 * made, so it is set here, before any context, and never over the user's
 * own value. */
#include <stdio.h>
#include <stdlib.h>

#include "internal.h"
#include "pool.h"

/* 1 once LP_NUM_THREADS is this process's (set here), not the user's. */
static int lp_ours;

obs_status obs_threads_set(int n, char err[OBS_ERR_LEN])
{
    if (n < 0 || n > OBS__POOL_MAX_THREADS)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "threads %d is outside [1, %d] (0: no limit)", n,
                         OBS__POOL_MAX_THREADS);
    obs__pool_set_limit(n);
    if (getenv("LP_NUM_THREADS") && !lp_ours)
        return OBS_OK; /* the user's: kept, obs_threads_get says so */
    if (n == 0) {
        if (lp_ours)
            unsetenv("LP_NUM_THREADS");
        lp_ours = 0;
        return OBS_OK;
    }
    char v[16];
    snprintf(v, sizeof v, "%d", n);
    if (setenv("LP_NUM_THREADS", v, 1) != 0)
        return obs__fail(err, OBS_NO_MEMORY, "cannot set LP_NUM_THREADS");
    lp_ours = 1;
    return OBS_OK;
}

void obs_threads_get(obs_threads_info *out)
{
    const char *lp = getenv("LP_NUM_THREADS");
    out->limit = obs__pool_limit();
    out->pool = obs__pool_threads(0);
    out->llvmpipe = lp ? atoi(lp) : -1;
    out->llvmpipe_from_user = lp && !lp_ours;
}
