/* --backend auto's device (obs_device_choose, obscura.h): a GPU through
 * EGL when there is one; else the faster of the CPU device and the
 * software GL context for the chain, measured once per machine, method
 * and thread count on a synthetic frame and kept in the cache folder's
 * devices.txt. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "obscura/obscura.h"
#include "internal.h"
#include "obscura/params.h"
#include "pool.h"

/* The measurement's frame: 960x540 (a quarter of 1080p: the passes'
 * costs per pixel, not a fixed cost, decide), 1 warm-up and 3 timed
 * frames each, interleaved so that the machine's load hits both. */
enum { MEASURE_W = 960, MEASURE_H = 540, MEASURE_FRAMES = 3 };

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* An EGL GPU device, found by creating a context on it (then released):
 * the backend every other choice gives way to. */
static int gpu_found(obs_device_choice *out)
{
    obs_ctx_desc gpu = {.backend = OBS_BACKEND_EGL_DEVICE};
    obs_ctx *ctx;
    char why[OBS_ERR_LEN];
    if (obs_ctx_create(&gpu, &ctx, why) != OBS_OK)
        return 0;
    obs_ctx_destroy(ctx);
    out->backend = OBS_BACKEND_EGL_DEVICE;
    snprintf(out->why, sizeof out->why, "an EGL GPU device");
    return 1;
}

void obs__device_key(const char *method, char *buf, size_t n)
{
    char host[128] = "?";
    if (gethostname(host, sizeof host - 1) != 0)
        snprintf(host, sizeof host, "?");
    host[sizeof host - 1] = '\0';
    for (char *c = host; *c; c++)
        if (*c == ' ' || *c == '\t' || *c == '\n')
            *c = '_';
    snprintf(buf, n, "%s %s %s %d", host, OBS_VERSION, method, obs__pool_threads(0));
}

/* The cached choice for key: 1 cpu, 0 gl, -1 none (or no folder). */
static int cached(const char *path, const char *key, double *cpu_ms, double *gl_ms)
{
    FILE *fp = path[0] ? fopen(path, "r") : NULL;
    char line[512], choice[16];
    int found = -1;
    size_t kl = strlen(key);
    if (!fp)
        return -1;
    double c, g;
    while (fgets(line, sizeof line, fp)) /* the last whole line of the key wins */
        if (!strncmp(line, key, kl) && line[kl] == ' ' &&
            sscanf(line + kl, " %15s %lf %lf", choice, &c, &g) == 3 &&
            (!strcmp(choice, "cpu") || !strcmp(choice, "gl"))) {
            found = !strcmp(choice, "cpu");
            *cpu_ms = c;
            *gl_ms = g;
        }
    fclose(fp);
    return found;
}

