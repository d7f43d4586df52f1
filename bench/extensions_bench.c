/* The structure of VAO++ Table 1 on this machine: plain VAO, + adaptive
 * sampling (4.1), + culling pre-pass (4.2), VAO++ (both), at 2..32
 * samples and two resolutions, timed on the GL timeline.
 *
 *   extensions_bench [--backend B] [--frames N] [--frames-4k N]
 *                    [--sizes WxH,...] [--set NAME=VALUE]... G-BUFFER.exr
 *                    [CAMERA.json]
 *   extensions_bench --methods [same options]   (Table 2 instead)
 *
 * The G-buffer is scaled (nearest neighbour, same camera) to each size
 * unless it already has that size.  Per cell: the median over N frames of
 * the effect's GL time (culling pre-pass + AO pass, what Table 1 counts),
 * and of the whole chain (GL time of every pass; wall time of obs_run,
 * upload and readback included).  The four variants run interleaved, one
 * frame each in turn, so that the machine's drift hits them alike; the
 * ratios are to VAO in the same run.  The depth range check and the blur
 * stay on in every column (they are quality extensions, not timed by
 * Table 1), so every column is the same chain with one switch changed.
 * --set gives every variant a parameter of the table (adaptive_diameter,
 * say: adaptive sampling picks counts by the disk's size on screen, so
 * whether it saves anything depends on the scene and on that value).
 * --methods prints the structure of Table 2 instead: VAO++ at 2, 4, 8,
 * 16 samples against the other methods of --method at matching levels
 * (hemisphere 3, 6, 10, 16 samples as Table 2's Unity SSAO; angle and
 * hbao at the same number of depth samples: n/2 pairs, directions x steps
 * = n), the same effect time, ratios VAO++ / method.
 * Output: Markdown. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "obscura/io.h"
#include "obscura/obscura.h"

enum { VARIANTS = 4, COUNTS = 5, MAX_FRAMES = 64, MAX_SIZES = 4 };

static const char *const variant_name[VARIANTS] = {"VAO", "+adaptive", "+culling", "VAO++"};
static const int counts[COUNTS] = {2, 4, 8, 16, 32};

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

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof v[0], cmp);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static void die(const char *what, const char *err)
{
    fprintf(stderr, "extensions_bench: %s: %s\n", what, err);
    exit(1);
}

static void set(obs_params *p, const char *name, const char *value)
{
    char err[OBS_ERR_LEN];
    if (obs_param_set(p, name, value, err) != OBS_OK)
        die(name, err);
}

enum { MAX_SETS = 8 };
static const char *set_name[MAX_SETS], *set_value[MAX_SETS];
static int nsets;

static obs_params variant_params(int v, int samples)
{
    obs_params p = {0};
    for (int i = 0; i < nsets; i++)
        set(&p, set_name[i], set_value[i]);
    char n[16];
    snprintf(n, sizeof n, "%d", samples);
    set(&p, "samples", n);
    set(&p, "adaptive", v == 1 || v == 3 ? "on" : "off");
    set(&p, "culling", v == 2 || v == 3 ? "careful" : "off");
    return p;
}

/* Nearest-neighbour copy of one plane at w x h (tightly packed). */
static float *scale_plane(const obs_plane *p, int sw, int sh, int w, int h)
{
    if (!p->data)
        return NULL;
    float *out = malloc(sizeof(float) * (size_t)w * h * p->channels);
    if (!out)
        die("scaling", "out of memory");
    size_t stride = p->row_stride ? p->row_stride : sizeof(float) * (size_t)sw * p->channels;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const char *row = (const char *)p->data + (size_t)((long long)y * sh / h) * stride;
            const float *src = (const float *)row + (size_t)((long long)x * sw / w) * p->channels;
            memcpy(out + ((size_t)y * w + x) * p->channels, src, sizeof(float) * p->channels);
        }
    return out;
}

typedef struct cell {
    double effect, chain_gl, wall; /* medians, ms */
    double mean_samples;           /* per pixel with geometry */
} cell;

/* Mean sample count over the pixels that took samples (VAO++ 4.1's
 * debug output). */
static double mean_samples(obs_ctx *ctx, const obs_gbuffer *gb, int v, int samples)
{
    char err[OBS_ERR_LEN];
    obs_params p = variant_params(v, samples);
    obs_result r;
    obs_params resolved;
    obs_params_resolve(&p, &resolved);
    if (resolved.ao_resolution == OBS_RESOLUTION_HALF)
        return NAN; /* no per-pixel count at half resolution; printed "nan" */
    if (obs_run(ctx, gb, &p, OBS_OUTPUT_SAMPLE_COUNT, &r, err) != OBS_OK)
        die("obs_run", err);
    double sum = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < (size_t)r.sample_count.width * r.sample_count.height; i++)
        if (r.sample_count.data[i] > 0.0f) {
            sum += r.sample_count.data[i];
            n++;
        }
    obs_result_free(&r);
    return n ? sum / n : 0.0;
}

