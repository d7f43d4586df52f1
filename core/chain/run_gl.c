/* obs_run: uploads a G-buffer, runs the passes on the GL context, reads the
 * results back.  Textures and framebuffers are allocated once per
 * resolution and reused for every frame of that size. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "chain/frame_gl.h"
#include "context.h"
#include "gl/draw.h"
#include "methods/methods.h"
#include "obs_shaders.h"

static const char glsl_version[] = "#version 430 core\n";
/* Switches of the AO pass compiled in or out, by defines, instead of read
 * from uniforms: a uniform branch does not skip its body on a SIMD
 * rasteriser such as llvmpipe, which runs both sides for every pixel (the
 * bleed code cost the AO pass a third of its time with bleeding off;
 * bench/RESULTS.md).  Bits of the index of ctx->prog.vao; each program is
 * built on its first use. */
enum {
    AO_BLEED = 1,    /* OBS_BLEED: colour bleeding (section 4.7) */
    AO_ADAPTIVE = 2, /* OBS_ADAPTIVE: adaptive sampling (section 4.1) */
    AO_CULLING = 4,  /* OBS_CULLING: the culling test (section 4.2) */
    AO_RANGE = 8     /* OBS_RANGE_CHECK: the depth range check (section 4.4) */
};

static unsigned ao_variant(const obs__frame *f)
{
    return (f->bleed_step ? AO_BLEED : 0u) | (f->adaptive ? AO_ADAPTIVE : 0u) |
           (f->culling ? AO_CULLING : 0u) | (f->range_check ? AO_RANGE : 0u);
}

/* The AO program (pre 0) or the culling pre-pass's (pre 1; its variants
 * differ only in AO_RANGE) of the given variant, built on its first use. */
static obs_status build_vao_program(obs_ctx *ctx, int pre, unsigned v, char err[OBS_ERR_LEN])
{
    GLuint *prog = pre ? &ctx->prog.cull[(v & AO_RANGE) != 0] : &ctx->prog.vao[v];
    if (*prog)
        return OBS_OK;
    char defs[160];
    snprintf(defs, sizeof defs,
             "#define OBS_BLEED %d\n#define OBS_ADAPTIVE %d\n#define OBS_CULLING %d\n"
             "#define OBS_RANGE_CHECK %d\n",
             !pre && (v & AO_BLEED), !pre && (v & AO_ADAPTIVE), !pre && (v & AO_CULLING),
             (v & AO_RANGE) != 0);
    const char *src[] = {glsl_version, defs, obs__shader_common, obs__shader_vao,
                         pre ? obs__shader_cull_frag : obs__shader_vao_frag};
    return obs__gl_program(pre ? "cull" : "vao", obs__shader_fullscreen_vert, src, 5, prog, err);
}

static obs_status build_programs(obs_ctx *ctx, char err[OBS_ERR_LEN])
{
    if (ctx->prog.composite)
        return OBS_OK;
    const char *comp[] = {glsl_version, obs__shader_composite_frag};
    return obs__gl_program("composite", obs__shader_fullscreen_vert, comp, 2, &ctx->prog.composite,
                           err);
}

/* The finishing pass (luminance.frag.glsl) with the conversion of
 * ao_definition rays (OBS_RAYS) and luminance sensitivity (OBS_LUMINANCE)
 * compiled in or out, built on its first use: prog.finish[2 * rays + lum]. */
static obs_status build_finish_program(obs_ctx *ctx, int rays, int lum, char err[OBS_ERR_LEN])
{
    GLuint *prog = &ctx->prog.finish[2 * rays + lum];
    if ((!rays && !lum) || *prog)
        return OBS_OK;
    char defs[64];
    snprintf(defs, sizeof defs, "#define OBS_RAYS %d\n#define OBS_LUMINANCE %d\n", rays, lum);
    const char *src[] = {glsl_version, defs, obs__shader_common, obs__shader_luminance_frag};
    return obs__gl_program("finish", obs__shader_fullscreen_vert, src, 4, prog, err);
}

