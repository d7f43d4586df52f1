/* The CPU device's column of the pass table (passes.h): one kernel per
 * pass, each the CPU twin of the GL pass (passes_cpu.c), walked by
 * obs_run_cpu (run_cpu.c).  No GL.  Not installed. */
#ifndef OBSCURA_PASSES_CPU_H
#define OBSCURA_PASSES_CPU_H

#include <stdatomic.h>

#include "chain/passes.h"

/* One frame's planes on the CPU: the full-size ones and, with
 * ao_resolution half, the half-size ones the culling pre-pass, AO and
 * blur run on (a* point to the one or the other). */
typedef struct obs__cpu_run {
    const obs__plan *pl;
    obs_result *out;
    size_t npx;
    float *pos, *nrm, *ao, *tmp, *est, *col, *bleed; /* full size; col: packed RGBA */
    float *hpos, *hnrm, *hao, *htmp, *hbleed;       /* half size */
    float *hmask_w, *hmask_id; /* half size: the object masks (NULL: none) */
    float *apos, *anrm, *aao, *atmp, *ableed;       /* at the AO's size */
    /* each pixel's depth and view normal z, packed (vao_cpu.h), at the
     * AO's size: what the AO's samples read */
    float *dnz;
    /* a frame run in bands (bands_run.c): the full-size rows [row0,
     * row1) the planes hold, the half-size ones [hrow0, hrow1), the
     * culling texels' [crow0, crow1); each plane pointer is then that of
     * the frame's row 0 (its rows outside those never touched), so the
     * passes index the planes by the frame's coordinates.  row1 0: the
     * whole frame */
    int row0, row1, hrow0, hrow1, crow0, crow1;
    /* ... of those, the rows the AO's planes hold (ao, tmp, bleed at full
     * size; hao, htmp, hbleed at half size): the rows the AO, the blur
     * and the passes after them compute, not the halo */
    int arow0, arow1, harow0, harow1;
    void *block;                                    /* where the planes are */
    size_t block_size;
    /* the deadline (CLOCK_MONOTONIC ms; 0: none) and the caller's cancel
     * (obs_cpu_options; NULL: none); stopped: a tile found the deadline
     * past (OBS__CPU_PAST_DEADLINE) or the run cancelled
     * (OBS__CPU_CANCELLED), and the rest of the pass was skipped */
    double deadline_ms;
    int (*cancel)(void *user);
    void *cancel_user;
    atomic_int stopped;
} obs__cpu_run;

enum { OBS__CPU_PAST_DEADLINE = 1, OBS__CPU_CANCELLED = 2 };

/* c's deadline (from now), cancel and stopped, from the caller's options
 * (NULL: neither): the start of every CPU run, flat, banded or deep. */
void obs__cpu_arm(obs__cpu_run *c, const obs_cpu_options *opt);
/* Whether c's run is to stop (a tile's test, from any thread): the
 * deadline passed or the cancel said so; sets c->stopped (passes_cpu.c). */
int obs__cpu_stop_now(obs__cpu_run *c);
/* The failure of a run stopped (c->stopped) before or in (`where`) pass
 * p: OBS_CANCELLED or OBS_DEADLINE, named. */
obs_status obs__cpu_stopped_fail(obs__cpu_run *c, const char *where, obs_pass p, char err[OBS_ERR_LEN]);

/* The planes of c's plan, in one block: the one the last frame gave back
 * when it fits, else a new one (planes_cpu.c). */
obs_status obs__cpu_planes_take(obs__cpu_run *c, char err[OBS_ERR_LEN]);

/* The bytes obs__cpu_planes_take would take for c (its rows, when set). */
size_t obs__cpu_planes_need(const obs__cpu_run *c);

/* Gives the block back, to be kept for the next frame (the larger of it
 * and the one kept is kept, the other freed). */
void obs__cpu_planes_give(obs__cpu_run *c);

typedef obs_status (*obs__cpu_kernel)(obs__cpu_run *c, char err[OBS_ERR_LEN]);

/* By obs_pass: the kernel of each row of obs__passes. */
extern const obs__cpu_kernel obs__cpu_kernels[OBS_PASS_COUNT];

/* obs_run_cpu with, when times is not NULL, each pass's wall time (the
 * planes' allocation in the upload's); -1 for a pass that did not run. */
obs_status obs__run_cpu_timed(const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                              obs_result *out, obs_pass_times *times, char err[OBS_ERR_LEN]);

#endif