/* One frame of variant v; returns its times. */
static void frame(obs_ctx *ctx, const obs_gbuffer *gb, int v, int samples, double *effect,
                  double *chain_gl, double *wall)
{
    char err[OBS_ERR_LEN];
    obs_params p = variant_params(v, samples);
    obs_result r;
    obs_pass_times t;
    double t0 = now_ms();
    if (obs_run(ctx, gb, &p, OBS_OUTPUT_AO, &r, err) != OBS_OK)
        die("obs_run", err);
    *wall = now_ms() - t0;
    obs_result_free(&r);
    if (!obs_ctx_last_times(ctx, &t))
        die("timer queries", "no times after a timed frame");
    *effect = t.ms[OBS_PASS_AO] + (t.ms[OBS_PASS_CULL] > 0 ? t.ms[OBS_PASS_CULL] : 0);
    *chain_gl = t.total_ms;
}

static void measure(obs_ctx *ctx, const obs_gbuffer *gb, int frames, cell out[COUNTS][VARIANTS])
{
    for (int c = 0; c < COUNTS; c++) {
        double e[VARIANTS][MAX_FRAMES], g[VARIANTS][MAX_FRAMES], w[VARIANTS][MAX_FRAMES];
        /* one warm-up frame per variant: programs, targets, caches */
        for (int v = 0; v < VARIANTS; v++)
            frame(ctx, gb, v, counts[c], &e[v][0], &g[v][0], &w[v][0]);
        for (int i = 0; i < frames; i++)
            for (int v = 0; v < VARIANTS; v++)
                frame(ctx, gb, v, counts[c], &e[v][i], &g[v][i], &w[v][i]);
        for (int v = 0; v < VARIANTS; v++)
            out[c][v] = (cell){median(e[v], frames), median(g[v], frames), median(w[v], frames),
                               mean_samples(ctx, gb, v, counts[c])};
        fprintf(stderr, "extensions_bench: %dx%d, %d samples done\n", gb->width, gb->height,
                counts[c]);
    }
}

/* ---- Table 2: the methods at four quality levels ------------------------ */

enum { LEVELS = 4, METHODS = 4 };
/* per level: vaopp samples, hemisphere samples, angle pairs, hbao dirs, hbao steps */
static const int level[LEVELS][5] = {
    {2, 3, 1, 2, 1}, {4, 6, 2, 4, 1}, {8, 10, 4, 4, 2}, {16, 16, 8, 4, 4}};

static obs_params method_params(int m, int l)
{
    obs_params p = {0};
    char a[16], b[16];
    for (int i = 0; i < nsets; i++)
        set(&p, set_name[i], set_value[i]);
    if (m == 0) {
        snprintf(a, sizeof a, "%d", level[l][0]);
        set(&p, "samples", a);
    } else if (m == 1) {
        set(&p, "method", "hemisphere");
        snprintf(a, sizeof a, "%d", level[l][1]);
        set(&p, "hemisphere_samples", a);
    } else if (m == 2) {
        set(&p, "method", "angle");
        snprintf(a, sizeof a, "%d", level[l][2]);
        set(&p, "angle_pairs", a);
    } else {
        set(&p, "method", "hbao");
        snprintf(a, sizeof a, "%d", level[l][3]);
        snprintf(b, sizeof b, "%d", level[l][4]);
        set(&p, "hbao_directions", a);
        set(&p, "hbao_steps", b);
    }
    return p;
}

static double effect_of(obs_ctx *ctx, const obs_gbuffer *gb, const obs_params *p)
{
    char err[OBS_ERR_LEN];
    obs_result r;
    obs_pass_times t;
    if (obs_run(ctx, gb, p, OBS_OUTPUT_AO, &r, err) != OBS_OK)
        die("obs_run", err);
    obs_result_free(&r);
    if (!obs_ctx_last_times(ctx, &t))
        die("timer queries", "no times after a timed frame");
    return t.ms[OBS_PASS_AO] + (t.ms[OBS_PASS_CULL] > 0 ? t.ms[OBS_PASS_CULL] : 0);
}

