/* The GL device's column of the pass table (passes.h): one kernel per
 * pass (passes_gl.c), walked by obs_run (run_gl.c).  Not installed. */
#ifndef OBSCURA_PASSES_GL_H
#define OBSCURA_PASSES_GL_H

#include "chain/passes.h"
#include "context.h"

/* One frame on the GL context. */
typedef struct obs__gl_run {
    obs_ctx *ctx;
    const obs__plan *pl;
    obs__targets *t;  /* the full-size set */
    obs__targets *at; /* the set the AO runs at: t, or the half set */
    obs_result *out;
    double t_run;     /* when obs_run began: obs_ctx_set_deadline counts from here */
    GLuint ao_tex, ao_fbo; /* where the finished AO lies (the finishing pass moves it) */
} obs__gl_run;

typedef struct obs__gl_kernel {
    /* Builds the pass's programs on their first use (NULL: none). */
    obs_status (*build)(obs__programs *g, const obs__plan *pl, char err[OBS_ERR_LEN]);
    /* Runs the pass. */
    obs_status (*run)(obs__gl_run *r, char err[OBS_ERR_LEN]);
} obs__gl_kernel;

/* By obs_pass: the kernel of each row of obs__passes. */
extern const obs__gl_kernel obs__gl_kernels[OBS_PASS_COUNT];

#endif
