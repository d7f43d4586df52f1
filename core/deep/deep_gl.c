/* obs_deep_run: the multi-layer AO of deep input on the GL context.  The
 * compressed nodes (OITAO III-B) are prepared as for the CPU twin
 * (deep_cpu.c: view position, normal, alpha, interval end), uploaded as
 * 2D array textures of m layers (RGBA32F: position + planar depth, normal
 * + alpha; R32F: the interval ends, with deep_intervals) and one fragment
 * pass (core/shaders/deep.frag.glsl) writes the
 * front node's AO and the blended AO, each beside the front node's
 * planar depth; with the blur on (VAO++ 4.6, as the flat chain: --blur,
 * --blur-radius) both are blurred by the flat chain's program
 * (blur.frag.glsl, without the rays conversion: the deep pass converts
 * each node's AO before the blend), the front node's depth as the edge
 * guide, as the CPU twin does with obs__blur.
 *
 * The program is built once per context; the array textures, the output
 * texture and its framebuffer are kept for the next frame of the same
 * size and node count (the daemon runs deep frames back to back), as the
 * flat chain keeps its targets (run_gl.c).
 *
 * With obs_ctx_set_timing the upload, the AO pass, the blur and the
 * read-back (OBS_PASS_UPLOAD, OBS_PASS_AO, OBS_PASS_BLUR,
 * OBS_PASS_READBACK) are timed on the host
 * between glFinish calls, not with GL_TIME_ELAPSED queries: Mesa's
 * llvmpipe ends a query that no draw follows at its next flush, so with
 * the node textures of the last frame reused the AO pass's whole cost
 * was reported as the upload's.  Finishing each stage costs a GPU its
 * overlap, which timing mode gives up anyway (it waits for the results). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "chain/chain_gl.h"
#include "chain/frame_gl.h"
#include "context.h"
#include "mask_apply.h"
#include "deep/deep_internal.h"
#include "gl/draw.h"
#include "methods/methods.h"
#include "obs_shaders.h"

static GLuint array_texture(obs_ctx *ctx, int w, int h, int m, GLenum format)
{
    GLuint t;
    glGenTextures(1, &t);
    ctx->gl_objects_created++;
    glBindTexture(GL_TEXTURE_2D_ARRAY, t);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, format, w, h, m);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

static void upload_layers(GLuint tex, int w, int h, int m, GLenum format, const float *data)
{
    glBindTexture(GL_TEXTURE_2D_ARRAY, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, w, h, m, format, GL_FLOAT, data);
}

/* Switches of the deep pass compiled in or out by defines (a SIMD
 * rasteriser runs both sides of a uniform branch): bits of the index of
 * ctx->deep.prog. */
enum {
    DEEP_HEMISPHERE = 1, /* OBS_DEEP_HEMISPHERE: method hemisphere's samples */
    DEEP_THIN = 2,       /* OBS_DEEP_THIN: thin hulls, OITAO eqs 2-4 */
    DEEP_RANGE = 4,      /* OBS_RANGE_CHECK: VAO++ 4.4, eq 4 */
    DEEP_RAYS = 8,       /* OBS_RAYS: ao_definition rays' conversion of the VAO nodes */
    DEEP_INTERVALS = 16, /* OBS_DEEP_INTERVALS: the nodes' intervals (deep_intervals) */
    DEEP_GTAO = 32,      /* OBS_DEEP_HORIZON with gtao.glsl: method gtao's horizon search */
    DEEP_HBAO = 64,      /* OBS_DEEP_HORIZON with hbao.glsl: method hbao's */
    DEEP_NODES = 128     /* OBS_DEEP_NODES: every node's AO stored (obs_deep_run_nodes) */
};

