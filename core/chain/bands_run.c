/* The CPU chain in bands of rows (bands_run.h): a frame whose planes
 * would take more memory than the budget runs band by band, each band's
 * planes holding its rows and a halo of the rows its passes read.
 *
 * What a band reads beyond its rows, pass by pass (the largest reach of
 * any sample in the chain):
 *  - composite, finish, upsample: the pixel itself; the upsample (half
 *    resolution) the four half pixels around its centre, one half row
 *    either side;
 *  - the blur (section 4.6): blur_radius rows either side, at the AO's
 *    size, both passes fused (blur_cpu.c);
 *  - the AO pass's culling test (section 4.2): the four texels of the
 *    1/8 resolution estimate around each pixel corner, each the 8-sample
 *    AO of its block's centre pixel;
 *  - the AO estimator, at a pixel and at those centres: its samples'
 *    pixels, which have no bound in pixels (the AO radius projected:
 *    D f / z grows without bound as z nears the camera).  Each row's
 *    reach is therefore computed from its pixels' view positions and the
 *    camera (sample_reach): the band's halo is the largest reach of the
 *    rows it computes, so a band near the camera holds more rows, and
 *    the band's rows shrink until its planes fit the budget;
 *  - prep's normals from depth: one pixel either side.
 * Every pass runs on the frame's own coordinates (the frame keeps its
 * whole size; the planes' pointers are those of row 0, passes_cpu.h), so
 * every pixel of every band is computed by the arithmetic of the whole
 * frame: the same bytes (tests/unit/core/test_bands_run.c).  No GL. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "chain/bands_cpu.h"
#include "chain/bands_run.h"
#include "chain/multibounce.h"
#include "chain/vao_cpu.h"
#include "log.h"
#include "methods/gtao.h"

/* The rows of one band, at the full size (H), at the AO's size (the half
 * frame's rows with ao_resolution half) and of the culling texels. */
typedef struct band {
    int c0, c1; /* H: the rows the band delivers */
    int u0, u1; /* AO size: the blurred rows the band's rows read */
    int b0, b1; /* AO size: the rows the AO and the blur compute */
    int t0, t1; /* the culling texels the AO pass reads */
    int n0, n1; /* AO size: the rows the samples read (positions, normals, depth) */
    int p0, p1; /* H: the rows the prep computes */
    int a0, a1; /* H: the rows the planes hold */
} band;

