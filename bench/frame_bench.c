/* Frame timing: one context, many frames, medians.
 *
 *   frame_bench [--backend B] [--frames N] [--presets | --devices | --cpu-only WxH]
 *               G-BUFFER.exr CAMERA.json...
 *
 * For each G-buffer (and a 1920x1080 nearest-neighbour upscale of it):
 * the first frame (shaders compiled, targets allocated), the median of N
 * warm frames at 8/16/32 samples, and the CPU twin at 16 samples, all in
 * one run so the ratios are comparable.  Output is a Markdown table.
 * --presets: --quality's presets at 1920x1080 and 3840x2160; --devices:
 * every method on the CPU device (obs_run_cpu) against the GL context,
 * at the same sizes; --cpu-only WxH: the CPU device alone (no GL context:
 * for a profiler), every method at that size, per pass (FRAME_BENCH_METHOD:
 * one method, here and with --devices; FRAME_BENCH_MAX_WIDTH=1920: --devices
 * and --presets at 1920x1080 only), then the AO pass against a plain gather loop over the same
 * samples; with FRAME_BENCH_TABLE1=D[,D...] instead VAO++ Table 1's
 * structure on the CPU device at 16 samples, at each adaptive_diameter D. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "chain/bands_cpu.h"
#include "chain/passes_cpu.h"
#include "methods/methods.h"
#include "obscura/io.h"
#include "obscura/obscura.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median_run(obs_ctx *ctx, const obs_gbuffer *gb, int samples, int frames, int cpu)
{
    double t[64];
    char err[OBS_ERR_LEN];
    obs_params p = {0};
    p.samples = samples;
    if (frames > 64)
        frames = 64;
    for (int i = 0; i < frames; i++) {
        obs_result r;
        double t0 = now_ms();
        obs_status s = cpu ? obs_run_cpu(gb, &p, OBS_OUTPUT_AO, &r, err)
                           : obs_run(ctx, gb, &p, OBS_OUTPUT_AO, &r, err);
        t[i] = now_ms() - t0;
        if (s != OBS_OK) {
            fprintf(stderr, "frame_bench: %s\n", err);
            exit(1);
        }
        obs_result_free(&r);
    }
    qsort(t, (size_t)frames, sizeof t[0], cmp);
    return t[frames / 2];
}

/* Nearest-neighbour upscale of every plane to w x h (same camera). */
static float *upscale(const obs_plane *p, int sw, int sh, int w, int h)
{
    if (!p->data)
        return NULL;
    float *out = malloc(sizeof(float) * (size_t)w * h * p->channels);
    size_t stride = p->row_stride ? p->row_stride : sizeof(float) * (size_t)sw * p->channels;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *src = (const float *)((const char *)p->data + (size_t)(y * sh / h) * stride) +
                               (size_t)(x * sw / w) * p->channels;
            memcpy(out + ((size_t)y * w + x) * p->channels, src, sizeof(float) * p->channels);
        }
    return out;
}

/* gb's depth and normals upscaled to w x h (no colour), the same camera;
 * the caller frees up->depth.data and up->normal.data. */
static obs_gbuffer upscaled(const obs_gbuffer *gb, int w, int h)
{
    obs_gbuffer up = *gb;
    up.width = w;
    up.height = h;
    up.display_width = up.display_height = 0;
    up.display_x = up.display_y = 0;
    up.depth = (obs_plane){upscale(&gb->depth, gb->width, gb->height, w, h), 1, 0};
    up.normal = (obs_plane){upscale(&gb->normal, gb->width, gb->height, w, h), 3, 0};
    up.color = (obs_plane){NULL, 0, 0};
    return up;
}

static void bench(obs_ctx *ctx, const char *name, const obs_gbuffer *gb, int frames, int with_cpu)
{
    char err[OBS_ERR_LEN];
    obs_result r;
    double t0 = now_ms();
    if (obs_run(ctx, gb, NULL, OBS_OUTPUT_AO, &r, err) != OBS_OK) {
        fprintf(stderr, "frame_bench: %s\n", err);
        exit(1);
    }
    double first = now_ms() - t0;
    obs_result_free(&r);
    double m8 = median_run(ctx, gb, 8, frames, 0);
    double m16 = median_run(ctx, gb, 16, frames, 0);
    double m32 = median_run(ctx, gb, 32, frames, 0);
    printf("| %s | %dx%d | %.1f | %.1f | %.1f | %.1f |", name, gb->width, gb->height, first, m8, m16,
           m32);
    if (with_cpu) {
        double c16 = median_run(ctx, gb, 16, 3, 1);
        printf(" %.1f (%.1fx) |\n", c16, c16 / m16);
    } else {
        printf(" - |\n");
    }
    fflush(stdout);
}

