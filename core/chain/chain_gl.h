/* The chain's GL objects kept in the context between frames: the programs
 * (built on first use, kept) and the per-resolution textures and
 * framebuffers (kept while frames keep their size).  Not installed. */
#ifndef OBSCURA_CHAIN_GL_H
#define OBSCURA_CHAIN_GL_H

#include "chain/frame.h"
#include "gl/gl.h"

#define OBS__AO_VARIANTS 16  /* 4 switches of the AO pass, compiled in or out */

typedef struct obs__programs {
    /* [OBS_HALF: ao_resolution half's prep straight to half size][
     * OBS__DEPTH_MODES * (normals derived from depth) + depth mode - 1];
     * built on first use */
    GLuint prep[2][2 * OBS__DEPTH_MODES];
    GLuint vao[OBS__AO_VARIANTS]; /* AO pass by switches compiled in (run_gl.c: AO_*) */
    GLuint cull[2];               /* culling pre-pass without, with the range check */
    GLuint composite;
    /* ao_resolution half's upsample [OBS_RAYS][as prep's second index]
     * (it derives its own pixel's depth and normal as prep does) */
    GLuint up[2][2 * OBS__DEPTH_MODES];
    GLuint finish[4]; /* 2 * (ao_definition rays) + luminance: OBS_RAYS, OBS_LUMINANCE */
    /* by (the vertical pass with ao_definition rays' conversion: OBS_RAYS)
     * and blur_radius (BLUR_RADIUS); built on first use */
    GLuint blur[2][OBS_MAX_BLUR + 1];
    GLuint method[OBS_METHOD_COUNT]; /* a comparison method's AO pass, by obs_method (first use) */
} obs__programs;

typedef struct obs__targets {
    int width, height;          /* 0: none allocated yet */
    unsigned long long bytes;   /* the textures' storage (obs_ctx_kept_bytes) */
    GLuint tex_depth, tex_normal, tex_color;  /* inputs */
    GLuint tex_viewpos, tex_vnormal;          /* prep outputs */
    GLuint tex_dz;                            /* prep: planar depth, view normal z (RG) */
    GLuint tex_ao, tex_composite;             /* results */
    GLuint tex_blur;                          /* between the two blur passes */
    GLuint tex_count;                         /* debug: samples per pixel (4.1) */
    GLuint tex_cull;                          /* culling pre-pass AO, 1/8 size (4.2) */
    GLuint tex_cullmask;                      /* debug: culling candidates (4.2) */
    GLuint tex_bleed;                         /* colour-bleed term (4.7), RGBA */
    GLuint tex_lumfactor;                     /* debug: factor of eq 3 (4.3) */
    GLuint fbo_prep, fbo_ao, fbo_composite;  /* fbo_prep: viewpos + vnormal + dz */
    GLuint fbo_blur;                          /* tex_blur + tex_lumfactor */
    GLuint fbo_vao;                           /* AO pass: tex_ao + tex_count + tex_cullmask + tex_bleed */
    GLuint fbo_cull;                          /* culling pre-pass: tex_cull */
} obs__targets;

/* Builds, on its first use, the blur program of half-width radius
 * (section 4.6; rays 1: the vertical pass that converts for
 * ao_definition rays) into ctx->prog.blur[rays][radius] (run_gl.c; the
 * deep pass, deep_gl.c, blurs with it too). */
obs_status obs__blur_program(obs_ctx *ctx, int rays, int radius, char err[OBS_ERR_LEN]);

/* Deletes the chain's textures, framebuffers and programs (run_gl.c);
 * the context is current.  With prog NULL the programs stay. */
void obs__chain_release(obs__programs *prog, obs__targets *tg);

#endif
