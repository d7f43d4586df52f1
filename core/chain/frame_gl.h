/* The frame's uniform block on the GL side (frame_gl.c).  Not installed. */
#ifndef OBSCURA_FRAME_GL_H
#define OBSCURA_FRAME_GL_H

#include "context.h"

/* binding = 0 of common.glsl's Frame block */
#define OBS__FRAME_BINDING 0

/* Fills the block of f, uploads it and binds it for the passes; the
 * context is current. */
obs_status obs__frame_block_bind(obs_ctx *ctx, const obs__frame *f, char err[OBS_ERR_LEN]);

#endif