/* The cost of a deadline (obs_ctx_set_deadline): the AO pass in 16
 * scissored bands, each waited for, against one draw.  Frames alternate
 * between the two, so that the machine's drift hits both alike. */
static void bench_bands(obs_ctx *ctx, const char *name, const obs_gbuffer *gb, int frames,
                        char *line, size_t len)
{
    double t[2][64];
    char err[OBS_ERR_LEN];
    obs_params p = {0};
    p.samples = 16;
    if (frames > 64)
        frames = 64;
    for (int i = 0; i < frames; i++)
        for (int banded = 0; banded < 2; banded++) {
            obs_result r;
            obs_ctx_set_deadline(ctx, banded ? 3600.0 : 0.0, err);
            double t0 = now_ms();
            if (obs_run(ctx, gb, &p, OBS_OUTPUT_AO, &r, err) != OBS_OK) {
                fprintf(stderr, "frame_bench: %s\n", err);
                exit(1);
            }
            t[banded][i] = now_ms() - t0;
            obs_result_free(&r);
        }
    obs_ctx_set_deadline(ctx, 0.0, err);
    qsort(t[0], (size_t)frames, sizeof t[0][0], cmp);
    qsort(t[1], (size_t)frames, sizeof t[1][0], cmp);
    snprintf(line, len, "| %s | %dx%d | %.1f | %.1f | %.3f |\n", name, gb->width, gb->height,
             t[0][frames / 2], t[1][frames / 2], t[1][frames / 2] / t[0][frames / 2]);
}

/* The per-pass table of --presets, filled size by size. */
static char passes_md[8192];

static void presets_passes(void)
{
    printf("\nPer pass, median GL ms (\"-\": the pass did not run):\n\n| size | --quality |");
    for (int q = 0; q < OBS_PASS_COUNT; q++)
        printf(" %s |", obs_pass_name((obs_pass)q));
    printf("\n|---|---|");
    for (int q = 0; q < OBS_PASS_COUNT; q++)
        printf("---|");
    printf("\n%s", passes_md);
}

/* --quality's presets side by side: wall and GL time (the passes' timer
 * queries) of each, medians of `frames`, frames of the presets
 * interleaved so that the machine's drift hits them alike; the ratio to
 * default's in the same run. */
static void bench_presets(obs_ctx *ctx, const char *name, const obs_gbuffer *gb, int frames)
{
    static const char *const presets[] = {"preview", "default", "high", "reference"};
    enum { NP = sizeof presets / sizeof presets[0] };
    double wall[NP][64], gl[NP][64], pass[NP][OBS_PASS_COUNT][64];
    char err[OBS_ERR_LEN];
    obs_params p[NP];
    if (frames > 64)
        frames = 64;
    for (int k = 0; k < NP; k++) {
        memset(&p[k], 0, sizeof p[k]);
        obs_param_set(&p[k], "quality", presets[k], err);
    }
    obs_ctx_set_timing(ctx, 1, err);
    for (int i = -1; i < frames; i++) /* i = -1: warm-up, builds the programs */
        for (int k = 0; k < NP; k++) {
            obs_result r;
            obs_pass_times t;
            double t0 = now_ms();
            if (obs_run(ctx, gb, &p[k], OBS_OUTPUT_AO, &r, err) != OBS_OK) {
                fprintf(stderr, "frame_bench: %s: %s\n", presets[k], err);
                exit(1);
            }
            double took = now_ms() - t0;
            obs_result_free(&r);
            if (i < 0)
                continue;
            wall[k][i] = took;
            int timed = obs_ctx_last_times(ctx, &t);
            gl[k][i] = timed ? t.total_ms : -1.0;
            for (int q = 0; q < OBS_PASS_COUNT; q++)
                pass[k][q][i] = timed ? t.ms[q] : -1.0;
        }
    obs_ctx_set_timing(ctx, 0, err);
    double mw[NP], mg[NP];
    for (int k = 0; k < NP; k++) {
        qsort(wall[k], (size_t)frames, sizeof wall[k][0], cmp);
        qsort(gl[k], (size_t)frames, sizeof gl[k][0], cmp);
        mw[k] = wall[k][frames / 2];
        mg[k] = gl[k][frames / 2];
    }
    for (int k = 0; k < NP; k++)
        printf("| %s | %dx%d | %s | %.1f | %.1f | %.2f | %.2f |\n", name, gb->width, gb->height,
               presets[k], mw[k], mg[k], mw[k] / mw[1], mg[k] / mg[1]);
    /* where the time goes: each pass's median GL ms per preset, rows of
     * the second table, printed after the first (presets_passes) */
    for (int k = 0; k < NP; k++) {
        size_t n = strlen(passes_md);
        snprintf(passes_md + n, sizeof passes_md - n, "| %dx%d | %s |", gb->width, gb->height,
                 presets[k]);
        for (int q = 0; q < OBS_PASS_COUNT; q++) {
            qsort(pass[k][q], (size_t)frames, sizeof pass[k][q][0], cmp);
            double m = pass[k][q][frames / 2];
            n = strlen(passes_md);
            snprintf(passes_md + n, sizeof passes_md - n, m < 0 ? " - |" : " %.1f |", m);
        }
        n = strlen(passes_md);
        snprintf(passes_md + n, sizeof passes_md - n, "\n");
    }
    fflush(stdout);
}

