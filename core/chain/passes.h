/* The chain's pass order, written once: a table of passes, each with the
 * test on the frame that says whether it runs, walked in order by every
 * device's driver (run_gl.c: GL, run_cpu.c: the CPU twins), which holds
 * one kernel per pass.  A device adds a driver and a column of kernels;
 * a pass adds a row here (and its obs_pass) and a kernel per device.  No
 * GL here.  Not installed. */
#ifndef OBSCURA_PASSES_H
#define OBSCURA_PASSES_H

#include "methods/methods.h"

/* One frame's plan, the same for every device: its frame, the method,
 * the outputs asked for and what the passes' tests read. */
typedef struct obs__plan {
    const obs_gbuffer *gb;
    unsigned outputs;    /* OBS_OUTPUT_* bits the passes fill */
    unsigned asked;      /* the caller's: outputs less what a post step needs */
    int multibounce;     /* 1: the multi-bounce image is made (multibounce.c) */
    obs__frame f;        /* the full-resolution frame */
    obs__frame hf;       /* ao_resolution half: the frame at half size */
    const obs__frame *af; /* the frame the culling pre-pass, AO and blur run at: &f or &hf */
    const obs__method *method;
    /* colour: for the composite, luminance sensitivity (4.3), bleeding (4.7) */
    int has_color;
    /* Where ao_definition rays converts the blurred AO: in the blur's
     * vertical pass, else in the upsample at half resolution (which
     * filters the linear estimate, as the blur does), else in the
     * finishing pass. */
    int rays_in_blur, rays_in_finish;
} obs__plan;

/* Checks the outputs asked for, resolves the parameters for the G-buffer
 * and sets the frame (and the half frame) up.  The plan holds pointers
 * into itself: it is not copied. */
obs_status obs__plan_init(obs__plan *pl, obs_ctx *log_ctx, const obs_gbuffer *gb,
                          const obs_params *params, unsigned outputs, char err[OBS_ERR_LEN]);

/* The bent normal (bent_out.c): the method's view-space sums in
 * out->bent, normalised and turned into the normals' space, after the
 * readback by every device's driver. */
void obs__bent_finish(const obs__plan *pl, obs_result *out);

typedef struct obs__pass {
    obs_pass id;      /* its place in the order, its timing slot (obs_pass_times) */
    const char *name; /* obs_pass_name() */
    int (*when)(const obs__plan *pl); /* 1: the pass runs for this frame */
} obs__pass;

/* Every pass, in the order they run: row i has id i. */
extern const obs__pass obs__passes[OBS_PASS_COUNT];

#endif
