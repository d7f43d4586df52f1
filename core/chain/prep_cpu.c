/* CPU twin of the prep pass (GLSL: prep.frag.glsl, common.glsl): each
 * pixel's view-space position and normal, and the maps between pixels and
 * view space that every pass shares (obs__view_to_px; obs__px_ndc and
 * obs__view_ray are inline in frame.h). */
#include <math.h>
#include <string.h>

#include "chain/frame.h"
#include "chain/lanes.h"
#include "chain/prep_cpu.h"

/* GLSL: clip_range() in prep.frag.glsl.  The clip range (near, far) of
 * the projection's z row, z_ndc = (a z + b) / (c z + d): the planar depths
 * whose OpenGL depth is -1 and 1. */
static void clip_range(const float *P, float nf[2])
{
    float a = P[10], b = P[11], c = P[14], d = P[15];
    nf[0] = (d + b) / (a + c);
    nf[1] = (b - d) / (a - c);
}

/* GLSL: linear_depth() in prep.frag.glsl.  Planar depth from the raw value,
 * 0 for background. */
static float linear_depth(const obs__frame *f, float raw, const float dir[3])
{
    if (f->depth_mode == OBS_DEPTH_INVERSE) /* 1/Z: 0 (or below) is background */
        return raw > 0.0f && 1.0f / raw < OBS_BACKGROUND_DEPTH ? 1.0f / raw : 0.0f;
    if (f->depth_mode == OBS_DEPTH_NORMALIZED) { /* 0..1 between the clip planes */
        if (!(raw >= 0.0f) || raw >= 1.0f)
            return 0.0f;
        float nf[2];
        clip_range(f->proj, nf);
        return nf[0] + raw * (nf[1] - nf[0]);
    }
    if (!(raw > 0.0f) || raw >= OBS_BACKGROUND_DEPTH) /* also catches NaN */
        return 0.0f;
    if (f->depth_mode == OBS_DEPTH_RADIAL)
        return raw / sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (f->depth_mode == OBS_DEPTH_NDC) {
        if (raw >= 1.0f)
            return 0.0f;
        /* z_ndc = (P22 z + P23) / (P32 z + P33), solved for view z. */
        const float *P = f->proj;
        float zn = 2.0f * raw - 1.0f;
        float z = (P[11] - zn * P[15]) / (zn * P[14] - P[10]);
        return -z > 0.0f ? -z : 0.0f;
    }
    return raw;
}

void obs__prep_position(const obs__frame *f, float raw_depth, int x, int y, float out[4])
{
    float ndc[2], o[3], dir[3];
    obs__px_ndc(f, x, y, ndc);
    obs__view_ray(f->proj, ndc, o, dir);
    float d = linear_depth(f, raw_depth, dir);
    if (d <= 0.0f || !isfinite(d)) {
        out[0] = out[1] = out[2] = out[3] = 0.0f;
        return;
    }
    out[0] = o[0] + d * dir[0];
    out[1] = o[1] + d * dir[1];
    out[2] = -d;
    out[3] = d;
}

static void normalize3(float v[3])
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0f) {
        v[0] /= l;
        v[1] /= l;
        v[2] /= l;
    }
}

/* GLSL: neighbour_delta() in prep.frag.glsl.  The difference towards the
 * neighbour (along +x or +y) whose depth is closer to the centre's, so
 * that edges do not bend the normal; 0 if neither neighbour is geometry. */
static int neighbour_delta(const obs__frame *f, const float *pos, int x, int y, int dx, int dy,
                           float out[3])
{
    const float *c = pos + 4 * ((size_t)y * (size_t)f->width + (size_t)x);
    const float *best = NULL;
    float best_dz = 0.0f, sign = 1.0f;
    for (int s = -1; s <= 1; s += 2) {
        int nx = x + s * dx, ny = y + s * dy;
        if (nx < 0 || ny < 0 || nx >= f->width || ny >= f->height)
            continue;
        const float *q = pos + 4 * ((size_t)ny * (size_t)f->width + (size_t)nx);
        if (q[3] <= 0.0f)
            continue;
        float dz = fabsf(q[3] - c[3]);
        if (!best || dz < best_dz) {
            best = q;
            best_dz = dz;
            sign = (float)s;
        }
    }
    if (!best)
        return 0;
    for (int k = 0; k < 3; k++)
        out[k] = sign * (best[k] - c[k]);
    return 1;
}

