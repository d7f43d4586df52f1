/* The chain's frame targets: textures and framebuffers per resolution,
 * made on a frame's first need of them and kept while frames keep their
 * size (obs__targets, chain_gl.h); and their release. */
#include <string.h>

#include "chain/chain_gl.h"

static GLuint make_texture(unsigned long *created, obs__targets *set, GLenum format, int w, int h)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexStorage2D(GL_TEXTURE_2D, 1, format, w, h);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    (*created)++;
    const unsigned texel = format == GL_RGBA32F ? 16 : format == GL_RG32F ? 8 : 4;
    set->bytes += (unsigned long long)w * (unsigned long long)h * texel;
    return t;
}

static obs_status make_fbo(unsigned long *created, GLuint *fbo, const GLuint *tex, int count,
                           const char *name, char err[OBS_ERR_LEN])
{
    static const GLenum bufs[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1,
                                  GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3};
    glGenFramebuffers(1, fbo);
    (*created)++;
    glBindFramebuffer(GL_FRAMEBUFFER, *fbo);
    for (int i = 0; i < count; i++)
        glFramebufferTexture2D(GL_FRAMEBUFFER, bufs[i], GL_TEXTURE_2D, tex[i], 0);
    glDrawBuffers(count, bufs);
    GLenum st = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (st != GL_FRAMEBUFFER_COMPLETE)
        return obs__fail(err, OBS_GL_ERROR, "framebuffer %s incomplete (0x%04x)", name, (unsigned)st);
    return OBS_OK;
}

void obs__chain_release(obs__programs *g, obs__targets *t)
{
    GLuint tex[] = {t->tex_depth,   t->tex_normal, t->tex_color,     t->tex_viewpos, t->tex_vnormal,
                    t->tex_dz,      t->tex_ao,     t->tex_composite, t->tex_blur,    t->tex_count,
                    t->tex_cull,    t->tex_cullmask, t->tex_bleed,   t->tex_lumfactor, t->tex_bent,
                    t->tex_mask_w,  t->tex_mask_id};
    GLuint fbo[] = {t->fbo_prep, t->fbo_ao, t->fbo_blur, t->fbo_composite, t->fbo_vao, t->fbo_cull};
    glDeleteTextures((GLsizei)(sizeof tex / sizeof tex[0]), tex);
    glDeleteFramebuffers((GLsizei)(sizeof fbo / sizeof fbo[0]), fbo);
    memset(t, 0, sizeof *t);
    if (!g)
        return;
    OBS__GL_DELETE_PROGRAMS(g->vao);
    OBS__GL_DELETE_PROGRAMS(g->cull);
    obs__gl_delete_programs(&g->blur[0][0], sizeof g->blur / sizeof g->blur[0][0]);
    OBS__GL_DELETE_PROGRAMS(g->method);
    OBS__GL_DELETE_PROGRAMS(g->finish);
    obs__gl_delete_programs(&g->composite, 1);
    obs__gl_delete_programs(&g->prep[0][0], sizeof g->prep / sizeof g->prep[0][0]);
    obs__gl_delete_programs(&g->up[0][0], sizeof g->up / sizeof g->up[0][0]);
    memset(g, 0, sizeof *g);
}

/* The targets t (the context's full-size set, or the half-size set of
 * ao_resolution half) for w x h. */
obs_status obs__targets_ensure(obs_ctx *log_ctx, unsigned long *created, obs__targets *t, int w,
                               int h, char err[OBS_ERR_LEN])
{
    if (t->width == w && t->height == h)
        return OBS_OK;
    if (t->width) {
        /* a new resolution: drop the old set, keep the programs */
        obs__chain_release(NULL, t);
    }
    /* what every frame needs; the rest is made on a frame's first need
     * of it (need_texture, need_planes) and kept with the set */
    t->tex_depth = make_texture(created, t, GL_R32F, w, h);
    t->tex_ao = make_texture(created, t, GL_RG32F, w, h);     /* AO, depth (blur.frag.glsl) */
    t->tex_blur = make_texture(created, t, GL_RG32F, w, h);
    /* Section 4.2: the pre-pass texture, one texel per 8 x 8 block; the AO
     * pass filters it itself (cull_candidate in vao.frag.glsl). */
    t->tex_cull = make_texture(created, t, GL_R32F, (w + OBS_CULL_BLOCK - 1) / OBS_CULL_BLOCK,
                               (h + OBS_CULL_BLOCK - 1) / OBS_CULL_BLOCK);
    obs_status s = make_fbo(created, &t->fbo_vao, &t->tex_ao, 1, "vao", err);
    if (s == OBS_OK)
        s = make_fbo(created, &t->fbo_cull, &t->tex_cull, 1, "cull", err);
    if (s == OBS_OK)
        s = make_fbo(created, &t->fbo_ao, &t->tex_ao, 1, "ao", err);
    if (s == OBS_OK)
        s = make_fbo(created, &t->fbo_blur, &t->tex_blur, 1, "blur", err);
    if (s == OBS_OK)
        s = obs__gl_check("allocating frame targets", err);
    if (s != OBS_OK) {
        obs__chain_release(NULL, t);
        return s;
    }
    t->width = w;
    t->height = h;
    obs__log(log_ctx, OBS_LOG_DEBUG, "allocated frame targets for %dx%d", w, h);
    return OBS_OK;
}

