/* The context: one GL device and what the passes keep on it between
 * frames.  It sits above the passes (it tears their objects down), the
 * passes above core/gl.  Not installed. */
#ifndef OBSCURA_CONTEXT_H
#define OBSCURA_CONTEXT_H

#include "chain/chain_gl.h"
#include "deep/deep_targets_gl.h"
#include "gl/gl.h"
#include "log.h"

struct obs_ctx {
    obs__log_sink log; /* first: obs__log (log.c) reads it through an obs_ctx pointer */
    obs__gl_device dev;
    obs__programs prog;        /* the chain's (chain/run_gl.c) */
    obs__targets tg;
    obs__targets tg_half;      /* ao_resolution half: the AO passes' targets */
    obs__deep_targets deep;    /* deep input's (deep/deep_gl.c) */
    GLuint frame_ubo;                 /* the frame's uniform block (chain/frame_gl.c) */
    unsigned long gl_objects_created; /* textures + framebuffers, for tests */
    int timing;                       /* obs_ctx_set_timing */
    double deadline_ms;               /* obs_ctx_set_deadline; 0: none */
    GLuint queries[OBS_PASS_COUNT];   /* GL_TIME_ELAPSED, one per pass */
    int times_valid;
    obs_pass_times times;             /* of the last timed frame */
};

/* Makes the context current on the calling thread. */
static inline obs_status obs__ctx_bind(obs_ctx *ctx, char err[OBS_ERR_LEN])
{
    return obs__gl_device_bind(&ctx->dev, err);
}

#endif