void obs__prep_normal(const obs__frame *f, const float *pos, const float *in_normal, int x, int y,
                      float out[3])
{
    const float *p = pos + 4 * ((size_t)y * (size_t)f->width + (size_t)x);
    if (!f->reconstruct_normals) {
        const float *m = f->normal_matrix;
        for (int k = 0; k < 3; k++)
            out[k] = m[3 * k] * in_normal[0] + m[3 * k + 1] * in_normal[1] +
                     m[3 * k + 2] * in_normal[2];
        normalize3(out);
        return;
    }
    float ddx[3], ddy[3];
    if (neighbour_delta(f, pos, x, y, 1, 0, ddx) && neighbour_delta(f, pos, x, y, 0, 1, ddy)) {
        out[0] = ddx[1] * ddy[2] - ddx[2] * ddy[1];
        out[1] = ddx[2] * ddy[0] - ddx[0] * ddy[2];
        out[2] = ddx[0] * ddy[1] - ddx[1] * ddy[0];
    } else {
        out[0] = out[1] = out[2] = 0.0f;
    }
    if (out[0] == 0.0f && out[1] == 0.0f && out[2] == 0.0f) {
        /* isolated pixel: face the camera */
        out[0] = -p[0];
        out[1] = -p[1];
        out[2] = -p[2];
    } else if (out[0] * p[0] + out[1] * p[1] + out[2] * p[2] > 0.0f) {
        /* a visible surface faces the camera */
        out[0] = -out[0];
        out[1] = -out[1];
        out[2] = -out[2];
    }
    normalize3(out);
}

/* The clip-space x, y and w of view-space point p (row-major projection
 * P); returns w. */
static float clip_xyw(const float *P, const float p[3], float *x, float *y)
{
    *x = P[0] * p[0] + P[1] * p[1] + P[2] * p[2] + P[3];
    *y = P[4] * p[0] + P[5] * p[1] + P[6] * p[2] + P[7];
    return P[12] * p[0] + P[13] * p[1] + P[14] * p[2] + P[15];
}

/* GLSL: view_to_px() in common.glsl. */
int obs__view_to_px(const obs__frame *f, const float s[3], int *qx, int *qy)
{
    float cx, cy, cw = clip_xyw(f->proj, s, &cx, &cy);
    if (!(cw > 0.0f))
        return 0;
    float u = (cx / cw * 0.5f + 0.5f) * f->viewport[2] - f->viewport[0];
    float v = (0.5f - cy / cw * 0.5f) * f->viewport[3] - f->viewport[1];
    float fu = floorf(u), fv = floorf(v);
    if (!(fu >= 0.0f && fv >= 0.0f && fu < (float)f->width && fv < (float)f->height))
        return 0;
    *qx = (int)fu;
    *qy = (int)fv;
    return 1;
}

/* GLSL: radius_px() in method.glsl */
float obs__radius_px(const obs__frame *f, const float p[3], float r)
{
    const float *P = f->proj;
    float X, Y, w = clip_xyw(P, p, &X, &Y);
    if (!(w > 0.0f))
        return 0.0f;
    float w2 = w * w;
    float j00 = (P[0] * w - X * P[12]) / w2, j01 = (P[1] * w - X * P[13]) / w2;
    float j10 = (P[4] * w - Y * P[12]) / w2, j11 = (P[5] * w - Y * P[13]) / w2;
    return r * sqrtf(fabsf(j00 * j11 - j01 * j10) * f->viewport[2] * f->viewport[3] * 0.25f);
}

/* linear_depth() as selects, for the lanes: the same value in every mode
 * (nf: clip_range() of the projection, computed once; mode a constant
 * where this is inlined, so only its own terms remain) */
static inline __attribute__((always_inline)) float linear_depth_lane(const float *P, int mode,
                                                                     float raw, float dl,
                                                                     const float nf[2])
{
    if (mode == OBS_DEPTH_INVERSE) {
        const float inv = 1.0f / raw;
        return (raw > 0.0f) & (inv < OBS_BACKGROUND_DEPTH) ? inv : 0.0f;
    }
    if (mode == OBS_DEPTH_NORMALIZED)
        return (raw >= 0.0f) & (raw < 1.0f) ? nf[0] + raw * (nf[1] - nf[0]) : 0.0f;
    const int fg = (raw > 0.0f) & (raw < OBS_BACKGROUND_DEPTH);
    if (mode == OBS_DEPTH_RADIAL)
        return fg ? raw / dl : 0.0f;
    if (mode == OBS_DEPTH_NDC) {
        const float zn = 2.0f * raw - 1.0f;
        const float z = (P[11] - zn * P[15]) / (zn * P[14] - P[10]);
        return fg & (raw < 1.0f) & (-z > 0.0f) ? -z : 0.0f;
    }
    return fg ? raw : 0.0f;
}

