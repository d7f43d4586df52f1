/* obs_deep_run: the multi-layer AO of deep input on the GL context.  The
 * compressed nodes (OITAO III-B) are prepared as for the CPU twin
 * (deep_cpu.c: view position, normal, alpha), uploaded as two 2D array
 * textures of m layers (RGBA32F: position + planar depth, normal +
 * alpha) and one fragment pass (core/shaders/deep.frag.glsl) writes the
 * front node's AO and the blended AO.  The resources live for one call:
 * deep input is a file-at-a-time path, not the daemon's frame loop. */
#include <stdlib.h>
#include <string.h>

#include "deep_internal.h"
#include "gl/gl.h"
#include "obs_shaders.h"

static GLuint array_texture(int w, int h, int m, const float *data)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D_ARRAY, t);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_RGBA32F, w, h, m);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, w, h, m, GL_RGBA, GL_FLOAT, data);
    return t;
}

obs_status obs_deep_run(obs_ctx *ctx, const obs_deep_image *d, const obs_params *params,
                        obs_deep_result *out, char err[OBS_ERR_LEN])
{
    static const char glsl_version[] = "#version 430 core\n";
    obs__deep_frame df;
    GLuint prog = 0, tex[3] = {0, 0, 0}, fbo = 0;
    float *rgba = NULL;
    obs_status s;

    if (!ctx || !out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_deep_run: NULL argument");
    memset(out, 0, sizeof *out);
    if ((s = obs__ctx_bind(ctx, err)) != OBS_OK)
        return s;
    if ((s = obs__deep_frame_setup(d, params, &df, err)) != OBS_OK)
        return s;
    const obs__frame *f = &df.f;
    const int w = f->width, h = f->height;
    if ((s = obs__deep_result_alloc(out, w, h, err)) != OBS_OK)
        goto fail;
    if (!(rgba = malloc((size_t)w * (size_t)h * 4 * sizeof *rgba))) {
        s = obs__fail(err, OBS_NO_MEMORY, "deep AO read-back of %dx%d", w, h);
        goto fail;
    }
    const char *src[] = {glsl_version, obs__shader_common, obs__shader_deep_frag};
    if ((s = obs__gl_program("deep", obs__shader_fullscreen_vert, src, 3, &prog, err)) != OBS_OK)
        goto fail;

    tex[0] = array_texture(w, h, df.m, df.pos);
    tex[1] = array_texture(w, h, df.m, df.nrm);
    glGenTextures(1, &tex[2]);
    glBindTexture(GL_TEXTURE_2D, tex[2]);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, w, h);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex[2], 0);
    GLenum buf = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &buf);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        s = obs__fail(err, OBS_GL_ERROR, "deep AO framebuffer incomplete");
        goto fail;
    }

    glUseProgram(prog);
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_proj"), 1, GL_TRUE, f->proj);
    glUniform4fv(glGetUniformLocation(prog, "u_viewport"), 1, f->viewport);
    glUniform1i(glGetUniformLocation(prog, "u_depth_mode"), f->depth_mode);
    glUniform2i(glGetUniformLocation(prog, "u_size"), w, h);
    glUniform1f(glGetUniformLocation(prog, "u_radius"), f->radius);
    glUniform1i(glGetUniformLocation(prog, "u_ns"), f->samples);
    glUniform2fv(glGetUniformLocation(prog, "u_samples"), f->samples, f->sample_xy);
    glUniform2fv(glGetUniformLocation(prog, "u_rot"), 9, &f->rot[0][0]);
    glUniform1i(glGetUniformLocation(prog, "u_range_check"), f->range_check);
    glUniform1f(glGetUniformLocation(prog, "u_range_u"), f->range_u);
    glUniform1i(glGetUniformLocation(prog, "u_m"), df.m);
    glUniform1i(glGetUniformLocation(prog, "u_multi"), df.multi);
    glUniform1i(glGetUniformLocation(prog, "u_thin"), df.thin);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D_ARRAY, tex[0]);
    glUniform1i(glGetUniformLocation(prog, "u_lpos"), 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D_ARRAY, tex[1]);
    glUniform1i(glGetUniformLocation(prog, "u_lnrm"), 1);
    glViewport(0, 0, w, h);
    glBindVertexArray(ctx->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, rgba);
    glActiveTexture(GL_TEXTURE0);
    if ((s = obs__gl_check("deep AO pass", err)) != OBS_OK)
        goto fail;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        out->ao_front.data[i] = rgba[4 * i];
        out->ao_blend.data[i] = rgba[4 * i + 1];
    }
    obs__deep_composite(d, out);
fail:
    if (fbo) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &fbo);
    }
    glDeleteTextures(3, tex);
    if (prog)
        glDeleteProgram(prog);
    free(rgba);
    obs__deep_frame_free(&df);
    if (s != OBS_OK)
        obs_deep_result_free(out);
    return s;
}