static void methods_table(obs_ctx *ctx, const obs_gbuffer *gb, int frames)
{
    printf("%dx%d, median of %d frames, effect GL ms (culling pre-pass + AO pass); in "
           "brackets VAO++ / method.\n\n| level | VAO++ | hemisphere | angle | hbao |\n"
           "|---|---|---|---|---|\n",
           gb->width, gb->height, frames);
    for (int l = 0; l < LEVELS; l++) {
        double t[METHODS][MAX_FRAMES], med[METHODS];
        obs_params p[METHODS];
        for (int m = 0; m < METHODS; m++) {
            p[m] = method_params(m, l);
            effect_of(ctx, gb, &p[m]); /* warm-up: programs, caches */
        }
        for (int i = 0; i < frames; i++)
            for (int m = 0; m < METHODS; m++)
                t[m][i] = effect_of(ctx, gb, &p[m]);
        for (int m = 0; m < METHODS; m++)
            med[m] = median(t[m], frames);
        printf("| %d |", l + 1);
        printf(" %d samples: %.1f |", level[l][0], med[0]);
        printf(" %d samples: %.1f (%.0f %%) |", level[l][1], med[1], 100.0 * med[0] / med[1]);
        printf(" %d pairs: %.1f (%.0f %%) |", level[l][2], med[2], 100.0 * med[0] / med[2]);
        printf(" %dx%d: %.1f (%.0f %%) |\n", level[l][3], level[l][4], med[3],
               100.0 * med[0] / med[3]);
        fflush(stdout);
        fprintf(stderr, "extensions_bench: %dx%d, methods level %d done\n", gb->width,
                gb->height, l + 1);
    }
    printf("\n");
}

static void print_table(int w, int h, int frames, cell t[COUNTS][VARIANTS])
{
    printf("%dx%d, median of %d frames. Effect = GL time of the culling pre-pass + AO pass "
           "(ms, %% of VAO); chain = GL time of every pass / wall time of obs_run (ms).\n\n",
           w, h, frames);
    printf("| samples |");
    for (int v = 0; v < VARIANTS; v++)
        printf(" %s effect |", variant_name[v]);
    for (int v = 0; v < VARIANTS; v++)
        printf(" %s chain GL / wall |", variant_name[v]);
    printf(" mean samples/pixel +adaptive, VAO++ |");
    printf("\n|---|");
    for (int v = 0; v < 2 * VARIANTS + 1; v++)
        printf("---|");
    printf("\n");
    for (int c = 0; c < COUNTS; c++) {
        printf("| %d |", counts[c]);
        for (int v = 0; v < VARIANTS; v++) {
            if (v == 0)
                printf(" %.1f |", t[c][v].effect);
            else
                printf(" %.1f (%.0f %%) |", t[c][v].effect, 100.0 * t[c][v].effect / t[c][0].effect);
        }
        for (int v = 0; v < VARIANTS; v++)
            printf(" %.1f / %.1f |", t[c][v].chain_gl, t[c][v].wall);
        printf(" %.1f, %.1f |\n", t[c][1].mean_samples, t[c][3].mean_samples);
    }
    printf("\n");
    fflush(stdout);
}

/* The default chain, pass by pass (what limits the 50 ms goal). */
static void print_passes(obs_ctx *ctx, const obs_gbuffer *gb, int frames)
{
    char err[OBS_ERR_LEN];
    double ms[OBS_PASS_COUNT][MAX_FRAMES], wall[MAX_FRAMES];
    obs_params vpp = variant_params(3, 16);
    for (int i = -1; i < frames; i++) {
        obs_result r;
        obs_pass_times t;
        double t0 = now_ms();
        if (obs_run(ctx, gb, &vpp, OBS_OUTPUT_AO, &r, err) != OBS_OK)
            die("obs_run", err);
        double wt = now_ms() - t0;
        obs_result_free(&r);
        if (i < 0 || !obs_ctx_last_times(ctx, &t))
            continue;
        for (int p = 0; p < OBS_PASS_COUNT; p++)
            ms[p][i] = t.ms[p];
        wall[i] = wt;
    }
    printf("VAO++ chain (16 samples, range check, blur; --set values) at %dx%d, per pass, median of "
           "%d frames:\n\n| pass | GL ms |\n|---|---|\n",
           gb->width, gb->height, frames);
    for (int p = 0; p < OBS_PASS_COUNT; p++) {
        double m = median(ms[p], frames);
        if (m >= 0.0)
            printf("| %s | %.1f |\n", obs_pass_name((obs_pass)p), m);
    }
    printf("| obs_run wall time | %.1f |\n\n", median(wall, frames));
    fflush(stdout);
}