static inline __attribute__((always_inline)) void position_row(const obs__frame *f,
                                                               const float *depth, size_t dc,
                                                               int y, float *out, const int mode)
{
    float P[16], nf[2]; /* copies: the row's stores cannot alias them */
    memcpy(P, f->proj, sizeof P);
    clip_range(P, nf);
    const float vx = f->viewport[0], vw = f->viewport[2];
    const int w = f->width;
    const float ny = 1.0f - ((float)y + 0.5f + f->viewport[1]) / f->viewport[3] * 2.0f;
    const float c = P[4] - ny * P[12], d = P[5] - ny * P[13];
    const float b0y = ny * P[15] - P[7], b1y = ny * P[14] - P[6];
#pragma omp simd
    for (int x = 0; x < w; x++) {
        /* obs__px_ndc(), obs__view_ray() */
        const float nx = ((float)x + 0.5f + vx) / vw * 2.0f - 1.0f;
        const float a = P[0] - nx * P[12], b = P[1] - nx * P[13];
        const float b0x = nx * P[15] - P[3], b1x = nx * P[14] - P[2];
        const float inv = 1.0f / (a * d - b * c);
        const float o0 = (d * b0x - b * b0y) * inv, o1 = (a * b0y - c * b0x) * inv;
        const float dir0 = -(d * b1x - b * b1y) * inv, dir1 = -(a * b1y - c * b1x) * inv;
        const float dl = sqrtf(dir0 * dir0 + dir1 * dir1 + -1.0f * -1.0f);
        const float z = linear_depth_lane(P, mode, depth[dc * (size_t)x], dl, nf);
        const int keep = (z > 0.0f) & (fabsf(z) < INFINITY); /* not (z <= 0 or not finite) */
        out[4 * x] = keep ? o0 + z * dir0 : 0.0f;
        out[4 * x + 1] = keep ? o1 + z * dir1 : 0.0f;
        out[4 * x + 2] = keep ? -z : 0.0f;
        out[4 * x + 3] = keep ? z : 0.0f;
    }
}

/* obs__prep_position of the pixels of row y, their depths at depth[dc x],
 * into out[4 x], the pixels in SIMD lanes: the same arithmetic, the same
 * floats. */
OBS__LANES
void obs__prep_position_row(const obs__frame *f, const float *depth, size_t dc, int y, float *out)
{
    switch (f->depth_mode) {
    case OBS_DEPTH_RADIAL:
        position_row(f, depth, dc, y, out, OBS_DEPTH_RADIAL);
        break;
    case OBS_DEPTH_NDC:
        position_row(f, depth, dc, y, out, OBS_DEPTH_NDC);
        break;
    case OBS_DEPTH_INVERSE:
        position_row(f, depth, dc, y, out, OBS_DEPTH_INVERSE);
        break;
    case OBS_DEPTH_NORMALIZED:
        position_row(f, depth, dc, y, out, OBS_DEPTH_NORMALIZED);
        break;
    default:
        position_row(f, depth, dc, y, out, OBS_DEPTH_PLANAR);
    }
}

static inline __attribute__((always_inline)) void normal_row(const obs__frame *f,
                                                             const float *pos, const float *in,
                                                             size_t nc, float *out, float *dnz,
                                                             const int packed)
{
    float m[9];
    memcpy(m, f->normal_matrix, sizeof m);
    const int w = f->width;
#pragma omp simd
    for (int x = 0; x < w; x++) {
        const float *v = in + nc * (size_t)x;
        const float o0 = m[0] * v[0] + m[1] * v[1] + m[2] * v[2];
        const float o1 = m[3] * v[0] + m[4] * v[1] + m[5] * v[2];
        const float o2 = m[6] * v[0] + m[7] * v[1] + m[8] * v[2];
        const float l = sqrtf(o0 * o0 + o1 * o1 + o2 * o2); /* normalize3() */
        const int sc = l > 0.0f;
        out[3 * x] = sc ? o0 / l : o0;
        out[3 * x + 1] = sc ? o1 / l : o1;
        out[3 * x + 2] = sc ? o2 / l : o2;
        if (packed) {
            dnz[2 * x] = pos[4 * x + 3];
            dnz[2 * x + 1] = sc ? o2 / l : o2;
        }
    }
}

/* obs__prep_normal of the pixels of a row from the input normals
 * in[nc x] (not reconstruct_normals) into out[3 x], and (dnz not NULL)
 * the packed plane's dnz[2 x] = pos[4 x + 3], dnz[2 x + 1] = out[3 x + 2]:
 * the pixels in SIMD lanes, the same floats. */
OBS__LANES
void obs__prep_normal_row(const obs__frame *f, const float *pos, const float *in, size_t nc,
                          float *out, float *dnz)
{
    if (dnz)
        normal_row(f, pos, in, nc, out, dnz, 1);
    else
        normal_row(f, pos, in, nc, out, NULL, 0);
}