static int clampi(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* The most rows (at the AO's size, frame af) between the pixel of view
 * point p and any pixel a sample of its AO reads, or `all` where there
 * is no bound (a sample may reach the camera's plane).  With the
 * projection's rows a (clip y) and b (clip w), a point s = p + d has
 * ndc_y(s) - ndc_y(p) = (a - ndc_y(p) b) . d / w(s), w(s) >= w(p) - |b . d|:
 *  - vaopp, vao: the samples lie on the disk of radius r = R/2 around
 *    c = p + n r, perpendicular to view z (vao_cpu.c): |d| <= 2r,
 *    |b . d| <= r (|b| + |b_xy|);
 *  - hemisphere, angle: within R of p (the kernel, the pair's offsets);
 *  - hbao, gtao: screen-space steps up to obs__radius_px pixels.
 * Two rows more for the floor of the sample's pixel and the border's
 * (obs__border_px, on the segment to the sample). */
static int sample_reach(const obs__frame *af, const float p[3], int all)
{
    const float *P = af->proj;
    float rpx = -1.0f;
    if (af->method == OBS_METHOD_HBAO)
        rpx = obs__radius_px(af, p, af->radius);
    else if (af->method == OBS_METHOD_GTAO)
        rpx = obs__radius_px(af, p, obs__gtao_of(af)->radius);
    if (rpx >= 0.0f)
        return isfinite(rpx) && rpx < (float)all ? (int)ceilf(rpx) + 2 : all;
    double a[3] = {P[4], P[5], P[6]}, b[3] = {P[12], P[13], P[14]};
    double w = b[0] * p[0] + b[1] * p[1] + b[2] * p[2] + P[15];
    double ndc = (a[0] * p[0] + a[1] * p[1] + a[2] * p[2] + P[7]) / w;
    double g = sqrt((a[0] - ndc * b[0]) * (a[0] - ndc * b[0]) + (a[1] - ndc * b[1]) * (a[1] - ndc * b[1]) +
                    (a[2] - ndc * b[2]) * (a[2] - ndc * b[2]));
    double bl = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]), bxy = sqrt(b[0] * b[0] + b[1] * b[1]);
    const double R = af->radius; /* |d| <= R for every one of these methods */
    const double wmin = af->method == OBS_METHOD_VAOPP || af->method == OBS_METHOD_VAO
                            ? w - 0.5 * R * (bl + bxy)
                            : w - R * bl;
    if (!(w > 0.0) || !(wmin > 0.0))
        return all;
    double rows = 0.5 * af->viewport[3] * g * R / wmin;
    return isfinite(rows) && rows < (double)all ? (int)ceil(rows) + 2 : all;
}

typedef struct reach_job {
    const obs__plan *pl;
    const obs_gbuffer *gb; /* its depth read by the frame's rows */
    int *reach; /* per full row, in rows at the AO's size */
} reach_job;

static void reach_rows(void *ctx, int y0, int y1)
{
    const reach_job *j = ctx;
    const obs__frame *f = &j->pl->f, *af = j->pl->af;
    const obs_gbuffer *gb = j->gb;
    for (int y = y0; y < y1; y++) {
        const float *depth = obs__plane_px(&gb->depth, f->width, 0, y);
        const size_t dc = (size_t)gb->depth.channels;
        int most = 0;
        for (int x = 0; x < f->width && most < af->height; x++) {
            float v[4];
            obs__prep_position(f, depth[dc * (size_t)x], x, y, v);
            if (!(v[3] > 0.0f)) /* background: no samples */
                continue;
            int r = sample_reach(af, v, af->height);
            most = r > most ? r : most;
        }
        j->reach[y] = most;
    }
}

/* The reach of each row at the AO's size (the larger of a half row's two
 * full rows with ao_resolution half), into reach[af->height], from each
 * full row's in full[] (reach_rows). */
static void row_reach(const obs__plan *pl, const int *full, int *reach)
{
    for (int y = 0; y < pl->af->height; y++) {
        int r = full[pl->f.half ? 2 * y : y];
        if (pl->f.half && 2 * y + 1 < pl->f.height && full[2 * y + 1] > r)
            r = full[2 * y + 1];
        reach[y] = r;
    }
}

/* The rows band b of rows [c0, c1) computes and holds (see the top). */
static void band_plan(const obs__plan *pl, const int *reach, int c0, int c1, band *b)
{
    const obs__frame *f = &pl->f, *af = pl->af;
    const int H = f->height, AH = af->height, br = af->blur_radius;
    b->c0 = c0;
    b->c1 = c1;
    if (f->half) { /* up.frag: the half pixels around each full pixel's centre */
        b->u0 = clampi(c0 / 2 - 1, 0, AH);
        b->u1 = clampi((c1 + 1) / 2 + 1, 0, AH);
    } else {
        b->u0 = c0;
        b->u1 = c1;
    }
    b->b0 = clampi(b->u0 - br, 0, AH);
    b->b1 = clampi(b->u1 + br, 0, AH);
    int n0 = b->b0, n1 = b->b1;
    for (int y = b->b0; y < b->b1; y++) {
        n0 = y - reach[y] < n0 ? y - reach[y] : n0;
        n1 = y + reach[y] + 1 > n1 ? y + reach[y] + 1 : n1;
    }
    b->t0 = b->t1 = 0;
    if (f->culling) { /* pixel corners y in [b0, b1]: texels floor(y / 8 - 0.5) and the next */
        b->t0 = clampi((int)floorf((float)b->b0 * 0.125f - 0.5f), 0, af->cull_h);
        b->t1 = clampi((int)floorf((float)b->b1 * 0.125f - 0.5f) + 2, 0, af->cull_h);
        for (int t = b->t0; t < b->t1; t++) { /* each texel's centre pixel's samples */
            int y = OBS_CULL_BLOCK * t + OBS_CULL_BLOCK / 2;
            y = y < AH ? y : AH - 1;
            n0 = y - reach[y] < n0 ? y - reach[y] : n0;
            n1 = y + reach[y] + 1 > n1 ? y + reach[y] + 1 : n1;
        }
    }
    b->n0 = clampi(n0, 0, AH);
    b->n1 = clampi(n1, 0, AH);
    /* the normals of those rows read the positions one row either side */
    b->p0 = clampi(f->half ? 2 * b->n0 - 1 : b->n0 - 1, 0, H);
    b->p1 = clampi(f->half ? 2 * b->n1 + 1 : b->n1 + 1, 0, H);
    b->a0 = clampi(b->p0 - 1, 0, H);
    b->a1 = clampi(b->p1 + 1, 0, H);
}

static void window1(obs__cpu_window *w, int i, int height, int lo, int hi)
{
    w->height[i] = height;
    w->lo[i] = lo;
    w->hi[i] = hi;
}

/* The windows of pass `pass` for band b (bands_cpu.h): the rows each of
 * its loops runs. */
static void pass_window(const obs__plan *pl, const band *b, int pass, obs__cpu_window *w)
{
    const int H = pl->f.height, AH = pl->af->height;
    memset(w, 0, sizeof *w);
    switch (pass) {
    case OBS_PASS_UPLOAD:
    case OBS_PASS_PREP:
        window1(w, 0, H, b->p0, b->p1);
        break;
    case OBS_PASS_DOWNSAMPLE:
        window1(w, 0, H, b->p0, b->p1);
        window1(w, 1, AH, b->n0, b->n1);
        break;
    case OBS_PASS_CULL:
        window1(w, 0, pl->af->cull_h, b->t0, b->t1);
        break;
    case OBS_PASS_AO:
        window1(w, 0, AH, b->b0, b->b1);
        break;
    default: /* upsample, finish, composite: the band's own rows */
        window1(w, 0, H, b->c0, b->c1);
        break;
    }
}

/* The blur (section 4.6) of the rows [b0, b1) at the AO's size: the
 * frame seen as those rows alone (the filter reads no coordinate but the
 * row's), right on [u0, u1), which lie blur_radius inside; then the two
 * planes' roles as cpu_blur (passes_cpu.c) leaves them. */
static void band_blur(obs__cpu_run *c, const band *b)
{
    obs__frame vf = *c->pl->af;
    vf.height = b->b1 - b->b0;
    const size_t o = (size_t)b->b0 * (size_t)vf.width;
    float *ao = c->aao + o;
    float *res = obs__blur_dnz(&vf, c->apos + 4 * o, c->dnz + 2 * o, ao, c->atmp + o,
                               c->pl->rays_in_blur);
    if (res != ao) { /* the result in the other plane: the two swap roles */
        c->atmp = c->aao;
        c->aao = res - o;
        if (c->pl->f.half) {
            c->htmp = c->atmp;
            c->hao = c->aao;
        } else {
            c->tmp = c->atmp;
            c->ao = c->aao;
        }
    }
}

/* The band's rows of the AO and the bleed term into the result (the
 * readback's part that is per pixel; the rest once, obs__bands_run). */
static void band_readback(obs__cpu_run *c, const band *b)
{
    obs_result *out = c->out;
    const size_t w = (size_t)c->pl->f.width, o = (size_t)b->c0 * w, n = (size_t)(b->c1 - b->c0) * w;
    if (out->ao.data)
        memcpy(out->ao.data + o, c->ao + o, n * sizeof(float));
    if (out->bleed.data && !c->pl->f.half)
        memcpy(out->bleed.data + 3 * o, c->bleed + 3 * o, 3 * n * sizeof(float));
}

/* The rows band b's planes hold (passes_cpu.h). */
static void band_rows_of(obs__cpu_run *c, const band *b)
{
    c->row0 = b->a0;
    c->row1 = b->a1;
    c->hrow0 = b->a0 / 2;
    c->hrow1 = clampi((b->a1 + 1) / 2, 0, c->pl->af->height);
    c->crow0 = b->t0;
    c->crow1 = b->t1;
    /* the AO's planes: the rows the AO and the blur compute; at half
     * resolution the full-size AO only the upsample's rows (the band's) */
    c->arow0 = c->pl->f.half ? b->c0 : b->b0;
    c->arow1 = c->pl->f.half ? b->c1 : b->b1;
    c->harow0 = b->b0;
    c->harow1 = b->b1;
}

/* One band: its planes, then every pass of the table that runs, each
 * on its window. */
static obs_status band_run(obs__cpu_run *c, obs__plan *pl, const band *b, obs_pass_times *t,
                           char err[OBS_ERR_LEN])
{
    band_rows_of(c, b);
    double t0 = t ? now_ms() : 0.0;
    obs_status s = obs__cpu_planes_take(c, err);
    /* object masks at half resolution: the band's half planes */
    pl->hf.mask_occl = c->hmask_w;
    pl->hf.mask_id = c->hmask_id;
    if (t) {
        t->ms[OBS_PASS_UPLOAD] += now_ms() - t0;
        t->total_ms += now_ms() - t0;
    }
    for (int i = 0; s == OBS_OK && i < OBS_PASS_COUNT; i++) {
        if (!obs__passes[i].when(pl))
            continue;
        if (obs__cpu_stop_now(c)) {
            s = obs__cpu_stopped_fail(c, "before", (obs_pass)i, err);
            break;
        }
        t0 = t ? now_ms() : 0.0;
        obs__cpu_window w;
        pass_window(pl, b, i, &w);
        const obs__cpu_window *old = obs__cpu_window_set(&w);
        if (i == OBS_PASS_BLUR)
            band_blur(c, b);
        else if (i == OBS_PASS_READBACK)
            band_readback(c, b);
        else
            s = obs__cpu_kernels[i](c, err);
        obs__cpu_window_set(old);
        if (s == OBS_OK && atomic_load(&c->stopped))
            s = obs__cpu_stopped_fail(c, "in", (obs_pass)i, err);
        if (t) {
            t->ms[i] += now_ms() - t0;
            t->total_ms += now_ms() - t0;
        }
    }
    obs__cpu_planes_give(c);
    return s;
}

int obs__bands_rows(obs__cpu_run *c, const obs_cpu_options *opt)
{
    const obs__plan *pl = c->pl;
    /* under 64 rows the heights of the windows (bands_cpu.h) could meet */
    if (pl->f.height < OBS__BANDS_MIN_HEIGHT)
        return 0;
    if (opt && opt->band_rows > 0)
        return opt->band_rows < pl->f.height ? opt->band_rows : 0;
    size_t need = obs__cpu_planes_need(c), budget = obs_cpu_memory_budget(opt);
    if (need <= budget)
        return 0;
    /* the first try: half the budget's rows (obs__bands_run fits each
     * band to the budget from its halo) */
    size_t per_row = need / (size_t)pl->f.height + 1;
    int rows = (int)(budget / per_row / 2);
    return rows > OBS__BANDS_MIN_ROWS ? rows : OBS__BANDS_MIN_ROWS;
}

static void band_log(const obs_cpu_options *opt, int k, const band *b, int H, size_t bytes)
{
    if (!opt || !opt->log)
        return;
    char msg[192];
    snprintf(msg, sizeof msg, "band %d: rows %d-%d of %d (holds rows %d-%d, %.1f MiB of planes)", k,
             b->c0, b->c1, H, b->a0, b->a1, (double)bytes / 1048576.0);
    opt->log(opt->log_user, OBS_LOG_INFO, msg);
}

/* Said once a frame, after its bands: bands as tall as their halo were
 * over the budget; the largest halo and band (the budget's name as the
 * caller gave it). */
static void over_budget_log(const obs_cpu_options *opt, int halo, size_t need, size_t budget)
{
    if (!opt || !opt->log)
        return;
    const char *name = opt->max_memory_name;
    if (!name)
        name = opt->max_memory ? "the memory budget"
                               : "the memory budget (a quarter of the usable memory; --max-memory MIB "
                                 "sets it)";
    char msg[320];
    snprintf(msg, sizeof msg, "%s: the AO's samples reach up to %d rows either side at this depth: "
             "bands hold up to %.1f MiB of planes, over the %.1f MiB the budget leaves them",
             name, halo, (double)need / 1048576.0, (double)budget / 1048576.0);
    opt->log(opt->log_user, OBS_LOG_WARN, msg);
}

/* What a band does before and after its passes: nothing for a frame in
 * memory (obs__bands_run); the rows read and the result's rows handed
 * on for a frame by rows (obs_run_cpu_rows). */
typedef struct band_io {
    obs_status (*in)(struct band_io *io, obs__cpu_run *c, const band *b, char err[OBS_ERR_LEN]);
    obs_status (*out)(struct band_io *io, obs__cpu_run *c, const band *b, char err[OBS_ERR_LEN]);
} band_io;

/* Every band of c's plan, from the rows' reach (reach[], at the AO's
 * size). */
static obs_status bands_loop(obs__cpu_run *c, obs__plan *pl, int rows, const int *reach,
                             const obs_cpu_options *opt, obs_pass_times *t, band_io *io,
                             char err[OBS_ERR_LEN])
{
    const int H = pl->f.height;
    const int forced = opt && opt->band_rows > 0;
    const size_t budget = obs_cpu_memory_budget(opt);
    obs_status s = OBS_OK;
    int over = 0, over_halo = 0; /* bands over the budget, their largest halo: said at the end */
    size_t over_need = 0;
    for (int c0 = 0, k = 1; s == OBS_OK && c0 < H; k++) {
        int n = rows;
        band b;
        for (int tries = 0;; tries++) { /* the band's rows until its planes fit the budget */
            band_plan(pl, reach, c0, c0 + n < H ? c0 + n : H, &b);
            band_rows_of(c, &b);
            size_t need = obs__cpu_planes_need(c);
            if (forced || need <= budget || n <= OBS__BANDS_MIN_ROWS || tries > 32)
                break;
            /* the rows the budget holds, less the halo the band reads */
            const int held = b.a1 - b.a0, halo = (held - (b.c1 - b.c0) + 1) / 2;
            const int fit = (int)((double)budget / (double)need * held) - 2 * halo;
            if (fit >= halo && fit >= OBS__BANDS_MIN_ROWS && fit < n) {
                n = fit;
                continue;
            }
            if (fit < halo || fit < OBS__BANDS_MIN_ROWS) {
                /* the budget holds less than three halos: bands as tall
                 * as the halo (over the budget), so that each band's prep
                 * runs over at most three times its rows, not over a
                 * halo many times a thin band's rows */
                int m = halo > OBS__BANDS_MIN_ROWS ? halo : OBS__BANDS_MIN_ROWS;
                if (m < n) {
                    n = m;
                    band_plan(pl, reach, c0, c0 + n < H ? c0 + n : H, &b);
                    band_rows_of(c, &b);
                }
                break;
            }
            n /= 2;
        }
        const size_t need = obs__cpu_planes_need(c);
        if (!forced && need > budget) { /* its halo alone is too much */
            const int halo = (b.a1 - b.a0 - (b.c1 - b.c0) + 1) / 2;
            over++;
            over_halo = halo > over_halo ? halo : over_halo;
            over_need = need > over_need ? need : over_need;
        }
        band_log(opt, k, &b, H, need);
        if (io)
            s = io->in(io, c, &b, err);
        if (s == OBS_OK)
            s = band_run(c, pl, &b, t, err);
        if (s == OBS_OK && io)
            s = io->out(io, c, &b, err);
        c0 = b.c1;
    }
    c->row0 = c->row1 = 0;
    if (over)
        over_budget_log(opt, over_halo, over_need, budget);
    return s;
}

/* The readback's neutral planes (cpu_readback, passes_cpu.c) of an
 * image of n pixels. */
static void neutral_planes(const obs__plan *pl, obs_result *out, size_t n)
{
    if (out->bleed.data && pl->f.half)
        for (size_t i = 0; i < n * 3; i++)
            out->bleed.data[i] = 1.0f;
    if (out->luminance.data && !pl->f.luminance)
        for (size_t i = 0; i < n; i++)
            out->luminance.data[i] = 1.0f;
}

obs_status obs__bands_run(obs__cpu_run *c, obs__plan *pl, int rows, const obs_cpu_options *opt,
                          obs_pass_times *t, char err[OBS_ERR_LEN])
{
    const int H = pl->f.height;
    int *full = malloc(sizeof(int) * ((size_t)H + (size_t)pl->af->height));
    if (!full)
        return obs__fail(err, OBS_NO_MEMORY, "out of memory for the bands of a %dx%d frame",
                         pl->f.width, H);
    reach_job j = {pl, pl->gb, full};
    obs__cpu_rows(H, 0, reach_rows, &j);
    row_reach(pl, full, full + H);
    obs_status s = bands_loop(c, pl, rows, full + H, opt, t, NULL, err);
    free(full);
    if (s == OBS_OK)
        neutral_planes(pl, c->out, c->npx);
    return s;
}

/* ---- a frame by rows (obs_run_cpu_rows) ------------------------------------ */

/* The images a band's result can hold. */
#define BAND_IMAGES 8
static void result_images(obs_result *r, obs_image *img[BAND_IMAGES])
{
    obs_image *list[BAND_IMAGES] = {&r->ao,   &r->composite, &r->sample_count, &r->cull_mask,
                                    &r->bleed, &r->luminance, &r->bent,        &r->multibounce};
    memcpy(img, list, sizeof list);
}

typedef struct rows_io {
    band_io io;
    obs__plan *pl;
    obs_rows_in_fn in;
    obs_rows_out_fn out;
    void *user;
    obs_gbuffer gb;   /* the band's rows, its planes' data at the frame's row 0 */
    obs_result held;  /* the band's result over the rows it holds (allocated) */
    obs_result at0;   /* the same images, data at the frame's row 0 */
} rows_io;

/* A gbuffer of rows [y0, ...) as the source gives it, with its planes'
 * data at the frame's row 0. */
static void rows_at0(obs_gbuffer *gb, int y0)
{
    obs_plane *planes[] = {&gb->depth, &gb->normal, &gb->color};
    for (int i = 0; i < 3; i++)
        if (planes[i]->data) {
            size_t row = planes[i]->row_stride ? planes[i]->row_stride
                                               : (size_t)gb->width * (size_t)planes[i]->channels * sizeof(float);
            planes[i]->data = (const float *)(const void *)((const char *)planes[i]->data - (size_t)y0 * row);
        }
}

static obs_status rows_fetch(rows_io *r, int y0, int y1, char err[OBS_ERR_LEN])
{
    obs_gbuffer g;
    memset(&g, 0, sizeof g);
    obs_status s = r->in(r->user, y0, y1, &g, err);
    if (s != OBS_OK)
        return s;
    if (g.width != r->pl->f.width || g.height != r->pl->f.height || !g.depth.data ||
        !g.normal.data != !r->gb.normal.data || !g.color.data != !r->gb.color.data)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "rows %d-%d are not the frame's (%dx%d, the same planes)",
                         y0, y1, r->pl->f.width, r->pl->f.height);
    rows_at0(&g, y0);
    r->gb = g;
    return OBS_OK;
}

static obs_status rows_in(band_io *io, obs__cpu_run *c, const band *b, char err[OBS_ERR_LEN])
{
    rows_io *r = (rows_io *)io;
    obs_status s = rows_fetch(r, b->a0, b->a1, err);
    if (s != OBS_OK)
        return s;
    r->pl->gb = &r->gb;
    /* the result of the rows held, its images' data at the frame's row 0 */
    s = obs__alloc_result(&r->held, r->pl->f.width, b->a1 - b->a0, r->pl->outputs, err);
    if (s != OBS_OK)
        return s;
    r->at0 = r->held;
    obs_image *img[BAND_IMAGES];
    result_images(&r->at0, img);
    for (int i = 0; i < BAND_IMAGES; i++)
        if (img[i]->data)
            img[i]->data -= (size_t)b->a0 * (size_t)img[i]->width * (size_t)img[i]->channels;
    c->out = &r->at0;
    return OBS_OK;
}

/* The band's own rows: copied out of the rows held, finished as the
 * whole frame's result is (multi-bounce, bent normals, neutral planes),
 * handed on. */
static obs_status rows_out(band_io *io, obs__cpu_run *c, const band *b, char err[OBS_ERR_LEN])
{
    rows_io *r = (rows_io *)io;
    const obs__plan *pl = r->pl;
    const int n = b->c1 - b->c0;
    obs_result part;
    obs_status s = obs__alloc_result(&part, pl->f.width, n, pl->outputs, err);
    obs_image *from[BAND_IMAGES], *to[BAND_IMAGES];
    result_images(&r->held, from);
    result_images(&part, to);
    for (int i = 0; s == OBS_OK && i < BAND_IMAGES; i++)
        if (to[i]->data)
            memcpy(to[i]->data,
                   from[i]->data + (size_t)(b->c0 - b->a0) * (size_t)from[i]->width * (size_t)from[i]->channels,
                   (size_t)n * (size_t)to[i]->width * (size_t)to[i]->channels * sizeof(float));
    obs_result_free(&r->held);
    c->out = NULL;
    obs_gbuffer view = r->gb; /* the band's rows, for the multi-bounce fit's colour */
    view.height = n;
    rows_at0(&view, -b->c0);
    if (s == OBS_OK)
        s = obs__multibounce_finish(&view, pl->multibounce, pl->asked, &part, err);
    if (s == OBS_OK) {
        obs__bent_finish(pl, &part);
        neutral_planes(pl, &part, (size_t)n * (size_t)pl->f.width);
        s = r->out(r->user, b->c0, b->c1, &part, err);
    }
    obs_result_free(&part);
    return s;
}

obs_status obs_run_cpu_rows(const obs_gbuffer *frame, obs_rows_in_fn in, obs_rows_out_fn out, void *user,
                            const obs_params *params, unsigned outputs, const obs_cpu_options *opt,
                            char err[OBS_ERR_LEN])
{
    static const float present = 0.0f; /* a plane the frame has, for the plan: never read */
    obs__plan pl;
    obs__cpu_run c = {0};
    obs_log_fn log = opt ? opt->log : NULL;
    obs__log_sink sink = {log, opt ? opt->log_user : NULL};
    if (!frame || !in || !out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_run_cpu_rows: no frame, source or sink");
    if (frame->receivers.data || frame->occluders.data || frame->object_id.data)
        return obs__fail(err, OBS_UNSUPPORTED, "object masks need the frame in memory (obs_run_cpu)");
    obs_gbuffer head = *frame;
    head.depth.data = &present;
    head.normal.data = frame->normal.channels > 0 ? &present : NULL;
    head.color.data = frame->color.channels > 0 ? &present : NULL;
    head.position = (obs_plane){NULL, 0, 0};
    head.depth.row_stride = head.normal.row_stride = head.color.row_stride = 0;
    obs__cpu_arm(&c, opt);
    obs_status s = obs__plan_init(&pl, log ? obs__log_only_ctx(&sink) : NULL, &head, params, outputs, err);
    if (s != OBS_OK)
        return s;
    c.pl = &pl;
    c.npx = (size_t)pl.f.width * (size_t)pl.f.height;
    const int H = pl.f.height;
    int rows = H < OBS__BANDS_MIN_HEIGHT ? H : obs__bands_rows(&c, opt);
    if (rows <= 0) /* whole, as one band */
        rows = H;
    rows_io r = {{rows_in, rows_out}, &pl, in, out, user};
    r.gb = head;
    int *full = malloc(sizeof(int) * ((size_t)H + (size_t)pl.af->height));
    if (!full)
        return obs__fail(err, OBS_NO_MEMORY, "out of memory for the bands of a %dx%d frame", pl.f.width, H);
    /* the rows' reach, from the depth, a few rows at a time */
    const int step = OBS__BANDS_REACH_ROWS;
    for (int y0 = 0; s == OBS_OK && y0 < H; y0 += step) {
        const int y1 = y0 + step < H ? y0 + step : H;
        s = rows_fetch(&r, y0, y1, err);
        if (s != OBS_OK)
            break;
        obs__cpu_window w = {{H}, {y0}, {y1}};
        const obs__cpu_window *old = obs__cpu_window_set(&w);
        reach_job j = {&pl, &r.gb, full};
        obs__cpu_rows(H, 0, reach_rows, &j);
        obs__cpu_window_set(old);
    }
    if (s == OBS_OK) {
        row_reach(&pl, full, full + H);
        s = bands_loop(&c, &pl, rows, full + H, opt, NULL, &r.io, err);
    }
    obs_result_free(&r.held);
    free(full);
    return s;
}