/* --devices: each method's default chain on the CPU device and on the GL
 * context, wall ms (AO out, upload and readback included), medians of
 * `frames`, the two devices' frames interleaved so that the machine's
 * drift hits both alike; the ratio cpu / GL from the same run.  The CPU
 * device's median wall ms per pass go to a second table (devices_md). */
static char devices_md[8192];

static void bench_devices(obs_ctx *ctx, const char *name, const obs_gbuffer *gb, int frames,
                          int threads)
{
    double t[2][64], pass[OBS_PASS_COUNT][64];
    char err[OBS_ERR_LEN];
    if (frames > 64)
        frames = 64;
    const char *only = getenv("FRAME_BENCH_METHOD"); /* one method */
    for (int m = 0; m < obs__method_count(); m++) {
        obs_params p = {0};
        const char *method = obs__method_at(m)->name;
        if (only && strcmp(only, method))
            continue;
        if (obs_param_set(&p, "method", method, err) != OBS_OK) {
            fprintf(stderr, "frame_bench: %s\n", err);
            exit(1);
        }
        for (int i = -1; i < frames; i++) /* i = -1: warm-up, builds the programs */
            for (int cpu = 0; cpu < 2; cpu++) {
                obs_result r;
                obs_pass_times pt;
                double t0 = now_ms();
                obs_status s = cpu ? obs__run_cpu_timed(gb, &p, OBS_OUTPUT_AO, &r, &pt, err)
                                   : obs_run(ctx, gb, &p, OBS_OUTPUT_AO, &r, err);
                double took = now_ms() - t0;
                if (s != OBS_OK) {
                    fprintf(stderr, "frame_bench: %s: %s\n", method, err);
                    exit(1);
                }
                obs_result_free(&r);
                if (i < 0)
                    continue;
                t[cpu][i] = took;
                for (int q = 0; cpu && q < OBS_PASS_COUNT; q++)
                    pass[q][i] = pt.ms[q];
            }
        qsort(t[0], (size_t)frames, sizeof t[0][0], cmp);
        qsort(t[1], (size_t)frames, sizeof t[1][0], cmp);
        double gl = t[0][frames / 2], cpu = t[1][frames / 2];
        printf("| %s | %dx%d | %s | %d | %.1f | %.1f | %.2f |\n", name, gb->width, gb->height,
               method, threads, gl, cpu, cpu / gl);
        fflush(stdout);
        size_t n = strlen(devices_md);
        snprintf(devices_md + n, sizeof devices_md - n, "| %dx%d | %s |", gb->width, gb->height,
                 method);
        for (int q = 0; q < OBS_PASS_COUNT; q++) {
            qsort(pass[q], (size_t)frames, sizeof pass[q][0], cmp);
            double v = pass[q][frames / 2];
            n = strlen(devices_md);
            snprintf(devices_md + n, sizeof devices_md - n, v < 0 ? " - |" : " %.1f |", v);
        }
        n = strlen(devices_md);
        snprintf(devices_md + n, sizeof devices_md - n, "\n");
    }
}