static unsigned deep_variant(const obs__deep_frame *df)
{
    return (df->f.method == OBS_METHOD_HEMISPHERE ? DEEP_HEMISPHERE : 0u) |
           (df->thin ? DEEP_THIN : 0u) | (df->f.range_check ? DEEP_RANGE : 0u) |
           (df->f.rays ? DEEP_RAYS : 0u) | (df->intervals || df->inside ? DEEP_INTERVALS : 0u) |
           (df->f.method == OBS_METHOD_GTAO ? DEEP_GTAO : 0u) |
           (df->f.method == OBS_METHOD_HBAO ? DEEP_HBAO : 0u);
}

/* A framebuffer writing the n textures; OBS_GL_ERROR when incomplete. */
static obs_status deep_fbo(obs_ctx *ctx, GLuint *fbo, const GLuint *tex, int n)
{
    GLenum bufs[2];
    glGenFramebuffers(1, fbo);
    ctx->gl_objects_created++;
    glBindFramebuffer(GL_FRAMEBUFFER, *fbo);
    for (int i = 0; i < n; i++) {
        bufs[i] = GL_COLOR_ATTACHMENT0 + (GLenum)i;
        glFramebufferTexture2D(GL_FRAMEBUFFER, bufs[i], GL_TEXTURE_2D, tex[i], 0);
    }
    glDrawBuffers(n, bufs);
    return glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE ? OBS_OK
                                                                              : OBS_GL_ERROR;
}

/* The flat chain's blur (blur.frag.glsl, no rays conversion) of the RG
 * plane tex in place, through tmp: along x into tmp, along y back. */
