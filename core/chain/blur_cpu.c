/* CPU twin of the low-pass filter (VAO++ section 4.6, GLSL:
 * blur.frag.glsl): a depth-aware cross-bilateral Gaussian blur in two
 * passes, horizontal then vertical.  Same arithmetic in the same order as
 * the shader; tests/unit/core/test_gl_twin.c compares them. */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "chain/bands_cpu.h"
#include "chain/frame.h"
#include "chain/vao_cpu.h"

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

/* The n pixels from index i0 of one row, each neighbour k * step away
 * (k in [kmin, kmax]) inside the frame: obs__blur_pixel's arithmetic, in
 * its order of k for every pixel, with the loop over k outside the loop
 * over pixels, so that the pixels run in SIMD lanes (#pragma omp simd,
 * gcc -fopenmp-simd: no OpenMP runtime).  A neighbour left out adds +0
 * to both sums, which leaves them the same floats (they are never -0), so
 * the result is the scalar one, bit for bit.  Depths at z[zs * i]. */
static inline __attribute__((always_inline)) void blur_span(const obs__frame *f, const float *z, size_t zs, const float *src,
                             float *dst, size_t i0, int n, ptrdiff_t step, int kmin, int kmax)
{
    float sum[SPAN], wsum[SPAN];
    const float radius = f->radius;
    const float *zc = z + zs * i0;
    for (int j = 0; j < n; j++)
        sum[j] = wsum[j] = 0.0f;
    for (int k = kmin; k <= kmax; k++) {
        const float wk = f->blur_w[k < 0 ? -k : k];
        const float *zq = zc + (ptrdiff_t)zs * k * step, *aq = src + i0 + k * step;
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
    const float *a = src + i0;
    float *d = dst + i0;
#pragma omp simd
    for (int j = 0; j < n; j++) {
        /* in every lane; background keeps its AO (nothing to filter) */
        const float v = sum[j] / wsum[j], aj = a[j];
        d[j] = zc[(ptrdiff_t)zs * j] <= 0.0f ? aj : v;
    }
}

/* Rows [y0, y1) of one pass, horizontal (dx) or vertical; depths at
 * z[zs * i], positions (for the scalar pixels) at pos. */
static inline __attribute__((always_inline)) void blur_pass_rows(const obs__frame *f, const float *pos, const float *z, size_t zs,
                                  const float *src, float *dst, int dx, int y0, int y1)
{
    const int w = f->width, h = f->height, R = f->blur_radius;
    for (int y = y0; y < y1; y++) {
        const size_t row = (size_t)y * (size_t)w;
        if (dx) { /* the first and last R pixels reach past the row: scalar */
            int xa = R < w ? R : w, xb = w - R > xa ? w - R : xa;
            for (int x = 0; x < xa; x++)
                dst[row + x] = obs__blur_pixel(f, pos, src, x, y, 1, 0);
            for (int x = xa; x < xb; x += SPAN)
                blur_span(f, z, zs, src, dst, row + (size_t)x, xb - x < SPAN ? xb - x : SPAN,
                          1, -R, R);
            for (int x = xb; x < w; x++)
                dst[row + x] = obs__blur_pixel(f, pos, src, x, y, 1, 0);
        } else { /* rows past the frame are left out for the whole row */
            int kmin = -y > -R ? -y : -R, kmax = h - 1 - y < R ? h - 1 - y : R;
            for (int x = 0; x < w; x += SPAN)
                blur_span(f, z, zs, src, dst, row + (size_t)x, w - x < SPAN ? w - x : SPAN,
                          (ptrdiff_t)w, kmin, kmax);
        }
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

static void blur(const obs__frame *f, const float *pos, const float *dnz, float *ao, float *tmp,
                 int rays)
{
    if (f->blur_radius <= 0)
        return;
    blur_job h = {f, pos, dnz, ao, tmp, 1, 0}, v = {f, pos, dnz, tmp, ao, 0, rays};
    obs__cpu_rows(f->height, 0, blur_rows, &h);
    obs__cpu_rows(f->height, 0, blur_rows, &v);
}

/* The two passes in row bands on the worker pool (bands_cpu.h); the
 * vertical one starts when every row of the horizontal one is done. */
void obs__blur(const obs__frame *f, const float *pos, float *ao, float *tmp)
{
    blur(f, pos, NULL, ao, tmp, 0);
}

void obs__blur_dnz(const obs__frame *f, const float *pos, const float *dnz, float *ao, float *tmp,
                   int rays)
{
    blur(f, pos, dnz, ao, tmp, rays);
}