/* The prep pass that reads the normals or derives them from depth
 * (OBS_RECONSTRUCT), for the frame's depth mode (OBS_DEPTH_MODE: planar,
 * radial, ndc, inverse, normalized; resolved, never OBS_DEPTH_DEFAULT), at
 * full size or, for ao_resolution half, straight to the half planes
 * (OBS_HALF), built on its first use: ctx->prog.prep[half][prep_index(f)].
 * The same defines select ao_resolution half's upsample, which derives its
 * own pixel's depth and normal with prep.glsl. */
static int prep_index(const obs__frame *f)
{
    int mode = f->depth_mode >= OBS_DEPTH_PLANAR && f->depth_mode <= OBS_DEPTH_NORMALIZED
                   ? f->depth_mode
                   : OBS_DEPTH_PLANAR;
    return OBS__DEPTH_MODES * (f->reconstruct_normals != 0) + mode - OBS_DEPTH_PLANAR;
}

static void prep_defines(int k, char *defs, size_t size)
{
    snprintf(defs, size, "#define OBS_RECONSTRUCT %d\n#define OBS_DEPTH_MODE %d\n",
             k / OBS__DEPTH_MODES, k % OBS__DEPTH_MODES + OBS_DEPTH_PLANAR);
}

static obs_status build_prep_program(obs_ctx *ctx, const obs__frame *f, char err[OBS_ERR_LEN])
{
    int k = prep_index(f), half = f->half != 0;
    if (ctx->prog.prep[half][k])
        return OBS_OK;
    char defs[80];
    prep_defines(k, defs, sizeof defs);
    const char *src[] = {glsl_version, defs, half ? "#define OBS_HALF 1\n" : "#define OBS_HALF 0\n",
                         obs__shader_common, obs__shader_prep, obs__shader_prep_frag};
    const char *name = half ? (k / OBS__DEPTH_MODES ? "prep to half size (normals from depth)"
                                                    : "prep to half size")
                            : (k / OBS__DEPTH_MODES ? "prep (normals from depth)" : "prep");
    return obs__gl_program(name, obs__shader_fullscreen_vert, src, 6, &ctx->prog.prep[half][k],
                           err);
}

/* The blur of half-width radius (section 4.6), built on its first use:
 * the radius is a compile-time constant, so the taps' loop is unrolled;
 * rays 1 is the vertical pass that also converts its result
 * (ao_definition rays, OBS_RAYS in blur.frag.glsl). */
obs_status obs__blur_program(obs_ctx *ctx, int rays, int radius, char err[OBS_ERR_LEN])
{
    if (radius <= 0 || ctx->prog.blur[rays][radius])
        return OBS_OK;
    char def[64];
    snprintf(def, sizeof def, "#define BLUR_RADIUS %d\n#define OBS_RAYS %d\n", radius, rays);
    const char *src[] = {glsl_version, def, obs__shader_common, obs__shader_blur_frag};
    return obs__gl_program("blur", obs__shader_fullscreen_vert, src, 4,
                           &ctx->prog.blur[rays][radius], err);
}

/* The AO program of a comparison method (parameter method), built on its
 * first use: common.glsl, method.glsl, the method's file (its row of the
 * method table), method.frag.  Nothing for vaopp and vao. */
static obs_status build_method_program(obs_ctx *ctx, const obs__method *m, char err[OBS_ERR_LEN])
{
    if (!m->glsl || ctx->prog.method[m->id])
        return OBS_OK;
    const char *src[] = {glsl_version, obs__shader_common, obs__shader_method, m->glsl,
                         obs__shader_method_frag};
    return obs__gl_program(m->name, obs__shader_fullscreen_vert, src, 5, &ctx->prog.method[m->id],
                           err);
}

/* ao_resolution half's upsample (up.frag.glsl), built on its first use;
 * the downsample is the prep pass's OBS_HALF variant. */
