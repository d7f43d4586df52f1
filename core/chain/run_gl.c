/* obs_run: one frame on the GL context, the pass table (passes.c) walked
 * with the GL kernels (passes_gl.c): the programs the frame's passes need,
 * the targets (allocated once per resolution and reused for every frame
 * of that size), the passes in order, the per-pass timings. */
#include <string.h>

#include "chain/frame_gl.h"
#include "chain/multibounce.h"
#include "chain/passes_gl.h"
#include "mask_apply.h"

/* ---- per-pass timings (GL_TIME_ELAPSED queries) ------------------------ */

/* Brackets one pass; passes never nest (GL allows one active
 * GL_TIME_ELAPSED query). */
static void pass_begin(obs_ctx *ctx, obs_pass p, unsigned *ran)
{
    if (!ctx->timing)
        return;
    glBeginQuery(GL_TIME_ELAPSED, ctx->queries[p]);
    *ran |= 1u << p;
}

static void pass_end(obs_ctx *ctx)
{
    if (ctx->timing)
        glEndQuery(GL_TIME_ELAPSED);
}

/* Waits for the queries of the passes in `ran` (the frame has been read
 * back, so the GPU is done with them anyway). */
static void collect_times(obs_ctx *ctx, unsigned ran)
{
    if (!ctx->timing)
        return;
    obs_pass_times *t = &ctx->times;
    t->total_ms = 0.0;
    for (int p = 0; p < OBS_PASS_COUNT; p++) {
        t->ms[p] = -1.0;
        if (!(ran & (1u << p)))
            continue;
        GLuint64 ns = 0;
        glGetQueryObjectui64v(ctx->queries[p], GL_QUERY_RESULT, &ns);
        t->ms[p] = (double)ns / 1e6;
        t->total_ms += t->ms[p];
    }
    ctx->times_valid = 1;
}

/* The programs of every pass that runs, built on their first use. */
static obs_status build(obs_ctx *ctx, const obs__plan *pl, char err[OBS_ERR_LEN])
{
    obs_status s = OBS_OK;
    for (int i = 0; i < OBS_PASS_COUNT && s == OBS_OK; i++)
        if (obs__gl_kernels[i].build && obs__passes[i].when(pl))
            s = obs__gl_kernels[i].build(&ctx->prog, pl, err);
    return s;
}

/* The frame's targets, full size and (ao_resolution half) half size, the
 * frame's uniform block, read by every pass (common.glsl), and the
 * result's images. */
static obs_status prepare(obs__gl_run *r, char err[OBS_ERR_LEN])
{
    obs_ctx *ctx = r->ctx;
    const obs__plan *pl = r->pl;
    obs_status s = obs__targets_ensure(ctx, &ctx->gl_objects_created, &ctx->tg, pl->f.width,
                                       pl->f.height, err);
    if (s == OBS_OK && pl->f.half)
        s = obs__targets_ensure(ctx, &ctx->gl_objects_created, &ctx->tg_half, pl->hf.width,
                                pl->hf.height, err);
    r->t = &ctx->tg;
    r->at = pl->f.half ? &ctx->tg_half : &ctx->tg;
    r->ao_tex = r->t->tex_ao;
    r->ao_fbo = r->t->fbo_ao;
    if (s == OBS_OK)
        s = obs__targets_need(&ctx->gl_objects_created, &pl->f, r->t, r->at, pl->has_color,
                              pl->outputs, err);
    if (s == OBS_OK)
        s = obs__frame_block_bind(ctx, &pl->f, err);
    if (s == OBS_OK)
        s = obs__alloc_result(r->out, pl->f.width, pl->f.height, pl->outputs, err);
    return s;
}

/* Every pass that runs, in the table's order, each timed. */
static obs_status walk(obs__gl_run *r, unsigned *ran, char err[OBS_ERR_LEN])
{
    for (int i = 0; i < OBS_PASS_COUNT; i++) {
        if (!obs__passes[i].when(r->pl))
            continue;
        pass_begin(r->ctx, obs__passes[i].id, ran);
        obs_status s = obs__gl_kernels[i].run(r, err);
        pass_end(r->ctx);
        if (s != OBS_OK)
            return s;
    }
    return obs__gl_check("running the AO passes", err);
}

obs_status obs_run(obs_ctx *ctx, const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                   obs_result *out, char err[OBS_ERR_LEN])
{
    obs__gl_run r = {ctx, NULL, NULL, NULL, out, obs__now_ms(), 0, 0};
    unsigned ran = 0; /* passes timed in this frame */
    obs__plan pl;

    memset(out, 0, sizeof *out);
    if (!ctx)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no context");
    obs_status s = obs__plan_init(&pl, ctx, gb, params, outputs, err);
    if (s == OBS_OK)
        s = obs__gl_device_bind(&ctx->dev, err);
    if (s == OBS_OK)
        s = build(ctx, &pl, err);
    if (s != OBS_OK)
        return s;
    r.pl = &pl;
    s = prepare(&r, err);
    if (s == OBS_OK)
        s = walk(&r, &ran, err);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    if (s == OBS_OK)
        s = obs__multibounce_finish(pl.gb, pl.multibounce, pl.asked, out, err);
    if (s == OBS_OK)
        obs__bent_finish(&pl, out);
    if (s != OBS_OK) {
        ctx->times_valid = 0; /* no times for a frame cut short */
        obs_result_free(out);
        return s;
    }
    collect_times(ctx, ran);
    obs__receivers_apply(gb, out); /* object masks: receivers */
    return OBS_OK;
}