static void devices_passes(void)
{
    printf("\nThe CPU device per pass, median wall ms (\"-\": the pass did not run; the "
           "planes' allocation counts as the upload):\n\n| size | method |");
    for (int q = 0; q < OBS_PASS_COUNT; q++)
        printf(" %s |", obs_pass_name((obs_pass)q));
    printf("\n|---|---|");
    for (int q = 0; q < OBS_PASS_COUNT; q++)
        printf("---|");
    printf("\n%s", devices_md);
}

/* --cpu-only: each method's default chain on the CPU device alone at
 * one size, median wall ms per pass (no GL context: what a profiler such
 * as perf or callgrind sees is the CPU device's own). */
static void bench_cpu_only(const char *name, const obs_gbuffer *gb, int frames)
{
    char err[OBS_ERR_LEN];
    if (frames > 64)
        frames = 64;
    if (frames < 1)
        frames = 1;
    printf("| G-buffer (upscaled) | size | method | CPU threads | wall ms |");
    for (int q = 0; q < OBS_PASS_COUNT; q++)
        printf(" %s |", obs_pass_name((obs_pass)q));
    printf("\n|---|---|---|---|---|");
    for (int q = 0; q < OBS_PASS_COUNT; q++)
        printf("---|");
    printf("\n");
    const char *only = getenv("FRAME_BENCH_METHOD"); /* one method (profiling) */
    for (int m = 0; m < obs__method_count(); m++) {
        obs_params p = {0};
        const char *method = obs__method_at(m)->name;
        if (only && strcmp(only, method))
            continue;
        double t[64], pass[OBS_PASS_COUNT][64];
        if (obs_param_set(&p, "method", method, err) != OBS_OK) {
            fprintf(stderr, "frame_bench: %s\n", err);
            exit(1);
        }
        for (int i = 0; i < frames; i++) {
            obs_result r;
            obs_pass_times pt;
            double t0 = now_ms();
            if (obs__run_cpu_timed(gb, &p, OBS_OUTPUT_AO, &r, &pt, err) != OBS_OK) {
                fprintf(stderr, "frame_bench: %s: %s\n", method, err);
                exit(1);
            }
            t[i] = now_ms() - t0;
            obs_result_free(&r);
            for (int q = 0; q < OBS_PASS_COUNT; q++)
                pass[q][i] = pt.ms[q];
        }
        qsort(t, (size_t)frames, sizeof t[0], cmp);
        printf("| %s | %dx%d | %s | %d | %.1f |", name, gb->width, gb->height, method,
               obs__cpu_threads(), t[frames / 2]);
        for (int q = 0; q < OBS_PASS_COUNT; q++) {
            qsort(pass[q], (size_t)frames, sizeof pass[q][0], cmp);
            double v = pass[q][frames / 2];
            printf(v < 0 ? " - |" : " %.1f |", v);
        }
        printf("\n");
        fflush(stdout);
    }
}

/* The AO pass against the limit of its memory reads: the default chain
 * (vaopp) at one thread, its AO pass's time and sample count (each
 * sample one 8-byte fetch of the packed depth and normal z), then a plain
 * gather loop over a plane of the same size that fetches the same number
 * of samples per pixel at the same pixel offsets (the sample set scaled
 * by the pixel's projected radius) and sums them.  Fetches per second of
 * both: the distance of the AO pass to the gather limit. */