int main(int argc, char **argv)
{
    obs_ctx_desc desc = {0};
    int frames = 5, frames_big = 3;
    int sizes[MAX_SIZES][2] = {{1920, 1080}, {3840, 2160}}, nsizes = 2;
    int i = 1, methods = 0;
    for (; i < argc && argv[i][0] == '-'; i++) {
        if (!strcmp(argv[i], "--methods")) {
            methods = 1;
        } else if (!strcmp(argv[i], "--backend") && i + 1 < argc) {
            if (obs_backend_parse(argv[++i], &desc.backend) != OBS_OK)
                die("--backend", "unknown backend");
        } else if (!strcmp(argv[i], "--frames") && i + 1 < argc) {
            frames = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--frames-4k") && i + 1 < argc) {
            frames_big = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--sizes") && i + 1 < argc) {
            char *s = argv[++i];
            for (nsizes = 0; nsizes < MAX_SIZES && *s;) {
                char *end;
                sizes[nsizes][0] = (int)strtol(s, &end, 10);
                if (*end != 'x')
                    die("--sizes", "expected WxH,WxH...");
                sizes[nsizes][1] = (int)strtol(end + 1, &end, 10);
                nsizes++;
                s = *end == ',' ? end + 1 : end;
            }
        } else if (!strcmp(argv[i], "--set") && i + 1 < argc && nsets < MAX_SETS) {
            char *eq = strchr(argv[++i], '=');
            if (!eq)
                die("--set", "expected NAME=VALUE");
            *eq = '\0';
            set_name[nsets] = argv[i];
            set_value[nsets++] = eq + 1;
        } else {
            die(argv[i], "unknown option");
        }
    }
    if (argc - i < 1 || argc - i > 2 || frames < 1 || frames >= MAX_FRAMES || frames_big < 1 ||
        frames_big >= MAX_FRAMES) {
        fprintf(stderr, "usage: extensions_bench [--methods] [--backend B] [--frames N] "
                        "[--frames-4k N] [--sizes WxH,...] [--set NAME=VALUE]... GBUFFER.exr "
                        "[CAMERA.json]\n");
        return 2;
    }
    char err[OBS_ERR_LEN];
    obs_gbuffer_file gf = {0};
    if (obs_gbuffer_read_exr(argv[i], NULL, NULL, &gf, err) != OBS_OK)
        die(argv[i], err);
    if (argc - i == 2 && obs_camera_read_json(argv[i + 1], &gf.gb.camera, NULL, NULL, err) != OBS_OK)
        die(argv[i + 1], err);

    obs_ctx *ctx;
    if (obs_ctx_create(&desc, &ctx, err) != OBS_OK)
        die("GL context", err);
    if (obs_ctx_set_timing(ctx, 1, err) != OBS_OK)
        die("timer queries", err);
    obs_ctx_info info;
    obs_ctx_get_info(ctx, &info);
    printf("Renderer: %s, %s (backend %s). Input: %s (%dx%d), nearest-neighbour scaled to each size unless it has it.",
           info.gl_renderer, info.gl_version, obs_backend_name(info.backend), argv[i],
           gf.gb.width, gf.gb.height);
    for (int k = 0; k < nsets; k++)
        printf(" %s%s = %s", k ? "," : " Every variant:", set_name[k], set_value[k]);
    printf("\n\n");

    for (int s = 0; s < nsizes; s++) {
        int w = sizes[s][0], h = sizes[s][1];
        obs_gbuffer big = gf.gb;
        big.width = w;
        big.height = h;
        big.display_x = big.display_y = big.display_width = big.display_height = 0;
        float *d = scale_plane(&gf.gb.depth, gf.gb.width, gf.gb.height, w, h);
        float *n = scale_plane(&gf.gb.normal, gf.gb.width, gf.gb.height, w, h);
        float *c = scale_plane(&gf.gb.color, gf.gb.width, gf.gb.height, w, h);
        big.depth = (obs_plane){d, 1, 0};
        big.normal = (obs_plane){n, gf.gb.normal.channels, 0};
        big.color = (obs_plane){c, gf.gb.color.channels, 0};
        int nf = (long long)w * h > 4000000 ? frames_big : frames;
        if (methods) {
            methods_table(ctx, &big, nf);
        } else {
            cell t[COUNTS][VARIANTS];
            measure(ctx, &big, nf, t);
            print_table(w, h, nf, t);
            print_passes(ctx, &big, nf);
        }
        free(d);
        free(n);
        free(c);
    }
    obs_ctx_destroy(ctx);
    obs_gbuffer_free(&gf);
    return 0;
}