static void blur_plane(obs_ctx *ctx, GLuint prog, const obs__deep_targets *t, GLuint tex,
                       GLuint fbo)
{
    glUseProgram(prog);
    for (int pass = 0; pass < 2; pass++) {
        glBindImageTexture(0, pass ? t->tex_tmp : tex, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RG32F);
        glUniform1i(glGetUniformLocation(prog, "u_ao"), 0);
        glUniform2i(glGetUniformLocation(prog, "u_dir"), pass ? 0 : 1, pass ? 1 : 0);
        glBindFramebuffer(GL_FRAMEBUFFER, pass ? fbo : t->fbo_tmp);
        glViewport(0, 0, t->width, t->height);
        glBindVertexArray(ctx->dev.vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
}

/* The program of variant v, and the targets for w x h with m nodes: kept
 * from the last frame when they match. */
static obs_status ensure_deep(obs_ctx *ctx, unsigned v, int w, int h, int m,
                              char err[OBS_ERR_LEN])
{
    static const char glsl_version[] = "#version 430 core\n";
    obs__deep_targets *t = &ctx->deep;
    obs_status s;
    if (!t->prog[v]) {
        char defs[256];
        snprintf(defs, sizeof defs,
                 "#define OBS_DEEP_HEMISPHERE %d\n#define OBS_DEEP_THIN %d\n"
                 "#define OBS_RANGE_CHECK %d\n#define OBS_RAYS %d\n#define OBS_DEEP_INTERVALS %d\n"
                 "#define OBS_DEEP_HORIZON %d\n#define OBS_DEEP_NODES %d\n",
                 (v & DEEP_HEMISPHERE) != 0, (v & DEEP_THIN) != 0, (v & DEEP_RANGE) != 0,
                 (v & DEEP_RAYS) != 0, (v & DEEP_INTERVALS) != 0,
                 (v & (DEEP_GTAO | DEEP_HBAO)) != 0, (v & DEEP_NODES) != 0);
        /* method hemisphere's estimator, or method.glsl (radius_px) and
         * gtao's or hbao's, come after the pass, which defines how they
         * read the nodes (HS_NODE, GT_NODE, HB_NODE in deep.frag.glsl) */
        const int horizon = (v & (DEEP_GTAO | DEEP_HBAO)) != 0;
        const char *hs[] = {glsl_version, defs, obs__shader_common, obs__shader_deep_frag,
                            obs__shader_hemisphere};
        const char *hz[] = {glsl_version,          defs, obs__shader_common, obs__shader_method,
                            obs__shader_deep_frag, (v & DEEP_GTAO) ? obs__shader_gtao
                                                                   : obs__shader_hbao};
        const char *const *src = horizon ? hz : hs;
        const int parts = horizon ? 6 : (v & DEEP_HEMISPHERE) ? 5 : 4;
        if ((s = obs__gl_program("deep", obs__shader_fullscreen_vert, src, parts, &t->prog[v], err)) !=
            OBS_OK) {
            t->prog[v] = 0;
            return s;
        }
    }
    if (t->width == w && t->height == h && t->m == m)
        return OBS_OK;
    obs__deep_release(&ctx->deep, 0);
    t->tex_pos = array_texture(ctx, w, h, m, GL_RGBA32F);
    t->tex_nrm = array_texture(ctx, w, h, m, GL_RGBA32F);
    t->tex_end = array_texture(ctx, w, h, m, GL_R32F);
    /* two RGBA32F arrays and one R32F array of m layers and three RG32F
     * planes (the object masks' array is made by the first frame with
     * masks) */
    t->bytes = (unsigned long long)w * (unsigned long long)h *
               ((16ull * 2ull + 4ull) * (unsigned)m + 3ull * 8ull);
    GLuint *planes[] = {&t->tex_front, &t->tex_blend, &t->tex_tmp};
    for (int i = 0; i < 3; i++) {
        glGenTextures(1, planes[i]);
        ctx->gl_objects_created++;
        glBindTexture(GL_TEXTURE_2D, *planes[i]);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RG32F, w, h);
    }
    const GLuint pass_out[] = {t->tex_front, t->tex_blend};
    s = deep_fbo(ctx, &t->fbo, pass_out, 2);
    if (s == OBS_OK)
        s = deep_fbo(ctx, &t->fbo_front, &t->tex_front, 1);
    if (s == OBS_OK)
        s = deep_fbo(ctx, &t->fbo_blend, &t->tex_blend, 1);
    if (s == OBS_OK)
        s = deep_fbo(ctx, &t->fbo_tmp, &t->tex_tmp, 1);
    s = s == OBS_OK ? obs__gl_check("allocating deep targets", err)
                    : obs__fail(err, OBS_GL_ERROR, "deep AO framebuffer incomplete");
    if (s != OBS_OK) {
        obs__deep_release(&ctx->deep, 0);
        return s;
    }
    t->width = w;
    t->height = h;
    t->m = m;
    obs__log(ctx, OBS_LOG_DEBUG, "allocated deep targets for %dx%d, %d nodes", w, h, m);
    return OBS_OK;
}

/* Starts stage p when timing is on: the GL work queued before it is done
 * first. */
static void stage_begin(obs_ctx *ctx, double *t0)
{
    if (!ctx->timing)
        return;
    glFinish();
    *t0 = obs__now_ms();
}

static void stage_end(obs_ctx *ctx, obs_pass p, double t0, obs_pass_times *t)
{
    if (!ctx->timing)
        return;
    glFinish();
    t->ms[p] = obs__now_ms() - t0;
}

/* obs_deep_run, and with nodes not NULL obs_deep_run_nodes. */
static obs_status deep_run(obs_ctx *ctx, const obs_deep_image *d, const obs_params *params,
                           obs_deep_result *out, obs_deep_ao *nodes, char err[OBS_ERR_LEN])
{
    obs__deep_frame df;
    obs_pass_times times;
    double t0 = 0.0;
    const double t_run = obs__now_ms(); /* obs_ctx_set_deadline counts from here */
    float *node_ao = NULL;               /* nodes: the pass's per-node planes */
    obs_status s;

    if (!ctx || !out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_deep_run: NULL argument");
    memset(out, 0, sizeof *out);
    if (nodes)
        memset(nodes, 0, sizeof *nodes);
    if ((s = obs__gl_device_bind(&ctx->dev, err)) != OBS_OK)
        return s;
    ctx->times_valid = 0;
    if ((s = obs__deep_frame_setup(d, params, &df, err)) != OBS_OK)
        return s;
    const obs__frame *f = &df.f;
    const int w = f->width, h = f->height;
    if ((s = obs__deep_result_alloc(out, w, h, err)) != OBS_OK)
        goto fail;
    const unsigned variant = deep_variant(&df) | (nodes ? DEEP_NODES : 0u);
    if ((s = ensure_deep(ctx, variant, w, h, df.m, err)) != OBS_OK)
        goto fail;
    if ((s = obs__blur_program(&ctx->prog, 0, f->blur_radius, err)) != OBS_OK)
        goto fail;
    /* the frame's values, read by the pass (common.glsl's Frame block) */
    if ((s = obs__frame_block_bind(ctx, f, err)) != OBS_OK)
        goto fail;
    const obs__deep_targets *t = &ctx->deep;
    const GLuint prog = t->prog[variant];
    for (int p = 0; p < OBS_PASS_COUNT; p++)
        times.ms[p] = -1.0;

    stage_begin(ctx, &t0);
    upload_layers(t->tex_pos, w, h, df.m, GL_RGBA, df.pos);
    upload_layers(t->tex_nrm, w, h, df.m, GL_RGBA, df.nrm);
    if (df.intervals || df.inside)
        upload_layers(t->tex_end, w, h, df.m, GL_RED, df.end);
    /* object masks: each node's weight and object, interleaved, in an
     * RG32F array made on the first frame with masks and kept with the
     * others */
    if (f->mask_on && !t->tex_mask) {
        ctx->deep.tex_mask = array_texture(ctx, w, h, df.m, GL_RG32F);
        ctx->deep.bytes += (unsigned long long)w * (unsigned long long)h * 8ull * (unsigned)df.m;
    }
    if (f->mask_on) {
        const size_t nn = (size_t)w * (size_t)h * (size_t)df.m;
        float *rg = malloc(nn * 2 * sizeof *rg);
        if (!rg) {
            s = obs__fail(err, OBS_NO_MEMORY, "deep object masks of %dx%dx%d", w, h, df.m);
            goto fail;
        }
        for (size_t i = 0; i < nn; i++) {
            rg[2 * i] = f->mask_occl ? f->mask_occl[i] : 1.0f;
            rg[2 * i + 1] = f->mask_id ? f->mask_id[i] : 0.0f;
        }
        upload_layers(t->tex_mask, w, h, df.m, GL_RG, rg);
        free(rg);
    }
    /* the deep AO out: an R32F array made on the first frame that asks */
    if (nodes && !t->tex_nodes) {
        ctx->deep.tex_nodes = array_texture(ctx, w, h, df.m, GL_R32F);
        ctx->deep.bytes += (unsigned long long)w * (unsigned long long)h * 4ull * (unsigned)df.m;
    }
    stage_end(ctx, OBS_PASS_UPLOAD, t0, &times);

    stage_begin(ctx, &t0);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_m"), df.m);
    glUniform1i(glGetUniformLocation(prog, "u_multi"), df.multi);
    /* the method's own (method hemisphere's kernel; none for vaopp, vao) */
    obs__gl_set_uniforms(prog, f, obs__method_get(f->method)->uniforms);
    /* the node planes are read through images (imageLoad), as the planes
     * of run_gl.c are: cheaper than texelFetch on llvmpipe */
    glBindImageTexture(0, t->tex_pos, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    glUniform1i(glGetUniformLocation(prog, "u_lpos"), 0);
    glBindImageTexture(1, t->tex_nrm, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    glUniform1i(glGetUniformLocation(prog, "u_lnrm"), 1);
    if (df.intervals || df.inside) {
        glBindImageTexture(2, t->tex_end, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
        glUniform1i(glGetUniformLocation(prog, "u_lend"), 2);
    }
    /* object masks: node_weight() in deep.frag.glsl */
    glUniform1i(glGetUniformLocation(prog, "u_deep_mask"),
                (f->mask_occl ? 1 : 0) | (f->mask_id ? 2 : 0));
    if (f->mask_on) {
        glBindImageTexture(3, t->tex_mask, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RG32F);
        glUniform1i(glGetUniformLocation(prog, "u_lmask"), 3);
    }
    if (nodes) {
        glBindImageTexture(4, t->tex_nodes, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
        glUniform1i(glGetUniformLocation(prog, "u_lao"), 4);
    }
    s = obs__gl_draw_banded(ctx->dev.vao, w, h, t_run, ctx->deadline_ms, "deep AO", err);
    stage_end(ctx, OBS_PASS_AO, t0, &times);
    if (s != OBS_OK) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        goto fail;
    }

    /* the low-pass filter (VAO++ 4.6) of both planes, as the flat chain's */
    if (f->blur_radius > 0) {
        stage_begin(ctx, &t0);
        const GLuint blur = ctx->prog.blur[0][f->blur_radius];
        blur_plane(ctx, blur, t, t->tex_front, t->fbo_front);
        blur_plane(ctx, blur, t, t->tex_blend, t->fbo_blend);
        stage_end(ctx, OBS_PASS_BLUR, t0, &times);
    }

    stage_begin(ctx, &t0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo_front);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, w, h, GL_RED, GL_FLOAT, out->ao_front.data);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo_blend);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, w, h, GL_RED, GL_FLOAT, out->ao_blend.data);
    if (nodes) {
        /* every node's AO, the m planes as the frame's (k * npx + i); the
         * layers past a pixel's last node are not read */
        node_ao = malloc((size_t)w * (size_t)h * (size_t)df.m * sizeof *node_ao);
        if (!node_ao) {
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            s = obs__fail(err, OBS_NO_MEMORY, "deep AO nodes of %dx%dx%d", w, h, df.m);
            goto fail;
        }
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        glBindTexture(GL_TEXTURE_2D_ARRAY, t->tex_nodes);
        glGetTexImage(GL_TEXTURE_2D_ARRAY, 0, GL_RED, GL_FLOAT, node_ao);
    }
    stage_end(ctx, OBS_PASS_READBACK, t0, &times);
    glActiveTexture(GL_TEXTURE0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if ((s = obs__gl_check("deep AO pass", err)) != OBS_OK)
        goto fail;
    if (nodes && (s = obs__deep_ao_pack(d, &df, node_ao, nodes, err)) != OBS_OK)
        goto fail;
    if (ctx->timing) {
        times.total_ms = times.ms[OBS_PASS_UPLOAD] + times.ms[OBS_PASS_AO] +
                         (times.ms[OBS_PASS_BLUR] > 0.0 ? times.ms[OBS_PASS_BLUR] : 0.0) +
                         times.ms[OBS_PASS_READBACK];
        ctx->times = times;
        ctx->times_valid = 1;
    }
    obs__receivers_apply_deep(d, out); /* object masks: receivers */
    obs__deep_composite(d, out);
fail:
    free(node_ao);
    obs__deep_frame_free(&df);
    if (s != OBS_OK)
        obs_deep_result_free(out);
    return s;
}

obs_status obs_deep_run(obs_ctx *ctx, const obs_deep_image *d, const obs_params *params,
                        obs_deep_result *out, char err[OBS_ERR_LEN])
{
    return deep_run(ctx, d, params, out, NULL, err);
}

obs_status obs_deep_run_nodes(obs_ctx *ctx, const obs_deep_image *d, const obs_params *params,
                              obs_deep_result *out, obs_deep_ao *nodes, char err[OBS_ERR_LEN])
{
    if (!nodes)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_deep_run_nodes: no nodes output");
    return deep_run(ctx, d, params, out, nodes, err);
}