static obs_status build_up_program(obs_ctx *ctx, const obs__frame *f, char err[OBS_ERR_LEN])
{
    int k = prep_index(f), rays = f->rays != 0;
    if (ctx->prog.up[rays][k])
        return OBS_OK;
    char defs[80];
    prep_defines(k, defs, sizeof defs);
    const char *src[] = {glsl_version, defs, rays ? "#define OBS_RAYS 1\n" : "#define OBS_RAYS 0\n",
                         obs__shader_common, obs__shader_prep, obs__shader_up_frag};
    return obs__gl_program("upsample", obs__shader_fullscreen_vert, src, 6, &ctx->prog.up[rays][k],
                           err);
}

static GLuint make_texture(obs_ctx *ctx, obs__targets *set, GLenum format, int w, int h)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexStorage2D(GL_TEXTURE_2D, 1, format, w, h);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    ctx->gl_objects_created++;
    const unsigned texel = format == GL_RGBA32F ? 16 : format == GL_RG32F ? 8 : 4;
    set->bytes += (unsigned long long)w * (unsigned long long)h * texel;
    return t;
}

static obs_status make_fbo(obs_ctx *ctx, GLuint *fbo, const GLuint *tex, int count,
                           const char *name, char err[OBS_ERR_LEN])
{
    static const GLenum bufs[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1,
                                  GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3};
    glGenFramebuffers(1, fbo);
    ctx->gl_objects_created++;
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
                    t->tex_cull,    t->tex_cullmask, t->tex_bleed,   t->tex_lumfactor};
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
static obs_status ensure_targets(obs_ctx *ctx, obs__targets *t, int w, int h, char err[OBS_ERR_LEN])
{
    if (t->width == w && t->height == h)
        return OBS_OK;
    if (t->width) {
        /* a new resolution: drop the old set, keep the programs */
        obs__chain_release(NULL, t);
    }
    /* what every frame needs; the rest is made on a frame's first need
     * of it (need_texture, need_planes) and kept with the set */
    t->tex_depth = make_texture(ctx, t, GL_R32F, w, h);
    t->tex_ao = make_texture(ctx, t, GL_RG32F, w, h);     /* AO, depth (blur.frag.glsl) */
    t->tex_blur = make_texture(ctx, t, GL_RG32F, w, h);
    /* Section 4.2: the pre-pass texture, one texel per 8 x 8 block; the AO
     * pass filters it itself (cull_candidate in vao.frag.glsl). */
    t->tex_cull = make_texture(ctx, t, GL_R32F, (w + OBS_CULL_BLOCK - 1) / OBS_CULL_BLOCK,
                               (h + OBS_CULL_BLOCK - 1) / OBS_CULL_BLOCK);
    obs_status s = make_fbo(ctx, &t->fbo_vao, &t->tex_ao, 1, "vao", err);
    if (s == OBS_OK)
        s = make_fbo(ctx, &t->fbo_cull, &t->tex_cull, 1, "cull", err);
    if (s == OBS_OK)
        s = make_fbo(ctx, &t->fbo_ao, &t->tex_ao, 1, "ao", err);
    if (s == OBS_OK)
        s = make_fbo(ctx, &t->fbo_blur, &t->tex_blur, 1, "blur", err);
    if (s == OBS_OK)
        s = obs__gl_check("allocating frame targets", err);
    if (s != OBS_OK) {
        obs__chain_release(NULL, t);
        return s;
    }
    t->width = w;
    t->height = h;
    obs__log(ctx, OBS_LOG_DEBUG, "allocated frame targets for %dx%d", w, h);
    return OBS_OK;
}

/* A texture of set t made on the first frame that needs it (the normals
 * and colour, the debug outputs, the colour-bleed term), attached to fbo
 * at attachment when fbo is not 0. */
static obs_status need_texture(obs_ctx *ctx, obs__targets *t, GLuint *tex, GLenum format,
                               GLuint fbo, GLenum attachment, char err[OBS_ERR_LEN])
{
    if (*tex)
        return OBS_OK;
    *tex = make_texture(ctx, t, format, t->width, t->height);
    if (fbo) {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, attachment, GL_TEXTURE_2D, *tex, 0);
    }
    return obs__gl_check("allocating a frame target", err);
}

