/* The table of AO methods (parameter `method`): one row per method, the
 * one place that says what a method is made of.  Adding a method is a
 * row here plus its files (its state and functions in core/methods/<name>.h,
 * a CPU twin in core/methods/<name>.c, a GLSL file in core/shaders/
 * defining method_ao()); tests/unit/core/test_methods.c
 * checks the rows against the parameter's choices.  No GL here: the
 * uniforms are described as data, set by the GL pass (run_gl.c,
 * deep_gl.c), so the CPU twin links without GL.  Not installed. */
#ifndef OBSCURA_METHODS_H
#define OBSCURA_METHODS_H

#include "chain/frame.h"
#include "gl/uniform.h"

#define OBS__METHOD_MAX_UNIFORMS 8

typedef struct obs__method {
    obs_method id;
    const char *name;     /* as the parameter's choices spell it */
    /* The method's AO pass: NULL for vaopp and vao, which run the chain's
     * own (vao.frag.glsl); else the GLSL file defining method_ao(),
     * compiled between method.glsl and method.frag.glsl. */
    const char *glsl;
    /* Fills the method's own values (f->ms, its header's state type)
     * from the resolved parameters (NULL: nothing of its own). */
    void (*setup)(const obs_params *p, obs__frame *f);
    /* The CPU twin of method_ao(): the AO of the point p with normal n at
     * pixel (x, y), *count the samples taken (NULL for vaopp and vao). */
    float (*pixel)(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                   const float p[4], const float n[3], int *count);
    /* Samples a pixel takes at most, from the resolved parameters (the
     * measure of obs_frame_cost). */
    int (*samples_per_pixel)(const obs_params *p);
    obs__uniform uniforms[OBS__METHOD_MAX_UNIFORMS]; /* ends at a NULL name */
    int deep; /* 1: runs on deep input too (core/deep: OITAO's GetAO) */
    /* The method's bent normal (OBS_OUTPUT_BENT): pixel's twin that also
     * sums the view-space bent normal of its samples into bent[3] (not
     * normalised; every comparison method has one, its GLSL twin sums
     * g_bent in method.glsl). */
    float (*pixel_bent)(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                        const float p[4], const float n[3], int *count, float bent[3]);
} obs__method;

/* Resolves one frame (obs__frame_setup_common, frame.c) and fills the
 * method's own values by its row's setup. */
obs_status obs__frame_setup(obs_ctx *log_ctx, const obs_gbuffer *gb, const obs_params *resolved,
                            obs__frame *f, char err[OBS_ERR_LEN]);

/* The AO of pixel (x, y) by the frame's method other than vaopp/vao
 * (position and normal from the planes); *count: samples taken (GLSL:
 * main() of method.frag.glsl). */
float obs__method_pixel(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                        int *count);

/* obs__method_pixel with the bent normal summed into bent[3] (left 0 for
 * the background and methods without one). */
float obs__method_pixel_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                             int *count, float bent[3]);

/* The row of method id (resolved, 1 .. OBS_METHOD_COUNT - 1); NULL for
 * any other value. */
const obs__method *obs__method_get(int id);

/* Every row in the order of the enum (obs__method_count() rows). */
const obs__method *obs__method_at(int i);
int obs__method_count(void);

#endif
