/* The GL kernel of each pass (passes_gl.h): the programs it needs and
 * its draw calls.  The order and whether a pass runs are the table's
 * (passes.c); the driver is run_gl.c. */
#include "chain/frame_gl.h"
#include "chain/passes_gl.h"
#include "gl/draw.h"

static void upload(GLuint tex, const obs_plane *p, int w, int h, GLenum format)
{
    size_t px_bytes = (size_t)p->channels * sizeof(float);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, (GLint)(obs__plane_stride(p, w) / px_bytes));
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, format, GL_FLOAT, p->data);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
}

static void bind_tex(GLuint prog, const char *name, int unit, GLuint tex)
{
    glActiveTexture(GL_TEXTURE0 + (GLenum)unit);
    glBindTexture(GL_TEXTURE_2D, tex);
    glUniform1i(glGetUniformLocation(prog, name), unit);
}

/* A plane read with imageLoad (common.glsl says why not texelFetch). */
static void bind_img(GLuint prog, const char *name, int unit, GLuint tex, GLenum format)
{
    glBindImageTexture((GLuint)unit, tex, 0, GL_FALSE, 0, GL_READ_ONLY, format);
    glUniform1i(glGetUniformLocation(prog, name), unit);
}

/* The prep pass's planes, as the AO passes (VAO's and the methods') read
 * them. */
static void bind_prep_planes(GLuint prog, const obs__targets *t)
{
    bind_img(prog, "u_pos", 0, t->tex_viewpos, GL_RGBA32F);
    bind_img(prog, "u_vnormal", 1, t->tex_vnormal, GL_RGBA32F);
    bind_img(prog, "u_dz", 2, t->tex_dz, GL_RG32F);
}

/* Selects the AO program of a comparison method (built by
 * obs__prog_method) and sets its uniforms: method.glsl's and the
 * method's own (its row of the method table). */
static GLuint use_method_program(obs_ctx *ctx, const obs__method *m, const obs__frame *f,
                                 const obs__targets *t)
{
    GLuint prog = ctx->prog.method[m->id];
    glUseProgram(prog);
    bind_prep_planes(prog, t);
    obs__gl_set_uniforms(prog, f, m->uniforms);
    return prog;
}

static void draw(obs_ctx *ctx, GLuint fbo, int w, int h)
{
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, w, h);
    glBindVertexArray(ctx->dev.vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

static void read_back(GLuint fbo, GLenum attachment, int w, int h, GLenum format, float *dst)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glReadBuffer(attachment);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, w, h, format, GL_FLOAT, dst);
}

/* ---- the programs each pass needs ---------------------------------------- */

static obs_status build_prep(obs__programs *g, const obs__plan *pl, char err[OBS_ERR_LEN])
{
    return obs__prog_prep(g, &pl->f, err);
}

static obs_status build_cull(obs__programs *g, const obs__plan *pl, char err[OBS_ERR_LEN])
{
    return obs__prog_vao(g, 1, obs__ao_variant(&pl->f), err);
}

static obs_status build_ao(obs__programs *g, const obs__plan *pl, char err[OBS_ERR_LEN])
{
    if (pl->method->glsl) /* a comparison method in place of VAO */
        return obs__prog_method(g, pl->method, err);
    return obs__prog_vao(g, 0, obs__ao_variant(&pl->f), err);
}

static obs_status build_blur(obs__programs *g, const obs__plan *pl, char err[OBS_ERR_LEN])
{
    obs_status s = obs__blur_program(g, 0, pl->f.blur_radius, err);
    if (s == OBS_OK)
        s = obs__blur_program(g, pl->rays_in_blur, pl->f.blur_radius, err);
    return s;
}

static obs_status build_up(obs__programs *g, const obs__plan *pl, char err[OBS_ERR_LEN])
{
    return obs__prog_up(g, &pl->f, err);
}

static obs_status build_finish(obs__programs *g, const obs__plan *pl, char err[OBS_ERR_LEN])
{
    return obs__prog_finish(g, pl->rays_in_finish, pl->f.luminance != 0, err);
}

static obs_status build_composite(obs__programs *g, const obs__plan *pl, char err[OBS_ERR_LEN])
{
    (void)pl;
    return obs__prog_composite(g, err);
}

/* ---- the passes ------------------------------------------------------------ */

