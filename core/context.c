/* The context's life: obs_ctx_create makes the GL device (core/gl), and
 * every pass keeps its objects in the context until obs_ctx_destroy,
 * which tears the passes' objects down first and the device last.  Also
 * the context's info and per-pass timing switches. */
#include <stdlib.h>
#include <string.h>

#include "context.h"
#include "gl/progcache.h"

_Static_assert(offsetof(struct obs_ctx, log) == 0, "obs__log reads the sink at the context's start");

/* Where llvmpipe's thread count came from (obs_threads_set): a farm slot
 * limit is only kept when it reached LP_NUM_THREADS. */
static void log_llvmpipe_threads(obs_ctx *ctx)
{
    obs_threads_info ti;
    obs_threads_get(&ti);
    if (ti.llvmpipe < 0)
        obs__log(ctx, OBS_LOG_DEBUG, "llvmpipe: a thread per core (no thread limit, LP_NUM_THREADS unset)");
    else if (ti.llvmpipe_from_user)
        obs__log(ctx, OBS_LOG_DEBUG, "llvmpipe: %d threads (LP_NUM_THREADS from the environment, kept%s)",
                 ti.llvmpipe, ti.limit ? "; the thread limit bounds obscura's own pools" : "");
    else
        obs__log(ctx, OBS_LOG_DEBUG, "llvmpipe: %d threads (LP_NUM_THREADS set from the thread limit)",
                 ti.llvmpipe);
}

obs_status obs_ctx_create(const obs_ctx_desc *desc, obs_ctx **out, char err[OBS_ERR_LEN])
{
    obs_ctx_desc d = {0};
    if (desc)
        d = *desc;
    *out = NULL;
    if ((unsigned)d.backend >= OBS_BACKEND_COUNT)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "unknown backend %d", (int)d.backend);

    obs_ctx *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return obs__fail(err, OBS_NO_MEMORY, "out of memory creating the context");
#ifdef OBS_DEBUG
    ctx->dev.debug = 1; /* debug builds always install the KHR_debug callback */
#else
    ctx->dev.debug = d.debug;
#endif
    ctx->log.fn = d.log;
    ctx->log.user = d.log_user;
    ctx->dev.log = d.log;
    ctx->dev.log_user = d.log_user;
    /* before the backend: Mesa reads where its shader cache is when the
     * display is initialised */
    obs__progcache_open(&ctx->dev.cache, d.cache_dir, d.log, d.log_user);
    obs_status s = obs__gl_device_create(&ctx->dev, d.backend, err);
    if (s != OBS_OK) {
        free(ctx);
        return s;
    }
    obs__progcache_attach(&ctx->dev.cache, ctx->dev.vendor, ctx->dev.renderer, ctx->dev.version);
    obs__log(ctx, OBS_LOG_INFO, "GL context: %s, OpenGL %s, %s", obs_backend_name(ctx->dev.backend),
             ctx->dev.version, ctx->dev.renderer);
    if (strstr(ctx->dev.renderer, "llvmpipe"))
        log_llvmpipe_threads(ctx);
    *out = ctx;
    return OBS_OK;
}

void obs_ctx_get_info(const obs_ctx *ctx, obs_ctx_info *info)
{
    info->backend = ctx->dev.backend;
    info->gl_version = ctx->dev.version;
    info->gl_vendor = ctx->dev.vendor;
    info->gl_renderer = ctx->dev.renderer;
    info->cache_dir = ctx->dev.cache.dir[0] ? ctx->dev.cache.dir : NULL;
    info->cache_writable = ctx->dev.cache.writable;
    info->programs_compiled = ctx->dev.cache.compiled;
    info->programs_loaded = ctx->dev.cache.loaded;
    info->programs_rejected = ctx->dev.cache.rejected;
}

void obs_ctx_destroy(obs_ctx *ctx)
{
    if (!ctx)
        return;
    if (obs__ctx_bind(ctx, NULL) == OBS_OK) {
        obs__chain_release(&ctx->prog, &ctx->tg);
        obs__chain_release(NULL, &ctx->tg_half);
        obs__deep_release(&ctx->deep, 1);
        if (ctx->frame_ubo)
            glDeleteBuffers(1, &ctx->frame_ubo);
        if (ctx->queries[0])
            glDeleteQueries(OBS_PASS_COUNT, ctx->queries);
    }
    obs__gl_device_destroy(&ctx->dev);
    free(ctx);
}

/* ---- per-pass timings (GL_TIME_ELAPSED queries, taken by the passes;
 * their names: obs_pass_name, chain/passes.c) ---- */

obs_status obs_ctx_set_timing(obs_ctx *ctx, int on, char err[OBS_ERR_LEN])
{
    if (!ctx)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no context");
    obs_status s = obs__ctx_bind(ctx, err);
    if (s != OBS_OK)
        return s;
    if (on && !ctx->queries[0])
        glGenQueries(OBS_PASS_COUNT, ctx->queries);
    ctx->timing = on != 0;
    ctx->times_valid = 0;
    return obs__gl_check("creating timer queries", err);
}

obs_status obs_ctx_set_deadline(obs_ctx *ctx, double seconds, char err[OBS_ERR_LEN])
{
    if (!ctx)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no context");
    if (!(seconds >= 0.0 && seconds <= 1e6)) /* NaN fails too */
        return obs__fail(err, OBS_INVALID_ARGUMENT, "deadline %g s: not in 0..1e6", seconds);
    ctx->deadline_ms = seconds * 1e3;
    return OBS_OK;
}

int obs_ctx_last_times(const obs_ctx *ctx, obs_pass_times *out)
{
    if (!ctx || !ctx->times_valid)
        return 0;
    *out = ctx->times;
    return 1;
}

/* ---- what the context keeps between frames ------------------------------ */

unsigned long long obs_ctx_kept_bytes(const obs_ctx *ctx)
{
    return ctx ? ctx->tg.bytes + ctx->tg_half.bytes + ctx->deep.bytes : 0;
}

obs_status obs_ctx_trim(obs_ctx *ctx, unsigned long long budget, char err[OBS_ERR_LEN])
{
    if (!ctx)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no context");
    if (obs_ctx_kept_bytes(ctx) <= budget)
        return OBS_OK;
    obs_status s = obs__ctx_bind(ctx, err);
    if (s != OBS_OK)
        return s;
    unsigned long long before = obs_ctx_kept_bytes(ctx);
    obs__chain_release(NULL, &ctx->tg); /* the programs stay: they cost no frame size */
    obs__chain_release(NULL, &ctx->tg_half);
    obs__deep_release(&ctx->deep, 0);
    obs__log(ctx, OBS_LOG_DEBUG, "released %llu bytes of frame targets (budget %llu)", before, budget);
    return obs__gl_check("releasing frame targets", err);
}