/* The prep planes of set t and their framebuffer, made when a frame's
 * prep pass first writes that size (not the full set of ao_resolution
 * half, whose prep runs at half size). */
static obs_status need_prep_planes(obs_ctx *ctx, obs__targets *t, char err[OBS_ERR_LEN])
{
    if (t->fbo_prep)
        return OBS_OK;
    t->tex_viewpos = make_texture(ctx, t, GL_RGBA32F, t->width, t->height);
    t->tex_vnormal = make_texture(ctx, t, GL_RGBA32F, t->width, t->height);
    t->tex_dz = make_texture(ctx, t, GL_RG32F, t->width, t->height);
    GLuint prep[] = {t->tex_viewpos, t->tex_vnormal, t->tex_dz};
    return make_fbo(ctx, &t->fbo_prep, prep, 3, "prep", err);
}

/* The targets a frame needs beyond what every frame does: t the full
 * set, at the set the AO runs at (t, or the half set). */
static obs_status need_frame_targets(obs_ctx *ctx, const obs__frame *f, obs__targets *t,
                                     obs__targets *at, int has_color, unsigned outputs,
                                     char err[OBS_ERR_LEN])
{
    obs_status s = need_prep_planes(ctx, at, err);
    if (s == OBS_OK && !f->reconstruct_normals) /* read as an image: no RGB32F */
        s = need_texture(ctx, t, &t->tex_normal, GL_RGBA32F, 0, 0, err);
    if (s == OBS_OK && has_color)
        s = need_texture(ctx, t, &t->tex_color, GL_RGBA32F, 0, 0, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_SAMPLE_COUNT))
        s = need_texture(ctx, at, &at->tex_count, GL_R32F, at->fbo_vao, GL_COLOR_ATTACHMENT1, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_CULL_MASK))
        s = need_texture(ctx, at, &at->tex_cullmask, GL_R32F, at->fbo_vao, GL_COLOR_ATTACHMENT2,
                         err);
    if (s == OBS_OK && f->bleed_step)
        s = need_texture(ctx, at, &at->tex_bleed, GL_RGBA32F, at->fbo_vao, GL_COLOR_ATTACHMENT3,
                         err);
    if (s == OBS_OK && f->luminance && (outputs & OBS_OUTPUT_LUMINANCE))
        s = need_texture(ctx, t, &t->tex_lumfactor, GL_R32F, t->fbo_blur, GL_COLOR_ATTACHMENT1,
                         err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_COMPOSITE) && !t->fbo_composite) {
        s = need_texture(ctx, t, &t->tex_composite, GL_RGBA32F, 0, 0, err);
        if (s == OBS_OK)
            s = make_fbo(ctx, &t->fbo_composite, &t->tex_composite, 1, "composite", err);
    }
    return s;
}

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
 * build_method_program) and sets its uniforms: method.glsl's and the
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