static void bench_gather_limit(const obs_gbuffer *gb)
{
    char err[OBS_ERR_LEN];
    obs_params p = {0}, rp;
    obs_result r;
    obs_pass_times pt;
    int before = obs__cpu_set_threads(1);
    double ao_ms = 1e30;
    for (int i = 0; i < 3; i++) { /* the fastest of 3: the least disturbed by the load */
        if (obs__run_cpu_timed(gb, &p, OBS_OUTPUT_AO | OBS_OUTPUT_SAMPLE_COUNT, &r, &pt, err) !=
            OBS_OK) {
            fprintf(stderr, "frame_bench: %s\n", err);
            exit(1);
        }
        if (pt.ms[OBS_PASS_AO] < ao_ms)
            ao_ms = pt.ms[OBS_PASS_AO];
        if (i < 2)
            obs_result_free(&r);
    }
    obs__frame f;
    obs_params_resolve(&p, &rp);
    if (obs__frame_setup(NULL, gb, &rp, &f, err) != OBS_OK) {
        fprintf(stderr, "frame_bench: %s\n", err);
        exit(1);
    }
    const int w = gb->width, h = gb->height;
    const size_t npx = (size_t)w * (size_t)h;
    float *dnz = malloc(sizeof(float) * 2 * npx), *rpx = malloc(sizeof(float) * npx);
    double fetches = 0.0;
    for (int y = 0; y < h; y++) /* each pixel's projected radius (the setup, not timed) */
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            float q[4];
            obs__prep_position(&f, *obs__plane_px(&gb->depth, w, x, y), x, y, q);
            dnz[2 * i] = q[3];
            dnz[2 * i + 1] = 0.5f;
            rpx[i] = q[3] > 0.0f ? obs__radius_px(&f, q, 0.5f * f.radius) : 0.0f;
            fetches += r.sample_count.data[i];
        }
    double best = 1e30, sink = 0.0;
    for (int rep = 0; rep < 3; rep++) {
        double t0 = now_ms();
        float total = 0.0f;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t i = (size_t)y * w + x;
                int n = (int)r.sample_count.data[i];
                const float *xy = f.adaptive && n >= 2 ? f.sample_table + 2 * (n - 2) : f.sample_xy;
                for (int k = 0; k < n; k++) {
                    int qx = x + (int)(xy[2 * k] * rpx[i]), qy = y + (int)(xy[2 * k + 1] * rpx[i]);
                    qx = qx < 0 ? 0 : qx >= w ? w - 1 : qx;
                    qy = qy < 0 ? 0 : qy >= h ? h - 1 : qy;
                    const float *d = dnz + 2 * ((size_t)qy * w + qx);
                    total += d[0] * d[1];
                }
            }
        double t = now_ms() - t0;
        sink += total;
        if (t < best)
            best = t;
    }
    printf("| %dx%d | %.0f | %.1f | %.0f | %.1f | %.0f | %.1f |%s\n", w, h, fetches, ao_ms,
           fetches / ao_ms / 1e3, best, fetches / best / 1e3, ao_ms / best, sink == 0.5 ? " " : "");
    obs__cpu_set_threads(before);
    obs_result_free(&r);
    free(dnz);
    free(rpx);
}

/* VAO++ Table 1's structure on the CPU device at 16 samples: VAO,
 * + adaptive sampling (4.1), + culling pre-pass (4.2), VAO++ (both), the
 * effect's wall ms (culling pre-pass + AO pass, what Table 1 counts),
 * medians of `frames` interleaved, at adaptive_diameter `diameter`; the
 * ratio to VAO and the mean samples per pixel with geometry. */
static void bench_cpu_table1(const obs_gbuffer *gb, int frames, const char *diameter)
{
    char err[OBS_ERR_LEN];
    obs_params p[4];
    double t[4][64], mean[4] = {0};
    if (frames > 64)
        frames = 64;
    for (int v = 0; v < 4; v++) {
        memset(&p[v], 0, sizeof p[v]);
        if (obs_param_set(&p[v], "samples", "16", err) != OBS_OK ||
            obs_param_set(&p[v], "adaptive", v & 1 ? "on" : "off", err) != OBS_OK ||
            obs_param_set(&p[v], "culling", v & 2 ? "careful" : "off", err) != OBS_OK ||
            obs_param_set(&p[v], "adaptive_diameter", diameter, err) != OBS_OK) {
            fprintf(stderr, "frame_bench: %s\n", err);
            exit(1);
        }
    }
    for (int i = -1; i < frames; i++) /* -1: the planes allocated, the counts read */
        for (int v = 0; v < 4; v++) {
            obs_result r;
            obs_pass_times pt;
            unsigned out = OBS_OUTPUT_AO | (i < 0 ? OBS_OUTPUT_SAMPLE_COUNT : 0);
            if (obs__run_cpu_timed(gb, &p[v], out, &r, &pt, err) != OBS_OK) {
                fprintf(stderr, "frame_bench: %s\n", err);
                exit(1);
            }
            if (i < 0) {
                double sum = 0.0;
                size_t n = 0;
                for (size_t k = 0; k < (size_t)gb->width * gb->height; k++)
                    if (r.sample_count.data[k] > 0.0f) {
                        sum += r.sample_count.data[k];
                        n++;
                    }
                mean[v] = n ? sum / (double)n : 0.0;
            } else {
                t[v][i] = pt.ms[OBS_PASS_AO] + (pt.ms[OBS_PASS_CULL] > 0 ? pt.ms[OBS_PASS_CULL] : 0);
            }
            obs_result_free(&r);
        }
    double m[4];
    for (int v = 0; v < 4; v++) {
        qsort(t[v], (size_t)frames, sizeof t[v][0], cmp);
        m[v] = t[v][frames / 2];
    }
    printf("| %dx%d | %s |", gb->width, gb->height, diameter);
    for (int v = 0; v < 4; v++)
        printf(v ? " %.1f (%.0f %%) |" : " %.1f |", m[v], 100.0 * m[v] / m[0]);
    printf(" %.1f, %.1f, %.1f, %.1f |\n", mean[0], mean[1], mean[2], mean[3]);
    fflush(stdout);
}

