/* The AO at half resolution (parameter ao_resolution half), CPU twins of
 * prep.frag.glsl (OBS_HALF) and up.frag.glsl: the half frame, the depth-aware
 * downsample of the prep planes and the joint bilateral upsample of the
 * AO (frame.h says what each does).
 *
 * The downsample takes one whole pixel of each 2x2 block, never an
 * average: an average of the two sides of a depth edge is a surface that
 * exists on neither, which the AO pass would then shade (a halo).  The
 * nearest and the farthest alternate in a checkerboard, so that around any
 * edge both surfaces keep half pixels and each full pixel finds one of its
 * own surface among the four the upsample reads. */
#include <math.h>
#include <string.h>

#include "chain/frame.h"

void obs__frame_half(const obs__frame *f, obs__frame *hf)
{
    *hf = *f;
    /* object masks: the driver points these at its half-size planes,
     * filled by the downsample (obs__half_masks) */
    hf->mask_occl = hf->mask_id = NULL;
    hf->width = (f->width + 1) / 2;
    hf->height = (f->height + 1) / 2;
    for (int k = 0; k < 4; k++)
        hf->viewport[k] = f->viewport[k] * 0.5f;
    hf->cull_w = (hf->width + OBS_CULL_BLOCK - 1) / OBS_CULL_BLOCK;
    hf->cull_h = (hf->height + OBS_CULL_BLOCK - 1) / OBS_CULL_BLOCK;
}

long obs__half_source(const obs__frame *f, const float *pos, int hx, int hy)
{
    const int nearest = ((hx + hy) & 1) == 0;
    long best = -1;
    float best_z = 0.0f;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            int x = 2 * hx + i, y = 2 * hy + j;
            if (x >= f->width || y >= f->height)
                continue;
            long k = (long)y * f->width + x;
            float z = pos[4 * k + 3];
            if (z <= 0.0f)
                continue;
            if (best < 0 || (nearest ? z < best_z : z > best_z)) {
                best = k;
                best_z = z;
            }
        }
    return best;
}

void obs__half_masks(const obs__frame *f, long k, size_t h, float *hw, float *hid)
{
    /* k is the pixel obs__half_source kept the depth, position and normal
     * of: the weight and the self_only test then read the surface the
     * half pixel's depth came from, never a neighbour's across an edge */
    if (hw && f->mask_occl)
        hw[h] = f->mask_occl[k];
    if (hid && f->mask_id)
        hid[h] = f->mask_id[k];
}

/* The first of the two half pixels around coordinate c (half grid), both
 * inside 0..n-1. */
static int half_first(float c, int n)
{
    int i = (int)floorf(c), last = n > 1 ? n - 2 : 0;
    return i > last ? last : i < 0 ? 0 : i;
}

float obs__half_upsample(const obs__frame *f, const obs__frame *hf, const float *pos,
                         const float *nrm, const float *hpos, const float *hnrm,
                         const float *hao, int x, int y)
{
    const size_t i = (size_t)y * f->width + x;
    const float zp = pos[4 * i + 3];
    if (zp <= 0.0f)
        return 1.0f; /* background: what the AO pass writes there */
    const float *n = nrm + 3 * i;
    /* the pixel's centre on the half grid, and the 2x2 half pixels around
     * it; at the border the two inside (the weight of the outer one, 0,
     * leaves it to the nearest-depth fallback), so that a one-pixel
     * feature there still finds its surface's half pixel */
    const float u = ((float)x + 0.5f) * 0.5f - 0.5f, v = ((float)y + 0.5f) * 0.5f - 0.5f;
    const int x0 = half_first(u, hf->width), y0 = half_first(v, hf->height);
    const int dx = hf->width > 1, dy = hf->height > 1;
    const float fx = fminf(fmaxf(u - (float)x0, 0.0f), 1.0f);
    const float fy = fminf(fmaxf(v - (float)y0, 0.0f), 1.0f);
    float sum = 0.0f, wsum = 0.0f, near_ao = 1.0f, near_dz = 0.0f;
    int found = 0;
    for (int j = 0; j < 2; j++)
        for (int k = 0; k < 2; k++) {
            const int qx = x0 + k * dx, qy = y0 + j * dy;
            const size_t q = (size_t)qy * hf->width + qx;
            const float zq = hpos[4 * q + 3];
            if (zq <= 0.0f)
                continue;
            const float dz = fabsf(zq - zp);
            if (!found || dz < near_dz) {
                found = 1;
                near_dz = dz;
                near_ao = hao[q];
            }
            if (dz > f->radius) /* section 4.6's threshold */
                continue;
            const float *nq = hnrm + 3 * q;
            const float c = n[0] * nq[0] + n[1] * nq[1] + n[2] * nq[2];
            const float w = (k ? fx : 1.0f - fx) * (j ? fy : 1.0f - fy) * (c > 0.0f ? c : 0.0f);
            sum += w * hao[q];
            wsum += w;
        }
    return wsum > 0.0f ? sum / wsum : near_ao;
}