obs_status obs_run(obs_ctx *ctx, const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                   obs_result *out, char err[OBS_ERR_LEN])
{
    const double t_run = obs__now_ms(); /* obs_ctx_set_deadline counts from here */
    unsigned ran = 0; /* passes timed in this frame */
    obs_params p;
    obs__frame f;
    obs_status s;

    memset(out, 0, sizeof *out);
    if (!ctx)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no context");
    if (!(outputs & OBS__OUTPUTS_ALL))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no output requested");
    obs__params_for_gbuffer(params, gb, &p);
    s = obs__frame_setup(ctx, gb, &p, &f, err);
    if (s == OBS_OK)
        s = obs__frame_check_outputs(&f, outputs, err);
    if (s != OBS_OK)
        return s;
    const obs__method *method = obs__method_get(f.method);
    /* ao_resolution half: the culling pre-pass, AO and blur run on the
     * half frame hf (af) and its targets (at), between the downsample and
     * the upsample; everything else at full size */
    obs__frame hf;
    if (f.half)
        obs__frame_half(&f, &hf);
    const obs__frame *af = f.half ? &hf : &f;
    s = obs__ctx_bind(ctx, err);
    if (s != OBS_OK)
        return s;
    s = build_programs(ctx, err);
    if (s == OBS_OK)
        s = build_method_program(ctx, method, err);
    if (s == OBS_OK && !method->glsl)
        s = build_vao_program(ctx, 0, ao_variant(&f), err);
    if (s == OBS_OK && f.culling)
        s = build_vao_program(ctx, 1, ao_variant(&f), err);
    if (s == OBS_OK && f.half)
        s = build_up_program(ctx, &f, err);
    /* ao_definition rays converts the blurred AO: in the blur's vertical
     * pass, or in the finishing pass when there is no blur; at half
     * resolution in the upsample (which filters the linear estimate, as
     * the blur does) */
    const int rays_in_blur = f.rays && f.blur_radius > 0 && !f.half;
    const int finish_rays = f.rays && !rays_in_blur && !f.half, finish_lum = f.luminance != 0;
    if (s == OBS_OK)
        s = obs__blur_program(ctx, 0, f.blur_radius, err);
    if (s == OBS_OK)
        s = obs__blur_program(ctx, rays_in_blur, f.blur_radius, err);
    if (s == OBS_OK)
        s = build_finish_program(ctx, finish_rays, finish_lum, err);
    if (s == OBS_OK)
        s = build_prep_program(ctx, &f, err);
    if (s != OBS_OK)
        return s;
    s = ensure_targets(ctx, &ctx->tg, f.width, f.height, err);
    if (s == OBS_OK && f.half)
        s = ensure_targets(ctx, &ctx->tg_half, hf.width, hf.height, err);
    obs__targets *t = &ctx->tg;
    obs__targets *at = f.half ? &ctx->tg_half : t;
    /* colour: for the composite, luminance sensitivity (4.3), bleeding (4.7) */
    int has_color = gb->color.data != NULL &&
                    ((outputs & OBS_OUTPUT_COMPOSITE) || f.luminance || f.bleed_step);
    if (s == OBS_OK)
        s = need_frame_targets(ctx, &f, t, at, has_color, outputs, err);
    if (s == OBS_OK) /* the frame's values, read by every pass (common.glsl) */
        s = obs__frame_block_bind(ctx, &f, err);
    if (s != OBS_OK)
        return s;
    s = obs__alloc_result(out, f.width, f.height, outputs, err);
    if (s != OBS_OK)
        return s;

    int w = f.width, h = f.height, aw = af->width, ah = af->height;
    pass_begin(ctx, OBS_PASS_UPLOAD, &ran);
    upload(t->tex_depth, &gb->depth, w, h, GL_RED);
    if (!f.reconstruct_normals)
        upload(t->tex_normal, &gb->normal, w, h, GL_RGB);
    if (has_color)
        upload(t->tex_color, &gb->color, w, h, GL_RGBA);
    pass_end(ctx);

    /* prep pass; ao_resolution half: straight to the half planes, one
     * whole pixel of each 2x2 block (prep.frag.glsl, OBS_HALF), then the
     * half frame's block for the passes at that size */
    pass_begin(ctx, f.half ? OBS_PASS_DOWNSAMPLE : OBS_PASS_PREP, &ran);
    GLuint prog = ctx->prog.prep[f.half != 0][prep_index(&f)];
    glUseProgram(prog);
    bind_img(prog, "u_depth", 0, t->tex_depth, GL_R32F);
    bind_img(prog, "u_normal", 1, t->tex_normal, GL_RGBA32F);
    draw(ctx, at->fbo_prep, aw, ah);
    pass_end(ctx);
    if (f.half) {
        s = obs__frame_block_bind(ctx, &hf, err);
        if (s != OBS_OK) {
            obs_result_free(out);
            return s;
        }
    }

    /* culling pre-pass (section 4.2): 8-sample AO at 1/8 resolution */
    if (f.culling) {
        pass_begin(ctx, OBS_PASS_CULL, &ran);
        prog = ctx->prog.cull[f.range_check != 0];
        glUseProgram(prog);
        bind_prep_planes(prog, at);
        draw(ctx, at->fbo_cull, af->cull_w, af->cull_h);
        pass_end(ctx);
    }

    /* AO pass */
    pass_begin(ctx, OBS_PASS_AO, &ran);
    if (method->glsl) { /* a comparison method in place of VAO */
        prog = use_method_program(ctx, method, af, at);
    } else {
        prog = ctx->prog.vao[ao_variant(&f)];
        glUseProgram(prog);
        bind_prep_planes(prog, at);
        /* section 4.2: the pre-pass result, read at the pixel corners */
        bind_img(prog, "u_cull", 4, at->tex_cull, GL_R32F);
        /* section 4.7: colour bleeding reads the colour at the samples */
        bind_img(prog, "u_color", 3, t->tex_color, GL_RGBA32F);
    }
    /* the debug outputs go to their textures only when asked for */
    const GLenum vao_bufs[] = {
        GL_COLOR_ATTACHMENT0,
        (outputs & OBS_OUTPUT_SAMPLE_COUNT) ? GL_COLOR_ATTACHMENT1 : GL_NONE,
        (outputs & OBS_OUTPUT_CULL_MASK) ? GL_COLOR_ATTACHMENT2 : GL_NONE,
        f.bleed_step ? GL_COLOR_ATTACHMENT3 : GL_NONE};
    glBindFramebuffer(GL_FRAMEBUFFER, at->fbo_vao);
    glDrawBuffers(4, vao_bufs);
    /* the pass whose cost grows with the samples: in bands against the
     * deadline (obs_ctx_set_deadline) */
    s = obs__gl_draw_banded(ctx->dev.vao, aw, ah, t_run, ctx->deadline_ms, "AO", err);
    pass_end(ctx);
    if (s != OBS_OK) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glUseProgram(0);
        ctx->times_valid = 0; /* no times for a frame cut short */
        obs_result_free(out);
        return s;
    }

    /* low-pass filter (section 4.6): ao -> blur along x -> ao along y */
    if (f.blur_radius > 0) {
        pass_begin(ctx, OBS_PASS_BLUR, &ran);
        for (int pass = 0; pass < 2; pass++) { /* along x, then along y */
            prog = ctx->prog.blur[pass ? rays_in_blur : 0][f.blur_radius];
            glUseProgram(prog);
            bind_img(prog, "u_ao", 0, pass ? at->tex_blur : at->tex_ao, GL_RG32F);
            glUniform2i(glGetUniformLocation(prog, "u_dir"), !pass, pass);
            if (!pass) {
                const GLenum blur_bufs[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
                glBindFramebuffer(GL_FRAMEBUFFER, at->fbo_blur);
                glDrawBuffers(2, blur_bufs);
            }
            draw(ctx, pass ? at->fbo_ao : at->fbo_blur, aw, ah);
        }
        pass_end(ctx);
    }

    /* ao_resolution half: the joint bilateral upsample (up.frag.glsl)
     * into the full-size AO, under the full frame's block again */
    if (f.half) {
        s = obs__frame_block_bind(ctx, &f, err);
        if (s != OBS_OK) {
            obs_result_free(out);
            return s;
        }
        pass_begin(ctx, OBS_PASS_UPSAMPLE, &ran);
        prog = ctx->prog.up[f.rays != 0][prep_index(&f)];
        glUseProgram(prog);
        bind_img(prog, "u_depth", 0, t->tex_depth, GL_R32F);
        bind_img(prog, "u_normal", 1, t->tex_normal, GL_RGBA32F);
        bind_img(prog, "u_hnormal", 3, at->tex_vnormal, GL_RGBA32F);
        bind_img(prog, "u_hao", 4, at->tex_ao, GL_RG32F);
        glUniform2i(glGetUniformLocation(prog, "u_half_size"), aw, ah);
        draw(ctx, t->fbo_ao, w, h);
        pass_end(ctx);
    }

    /* the finishing pass, after the blur (luminance.frag.glsl): the
     * conversion of ao_definition rays when there was no blur to do it,
     * luminance sensitivity (section 4.3, eq 3); ao -> tex_blur, free once
     * the blur is done */
    GLuint ao_tex = t->tex_ao, ao_fbo = t->fbo_ao;
    if (finish_rays || finish_lum) {
        pass_begin(ctx, OBS_PASS_FINISH, &ran);
        prog = ctx->prog.finish[2 * finish_rays + finish_lum];
        glUseProgram(prog);
        bind_tex(prog, "u_ao", 0, t->tex_ao);
        bind_tex(prog, "u_color", 1, t->tex_color);
        const GLenum lum_bufs[] = {
            GL_COLOR_ATTACHMENT0,
            (outputs & OBS_OUTPUT_LUMINANCE) ? GL_COLOR_ATTACHMENT1 : GL_NONE};
        glBindFramebuffer(GL_FRAMEBUFFER, t->fbo_blur);
        glDrawBuffers(2, lum_bufs);
        draw(ctx, t->fbo_blur, w, h);
        ao_tex = t->tex_blur;
        ao_fbo = t->fbo_blur;
        pass_end(ctx);
    }

    if (outputs & OBS_OUTPUT_COMPOSITE) {
        pass_begin(ctx, OBS_PASS_COMPOSITE, &ran);
        prog = ctx->prog.composite;
        glUseProgram(prog);
        bind_tex(prog, "u_ao", 0, ao_tex);
        bind_tex(prog, "u_color", 1, t->tex_color);
        bind_tex(prog, "u_bleed", 2, t->tex_bleed);
        glUniform1i(glGetUniformLocation(prog, "u_has_color"), has_color);
        glUniform1i(glGetUniformLocation(prog, "u_has_bleed"), f.bleed_step > 0);
        draw(ctx, t->fbo_composite, w, h);
        pass_end(ctx);
    }
    pass_begin(ctx, OBS_PASS_READBACK, &ran);
    if (outputs & OBS_OUTPUT_COMPOSITE)
        read_back(t->fbo_composite, GL_COLOR_ATTACHMENT0, w, h, GL_RGBA, out->composite.data);
    if (outputs & OBS_OUTPUT_AO)
        read_back(ao_fbo, GL_COLOR_ATTACHMENT0, w, h, GL_RED, out->ao.data);
    if (outputs & OBS_OUTPUT_SAMPLE_COUNT)
        read_back(t->fbo_vao, GL_COLOR_ATTACHMENT1, w, h, GL_RED, out->sample_count.data);
    if (outputs & OBS_OUTPUT_CULL_MASK)
        read_back(t->fbo_vao, GL_COLOR_ATTACHMENT2, w, h, GL_RED, out->cull_mask.data);
    if (outputs & OBS_OUTPUT_BLEED) {
        if (f.bleed_step)
            read_back(t->fbo_vao, GL_COLOR_ATTACHMENT3, w, h, GL_RGB, out->bleed.data);
        else /* bleeding off: the neutral term, no GL work */
            for (size_t i = 0; i < (size_t)w * h * 3; i++)
                out->bleed.data[i] = 1.0f;
    }
    if (outputs & OBS_OUTPUT_LUMINANCE) {
        if (f.luminance)
            read_back(t->fbo_blur, GL_COLOR_ATTACHMENT1, w, h, GL_RED, out->luminance.data);
        else /* off: the factor is 1, no GL work */
            for (size_t i = 0; i < (size_t)w * h; i++)
                out->luminance.data[i] = 1.0f;
    }
    pass_end(ctx);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    collect_times(ctx, ran);

    s = obs__gl_check("running the AO passes", err);
    if (s != OBS_OK)
        obs_result_free(out);
    return s;
}