/* A texture of set t made on the first frame that needs it (the normals
 * and colour, the debug outputs, the colour-bleed term), attached to fbo
 * at attachment when fbo is not 0. */
static obs_status need_texture(unsigned long *created, obs__targets *t, GLuint *tex, GLenum format,
                               GLuint fbo, GLenum attachment, char err[OBS_ERR_LEN])
{
    if (*tex)
        return OBS_OK;
    *tex = make_texture(created, t, format, t->width, t->height);
    if (fbo) {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, attachment, GL_TEXTURE_2D, *tex, 0);
    }
    return obs__gl_check("allocating a frame target", err);
}

/* The prep planes of set t and their framebuffer, made when a frame's
 * prep pass first writes that size (not the full set of ao_resolution
 * half, whose prep runs at half size). */
static obs_status need_prep_planes(unsigned long *created, obs__targets *t, char err[OBS_ERR_LEN])
{
    if (t->fbo_prep)
        return OBS_OK;
    t->tex_viewpos = make_texture(created, t, GL_RGBA32F, t->width, t->height);
    t->tex_vnormal = make_texture(created, t, GL_RGBA32F, t->width, t->height);
    t->tex_dz = make_texture(created, t, GL_RG32F, t->width, t->height);
    GLuint prep[] = {t->tex_viewpos, t->tex_vnormal, t->tex_dz};
    return make_fbo(created, &t->fbo_prep, prep, 3, "prep", err);
}

/* The targets a frame needs beyond what every frame does: t the full
 * set, at the set the AO runs at (t, or the half set). */
obs_status obs__targets_need(unsigned long *created, const obs__frame *f, obs__targets *t,
                             obs__targets *at, int has_color, unsigned outputs,
                             char err[OBS_ERR_LEN])
{
    obs_status s = need_prep_planes(created, at, err);
    if (s == OBS_OK && !f->reconstruct_normals) /* read as an image: no RGB32F */
        s = need_texture(created, t, &t->tex_normal, GL_RGBA32F, 0, 0, err);
    if (s == OBS_OK && has_color)
        s = need_texture(created, t, &t->tex_color, GL_RGBA32F, 0, 0, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_SAMPLE_COUNT))
        s = need_texture(created, at, &at->tex_count, GL_R32F, at->fbo_vao, GL_COLOR_ATTACHMENT1, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_CULL_MASK))
        s = need_texture(created, at, &at->tex_cullmask, GL_R32F, at->fbo_vao, GL_COLOR_ATTACHMENT2,
                         err);
    if (s == OBS_OK && f->bleed_step)
        s = need_texture(created, at, &at->tex_bleed, GL_RGBA32F, at->fbo_vao, GL_COLOR_ATTACHMENT3,
                         err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_BENT))
        s = need_texture(created, at, &at->tex_bent, GL_RGBA32F, at->fbo_vao, GL_COLOR_ATTACHMENT4, err);
    if (s == OBS_OK && f->luminance && (outputs & OBS_OUTPUT_LUMINANCE))
        s = need_texture(created, t, &t->tex_lumfactor, GL_R32F, t->fbo_blur, GL_COLOR_ATTACHMENT1,
                         err);
    if (s == OBS_OK && f->mask_occl) /* object masks (core/mask.c) */
        s = need_texture(created, t, &t->tex_mask_w, GL_R32F, 0, 0, err);
    if (s == OBS_OK && f->mask_id)
        s = need_texture(created, t, &t->tex_mask_id, GL_R32F, 0, 0, err);
    /* ao_resolution half: the half-size masks the downsample writes */
    if (s == OBS_OK && f->half && f->mask_occl)
        s = need_texture(created, at, &at->tex_mask_w, GL_R32F, 0, 0, err);
    if (s == OBS_OK && f->half && f->mask_id)
        s = need_texture(created, at, &at->tex_mask_id, GL_R32F, 0, 0, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_COMPOSITE) && !t->fbo_composite) {
        s = need_texture(created, t, &t->tex_composite, GL_RGBA32F, 0, 0, err);
        if (s == OBS_OK)
            s = make_fbo(created, &t->fbo_composite, &t->tex_composite, 1, "composite", err);
    }
    return s;
}