static void remember(const char *dir, const char *path, const char *key, int cpu, double cpu_ms,
                     double gl_ms)
{
    if (!dir[0])
        return;
    if (mkdir(dir, 0755) != 0 && errno != EEXIST)
        return; /* no folder: measured again next time */
    FILE *fp = fopen(path, "a");
    if (!fp)
        return;
    fprintf(fp, "%s %s %.1f %.1f\n", key, cpu ? "cpu" : "gl", cpu_ms, gl_ms);
    fclose(fp);
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* A synthetic frame with something to occlude: a floor receding to the
 * horizon under a wall, with round bumps (depth only; normals from the
 * positions, as the chain reconstructs them). */
static float *synthetic_depth(void)
{
    float *d = malloc(sizeof(float) * MEASURE_W * MEASURE_H);
    if (!d)
        return NULL;
    for (int y = 0; y < MEASURE_H; y++)
        for (int x = 0; x < MEASURE_W; x++) {
            float v = (float)y / MEASURE_H, u = (float)x / MEASURE_W;
            float z = v > 0.45f ? 2.0f / (v - 0.4f) : 20.0f; /* floor, then the wall at 20 */
            z = z < 20.0f ? z : 20.0f;
            for (int k = 0; k < 6; k++) { /* bumps */
                float cu = 0.1f + 0.16f * (float)k, cv = 0.35f + 0.08f * (float)(k % 3);
                float r2 = ((u - cu) * (u - cu) * 3.2f + (v - cv) * (v - cv)) / 0.004f;
                if (r2 < 1.0f)
                    z -= 1.5f * sqrtf(1.0f - r2);
            }
            d[(size_t)y * MEASURE_W + (size_t)x] = z;
        }
    return d;
}

/* Median ms of the chain on both devices; 0, or the failing status. */
static obs_status measure(obs_ctx *ctx, const obs_params *params, double *cpu_ms, double *gl_ms,
                          char err[OBS_ERR_LEN])
{
    double t[2][MEASURE_FRAMES];
    float *depth = synthetic_depth();
    if (!depth) {
        snprintf(err, OBS_ERR_LEN, "out of memory for the device measurement's frame");
        return OBS_NO_MEMORY;
    }
    obs_gbuffer gb = {0};
    gb.width = MEASURE_W;
    gb.height = MEASURE_H;
    gb.depth = (obs_plane){depth, 1, 0};
    obs_params p = *params;
    obs_status s = obs_param_set(&p, "fov_y", "50", err);
    for (int i = -1; s == OBS_OK && i < MEASURE_FRAMES; i++) /* -1: warm-up */
        for (int cpu = 0; s == OBS_OK && cpu < 2; cpu++) {
            obs_result r;
            double t0 = now_ms();
            s = cpu ? obs_run_cpu(&gb, &p, OBS_OUTPUT_AO, &r, err)
                    : obs_run(ctx, &gb, &p, OBS_OUTPUT_AO, &r, err);
            if (s != OBS_OK)
                break;
            obs_result_free(&r);
            if (i >= 0)
                t[cpu][i] = now_ms() - t0;
        }
    free(depth);
    if (s != OBS_OK)
        return s;
    qsort(t[0], MEASURE_FRAMES, sizeof t[0][0], cmp);
    qsort(t[1], MEASURE_FRAMES, sizeof t[1][0], cmp);
    *gl_ms = t[0][MEASURE_FRAMES / 2];
    *cpu_ms = t[1][MEASURE_FRAMES / 2];
    return OBS_OK;
}

obs_status obs_device_choose(const char *cache_dir, const obs_params *params, int measure_now,
                             obs_device_choice *out, char err[OBS_ERR_LEN])
{
    obs_params none = {0}, resolved;
    char method[64], key[256], path[4200];
    const char *dir = cache_dir ? cache_dir : "";
    if (!params)
        params = &none;
    memset(out, 0, sizeof *out);
    out->backend = OBS_BACKEND_AUTO;
    out->cpu_ms = out->gl_ms = -1.0;
    obs_params_resolve(params, &resolved); /* the method by name, the default's too */
    obs_param_format(&resolved, obs_param_find("method"), method, sizeof method);
    obs__device_key(method, key, sizeof key);
    snprintf(path, sizeof path, "%s/devices.txt", dir);
    if (measure_now && gpu_found(out))
        return OBS_OK; /* a GPU first: it wins over both */
    int c = dir[0] ? cached(path, key, &out->cpu_ms, &out->gl_ms) : -1;
    if (c >= 0) {
        out->cpu = c;
        out->cached = 1;
        snprintf(out->why, sizeof out->why, "%s, measured before (cpu %.1f ms, GL %.1f ms; %.120s)",
                 c ? "the CPU device" : "the software GL context", out->cpu_ms, out->gl_ms, path);
        return OBS_OK;
    }
    if (!measure_now) { /* nothing kept: a GPU, else the CPU device */
        if (gpu_found(out))
            return OBS_OK;
        out->cpu = 1;
        snprintf(out->why, sizeof out->why,
                 "the CPU device (no EGL GPU device; faster than llvmpipe on every method, "
                 "bench/RESULTS.md; --backend auto measures this machine)");
        return OBS_OK;
    }
    obs_ctx_desc sw = {.backend = OBS_BACKEND_AUTO, .cache_dir = cache_dir};
    obs_ctx *ctx;
    char why[OBS_ERR_LEN];
    if (obs_ctx_create(&sw, &ctx, why) != OBS_OK) { /* no GL at all: the CPU device */
        out->cpu = 1;
        snprintf(out->why, sizeof out->why, "the CPU device (no GL context: %.160s)", why);
        return OBS_OK;
    }
    obs_status s = measure(ctx, params, &out->cpu_ms, &out->gl_ms, err);
    obs_ctx_destroy(ctx);
    if (s != OBS_OK)
        return s;
    out->cpu = out->cpu_ms < out->gl_ms;
    out->measured = 1;
    remember(dir, path, key, out->cpu, out->cpu_ms, out->gl_ms);
    snprintf(out->why, sizeof out->why, "%s, measured now (cpu %.1f ms, GL %.1f ms at %dx%d)",
             out->cpu ? "the CPU device" : "the software GL context", out->cpu_ms, out->gl_ms,
             MEASURE_W, MEASURE_H);
    return OBS_OK;
}
