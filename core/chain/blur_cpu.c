/* CPU twin of the low-pass filter (VAO++ section 4.6, GLSL:
 * blur.frag.glsl): a depth-aware cross-bilateral Gaussian blur in two
 * passes, horizontal then vertical.  Same arithmetic in the same order as
 * the shader; tests/unit/core/test_gl_twin.c compares them. */
#include <math.h>
#include <string.h>

#include "chain/bands_cpu.h"
#include "chain/frame.h"

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

typedef struct blur_job {
    const obs__frame *f;
    const float *pos, *src;
    float *dst;
    int dx, dy;
} blur_job;

static void blur_rows(void *ctx, int y0, int y1)
{
    const blur_job *j = ctx;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < j->f->width; x++)
            j->dst[(size_t)y * j->f->width + x] =
                obs__blur_pixel(j->f, j->pos, j->src, x, y, j->dx, j->dy);
}

/* The two passes in row bands on the worker pool (bands_cpu.h); the
 * vertical one starts when every row of the horizontal one is done. */
void obs__blur(const obs__frame *f, const float *pos, float *ao, float *tmp)
{
    if (f->blur_radius <= 0)
        return;
    blur_job h = {f, pos, ao, tmp, 1, 0}, v = {f, pos, tmp, ao, 0, 1};
    obs__cpu_rows(f->height, 0, blur_rows, &h);
    obs__cpu_rows(f->height, 0, blur_rows, &v);
}
