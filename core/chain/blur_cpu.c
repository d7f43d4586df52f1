/* CPU twin of the low-pass filter (VAO++ section 4.6, GLSL:
 * blur.frag.glsl): a depth-aware cross-bilateral Gaussian blur in two
 * passes, horizontal then vertical.  Same arithmetic in the same order as
 * the shader; tests/unit/core/test_gl_twin.c compares them. */
#include <math.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "chain/bands_cpu.h"
#include "chain/frame.h"
#include "chain/vao_cpu.h"
#include "pool.h"

float obs__blur_pixel(const obs__frame *f, const float *pos, const float *ao, int x, int y, int dx,
                      int dy)
{
    size_t w = (size_t)f->width;
    float a = ao[(size_t)y * w + (size_t)x];
    float zc = pos[4 * ((size_t)y * w + (size_t)x) + 3];
    if (zc <= 0.0f) /* background: nothing to filter */
        return a;
    float sum = 0.0f, wsum = 0.0f;
    for (int k = -f->blur_radius; k <= f->blur_radius; k++) {
        int qx = x + k * dx, qy = y + k * dy;
        if (qx < 0 || qy < 0 || qx >= f->width || qy >= f->height)
            continue;
        size_t qi = (size_t)qy * w + (size_t)qx;
        float zq = pos[4 * qi + 3];
        /* section 4.6: leave out neighbours over the depth threshold, the
         * AO radius in view units */
        if (zq <= 0.0f || fabsf(zq - zc) > f->radius)
            continue;
        float wk = f->blur_w[k < 0 ? -k : k];
        sum += wk * ao[qi];
        wsum += wk;
    }
    return sum / wsum; /* the centre always counts: wsum > 0 */
}

/* Pixels per span of the vectorised form. */
#define SPAN 256

/* The n pixels of one row from its pixel 0 (the depth at zc[0], the AO
 * at a[0], the result to d[0]), each neighbour k * step away (k in
 * [kmin, kmax]) inside the frame: obs__blur_pixel's arithmetic, in its
 * order of k for every pixel, with the loop over k outside the loop over
 * pixels, so that the pixels run in SIMD lanes (#pragma omp simd, gcc
 * -fopenmp-simd: no OpenMP runtime).  A neighbour left out adds +0 to
 * both sums, which leaves them the same floats (they are never -0), so
 * the result is the scalar one, bit for bit.  Depths zs floats apart;
 * the neighbours' AO step floats apart in a, their depths zstep. */
static inline __attribute__((always_inline)) void blur_span(const obs__frame *f, const float *zc,
                                                            size_t zs, const float *a, float *d,
                                                            int n, ptrdiff_t step, ptrdiff_t zstep,
                                                            int kmin, int kmax)
{
    float sum[SPAN], wsum[SPAN];
    const float radius = f->radius;
    for (int j = 0; j < n; j++)
        sum[j] = wsum[j] = 0.0f;
    for (int k = kmin; k <= kmax; k++) {
        const float wk = f->blur_w[k < 0 ? -k : k];
        const float *zq = zc + (ptrdiff_t)zs * k * zstep, *aq = a + k * step;
#pragma omp simd
        for (int j = 0; j < n; j++) {
            /* section 4.6: leave out neighbours over the depth threshold;
             * computed in every lane, then selected: no branch */
            const float zj = zq[(ptrdiff_t)zs * j];
            const int in = !(zj <= 0.0f) & !(fabsf(zj - zc[(ptrdiff_t)zs * j]) > radius);
            const float t = wk * aq[j];
            sum[j] += in ? t : 0.0f;
            wsum[j] += in ? wk : 0.0f;
        }
    }
#pragma omp simd
    for (int j = 0; j < n; j++) {
        /* in every lane; background keeps its AO (nothing to filter) */
        const float v = sum[j] / wsum[j], aj = a[j];
        d[j] = zc[(ptrdiff_t)zs * j] <= 0.0f ? aj : v;
    }
}