int main(int argc, char **argv)
{
    obs_ctx_desc desc = {0};
    int frames = 15, presets = 0, devices = 0, cpu_w = 0, cpu_h = 0;
    int i = 1;
    for (; i < argc && argv[i][0] == '-'; i++) {
        if (!strcmp(argv[i], "--backend") && i + 1 < argc)
            obs_backend_parse(argv[++i], &desc.backend);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc)
            frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--presets"))
            presets = 1;
        else if (!strcmp(argv[i], "--devices"))
            devices = 1;
        else if (!strcmp(argv[i], "--cpu-only") && i + 1 < argc &&
                 sscanf(argv[++i], "%dx%d", &cpu_w, &cpu_h) != 2) {
            fprintf(stderr, "frame_bench: --cpu-only takes WxH\n");
            return 2;
        }
    }
    if (argc - i < 2 || (argc - i) % 2) {
        fprintf(stderr, "usage: frame_bench [--backend B] [--frames N] [--presets | --devices | --cpu-only WxH] GBUFFER.exr CAMERA.json...\n");
        return 2;
    }
    char err[OBS_ERR_LEN];
    if (cpu_w > 0 && cpu_h > 0) { /* the CPU device alone: no context */
        obs_gbuffer_file gf = {0};
        if (obs_gbuffer_read_exr(argv[i], NULL, NULL, &gf, err) != OBS_OK ||
            obs_camera_read_json(argv[i + 1], &gf.gb.camera, NULL, NULL, err) != OBS_OK) {
            fprintf(stderr, "frame_bench: %s\n", err);
            return 1;
        }
        obs_gbuffer up = upscaled(&gf.gb, cpu_w, cpu_h);
        float *pd = (float *)up.depth.data, *pn = (float *)up.normal.data;
        const char *base = strrchr(argv[i], '/') ? strrchr(argv[i], '/') + 1 : argv[i];
        const char *t1 = getenv("FRAME_BENCH_TABLE1"); /* diameters, comma-separated */
        if (t1) {
            printf("VAO++ Table 1 on the CPU device, 16 samples: effect wall ms (culling pre-pass "
                   "+ AO pass), %% of VAO; mean samples per pixel with geometry\n\n"
                   "| size | adaptive_diameter | VAO | +adaptive | +culling | VAO++ | samples/px "
                   "VAO, +adaptive, +culling, VAO++ |\n|---|---|---|---|---|---|---|\n");
            char list[256];
            snprintf(list, sizeof list, "%s", t1);
            for (char *d = strtok(list, ","); d; d = strtok(NULL, ","))
                bench_cpu_table1(&up, frames, d);
            free(pd);
            free(pn);
            obs_gbuffer_free(&gf);
            return 0;
        }
        bench_cpu_only(base, &up, frames);
        printf("\nThe AO pass (vaopp, default chain, 1 thread, fastest of 3) against a plain gather "
               "loop fetching the same samples (each one 8-byte load of depth and normal z at the "
               "sample's pixel):\n\n| size | samples | AO pass ms | AO Mfetch/s | gather ms | "
               "gather Mfetch/s | AO / gather |\n|---|---|---|---|---|---|---|\n");
        bench_gather_limit(&up);
        free(pd);
        free(pn);
        obs_gbuffer_free(&gf);
        return 0;
    }
    obs_ctx *ctx;
    double t0 = now_ms();
    if (obs_ctx_create(&desc, &ctx, err) != OBS_OK) {
        fprintf(stderr, "frame_bench: %s\n", err);
        return 1;
    }
    double t_ctx = now_ms() - t0;
    obs_ctx_info info;
    obs_ctx_get_info(ctx, &info);
    printf("backend %s, %s, %s; context created in %.1f ms; median of %d warm frames "
           "(upload + passes + readback of AO)\n\n",
           obs_backend_name(info.backend), info.gl_version, info.gl_renderer, t_ctx, frames);
    if (devices)
        printf("| G-buffer (upscaled) | size | method | CPU threads | %s wall ms | cpu wall ms | "
               "cpu / %s |\n|---|---|---|---|---|---|---|\n",
               obs_backend_name(info.backend), obs_backend_name(info.backend));
    else if (presets)
        printf("| G-buffer (upscaled) | size | --quality | wall ms | GL ms | wall x default | GL x "
               "default |\n|---|---|---|---|---|---|---|\n");
    else
        printf("| G-buffer | size | first frame ms (16 samples, compiles shaders) | 8 samples ms | 16 samples ms | "
           "32 samples ms | CPU twin 16 samples ms (x GL) |\n|---|---|---|---|---|---|---|\n");
    char bands[8][512]; /* the deadline's cost, printed after the table */
    int nbands = 0;
    for (; i + 1 < argc; i += 2) {
        obs_gbuffer_file gf = {0};
        if (obs_gbuffer_read_exr(argv[i], NULL, NULL, &gf, err) != OBS_OK ||
            obs_camera_read_json(argv[i + 1], &gf.gb.camera, NULL, NULL, err) != OBS_OK) {
            fprintf(stderr, "frame_bench: %s\n", err);
            return 1;
        }
        const char *base = strrchr(argv[i], '/') ? strrchr(argv[i], '/') + 1 : argv[i];
        if (presets || devices) {
            /* --presets: --quality's presets at 1920x1080 and 3840x2160;
             * --devices: the methods on the two devices at those sizes */
            static const int sizes[2][2] = {{1920, 1080}, {3840, 2160}};
            const char *maxw = getenv("FRAME_BENCH_MAX_WIDTH"); /* e.g. 1920: 1080p only */
            for (int k = 0; k < 2; k++) {
                int pw = sizes[k][0], ph = sizes[k][1];
                if (maxw && pw > atoi(maxw))
                    continue;
                obs_gbuffer up = upscaled(&gf.gb, pw, ph);
                float *pd = (float *)up.depth.data, *pn = (float *)up.normal.data;
                int nf = k ? (frames < 5 ? frames : 5) : frames;
                if (devices)
                    bench_devices(ctx, base, &up, nf, obs__cpu_threads());
                else
                    bench_presets(ctx, base, &up, nf);
                free(pd);
                free(pn);
            }
            obs_gbuffer_free(&gf);
            continue;
        }
        bench(ctx, base, &gf.gb, frames, 1);

        /* the same frame at 1920x1080 */
        obs_gbuffer big = gf.gb;
        int w = 1920, h = 1080;
        float *d = upscale(&gf.gb.depth, gf.gb.width, gf.gb.height, w, h);
        float *n = upscale(&gf.gb.normal, gf.gb.width, gf.gb.height, w, h);
        float *c = upscale(&gf.gb.color, gf.gb.width, gf.gb.height, w, h);
        big.width = w;
        big.height = h;
        big.display_width = big.display_height = 0;
        big.display_x = big.display_y = 0;
        big.depth = (obs_plane){d, 1, 0};
        big.normal = (obs_plane){n, 3, 0};
        big.color = (obs_plane){c, 4, 0};
        char name[256];
        snprintf(name, sizeof name, "%s upscaled", base);
        bench(ctx, name, &big, frames, 0);
        if (nbands < 8)
            bench_bands(ctx, name, &big, frames, bands[nbands++], sizeof bands[0]);
        free(d);
        free(n);
        free(c);
        obs_gbuffer_free(&gf);
    }
    if (nbands)
        printf("\n| G-buffer (16 samples) | size | frame ms, AO pass in one draw | AO pass in 16 "
           "bands (a deadline set) ms | ratio |\n|---|---|---|---|---|\n");
    for (int b = 0; b < nbands; b++)
        fputs(bands[b], stdout);
    if (presets)
        presets_passes();
    if (devices)
        devices_passes();
    obs_ctx_destroy(ctx);
    return 0;
}
