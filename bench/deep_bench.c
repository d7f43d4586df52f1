/* deep_bench: OITAO (Bauer et al.) Table I for obscura's deep input: list
 * compression to m = 2, 4, 8 nodes against the uncompressed lists, time
 * per stage and the AO error, on the three deep EXRs of OpenEXR's
 * LowResLeftView set merged into one A-buffer (Balls, Leaves, Trunks:
 * their flat composite is composited.exr).  Stages: the compression
 * (eq 5, CPU, timed alone), the upload of the node planes, the AO pass and
 * the read-back (obs_ctx_set_timing: core/deep/deep_gl.c times them between
 * glFinish calls), and the
 * rest of the run on the CPU (node prep, composite).  Writes the AO PNGs
 * of bench/deep/ and a Markdown table on stdout.
 *
 *   deep_bench DIR OUTDIR [--cpu]
 *
 * The files carry no camera: a 40 degree vertical field of view is
 * assumed, and an AO distance of 20 depth units (their Z spans 72..992). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "obscura/deep.h"
#include "obscura/io.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static int cmp_z(const void *a, const void *b)
{
    float za = ((const float *)a)[OBS_DEEP_Z], zb = ((const float *)b)[OBS_DEEP_Z];
    return za < zb ? -1 : za > zb;
}

/* The images' samples in one A-buffer over the display window. */
static int merge(obs_deep_image *in, int n, obs_deep_image *out)
{
    int W = in[0].display_width, H = in[0].display_height;
    size_t npx = (size_t)W * H, total = 0;
    memset(out, 0, sizeof *out);
    for (int k = 0; k < n; k++)
        total += in[k].offset[(size_t)in[k].width * in[k].height];
    out->offset = calloc(npx + 1, sizeof *out->offset);
    out->samples = malloc(total * OBS_DEEP_CH * sizeof(float));
    if (!out->offset || !out->samples)
        return -1;
    for (int pass = 0; pass < 2; pass++) {
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                size_t i = (size_t)y * W + x, at = pass ? out->offset[i] : 0, c = 0;
                for (int k = 0; k < n; k++) {
                    int lx = x - in[k].display_x, ly = y - in[k].display_y;
                    if (lx < 0 || ly < 0 || lx >= in[k].width || ly >= in[k].height)
                        continue;
                    size_t j = (size_t)ly * in[k].width + lx;
                    size_t m = in[k].offset[j + 1] - in[k].offset[j];
                    if (pass)
                        memcpy(out->samples + (at + c) * OBS_DEEP_CH,
                               in[k].samples + in[k].offset[j] * OBS_DEEP_CH, m * OBS_DEEP_CH * sizeof(float));
                    c += m;
                }
                if (!pass)
                    out->offset[i + 1] = c;
                else
                    qsort(out->samples + at * OBS_DEEP_CH, c, OBS_DEEP_CH * sizeof(float), cmp_z);
            }
        if (!pass)
            for (size_t i = 0; i < npx; i++)
                out->offset[i + 1] += out->offset[i];
    }
    out->width = out->display_width = W;
    out->height = out->display_height = H;
    out->has_alpha = out->has_color = out->has_zback = 1;
    return 0;
}

typedef struct variant {
    const char *label;
    const char *layers, *front_half, *mode;
} variant;