/* The horizontal pass of row y (the frame's src) into drow (the row's
 * pixel 0); the first and last R pixels reach past the row: scalar. */
static inline __attribute__((always_inline)) void blur_h_row(const obs__frame *f,
                                                             const float *pos, const float *z,
                                                             size_t zs, const float *src,
                                                             float *drow, int y)
{
    const int w = f->width, R = f->blur_radius;
    const size_t row = (size_t)y * (size_t)w;
    int xa = R < w ? R : w, xb = w - R > xa ? w - R : xa;
    for (int x = 0; x < xa; x++)
        drow[x] = obs__blur_pixel(f, pos, src, x, y, 1, 0);
    for (int x = xa; x < xb; x += SPAN)
        blur_span(f, z + zs * (row + (size_t)x), zs, src + row + (size_t)x, drow + x,
                  xb - x < SPAN ? xb - x : SPAN, 1, 1, -R, R);
    for (int x = xb; x < w; x++)
        drow[x] = obs__blur_pixel(f, pos, src, x, y, 1, 0);
}

/* The vertical pass of row y: the horizontal result's row y at srow (its
 * rows sstride floats apart), into drow; rows past the frame are left
 * out for the whole row. */
static inline __attribute__((always_inline)) void blur_v_row(const obs__frame *f, const float *z,
                                                             size_t zs, const float *srow,
                                                             ptrdiff_t sstride, float *drow, int y)
{
    const int w = f->width, h = f->height, R = f->blur_radius;
    const size_t row = (size_t)y * (size_t)w;
    int kmin = -y > -R ? -y : -R, kmax = h - 1 - y < R ? h - 1 - y : R;
    for (int x = 0; x < w; x += SPAN)
        blur_span(f, z + zs * (row + (size_t)x), zs, srow + x, drow + x,
                  w - x < SPAN ? w - x : SPAN, sstride, (ptrdiff_t)w, kmin, kmax);
}

/* Rows [y0, y1) of one pass, horizontal (dx) or vertical, plane to
 * plane; depths at z[zs * i], positions (for the scalar pixels) at pos. */
static inline __attribute__((always_inline)) void blur_pass_rows(const obs__frame *f, const float *pos, const float *z, size_t zs,
                                  const float *src, float *dst, int dx, int y0, int y1)
{
    const size_t w = (size_t)f->width;
    for (int y = y0; y < y1; y++) {
        if (dx)
            blur_h_row(f, pos, z, zs, src, dst + (size_t)y * w, y);
        else
            blur_v_row(f, z, zs, src + (size_t)y * w, (ptrdiff_t)w, dst + (size_t)y * w, y);
    }
}

typedef struct blur_job {
    const obs__frame *f;
    const float *pos, *dnz, *src; /* dnz: NULL, or the packed plane (vao_cpu.h) */
    float *dst;
    int dx, rays; /* rays: the conversion of ao_definition rays after the pass */
} blur_job;

OBS__LANES
static void blur_rows(void *ctx, int y0, int y1)
{
    const blur_job *j = ctx;
    if (j->dnz) /* the strides as constants, for the vectoriser */
        blur_pass_rows(j->f, j->pos, j->dnz, 2, j->src, j->dst, j->dx, y0, y1);
    else
        blur_pass_rows(j->f, j->pos, j->pos + 3, 4, j->src, j->dst, j->dx, y0, y1);
    if (j->rays)
        obs__rays_rows(j->dst + (size_t)y0 * (size_t)j->f->width,
                       (size_t)(y1 - y0) * (size_t)j->f->width);
}

/* The two passes fused (the fallback when there is no memory for it:
 * one pass after the other through tmp).  A band of FUSED_ROWS rows runs
 * the horizontal pass over its rows and R rows either side into its
 * thread's scratch, which stays in the core's cache, then the vertical
 * pass from there into dst: the frame is read once and written once, and
 * no band waits for another.  The halo rows are computed by both bands
 * that read them, by the same arithmetic: the same floats. */
