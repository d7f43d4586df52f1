/* The frame's uniform block on the GL side: obs__frame_block (frame.h)
 * uploaded to the context's one buffer, bound at binding 0, where
 * common.glsl's Frame block reads it.  Every pass of the chain and the
 * deep pass take their frame values from it instead of setting them one
 * uniform at a time. */
#include "chain/frame_gl.h"

obs_status obs__frame_block_bind(obs_ctx *ctx, const obs__frame *f, char err[OBS_ERR_LEN])
{
    obs__frame_block b;
    obs__frame_block_fill(f, &b);
    if (!ctx->frame_ubo)
        glGenBuffers(1, &ctx->frame_ubo);
    glBindBuffer(GL_UNIFORM_BUFFER, ctx->frame_ubo);
    glBufferData(GL_UNIFORM_BUFFER, (GLsizeiptr)sizeof b, &b, GL_DYNAMIC_DRAW);
    glBindBufferBase(GL_UNIFORM_BUFFER, OBS__FRAME_BINDING, ctx->frame_ubo);
    glBindBuffer(GL_UNIFORM_BUFFER, 0);
    return obs__gl_check("uploading the frame's uniform block", err);
}
