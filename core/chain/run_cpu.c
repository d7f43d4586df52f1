/* obs_run_cpu: the chain on the CPU, the pass table (passes.c) walked
 * with each pass's CPU twin (passes_cpu.c); the same order, the same
 * tests of whether a pass runs, as obs_run on GL.  Links without the GL
 * libraries. */
#include <stdlib.h>
#include <string.h>

#include "chain/passes_cpu.h"

static obs_status alloc_planes(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    const obs__frame *f = &c->pl->f, *af = c->pl->af;
    const size_t n = c->npx, an = (size_t)af->width * (size_t)af->height;
    c->pos = malloc(n * 4 * sizeof(float));
    c->nrm = malloc(n * 3 * sizeof(float));
    c->ao = malloc(n * sizeof(float));
    c->tmp = malloc(n * sizeof(float));
    c->est = malloc((size_t)f->cull_w * (size_t)f->cull_h * sizeof(float));
    c->bleed = malloc(n * 3 * sizeof(float));
    /* colour, packed RGBA, for sections 4.3 and 4.7 */
    int col = f->luminance || f->bleed_step;
    if (col)
        c->col = malloc(n * 4 * sizeof(float));
    if (f->half) {
        c->hpos = malloc(an * 4 * sizeof(float));
        c->hnrm = malloc(an * 3 * sizeof(float));
        c->hao = malloc(an * sizeof(float));
        c->htmp = malloc(an * sizeof(float));
        c->hbleed = malloc(an * 3 * sizeof(float));
    }
    c->apos = f->half ? c->hpos : c->pos;
    c->anrm = f->half ? c->hnrm : c->nrm;
    c->aao = f->half ? c->hao : c->ao;
    c->atmp = f->half ? c->htmp : c->tmp;
    c->ableed = f->half ? c->hbleed : c->bleed;
    if (!c->pos || !c->nrm || !c->ao || !c->tmp || !c->est || !c->bleed || (col && !c->col) ||
        !c->apos || !c->anrm || !c->aao || !c->atmp || !c->ableed)
        return obs__fail(err, OBS_NO_MEMORY, "out of memory for a %dx%d frame", f->width,
                         f->height);
    return OBS_OK;
}

static void free_planes(obs__cpu_run *c)
{
    float *all[] = {c->pos, c->nrm,  c->ao,  c->tmp,  c->est,  c->col,
                    c->bleed, c->hpos, c->hnrm, c->hao, c->htmp, c->hbleed};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        free(all[i]);
}

/* Every pass that runs, in the table's order. */
static obs_status walk(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    for (int i = 0; i < OBS_PASS_COUNT; i++) {
        if (!obs__passes[i].when(c->pl))
            continue;
        obs_status s = obs__cpu_kernels[i](c, err);
        if (s != OBS_OK)
            return s;
    }
    return OBS_OK;
}

obs_status obs_run_cpu(const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                       obs_result *out, char err[OBS_ERR_LEN])
{
    obs__plan pl;
    obs__cpu_run c = {0};

    memset(out, 0, sizeof *out);
    obs_status s = obs__plan_init(&pl, NULL, gb, params, outputs, err);
    if (s != OBS_OK)
        return s;
    c.pl = &pl;
    c.out = out;
    c.npx = (size_t)pl.f.width * (size_t)pl.f.height;
    s = alloc_planes(&c, err);
    if (s == OBS_OK)
        s = obs__alloc_result(out, pl.f.width, pl.f.height, outputs, err);
    if (s == OBS_OK)
        s = walk(&c, err);
    free_planes(&c);
    if (s != OBS_OK)
        obs_result_free(out);
    return s;
}
