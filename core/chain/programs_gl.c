/* The chain's GL programs, each built on its first use and kept in the
 * context (obs__programs, chain_gl.h): the pass kernels (passes_gl.c) and the
 * deep pass (deep_gl.c) ask for the ones a frame needs. */
#include <stdio.h>

#include "chain/chain_gl.h"
#include "methods/methods.h"
#include "obs_shaders.h"

static const char glsl_version[] = "#version 430 core\n";
/* Switches of the AO pass compiled in or out, by defines, instead of read
 * from uniforms: a uniform branch does not skip its body on a SIMD
 * rasteriser such as llvmpipe, which runs both sides for every pixel (the
 * bleed code cost the AO pass a third of its time with bleeding off;
 * bench/RESULTS.md).  Bits of the index of g->vao; each program is
 * built on its first use. */
enum {
    AO_BLEED = 1,    /* OBS_BLEED: colour bleeding (section 4.7) */
    AO_ADAPTIVE = 2, /* OBS_ADAPTIVE: adaptive sampling (section 4.1) */
    AO_CULLING = 4,  /* OBS_CULLING: the culling test (section 4.2) */
    AO_RANGE = 8     /* OBS_RANGE_CHECK: the depth range check (section 4.4) */
};

unsigned obs__ao_variant(const obs__frame *f)
{
    return (f->bleed_step ? AO_BLEED : 0u) | (f->adaptive ? AO_ADAPTIVE : 0u) |
           (f->culling ? AO_CULLING : 0u) | (f->range_check ? AO_RANGE : 0u);
}

/* The AO program (pre 0) or the culling pre-pass's (pre 1; its variants
 * differ only in AO_RANGE) of the given variant, built on its first use. */
obs_status obs__prog_vao(obs__programs *g, int pre, unsigned v, char err[OBS_ERR_LEN])
{
    GLuint *prog = pre ? &g->cull[(v & AO_RANGE) != 0] : &g->vao[v];
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

obs_status obs__prog_composite(obs__programs *g, char err[OBS_ERR_LEN])
{
    if (g->composite)
        return OBS_OK;
    const char *comp[] = {glsl_version, obs__shader_composite_frag};
    return obs__gl_program("composite", obs__shader_fullscreen_vert, comp, 2, &g->composite, err);
}

/* The finishing pass (luminance.frag.glsl) with the conversion of
 * ao_definition rays (OBS_RAYS) and luminance sensitivity (OBS_LUMINANCE)
 * compiled in or out, built on its first use: prog.finish[2 * rays + lum]. */
obs_status obs__prog_finish(obs__programs *g, int rays, int lum, char err[OBS_ERR_LEN])
{
    GLuint *prog = &g->finish[2 * rays + lum];
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
 * (OBS_HALF), built on its first use: g->prep[half][obs__prep_index(f)].
 * The same defines select ao_resolution half's upsample, which derives its
 * own pixel's depth and normal with prep.glsl. */
int obs__prep_index(const obs__frame *f)
{
    int mode = f->depth_mode >= OBS_DEPTH_PLANAR && f->depth_mode <= OBS_DEPTH_NORMALIZED
                   ? f->depth_mode
                   : OBS_DEPTH_PLANAR;
    return OBS__DEPTH_MODES * (f->reconstruct_normals != 0) + mode - OBS_DEPTH_PLANAR;
}

/* A program of the prep family (prep.glsl with frag): variant k's
 * defines, then `flag` (OBS_HALF or OBS_RAYS), built into *prog. */
static obs_status prep_family(const char *name, int k, const char *flag, const char *frag,
                              GLuint *prog, char err[OBS_ERR_LEN])
{
    char defs[80];
    snprintf(defs, sizeof defs, "#define OBS_RECONSTRUCT %d\n#define OBS_DEPTH_MODE %d\n",
             k / OBS__DEPTH_MODES, k % OBS__DEPTH_MODES + OBS_DEPTH_PLANAR);
    const char *src[] = {glsl_version, defs, flag, obs__shader_common, obs__shader_prep, frag};
    return obs__gl_program(name, obs__shader_fullscreen_vert, src, 6, prog, err);
}

obs_status obs__prog_prep(obs__programs *g, const obs__frame *f, char err[OBS_ERR_LEN])
{
    int k = obs__prep_index(f), half = f->half != 0;
    if (g->prep[half][k])
        return OBS_OK;
    const char *name = half ? (k / OBS__DEPTH_MODES ? "prep to half size (normals from depth)"
                                                    : "prep to half size")
                            : (k / OBS__DEPTH_MODES ? "prep (normals from depth)" : "prep");
    return prep_family(name, k, half ? "#define OBS_HALF 1\n" : "#define OBS_HALF 0\n",
                       obs__shader_prep_frag, &g->prep[half][k], err);
}

/* The blur of half-width radius (section 4.6), built on its first use:
 * the radius is a compile-time constant, so the taps' loop is unrolled;
 * rays 1 is the vertical pass that also converts its result
 * (ao_definition rays, OBS_RAYS in blur.frag.glsl). */
obs_status obs__blur_program(obs__programs *g, int rays, int radius, char err[OBS_ERR_LEN])
{
    if (radius <= 0 || g->blur[rays][radius])
        return OBS_OK;
    char def[64];
    snprintf(def, sizeof def, "#define BLUR_RADIUS %d\n#define OBS_RAYS %d\n", radius, rays);
    const char *src[] = {glsl_version, def, obs__shader_common, obs__shader_blur_frag};
    return obs__gl_program("blur", obs__shader_fullscreen_vert, src, 4,
                           &g->blur[rays][radius], err);
}

/* The AO program of a comparison method (parameter method), built on its
 * first use: common.glsl, method.glsl, the method's file (its row of the
 * method table), method.frag.  Nothing for vaopp and vao. */
obs_status obs__prog_method(obs__programs *g, const struct obs__method *m, char err[OBS_ERR_LEN])
{
    if (!m->glsl || g->method[m->id])
        return OBS_OK;
    const char *src[] = {glsl_version, obs__shader_common, obs__shader_method, m->glsl,
                         obs__shader_method_frag};
    return obs__gl_program(m->name, obs__shader_fullscreen_vert, src, 5, &g->method[m->id],
                           err);
}

/* ao_resolution half's upsample (up.frag.glsl), built on its first use;
 * the downsample is the prep pass's OBS_HALF variant. */
obs_status obs__prog_up(obs__programs *g, const obs__frame *f, char err[OBS_ERR_LEN])
{
    int k = obs__prep_index(f), rays = f->rays != 0;
    if (g->up[rays][k])
        return OBS_OK;
    return prep_family("upsample", k, rays ? "#define OBS_RAYS 1\n" : "#define OBS_RAYS 0\n",
                       obs__shader_up_frag, &g->up[rays][k], err);
}