#define FUSED_ROWS 32

typedef struct fused_job {
    const obs__frame *f;
    const float *pos, *dnz, *src;
    float *dst, *scratch; /* scratch: per thread, (FUSED_ROWS + 2 R) rows */
    size_t per_thread;
    atomic_int next_slot;
    int rays;
} fused_job;

static void fused_begin(void *ctx, void *local)
{
    fused_job *j = ctx;
    *(float **)local = j->scratch + (size_t)atomic_fetch_add(&j->next_slot, 1) * j->per_thread;
}

static inline __attribute__((always_inline)) void fused_band(const fused_job *j, float *buf,
                                                             const float *z, size_t zs, int y0,
                                                             int y1)
{
    const obs__frame *f = j->f;
    const int R = f->blur_radius, w = f->width;
    const int ya = y0 - R > 0 ? y0 - R : 0, yb = y1 + R < f->height ? y1 + R : f->height;
    for (int y = ya; y < yb; y++)
        blur_h_row(f, j->pos, z, zs, j->src, buf + (size_t)(y - ya) * (size_t)w, y);
    for (int y = y0; y < y1; y++) {
        float *drow = j->dst + (size_t)y * (size_t)w;
        blur_v_row(f, z, zs, buf + (size_t)(y - ya) * (size_t)w, (ptrdiff_t)w, drow, y);
        if (j->rays)
            obs__rays_rows(drow, (size_t)w);
    }
}

OBS__LANES
static int fused_range(void *ctx, void *local, size_t i0, size_t i1)
{
    const fused_job *j = ctx;
    float *buf = *(float **)local;
    if (j->dnz) /* the strides as constants, for the vectoriser */
        fused_band(j, buf, j->dnz, 2, (int)i0, (int)i1);
    else
        fused_band(j, buf, j->pos + 3, 4, (int)i0, (int)i1);
    return 0;
}

/* Both passes from src into dst; with rays, the conversion of
 * ao_definition rays after the vertical one.  Returns the plane that
 * holds the result: dst, or src when the fused form found no memory for
 * its scratch (then the passes run one after the other, through dst). */
static float *blur(const obs__frame *f, const float *pos, const float *dnz, float *src,
                   float *dst, int rays)
{
    if (f->blur_radius <= 0)
        return src;
    const int threads = obs__cpu_threads();
    const size_t per_thread = (size_t)f->width * (size_t)(FUSED_ROWS + 2 * f->blur_radius);
    float *scratch = malloc(sizeof(float) * per_thread * (size_t)threads);
    if (!scratch) {
        blur_job h = {f, pos, dnz, src, dst, 1, 0}, v = {f, pos, dnz, dst, src, 0, rays};
        obs__cpu_rows(f->height, 0, blur_rows, &h);
        obs__cpu_rows(f->height, 0, blur_rows, &v);
        return src;
    }
    fused_job j = {f, pos, dnz, src, dst, scratch, per_thread, 0, rays};
    atomic_init(&j.next_slot, 0);
    obs__pool_for pf = {.end = (size_t)f->height, .chunk = FUSED_ROWS, .threads = threads,
                        .range = fused_range, .ctx = &j, .local_size = sizeof(float *),
                        .begin = fused_begin};
    obs__pool_run(&pf, NULL);
    free(scratch);
    return dst;
}

/* The twin's form: the result in ao. */
void obs__blur(const obs__frame *f, const float *pos, float *ao, float *tmp)
{
    if (blur(f, pos, NULL, ao, tmp, 0) == tmp)
        memcpy(ao, tmp, sizeof(float) * (size_t)f->width * (size_t)f->height);
}

float *obs__blur_dnz(const obs__frame *f, const float *pos, const float *dnz, float *ao,
                     float *tmp, int rays)
{
    return blur(f, pos, dnz, ao, tmp, rays);
}
