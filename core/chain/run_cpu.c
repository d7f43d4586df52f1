/* obs_run_cpu: the chain on the CPU, the pass table (passes.c) walked
 * with each pass's CPU twin (passes_cpu.c); the same order, the same
 * tests of whether a pass runs, as obs_run on GL.  Links without the GL
 * libraries. */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "chain/bands_run.h"
#include "chain/multibounce.h"
#include "chain/passes_cpu.h"
#include "log.h"
#include "mask_apply.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* Every pass that runs, in the table's order; with t, each one's wall
 * time. */
static obs_status walk(obs__cpu_run *c, obs_pass_times *t, char err[OBS_ERR_LEN])
{
    for (int i = 0; i < OBS_PASS_COUNT; i++) {
        if (!obs__passes[i].when(c->pl))
            continue;
        if (obs__cpu_stop_now(c))
            return obs__cpu_stopped_fail(c, "before", (obs_pass)i, err);
        double t0 = t ? now_ms() : 0.0;
        obs_status s = obs__cpu_kernels[i](c, err);
        if (s != OBS_OK)
            return s;
        if (atomic_load(&c->stopped)) /* a pass cut short: its output is not whole */
            return obs__cpu_stopped_fail(c, "in", (obs_pass)i, err);
        if (t) {
            t->ms[i] += now_ms() - t0;
            t->total_ms += now_ms() - t0;
        }
    }
    return OBS_OK;
}

static obs_status run(const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                      obs_result *out, obs_pass_times *times, const obs_cpu_options *opt,
                      char err[OBS_ERR_LEN]);

obs_status obs_run_cpu(const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                       obs_result *out, char err[OBS_ERR_LEN])
{
    return run(gb, params, outputs, out, NULL, NULL, err);
}

obs_status obs_run_cpu_opts(const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                            obs_result *out, const obs_cpu_options *opt, char err[OBS_ERR_LEN])
{
    return run(gb, params, outputs, out, NULL, opt, err);
}

obs_status obs__run_cpu_timed(const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                              obs_result *out, obs_pass_times *times, char err[OBS_ERR_LEN])
{
    return run(gb, params, outputs, out, times, NULL, err);
}

static obs_status run(const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                      obs_result *out, obs_pass_times *times, const obs_cpu_options *opt,
                      char err[OBS_ERR_LEN])
{
    obs__plan pl;
    obs__cpu_run c = {0};
    obs_log_fn log = opt ? opt->log : NULL;
    obs__log_sink sink = {log, opt ? opt->log_user : NULL}; /* the frame setup's messages */

    memset(out, 0, sizeof *out);
    obs__cpu_arm(&c, opt);
    obs_status s = obs__plan_init(&pl, log ? obs__log_only_ctx(&sink) : NULL, gb, params, outputs, err);
    if (s != OBS_OK)
        return s;
    c.pl = &pl;
    c.out = out;
    c.npx = (size_t)pl.f.width * (size_t)pl.f.height;
    if (times) {
        for (int i = 0; i < OBS_PASS_COUNT; i++)
            times->ms[i] = obs__passes[i].when(&pl) ? 0.0 : -1.0;
        times->total_ms = 0.0;
    }
    /* the planes' allocation counts as the upload, as GL's textures do */
    double t0 = times ? now_ms() : 0.0;
    const int bands = obs__bands_rows(&c, opt); /* 0: the whole frame; else bands_run.c */
    s = bands ? OBS_OK : obs__cpu_planes_take(&c, err);
    /* object masks at half resolution: the downsample's half planes (a
     * band's: set by bands_run.c) */
    pl.hf.mask_occl = c.hmask_w;
    pl.hf.mask_id = c.hmask_id;
    if (s == OBS_OK)
        s = obs__alloc_result(out, pl.f.width, pl.f.height, pl.outputs, err);
    if (times) {
        times->ms[OBS_PASS_UPLOAD] += now_ms() - t0;
        times->total_ms += now_ms() - t0;
    }
    if (s == OBS_OK)
        s = bands ? obs__bands_run(&c, &pl, bands, opt, times, err) : walk(&c, times, err);
    if (s == OBS_OK)
        s = obs__multibounce_finish(pl.gb, pl.multibounce, pl.asked, out, err);
    if (s == OBS_OK)
        obs__bent_finish(&pl, out);
    obs__cpu_planes_give(&c);
    if (s != OBS_OK)
        obs_result_free(out);
    else
        obs__receivers_apply(gb, out); /* object masks: receivers */
    return s;
}
