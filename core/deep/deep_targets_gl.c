/* Deep input's kept GL objects torn down (deep_targets_gl.h): by the deep pass
 * on a new size, by the context when it releases or is destroyed.  Needs
 * nothing of the context, so the context calls down into it and the deep
 * pass (deep_gl.c) does not call back up. */
#include <string.h>

#include "deep/deep_targets_gl.h"

/* Drops the size-dependent objects; the program stays unless `all`. */
void obs__deep_release(obs__deep_targets *t, int all)
{
    GLuint tex[] = {t->tex_pos,   t->tex_nrm,   t->tex_end, t->tex_mask,
                    t->tex_front, t->tex_blend, t->tex_tmp, t->tex_nodes};
    glDeleteTextures(8, tex);
    GLuint fbo[] = {t->fbo, t->fbo_front, t->fbo_blend, t->fbo_tmp};
    for (int i = 0; i < 4; i++)
        if (fbo[i])
            glDeleteFramebuffers(1, &fbo[i]);
    GLuint prog[OBS__DEEP_VARIANTS];
    memcpy(prog, t->prog, sizeof prog);
    memset(t, 0, sizeof *t);
    if (all)
        OBS__GL_DELETE_PROGRAMS(prog);
    else
        memcpy(t->prog, prog, sizeof prog);
}

