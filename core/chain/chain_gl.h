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
    GLuint vao[OBS__AO_VARIANTS]; /* AO pass by switches compiled in (programs_gl.c: AO_*) */
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
    GLuint tex_mask_w, tex_mask_id;           /* object masks: occluders weight, object ID */
    GLuint tex_bent;                          /* bent normal sums (view space), RGBA */
    GLuint fbo_prep, fbo_ao, fbo_composite;  /* fbo_prep: viewpos + vnormal + dz */
    GLuint fbo_blur;                          /* tex_blur + tex_lumfactor */
    GLuint fbo_vao;                           /* AO pass: tex_ao + tex_count + tex_cullmask + tex_bleed + tex_bent */
    GLuint fbo_cull;                          /* culling pre-pass: tex_cull */
} obs__targets;

/* The programs (programs_gl.c), each built on its first use into g.
 * obs__prog_vao: the AO pass (pre 0) or the culling pre-pass (pre 1) of
 * switch variant v (obs__ao_variant: bits of g->vao's index); _finish:
 * the finishing pass with ao_definition rays' conversion and luminance
 * sensitivity compiled in or out; _prep: the prep pass (or the
 * downsample, f->half) of f's depth mode and normals, g->prep[half][
 * obs__prep_index(f)]; _up: ao_resolution half's upsample; _method: a
 * comparison method's AO pass (nothing for vaopp and vao). */
unsigned obs__ao_variant(const obs__frame *f);
int obs__prep_index(const obs__frame *f);
struct obs__method;
obs_status obs__prog_vao(obs__programs *g, int pre, unsigned v, char err[OBS_ERR_LEN]);
obs_status obs__prog_composite(obs__programs *g, char err[OBS_ERR_LEN]);
obs_status obs__prog_finish(obs__programs *g, int rays, int lum, char err[OBS_ERR_LEN]);
obs_status obs__prog_prep(obs__programs *g, const obs__frame *f, char err[OBS_ERR_LEN]);
obs_status obs__prog_up(obs__programs *g, const obs__frame *f, char err[OBS_ERR_LEN]);
obs_status obs__prog_method(obs__programs *g, const struct obs__method *m, char err[OBS_ERR_LEN]);

/* The blur program of half-width radius (section 4.6; rays 1: the
 * vertical pass that converts for ao_definition rays) into
 * g->blur[rays][radius] (the deep pass, deep_gl.c, blurs with it too). */
obs_status obs__blur_program(obs__programs *g, int rays, int radius, char err[OBS_ERR_LEN]);

/* The targets (targets_gl.c).  obs__targets_ensure: what every frame of
 * w x h needs in t (the full-size set, or the half-size set of
 * ao_resolution half), kept while frames keep their size; _need: what
 * frame f needs beyond that, t the full set, at the set the AO runs at
 * (t, or the half set).  *created counts the textures and framebuffers
 * made (obs_ctx's gl_objects_created); log_ctx: where to log. */
obs_status obs__targets_ensure(obs_ctx *log_ctx, unsigned long *created, obs__targets *t, int w,
                               int h, char err[OBS_ERR_LEN]);
obs_status obs__targets_need(unsigned long *created, const obs__frame *f, obs__targets *t,
                             obs__targets *at, int has_color, unsigned outputs,
                             char err[OBS_ERR_LEN]);

/* Deletes the chain's textures, framebuffers and programs (targets_gl.c);
 * the context is current.  With prog NULL the programs stay. */
void obs__chain_release(obs__programs *prog, obs__targets *tg);

#endif
