/* CPU twin of the culling pre-pass (VAO++ section 4.2, GLSL:
 * cull.frag.glsl for the low-resolution pass, cull_candidate() in
 * vao.frag.glsl for the test in the full-resolution pass).
 *
 * Section 4.2: "We first calculate AO in a lower resolution texture (we
 * use 1/8 resolution of the final image) ... We also always use 8 samples
 * for this pass."  Texel (i, j) stands for the 8 x 8 block of pixels
 * 8i..8i+7 x 8j..8j+7 and holds the 8-sample AO of the block's centre
 * pixel (8i + 4, 8j + 4) (clamped into a partial last block), computed by
 * the same estimator as the full pass (range check included, adaptive
 * sampling not: the count is always 8).
 *
 * "Checking for estimated occlusion in the second pass is done via four
 * texel fetches from downsized AO texture in given pixel corners.
 * Texture interpolation mode is set to linear."  A pixel corner (x, y)
 * (integers, in pixels) lies at texel coordinate x / 8 - 0.5, so every
 * bilinear weight is a multiple of 1/8: exact in float and in the 8-bit
 * fixed-point weights some rasterisers use for filtering (llvmpipe does
 * so for 8-bit formats; this R32F texture it filters in float). */
#include <math.h>

#include "chain/bands_cpu.h"
#include "chain/frame.h"
#include "chain/vao_cpu.h"

typedef struct cull_job {
    const obs__frame *f;
    const float *pos, *nrm, *dnz; /* dnz: NULL, or the packed plane (vao_cpu.h) */
    float *est;
} cull_job;

/* The texel rows [j0, j1) of the pre-pass. */
static void cull_rows(void *ctx, int j0, int j1)
{
    const cull_job *c = ctx;
    const obs__frame *f = c->f;
    const float *pos = c->pos, *nrm = c->nrm;
    const float *xy = f->sample_table + 2 * (OBS_CULL_SAMPLES - 2);
    float bleed[3];
    for (int j = j0; j < j1; j++)
        for (int i = 0; i < f->cull_w; i++) {
            int x = OBS_CULL_BLOCK * i + OBS_CULL_BLOCK / 2;
            int y = OBS_CULL_BLOCK * j + OBS_CULL_BLOCK / 2;
            x = x < f->width ? x : f->width - 1;
            y = y < f->height ? y : f->height - 1;
            size_t k = (size_t)y * (size_t)f->width + (size_t)x;
            c->est[(size_t)j * (size_t)f->cull_w + (size_t)i] =
                !(pos[4 * k + 3] > 0.0f) ? 1.0f
                : c->dnz ? obs__vao_estimate_dnz(f, pos, nrm, c->dnz, NULL, x, y, pos + 4 * k,
                                                 nrm + 3 * k, OBS_CULL_SAMPLES, xy, bleed)
                         : obs__vao_estimate(f, pos, nrm, x, y, pos + 4 * k, nrm + 3 * k,
                                             OBS_CULL_SAMPLES, xy);
        }
}

void obs__cull_prepass(const obs__frame *f, const float *pos, const float *nrm, float *est)
{
    cull_job c = {f, pos, nrm, NULL, est};
    obs__cpu_rows(f->cull_h, 1, cull_rows, &c); /* a texel row: 8 rows of pixels */
}

void obs__cull_prepass_dnz(const obs__frame *f, const float *pos, const float *nrm,
                           const float *dnz, float *est)
{
    cull_job c = {f, pos, nrm, dnz, est};
    obs__cpu_rows(f->cull_h, 1, cull_rows, &c);
}

static inline int clampi(int v, int hi) { return v < 0 ? 0 : v > hi ? hi : v; }

/* GL_LINEAR with GL_CLAMP_TO_EDGE at the pixel corner (px, py), texel
 * coordinate (px / 8 - 0.5, py / 8 - 0.5) (exact in float), as
 * cull_candidate() in vao.frag.glsl computes it from four image loads. */
static inline __attribute__((always_inline)) float fetch(const obs__frame *f, const float *est,
                                                         int px, int py)
{
    float u = (float)px * 0.125f - 0.5f;
    float v = (float)py * 0.125f - 0.5f;
    float fu = floorf(u), fv = floorf(v);
    float a = u - fu, b = v - fv;
    int i0 = clampi((int)fu, f->cull_w - 1), i1 = clampi((int)fu + 1, f->cull_w - 1);
    int j0 = clampi((int)fv, f->cull_h - 1), j1 = clampi((int)fv + 1, f->cull_h - 1);
    size_t w = (size_t)f->cull_w;
    float t00 = est[(size_t)j0 * w + (size_t)i0], t10 = est[(size_t)j0 * w + (size_t)i1];
    float t01 = est[(size_t)j1 * w + (size_t)i0], t11 = est[(size_t)j1 * w + (size_t)i1];
    /* lerp(t0, t1, a) = fma(a, t1 - t0, t0), as the shader and llvmpipe's
     * sampler filter R32F (measured on the test scenes against the
     * sampler: every pixel; t0 + a * (t1 - t0) unfused differs by one ulp
     * at ~1 % of them, (1 - a) t0 + a t1 at ~15 %).  Where a = 0 this is
     * t0 exactly, the texel the shader takes there. */
    float top = fmaf(a, t10 - t00, t00), bottom = fmaf(a, t11 - t01, t01);
    return fmaf(b, bottom - top, top);
}

float obs__cull_fetch(const obs__frame *f, const float *est, int px, int py)
{
    return fetch(f, est, px, py);
}

int obs__cull_candidate(const obs__frame *f, const float *est, int x, int y)
{
    /* Section 4.2: "When at least one of these pixels exhibits occlusion,
     * we calculate full AO - otherwise the pixel is a candidate for
     * culling." */
    for (int k = 0; k < 4; k++)
        if (fetch(f, est, x + (k & 1), y + (k >> 1)) < f->cull_threshold)
            return 0;
    return 1;
}

/* obs__cull_candidate of a tile's pixels: a pixel corner is shared by
 * four pixels, so each corner's fetch is computed once, row of corners by
 * row of corners (the same fetch, the same comparison: the same answer).
 * In the clones of OBS__LANES, fmaf and floorf are instructions. */
OBS__LANES
void obs__cull_candidates(const obs__frame *f, const float *est, int x0, int x1, int y0, int y1,
                          unsigned char *cand)
{
    const int n = x1 - x0;
    const float thr = f->cull_threshold;
    unsigned char row[2][OBS__CULL_TILE_MAX + 1]; /* corner row y, y + 1: "shows occlusion" */
    if (n <= 0 || n > OBS__CULL_TILE_MAX) { /* not a tile this form takes */
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++)
                cand[(size_t)(y - y0) * (size_t)n + (size_t)(x - x0)] =
                    (unsigned char)obs__cull_candidate(f, est, x, y);
        return;
    }
    for (int i = 0; i <= n; i++)
        row[0][i] = fetch(f, est, x0 + i, y0) < thr;
    for (int y = y0; y < y1; y++) {
        const unsigned char *top = row[(y - y0) & 1];
        unsigned char *bottom = row[(y - y0 + 1) & 1];
        for (int i = 0; i <= n; i++)
            bottom[i] = fetch(f, est, x0 + i, y + 1) < thr;
        unsigned char *out = cand + (size_t)(y - y0) * (size_t)n;
        for (int i = 0; i < n; i++)
            out[i] = !(top[i] | top[i + 1] | bottom[i] | bottom[i + 1]);
    }
}