static obs_status run_upload(obs__gl_run *r, char err[OBS_ERR_LEN])
{
    const obs__frame *f = &r->pl->f;
    const obs_gbuffer *gb = r->pl->gb;
    (void)err;
    upload(r->t->tex_depth, &gb->depth, f->width, f->height, GL_RED);
    if (!f->reconstruct_normals)
        upload(r->t->tex_normal, &gb->normal, f->width, f->height, GL_RGB);
    if (r->pl->has_color)
        upload(r->t->tex_color, &gb->color, f->width, f->height, GL_RGBA);
    if (f->mask_occl) /* object masks */
        upload(r->t->tex_mask_w, &gb->occluders, f->width, f->height, GL_RED);
    if (f->mask_id)
        upload(r->t->tex_mask_id, &gb->object_id, f->width, f->height, GL_RED);
    return OBS_OK;
}

/* The prep pass; ao_resolution half: straight to the half planes, one
 * whole pixel of each 2x2 block (prep.frag.glsl, OBS_HALF), then the
 * half frame's block for the passes at that size. */
static obs_status run_prep(obs__gl_run *r, char err[OBS_ERR_LEN])
{
    const obs__frame *f = &r->pl->f, *af = r->pl->af;
    GLuint prog = r->ctx->prog.prep[f->half != 0][obs__prep_index(f)];
    glUseProgram(prog);
    bind_img(prog, "u_depth", 0, r->t->tex_depth, GL_R32F);
    bind_img(prog, "u_normal", 1, r->t->tex_normal, GL_RGBA32F);
    if (f->half) { /* object masks: the half pixels' from their full pixels' */
        glUniform1i(glGetUniformLocation(prog, "u_mask_on"),
                    (f->mask_occl ? 1 : 0) | (f->mask_id ? 2 : 0));
        if (f->mask_occl) {
            bind_img(prog, "u_mask_w", 5, r->t->tex_mask_w, GL_R32F);
            glBindImageTexture(2, r->at->tex_mask_w, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
            glUniform1i(glGetUniformLocation(prog, "u_hmask_w"), 2);
        }
        if (f->mask_id) {
            bind_img(prog, "u_mask_id", 6, r->t->tex_mask_id, GL_R32F);
            glBindImageTexture(3, r->at->tex_mask_id, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
            glUniform1i(glGetUniformLocation(prog, "u_hmask_id"), 3);
        }
    }
    draw(r->ctx, r->at->fbo_prep, af->width, af->height);
    if (f->half && f->mask_on) /* the AO pass reads what the images got */
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    return f->half ? obs__frame_block_bind(r->ctx, af, err) : OBS_OK;
}

/* Section 4.2: 8-sample AO at 1/8 resolution. */
static obs_status run_cull(obs__gl_run *r, char err[OBS_ERR_LEN])
{
    (void)err;
    GLuint prog = r->ctx->prog.cull[r->pl->f.range_check != 0];
    glUseProgram(prog);
    bind_prep_planes(prog, r->at);
    draw(r->ctx, r->at->fbo_cull, r->pl->af->cull_w, r->pl->af->cull_h);
    return OBS_OK;
}

static obs_status run_ao(obs__gl_run *r, char err[OBS_ERR_LEN])
{
    const obs__plan *pl = r->pl;
    const obs__targets *at = r->at;
    GLuint prog;
    if (pl->method->glsl) { /* a comparison method in place of VAO */
        prog = use_method_program(r->ctx, pl->method, pl->af, at);
    } else {
        prog = r->ctx->prog.vao[obs__ao_variant(&pl->f)];
        glUseProgram(prog);
        bind_prep_planes(prog, at);
        /* section 4.2: the pre-pass result, read at the pixel corners */
        bind_img(prog, "u_cull", 4, at->tex_cull, GL_R32F);
        /* section 4.7: colour bleeding reads the colour at the samples */
        bind_img(prog, "u_color", 3, r->t->tex_color, GL_RGBA32F);
    }
    /* object masks: occluder_weight() in common.glsl */
    glUniform1i(glGetUniformLocation(prog, "u_mask_on"),
                (pl->f.mask_occl ? 1 : 0) | (pl->f.mask_id ? 2 : 0));
    if (pl->f.mask_occl) /* at the AO's size (half: the downsample's) */
        bind_img(prog, "u_mask_w", 5, at->tex_mask_w, GL_R32F);
    if (pl->f.mask_id)
        bind_img(prog, "u_mask_id", 6, at->tex_mask_id, GL_R32F);
    /* the debug outputs go to their textures only when asked for */
    const GLenum vao_bufs[] = {
        GL_COLOR_ATTACHMENT0,
        (pl->outputs & OBS_OUTPUT_SAMPLE_COUNT) ? GL_COLOR_ATTACHMENT1 : GL_NONE,
        (pl->outputs & OBS_OUTPUT_CULL_MASK) ? GL_COLOR_ATTACHMENT2 : GL_NONE,
        pl->f.bleed_step ? GL_COLOR_ATTACHMENT3 : GL_NONE,
        (pl->outputs & OBS_OUTPUT_BENT) ? GL_COLOR_ATTACHMENT4 : GL_NONE};
    glBindFramebuffer(GL_FRAMEBUFFER, at->fbo_vao);
    glDrawBuffers(5, vao_bufs);
    /* the pass whose cost grows with the samples: in bands against the
     * deadline (obs_ctx_set_deadline) */
    return obs__gl_draw_banded(r->ctx->dev.vao, pl->af->width, pl->af->height, r->t_run,
                               r->ctx->deadline_ms, "AO", err);
}

/* Section 4.6, the low-pass filter: ao -> blur along x -> ao along y. */
static obs_status run_blur(obs__gl_run *r, char err[OBS_ERR_LEN])
{
    const obs__frame *af = r->pl->af;
    const obs__targets *at = r->at;
    (void)err;
    for (int pass = 0; pass < 2; pass++) { /* along x, then along y */
        GLuint prog = r->ctx->prog.blur[pass ? r->pl->rays_in_blur : 0][r->pl->f.blur_radius];
        glUseProgram(prog);
        bind_img(prog, "u_ao", 0, pass ? at->tex_blur : at->tex_ao, GL_RG32F);
        glUniform2i(glGetUniformLocation(prog, "u_dir"), !pass, pass);
        if (!pass) {
            const GLenum blur_bufs[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
            glBindFramebuffer(GL_FRAMEBUFFER, at->fbo_blur);
            glDrawBuffers(2, blur_bufs);
        }
        draw(r->ctx, pass ? at->fbo_ao : at->fbo_blur, af->width, af->height);
    }
    return OBS_OK;
}

/* ao_resolution half: the joint bilateral upsample (up.frag.glsl) into
 * the full-size AO, under the full frame's block again. */
static obs_status run_up(obs__gl_run *r, char err[OBS_ERR_LEN])
{
    const obs__frame *f = &r->pl->f, *af = r->pl->af;
    obs_status s = obs__frame_block_bind(r->ctx, f, err);
    if (s != OBS_OK)
        return s;
    GLuint prog = r->ctx->prog.up[f->rays != 0][obs__prep_index(f)];
    glUseProgram(prog);
    bind_img(prog, "u_depth", 0, r->t->tex_depth, GL_R32F);
    bind_img(prog, "u_normal", 1, r->t->tex_normal, GL_RGBA32F);
    bind_img(prog, "u_hnormal", 3, r->at->tex_vnormal, GL_RGBA32F);
    bind_img(prog, "u_hao", 4, r->at->tex_ao, GL_RG32F);
    glUniform2i(glGetUniformLocation(prog, "u_half_size"), af->width, af->height);
    draw(r->ctx, r->t->fbo_ao, f->width, f->height);
    return OBS_OK;
}

/* The finishing pass, after the blur (luminance.frag.glsl): the
 * conversion of ao_definition rays when there was no blur to do it,
 * luminance sensitivity (section 4.3, eq 3); ao -> tex_blur, free once
 * the blur is done. */
static obs_status run_finish(obs__gl_run *r, char err[OBS_ERR_LEN])
{
    const obs__plan *pl = r->pl;
    obs__targets *t = r->t;
    (void)err;
    GLuint prog = r->ctx->prog.finish[2 * pl->rays_in_finish + (pl->f.luminance != 0)];
    glUseProgram(prog);
    bind_tex(prog, "u_ao", 0, t->tex_ao);
    bind_tex(prog, "u_color", 1, t->tex_color);
    const GLenum lum_bufs[] = {GL_COLOR_ATTACHMENT0, (pl->outputs & OBS_OUTPUT_LUMINANCE)
                                                         ? GL_COLOR_ATTACHMENT1
                                                         : GL_NONE};
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo_blur);
    glDrawBuffers(2, lum_bufs);
    draw(r->ctx, t->fbo_blur, pl->f.width, pl->f.height);
    r->ao_tex = t->tex_blur;
    r->ao_fbo = t->fbo_blur;
    return OBS_OK;
}

static obs_status run_composite(obs__gl_run *r, char err[OBS_ERR_LEN])
{
    const obs__targets *t = r->t;
    (void)err;
    GLuint prog = r->ctx->prog.composite;
    glUseProgram(prog);
    bind_tex(prog, "u_ao", 0, r->ao_tex);
    bind_tex(prog, "u_color", 1, t->tex_color);
    bind_tex(prog, "u_bleed", 2, t->tex_bleed);
    glUniform1i(glGetUniformLocation(prog, "u_has_color"), r->pl->has_color);
    glUniform1i(glGetUniformLocation(prog, "u_has_bleed"), r->pl->f.bleed_step > 0);
    glUniform1i(glGetUniformLocation(prog, "u_multibounce"), r->pl->multibounce);
    draw(r->ctx, t->fbo_composite, r->pl->f.width, r->pl->f.height);
    return OBS_OK;
}

/* Fills n floats with 1: an output of a part that is off (no GL work). */
static void fill_ones(float *dst, size_t n)
{
    for (size_t i = 0; i < n; i++)
        dst[i] = 1.0f;
}

static obs_status run_readback(obs__gl_run *r, char err[OBS_ERR_LEN])
{
    const obs__frame *f = &r->pl->f;
    const unsigned outputs = r->pl->outputs;
    const obs__targets *t = r->t;
    obs_result *out = r->out;
    const int w = f->width, h = f->height;
    (void)err;
    if (outputs & OBS_OUTPUT_COMPOSITE)
        read_back(t->fbo_composite, GL_COLOR_ATTACHMENT0, w, h, GL_RGBA, out->composite.data);
    if (outputs & OBS_OUTPUT_AO)
        read_back(r->ao_fbo, GL_COLOR_ATTACHMENT0, w, h, GL_RED, out->ao.data);
    if (outputs & OBS_OUTPUT_SAMPLE_COUNT)
        read_back(t->fbo_vao, GL_COLOR_ATTACHMENT1, w, h, GL_RED, out->sample_count.data);
    if (outputs & OBS_OUTPUT_CULL_MASK)
        read_back(t->fbo_vao, GL_COLOR_ATTACHMENT2, w, h, GL_RED, out->cull_mask.data);
    if ((outputs & OBS_OUTPUT_BLEED) && f->bleed_step)
        read_back(t->fbo_vao, GL_COLOR_ATTACHMENT3, w, h, GL_RGB, out->bleed.data);
    else if (outputs & OBS_OUTPUT_BLEED) /* bleeding off: the neutral term */
        fill_ones(out->bleed.data, (size_t)w * h * 3);
    if (outputs & OBS_OUTPUT_BENT)
        read_back(t->fbo_vao, GL_COLOR_ATTACHMENT4, w, h, GL_RGB, out->bent.data);
    if ((outputs & OBS_OUTPUT_LUMINANCE) && f->luminance)
        read_back(t->fbo_blur, GL_COLOR_ATTACHMENT1, w, h, GL_RED, out->luminance.data);
    else if (outputs & OBS_OUTPUT_LUMINANCE) /* off: the factor is 1 */
        fill_ones(out->luminance.data, (size_t)w * h);
    return OBS_OK;
}

const obs__gl_kernel obs__gl_kernels[OBS_PASS_COUNT] = {
    [OBS_PASS_UPLOAD] = {NULL, run_upload},
    [OBS_PASS_PREP] = {build_prep, run_prep},
    [OBS_PASS_DOWNSAMPLE] = {build_prep, run_prep},
    [OBS_PASS_CULL] = {build_cull, run_cull},
    [OBS_PASS_AO] = {build_ao, run_ao},
    [OBS_PASS_BLUR] = {build_blur, run_blur},
    [OBS_PASS_UPSAMPLE] = {build_up, run_up},
    [OBS_PASS_FINISH] = {build_finish, run_finish},
    [OBS_PASS_COMPOSITE] = {build_composite, run_composite},
    [OBS_PASS_READBACK] = {NULL, run_readback},
};