int main(int argc, char **argv)
{
    static const char *const names[] = {"Balls", "Leaves", "Trunks"};
    obs_deep_image img[3], all;
    obs_ctx *ctx = NULL;
    char err[OBS_ERR_LEN] = "", path[1024];
    int cpu = argc > 3 && !strcmp(argv[3], "--cpu");
    if (argc < 3) {
        fprintf(stderr, "usage: deep_bench DIR OUTDIR [--cpu]\n");
        return 2;
    }
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/%s.exr", argv[1], names[k]);
        if (obs_deep_read_exr(path, NULL, &img[k], err) != OBS_OK) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
    }
    if (merge(img, 3, &all) != 0)
        return 1;
    size_t npx = (size_t)all.width * all.height;
    uint64_t most = 0;
    for (size_t i = 0; i < npx; i++)
        if (all.offset[i + 1] - all.offset[i] > most)
            most = all.offset[i + 1] - all.offset[i];
    obs_ctx_desc desc = {0};
    if (!cpu && obs_ctx_create(&desc, &ctx, err) != OBS_OK) {
        fprintf(stderr, "no GL (%s): CPU twin\n", err);
        cpu = 1;
    }
    obs_ctx_info ci = {0};
    if (ctx) {
        obs_ctx_get_info(ctx, &ci);
        if (obs_ctx_set_timing(ctx, 1, err) != OBS_OK) {
            fprintf(stderr, "timer queries: %s\n", err);
            return 1;
        }
    }

    /* AO PNGs of each file alone, then the merged scene below */
    for (int k = 0; k < 3; k++) {
        obs_params p = {0};
        obs_deep_result r;
        obs_param_set(&p, "fov_y", "40", err);
        obs_param_set(&p, "radius", "20", err);
        obs_status s = cpu ? obs_deep_run_cpu(&img[k], &p, &r, err) : obs_deep_run(ctx, &img[k], &p, &r, err);
        if (s != OBS_OK) {
            fprintf(stderr, "%s: %s\n", names[k], err);
            return 1;
        }
        snprintf(path, sizeof path, "%s/%s.ao.png", argv[2], names[k]);
        obs_png_write(path, &r.ao_blend, 8, 0, err);
        obs_deep_result_free(&r);
    }

    const variant v[] = {
        {"uncompressed", "8", "off", "multi"}, /* m = 8 >= the most samples of a pixel */
        {"m = 8", "8", "off", "multi"},
        {"m = 4", "4", "off", "multi"},
        {"m = 4, front half", "4", "on", "multi"},
        {"m = 2", "2", "off", "multi"},
        {"m = 2, front half", "2", "on", "multi"},
        {"single layer (m = 4)", "4", "off", "single"},
    };
    const int nv = (int)(sizeof v / sizeof v[0]);
    obs_image ref = {0};
    printf("Merged A-buffer: %dx%d, %llu samples, at most %llu per pixel; %s; 16 samples, "
           "radius 20, fov 40 (assumed).\n\n",
           all.width, all.height, (unsigned long long)all.offset[npx], (unsigned long long)most,
           cpu ? "CPU twin" : ci.gl_renderer);
    printf("| stage | %s", v[0].label);
    for (int k = 1; k < nv; k++)
        printf(" | %s", v[k].label);
    printf(" |\n|---");
    for (int k = 0; k < nv; k++)
        printf("|---");
    printf("|\n");
    double t_comp[16], t_ao[16], mean_err[16], max_err[16], frac[16];
    obs_pass_times gl[16];
    for (int k = 0; k < nv; k++) {
        obs_params p = {0};
        obs_deep_layers l;
        obs_deep_result r;
        obs_param_set(&p, "fov_y", "40", err);
        obs_param_set(&p, "radius", "20", err);
        obs_param_set(&p, "deep_layers", v[k].layers, err);
        obs_param_set(&p, "deep_front_half", v[k].front_half, err);
        obs_param_set(&p, "deep_mode", v[k].mode, err);
        /* the compression alone (the paper's "Resolve OIT" stage), best of 3 */
        t_comp[k] = 1e30;
        for (int rep = 0; rep < 3; rep++) {
            double t0 = now_ms();
            if (k == 0)
                obs_deep_compress(&all, 0, 0, &l, err); /* front nodes as they are */
            else
                obs_deep_compress(&all, atoi(v[k].layers), !strcmp(v[k].front_half, "on"), &l, err);
            double t = now_ms() - t0;
            t_comp[k] = t < t_comp[k] ? t : t_comp[k];
            obs_deep_layers_free(&l);
        }
        /* the whole run (compression, node prep, AO pass, composite), best of 2 */
        t_ao[k] = 1e30;
        for (int rep = 0; rep < 2; rep++) {
            double t0 = now_ms();
            obs_status s = cpu ? obs_deep_run_cpu(&all, &p, &r, err) : obs_deep_run(ctx, &all, &p, &r, err);
            double t = now_ms() - t0;
            if (s != OBS_OK) {
                fprintf(stderr, "%s: %s\n", v[k].label, err);
                return 1;
            }
            if (t < t_ao[k]) {
                t_ao[k] = t;
                if (!ctx || !obs_ctx_last_times(ctx, &gl[k]))
                    for (int q = 0; q < OBS_PASS_COUNT; q++)
                        gl[k].ms[q] = 0.0;
            }
            if (rep == 0) {
                if (k == 0) {
                    ref = r.ao_blend;
                    r.ao_blend.data = NULL;
                    snprintf(path, sizeof path, "%s/merged_multi.ao.png", argv[2]);
                    obs_png_write(path, &ref, 8, 0, err);
                }
                if (!strcmp(v[k].mode, "single")) {
                    snprintf(path, sizeof path, "%s/merged_single.ao.png", argv[2]);
                    obs_png_write(path, &r.ao_blend, 8, 0, err);
                }
                if (!strcmp(v[k].label, "m = 2")) {
                    snprintf(path, sizeof path, "%s/merged_m2.ao.png", argv[2]);
                    obs_png_write(path, &r.ao_blend, 8, 0, err);
                }
                double sum = 0, mx = 0;
                size_t big = 0;
                for (size_t i = 0; i < npx; i++) {
                    double e = r.ao_blend.data ? fabs((double)r.ao_blend.data[i] - ref.data[i]) : 0.0;
                    sum += e;
                    mx = e > mx ? e : mx;
                    big += e > 1.0 / 255.0;
                }
                mean_err[k] = sum / (double)npx;
                max_err[k] = mx;
                frac[k] = 100.0 * (double)big / (double)npx;
            }
            obs_deep_result_free(&r);
        }
    }
    printf("| compression (ms, CPU) |");
    for (int k = 0; k < nv; k++)
        printf(" %.1f |", t_comp[k]);
    static const struct {
        obs_pass pass;
        const char *label;
    } stages[] = {{OBS_PASS_UPLOAD, "upload of the m node planes (ms, GL, glFinish to glFinish)"},
                  {OBS_PASS_AO, "AO pass (ms, GL, glFinish to glFinish)"},
                  {OBS_PASS_READBACK, "read-back (ms, GL, glFinish to glFinish)"}};
    for (int q = 0; q < 3; q++) {
        printf("\n| %s |", stages[q].label);
        for (int k = 0; k < nv; k++)
            printf(" %.1f |", gl[k].ms[stages[q].pass]);
    }
    printf("\n| node prep, composite, the rest (ms, CPU: whole run minus the above) |");
    for (int k = 0; k < nv; k++)
        printf(" %.0f |", t_ao[k] - t_comp[k] - gl[k].ms[OBS_PASS_UPLOAD] - gl[k].ms[OBS_PASS_AO] -
                              gl[k].ms[OBS_PASS_READBACK]);
    printf("\n| **whole run** (ms, wall clock) |");
    for (int k = 0; k < nv; k++)
        printf(" **%.0f** |", t_ao[k]);
    printf("\n| mean abs. AO error vs uncompressed |");
    for (int k = 0; k < nv; k++)
        printf(" %.5f |", mean_err[k]);
    printf("\n| max abs. AO error |");
    for (int k = 0; k < nv; k++)
        printf(" %.3f |", max_err[k]);
    printf("\n| pixels off by > 1/255 (%%) |");
    for (int k = 0; k < nv; k++)
        printf(" %.2f |", frac[k]);
    printf("\n");
    obs_image_free(&ref);
    for (int k = 0; k < 3; k++)
        obs_deep_free(&img[k]);
    obs_deep_free(&all);
    obs_ctx_destroy(ctx);
    return 0;
}
