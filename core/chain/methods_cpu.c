/* The comparison methods' CPU twins (core/methods/: hemisphere.c,
 * angle.c, hbao.c) over a tile's pixels in SIMD lanes: a chunk of
 * METHOD_LANES pixels, each sample's arithmetic for all of them, every
 * pixel's sums in the twin's order, so each result is the twin's, bit for
 * bit (tests/unit/core/test_cpu_simd.c).  The flat chain only (one node a
 * pixel), without object masks and without the bent normal, and angle
 * with its linear or quadratic arc cosine (exact is libm's acosf, a call):
 * the callers take the twins pixel by pixel for the rest, and for gtao. */
#include <string.h>

#include "chain/vao_cpu.h"
#include "methods/angle.h"
#include "methods/gtao.h"
#include "methods/hbao.h"
#include "methods/hemisphere.h"

#define METHOD_LANES 16

/* The pixels' indices, coordinates and tile rotations of one chunk; lanes
 * past the cnt pixels repeat the first. */
typedef struct chunk {
    int cnt, k[METHOD_LANES], x[METHOD_LANES], y[METHOD_LANES];
    float ro0[METHOD_LANES], ro1[METHOD_LANES];
} chunk;

static void chunk_at(const obs__frame *f, const int *px, int m, int j0, chunk *c)
{
    c->cnt = m - j0 < METHOD_LANES ? m - j0 : METHOD_LANES;
    for (int j = 0; j < METHOD_LANES; j++) {
        const int k = px[j0 + (j < c->cnt ? j : 0)];
        c->k[j] = k;
        c->x[j] = k % f->width;
        c->y[j] = k / f->width;
        const float *rot = f->rot[obs__tile_index(f, c->x[j], c->y[j])];
        c->ro0[j] = rot[0];
        c->ro1[j] = rot[1];
    }
}

/* GLSL: view_to_px() in common.glsl (obs__view_to_px): 1 and the pixel of
 * view point s on the planes, else 0 (and pixel 0, 0). */
static inline __attribute__((always_inline)) int view_px_lane(const float *P, const float *vp,
                                                              float fw, float fh, float s0,
                                                              float s1, float s2, int *qx,
                                                              int *qy)
{
    const float cx = P[0] * s0 + P[1] * s1 + P[2] * s2 + P[3];
    const float cy = P[4] * s0 + P[5] * s1 + P[6] * s2 + P[7];
    const float cw = P[12] * s0 + P[13] * s1 + P[14] * s2 + P[15];
    const float u = (cx / cw * 0.5f + 0.5f) * vp[2] - vp[0];
    const float v = (0.5f - cy / cw * 0.5f) * vp[3] - vp[1];
    const float fu = floor_lane(u), fv = floor_lane(v);
    const int ok = (cw > 0.0f) & (fu >= 0.0f) & (fv >= 0.0f) & (fu < fw) & (fv < fh);
    *qx = (int)fu & -ok;
    *qy = (int)fv & -ok;
    return ok;
}

/* The pixels' positions and normals of a chunk, in lanes. */
typedef struct lanes_pn {
    float p0[METHOD_LANES], p1[METHOD_LANES], p2[METHOD_LANES], p3[METHOD_LANES];
    float n0[METHOD_LANES], n1[METHOD_LANES], n2[METHOD_LANES];
} lanes_pn;

static inline __attribute__((always_inline)) void lanes_load(const float *pos, const float *nrm,
                                                             const chunk *c, lanes_pn *v)
{
#pragma omp simd
    for (int j = 0; j < METHOD_LANES; j++) {
        const int k = c->k[j]; /* < 2^28 (the frame's size limit): 4 k fits */
        v->p0[j] = pos[4 * k];
        v->p1[j] = pos[4 * k + 1];
        v->p2[j] = pos[4 * k + 2];
        v->p3[j] = pos[4 * k + 3];
        v->n0[j] = nrm[3 * k];
        v->n1[j] = nrm[3 * k + 1];
        v->n2[j] = nrm[3 * k + 2];
    }
}

/* hemisphere: obs__hemisphere_pixel */
OBS__LANES
static void hemisphere_pixels(const obs__frame *f, const float *pos, const float *nrm,
                              const int *px, int m, float *ao)
{
    const obs__hemisphere_state *hs = obs__hemisphere_of(f);
    const float R = f->radius, bias = hs->bias, fw = (float)f->width, fh = (float)f->height;
    const int w = f->width, ns = hs->count;
    float P[16], vp[4];
    memcpy(P, f->proj, sizeof P);
    memcpy(vp, f->viewport, sizeof vp);
    for (int j0 = 0; j0 < m; j0 += METHOD_LANES) {
        chunk c;
        lanes_pn v;
        float t10[METHOD_LANES], t11[METHOD_LANES], t12[METHOD_LANES], t20[METHOD_LANES],
            t21[METHOD_LANES], t22[METHOD_LANES], occ[METHOD_LANES];
        chunk_at(f, px, m, j0, &c);
        lanes_load(pos, nrm, &c, &v);
#pragma omp simd
        for (int j = 0; j < METHOD_LANES; j++) {
            /* obs__hemisphere_basis() */
            const float n0 = v.n0[j], n1 = v.n1[j], n2 = v.n2[j];
            const float sg = n2 >= 0.0f ? 1.0f : -1.0f;
            const float a = -1.0f / (sg + n2), b = n0 * n1 * a;
            t10[j] = 1.0f + sg * n0 * n0 * a;
            t11[j] = sg * b;
            t12[j] = -sg * n0;
            t20[j] = b;
            t21[j] = sg + n1 * n1 * a;
            t22[j] = -n1;
            occ[j] = 0.0f;
        }
        for (int i = 0; i < ns; i++) {
            const float k0 = hs->kernel[i][0], k1 = hs->kernel[i][1], k2 = hs->kernel[i][2];
#pragma omp simd
            for (int j = 0; j < METHOD_LANES; j++) {
                /* obs__hemisphere_sample() */
                const float kx = c.ro0[j] * k0 - c.ro1[j] * k1;
                const float ky = c.ro1[j] * k0 + c.ro0[j] * k1;
                const float s0 = v.p0[j] + R * (kx * t10[j] + ky * t20[j] + k2 * v.n0[j]);
                const float s1 = v.p1[j] + R * (kx * t11[j] + ky * t21[j] + k2 * v.n1[j]);
                const float s2 = v.p2[j] + R * (kx * t12[j] + ky * t22[j] + k2 * v.n2[j]);
                int qx, qy;
                const int ok = view_px_lane(P, vp, fw, fh, s0, s1, s2, &qx, &qy);
                const float zn = pos[4 * (qy * w + qx) + 3];
                const float dz = fabsf(-v.p2[j] - zn);
                const float r = dz > R ? R / dz : 1.0f;
                /* an = 1 (one opaque node), so an * r = r; fmaxf(0, x) = x
                 * for x >= 0; the object masks' weight 1 */
                const float x = r * r * (3.0f - 2.0f * r);
                occ[j] += ok & (zn > 0.0f) & (zn <= -s2 - bias) ? x : 0.0f;
            }
        }
        for (int j = 0; j < c.cnt; j++)
            ao[c.k[j]] = ns > 0 ? 1.0f - occ[j] / (float)ns : 1.0f;
    }
}

/* c ? v : +0, by the bits: v computed in every lane (a select lets gcc
 * move v's loads under the condition, masked gathers the lanes lack) */
static inline __attribute__((always_inline)) float keep_if(int c, float v)
{
    union {
        float f;
        unsigned u;
    } b = {v};
    b.u &= -(unsigned)c;
    return b.f;
}

/* One sample of angle_pixels at view (sx, sy, p2): the vector u0..u2
 * towards it and its far weight fr (off the image or background: far, no
 * point; the object masks' term adds (1 - far) * 0 = +0; the clamp of a
 * number, without NaN's case).  A macro: the lanes take no struct nor
 * pointer to a lane's value. */
#define ANGLE_SIDE(sx, sy, u0, u1, u2, fr)                                                   \
    int qx_##fr, qy_##fr;                                                                    \
    const int ok_##fr = view_px_lane(P, vp, fw, fh, sx, sy, p2, &qx_##fr, &qy_##fr);        \
    const int k_##fr = 4 * (qy_##fr * w + qx_##fr);                                          \
    const float qa_##fr = pos[k_##fr], qb_##fr = pos[k_##fr + 1]; /* loaded in every lane: */ \
    const float qc_##fr = pos[k_##fr + 2], qd_##fr = pos[k_##fr + 3]; /* no masked gathers */ \
    const int got_##fr = ok_##fr & (qd_##fr > 0.0f);                                         \
    const float u0 = keep_if(got_##fr, qa_##fr - p0);                                        \
    const float u1 = keep_if(got_##fr, qb_##fr - p1);                                        \
    const float u2 = keep_if(got_##fr, qc_##fr - p2);                                        \
    const float t_##fr = fabsf(qd_##fr - p3) / R - 1.0f;                                     \
    const float fr = got_##fr ? (t_##fr < 0.0f ? 0.0f : t_##fr > 1.0f ? 1.0f : t_##fr) : 1.0f

/* angle_to_normal(), obs__acos_mode()'s linear and quadratic forms */
static inline __attribute__((always_inline)) float angle_of(float n0, float n1, float n2, int quad,
                                                            float u0, float u1, float u2)
{
    const float pi = (float)M_PI;
    const float l = sqrtf(u0 * u0 + u1 * u1 + u2 * u2);
    const float cs = l > 0.0f ? (n0 * u0 + n1 * u1 + n2 * u2) / l : 0.0f;
    const float x = cs < -1.0f ? -1.0f : cs > 1.0f ? 1.0f : cs; /* a number, as t above */
    return quad ? pi * (1.0f - (x >= 0.0f ? x * x : -x * x)) * 0.5f : pi * (1.0f - x) * 0.5f;
}

/* angle: obs__angle_pixel, with obs__acos_mode's quadratic form (quad 1,
 * a constant where this is inlined) or its linear one */
static inline __attribute__((always_inline)) void angle_body(const obs__frame *f, const float *pos,
                                                             const float *nrm, const int *px,
                                                             int m, float *ao, const int quad)
{
    const obs__angle_state *an = obs__angle_of(f);
    const float R = f->radius, fw = (float)f->width, fh = (float)f->height;
    const int w = f->width, pairs = an->pairs;
    float P[16], vp[4];
    memcpy(P, f->proj, sizeof P);
    memcpy(vp, f->viewport, sizeof vp);
    for (int j0 = 0; j0 < m; j0 += METHOD_LANES) {
        chunk c;
        lanes_pn v;
        float sum[METHOD_LANES], wsum[METHOD_LANES];
        chunk_at(f, px, m, j0, &c);
        lanes_load(pos, nrm, &c, &v);
        for (int j = 0; j < METHOD_LANES; j++)
            sum[j] = wsum[j] = 0.0f;
        for (int i = 0; i < pairs; i++) {
            const float a0 = an->xy[i][0], a1 = an->xy[i][1];
#pragma omp simd
            for (int j = 0; j < METHOD_LANES; j++) {
                const float ox = R * (c.ro0[j] * a0 - c.ro1[j] * a1);
                const float oy = R * (c.ro1[j] * a0 + c.ro0[j] * a1);
                const float p0 = v.p0[j], p1 = v.p1[j], p2 = v.p2[j], p3 = v.p3[j];
                const float n0 = v.n0[j], n1 = v.n1[j], n2 = v.n2[j];
                ANGLE_SIDE(p0 + 1.0f * ox, p1 + 1.0f * oy, a00, a01, a02, fa);
                ANGLE_SIDE(p0 + -1.0f * ox, p1 + -1.0f * oy, b00, b01, b02, fb);
                const float wt = 1.0f - 0.5f * (fa + fb);
                /* a far sample moves towards the coplanar point: -v_other */
                float th = 0.0f;
                th += angle_of(n0, n1, n2, quad, a00 + fa * (-b00 - a00), a01 + fa * (-b01 - a01),
                               a02 + fa * (-b02 - a02));
                th += angle_of(n0, n1, n2, quad, b00 + fb * (-a00 - b00), b01 + fb * (-a01 - b01),
                               b02 + fb * (-a02 - b02));
                const int take = wt > 0.0f;
                const float tp = th / (float)M_PI;
                sum[j] += take ? wt * (tp <= 1.0f ? tp : 1.0f) : 0.0f;
                wsum[j] += take ? wt : 0.0f;
            }
        }
        for (int j = 0; j < c.cnt; j++)
            ao[c.k[j]] = wsum[j] > 0.0f ? sum[j] / wsum[j] : 1.0f;
    }
}
#undef ANGLE_SIDE

OBS__LANES
static void angle_pixels(const obs__frame *f, const float *pos, const float *nrm, const int *px,
                         int m, float *ao)
{
    if (obs__angle_of(f)->acos == OBS_ACOS_QUADRATIC)
        angle_body(f, pos, nrm, px, m, ao, 1);
    else
        angle_body(f, pos, nrm, px, m, ao, 0);
}

/* hbao: obs__hbao_pixel */
OBS__LANES
static void hbao_pixels(const obs__frame *f, const float *pos, const float *nrm, const int *px,
                        int m, float *ao, float *count)
{
    const obs__hbao_state *hb = obs__hbao_of(f);
    const float R = f->radius, R2 = R * R;
    const int w = f->width, h = f->height, dirs = hb->dirs, steps = hb->steps;
    const float bc = hb->bias_cs[0], bs = hb->bias_cs[1];
    float P[16], vp[4];
    memcpy(P, f->proj, sizeof P);
    memcpy(vp, f->viewport, sizeof vp);
    for (int j0 = 0; j0 < m; j0 += METHOD_LANES) {
        chunk c;
        lanes_pn v;
        float step[METHOD_LANES], o[METHOD_LANES], sin_h[METHOD_LANES], dx[METHOD_LANES],
            dy[METHOD_LANES];
        int ns[METHOD_LANES], reach[METHOD_LANES], taken[METHOD_LANES], alive[METHOD_LANES];
        chunk_at(f, px, m, j0, &c);
        lanes_load(pos, nrm, &c, &v);
#pragma omp simd
        for (int j = 0; j < METHOD_LANES; j++) {
            /* obs__radius_px() */
            const float p0 = v.p0[j], p1 = v.p1[j], p2 = v.p2[j];
            const float X = P[0] * p0 + P[1] * p1 + P[2] * p2 + P[3];
            const float Y = P[4] * p0 + P[5] * p1 + P[6] * p2 + P[7];
            const float cw = P[12] * p0 + P[13] * p1 + P[14] * p2 + P[15];
            const float w2 = cw * cw;
            const float j00 = (P[0] * cw - X * P[12]) / w2, j01 = (P[1] * cw - X * P[13]) / w2;
            const float j10 = (P[4] * cw - Y * P[12]) / w2, j11 = (P[5] * cw - Y * P[13]) / w2;
            const float rj = R * sqrtf(fabsf(j00 * j11 - j01 * j10) * vp[2] * vp[3] * 0.25f);
            const float rpx = cw > 0.0f ? rj : 0.0f;
            reach[j] = rpx >= 1.0f; /* else the kernel reaches no other pixel: AO 1 */
            const int ri = reach[j] ? (int)rpx : 0;
            ns[j] = steps < ri ? steps : ri;
            step[j] = rpx / (float)(ns[j] + 1);
            o[j] = 0.0f;
            taken[j] = 0;
        }
        for (int d = 0; d < dirs; d++) {
            const float e0 = hb->dir[d][0], e1 = hb->dir[d][1];
#pragma omp simd
            for (int j = 0; j < METHOD_LANES; j++) {
                dx[j] = c.ro0[j] * e0 - c.ro1[j] * e1;
                dy[j] = c.ro1[j] * e0 + c.ro0[j] * e1;
                /* t(theta) + bias (hbao.c) */
                const float nd = v.n0[j] * dx[j] + v.n1[j] * dy[j], nz = max_f(v.n2[j], 0.0f);
                const float l = sqrtf(nd * nd + nz * nz);
                const float st = l > 0.0f ? -nd / l : 0.0f, ct = l > 0.0f ? nz / l : 1.0f;
                sin_h[j] = ct * bc - st * bs < 0.0f ? 1.0f : st * bc + ct * bs;
                alive[j] = 1;
            }
            for (int s = 1; s <= steps; s++) {
#pragma omp simd
                for (int j = 0; j < METHOD_LANES; j++) {
                    const int qx = c.x[j] + (int)floor_lane(dx[j] * step[j] * (float)s + 0.5f);
                    const int qy = c.y[j] + (int)floor_lane(-dy[j] * step[j] * (float)s + 0.5f);
                    const int in = (qx >= 0) & (qy >= 0) & (qx < w) & (qy < h);
                    /* the twin's loop ends after ns steps, or on leaving the planes */
                    const int live = alive[j] & (s <= ns[j]) & in;
                    alive[j] = live;
                    taken[j] += live;
                    const int q = live ? qy * w + qx : c.k[j];
                    const float v0 = pos[4 * q] - v.p0[j], v1 = pos[4 * q + 1] - v.p1[j];
                    const float v2 = pos[4 * q + 2] - v.p2[j], q3 = pos[4 * q + 3];
                    /* hbao_sample() with the object masks' weight 1 */
                    const float r2 = v0 * v0 + v1 * v1 + v2 * v2;
                    const float sin_s = v2 / sqrtf(r2);
                    const int rise =
                        live & (q3 > 0.0f) & (r2 < R2) & (r2 > 0.0f) & (sin_s > sin_h[j]);
                    o[j] += rise ? 1.0f * (1.0f - r2 / R2) * (sin_s - sin_h[j]) : 0.0f;
                    sin_h[j] = rise ? sin_s : sin_h[j];
                }
            }
        }
        for (int j = 0; j < c.cnt; j++) {
            ao[c.k[j]] = reach[j] ? max_f(0.0f, 1.0f - o[j] / (float)dirs) : 1.0f;
            if (count)
                count[c.k[j]] = (float)(reach[j] ? taken[j] : 0);
        }
    }
}

/* gtao: obs__gtao_pixel, the one method here that is not the twin's bits:
 * the slices' set-up and visibility in lanes with acosf, sinf and cosf by
 * polynomials (acos_lane, sincos_lane: about 3e-7 and 1e-7 absolute),
 * within 1e-5 of the twin (test_cpu_simd); the slices' directions and
 * the final powf are libm's, as the twin's.  The horizon steps in lanes
 * (their largest cosine per lane in the steps' order); a side with a step off the planes (the
 * surface continued past the border, border_cpu.c) is taken again step by
 * step in order, those steps through gtao.c. */
OBS__LANES
static void gtao_pixels(const obs__frame *f, const float *pos, const float *nrm, const int *px,
                        int m, float *ao, float *count)
{
    const obs__gtao_state *g = obs__gtao_of(f);
    const int w = f->width, h = f->height, steps = g->steps, slices = g->slices;
    const float thin1 = 1.0f + g->thin_power[0], fmul = g->falloff[0], fadd = g->falloff[1];
    const int heur = g->heuristics;
    float noise[9][2], cs[9][32][2]; /* each tile's noise and slices' directions (<= 32) */
    for (int t = 0; t < 9; t++) {
        obs__gtao_noise(t, noise[t]);
        for (int sl = 0; sl < slices; sl++)
            obs__gtao_slice_dir(g, sl, noise[t][0], cs[t][sl]);
    }
    for (int j0 = 0; j0 < m; j0 += METHOD_LANES) {
        chunk c;
        lanes_pn v;
        float c0[METHOD_LANES], c1[METHOD_LANES], c2[METHOD_LANES], v0[METHOD_LANES],
            v1[METHOD_LANES], v2[METHOD_LANES], rpx[METHOD_LANES], min_s[METHOD_LANES],
            nz1[METHOD_LANES], vis[METHOD_LANES], om0[METHOD_LANES],
            om1[METHOD_LANES], hc[2][METHOD_LANES];
        float sval[32][METHOD_LANES]; /* a side's steps' cosines (steps <= 32) */
        float np_len[METHOD_LANES], cosg[METHOD_LANES], gam[METHOD_LANES], lo[2][METHOD_LANES];
        int ok[METHOD_LANES], taken[METHOD_LANES], out[METHOD_LANES], ti[METHOD_LANES];
        int sqx[32][METHOD_LANES], sqy[32][METHOD_LANES];
        chunk_at(f, px, m, j0, &c);
        lanes_load(pos, nrm, &c, &v);
        for (int j = 0; j < METHOD_LANES; j++) {
            const float p[3] = {v.p0[j], v.p1[j], v.p2[j]};
            rpx[j] = obs__radius_px(f, p, g->radius);
            ok[j] = rpx[j] > 0.0f; /* else behind the camera: 1 */
            c0[j] = p[0] * GTAO_CENTRE_SCALE;
            c1[j] = p[1] * GTAO_CENTRE_SCALE;
            c2[j] = p[2] * GTAO_CENTRE_SCALE;
            v0[j] = v1[j] = 0.0f; /* towards the camera; orthographic: +z */
            v2[j] = 1.0f;
            if (f->proj[14] != 0.0f) {
                const float l = sqrtf(c0[j] * c0[j] + c1[j] * c1[j] + c2[j] * c2[j]);
                ok[j] &= l > 0.0f;
                v0[j] = -c0[j] / l;
                v1[j] = -c1[j] / l;
                v2[j] = -c2[j] / l;
            }
            ti[j] = obs__tile_index(f, c.x[j], c.y[j]);
            nz1[j] = noise[ti[j]][1];
            min_s[j] = GTAO_TOO_CLOSE / rpx[j];
            vis[j] = obs__gtao_vis0(g, rpx[j]);
            taken[j] = 0;
        }
        for (int sl = 0; sl < slices; sl++) {
            float cpl[METHOD_LANES], spl[METHOD_LANES];
            for (int j = 0; j < METHOD_LANES; j++) {
                cpl[j] = cs[ti[j]][sl][0];
                spl[j] = cs[ti[j]][sl][1];
            }
            /* obs__gtao_slice_setup(), its acosf and cosf by polynomials */
#pragma omp simd
            for (int j = 0; j < METHOD_LANES; j++) {
                const float cp = cpl[j], sp = spl[j];
                const float a0 = v0[j], a1 = v1[j], a2 = v2[j];
                const float n0 = v.n0[j], n1 = v.n1[j], n2 = v.n2[j];
                om0[j] = cp * rpx[j];
                om1[j] = -sp * rpx[j];
                const float dv = cp * a0 + sp * a1 + 0.0f * a2;
                const float od0 = cp - dv * a0, od1 = sp - dv * a1, od2 = 0.0f - dv * a2;
                float ax0 = od1 * a2 - od2 * a1, ax1 = od2 * a0 - od0 * a2;
                float ax2 = od0 * a1 - od1 * a0;
                const float al = sqrtf(ax0 * ax0 + ax1 * ax1 + ax2 * ax2);
                ax0 /= al;
                ax1 /= al;
                ax2 /= al;
                const float na = n0 * ax0 + n1 * ax1 + n2 * ax2;
                const float np0 = n0 - ax0 * na, np1 = n1 - ax1 * na, np2 = n2 - ax2 * na;
                const float npl = sqrtf(np0 * np0 + np1 * np1 + np2 * np2);
                const float cg = (np0 * a0 + np1 * a1 + np2 * a2) / npl;
                const float cgs = cg < 0.0f ? 0.0f : cg > 1.0f ? 1.0f : cg; /* saturate */
                const float cos_g = npl > 0.0f ? cgs : 1.0f;
                const float on = od0 * np0 + od1 * np1 + od2 * np2;
                const float gamma = (float)((on > 0.0f) - (on < 0.0f)) * acos_lane(cos_g);
                np_len[j] = npl;
                cosg[j] = cos_g;
                gam[j] = gamma;
                hc[0][j] = lo[0][j] = sincos_lane(gamma + (float)M_PI_2, 1);
                hc[1][j] = lo[1][j] = sincos_lane(gamma - (float)M_PI_2, 1);
            }
            for (int side = 0; side < 2; side++) {
                const int dir = side ? -1 : 1;
                float *hs = hc[side];
                for (int j = 0; j < METHOD_LANES; j++)
                    out[j] = 0;
                for (int st = 0; st < steps; st++) {
                    const float base = (float)(sl + st * steps) * GTAO_R1;
#pragma omp simd
                    for (int j = 0; j < METHOD_LANES; j++) {
                        float sn = nz1[j] + base;
                        sn -= floor_lane(sn);
                        float s = ((float)st + sn) / (float)steps;
                        s = s * s + min_s[j]; /* power 2, then off the centre pixel */
                        const int qx = c.x[j] + dir * (int)floor_lane(s * om0[j] + 0.5f);
                        const int qy = c.y[j] + dir * (int)floor_lane(s * om1[j] + 0.5f);
                        const int in = (qx >= 0) & (qy >= 0) & (qx < w) & (qy < h);
                        out[j] |= !in;
                        taken[j] += in;
                        sqx[st][j] = qx;
                        sqy[st][j] = qy;
                        const int k = 4 * (in ? qy * w + qx : c.k[j]);
                        const float q0 = pos[k], q1 = pos[k + 1], q2 = pos[k + 2];
                        const float q3 = pos[k + 3];
                        /* sample_cos() with the object masks' weight 1 */
                        const float d0 = q0 - c0[j], d1 = q1 - c1[j], d2 = q2 - c2[j];
                        const float dist = sqrtf(d0 * d0 + d1 * d1 + d2 * d2);
                        const float shc = (d0 * v0[j] + d1 * v1[j] + d2 * v2[j]) / dist;
                        const float dz = d2 * thin1;
                        const float fb = sqrtf(d0 * d0 + d1 * d1 + dz * dz);
                        const float t = fb * fmul + fadd; /* a number: the clamp without NaN */
                        const float wt = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
                        const float low = lo[side][j];
                        const float val =
                            (q3 > 0.0f) & (dist > 0.0f) ? low + (shc - low) * wt : low;
                        sval[st][j] = val;
                        hs[j] = in ? max_f(hs[j], val) : hs[j];
                    }
                }
                /* a side with a step off the planes: its largest cosine
                 * again in the steps' order, those steps read past the
                 * border (gtao.c) */
                for (int j = 0; j < METHOD_LANES; j++) {
                    if (!out[j] || !ok[j])
                        continue;
                    const float cc[3] = {c0[j], c1[j], c2[j]}, vv[3] = {v0[j], v1[j], v2[j]};
                    const int x = c.x[j], y = c.y[j];
                    float hm = lo[side][j], ext[4];
                    for (int st = 0; st < steps; st++) {
                        const int qx = sqx[st][j], qy = sqy[st][j];
                        if (qx >= 0 && qy >= 0 && qx < w && qy < h)
                            hm = max_f(hm, sval[st][j]);
                        else
                            obs__gtao_border_step(f, pos, nrm, 0, x, y, qx, qy, cc, vv,
                                                  lo[side][j], &hm, &taken[j], ext);
                    }
                    hs[j] = hm;
                }
            }
            /* obs__gtao_slice_vis(), its acosf, sinf and cosf by polynomials */
#pragma omp simd
            for (int j = 0; j < METHOD_LANES; j++) {
                const float half_pi = (float)M_PI_2, gamma = gam[j], cg = cosg[j];
                const float npl = heur ? np_len[j] + (1.0f - np_len[j]) * GTAO_SLOPE_FUDGE
                                       : np_len[j];
                const float k1 = hc[1][j] < -1.0f ? -1.0f : hc[1][j] > 1.0f ? 1.0f : hc[1][j];
                const float k0 = hc[0][j] < -1.0f ? -1.0f : hc[0][j] > 1.0f ? 1.0f : hc[0][j];
                const float e0 = -acos_lane(k1) - gamma, e1 = acos_lane(k0) - gamma;
                const float h0 = gamma + (e0 > -half_pi ? e0 : -half_pi);
                const float h1 = gamma + (e1 < half_pi ? e1 : half_pi);
                const float sg = sincos_lane(gamma, 0);
                /* obs__gtao_arc(): (cos g + 2 h sin g - cos(2 h - g)) / 4 */
                const float a0 = (cg + 2.0f * h0 * sg - sincos_lane(2.0f * h0 - gamma, 1)) / 4.0f;
                const float a1 = (cg + 2.0f * h1 * sg - sincos_lane(2.0f * h1 - gamma, 1)) / 4.0f;
                vis[j] += npl * (a0 + a1);
            }
        }
        for (int j = 0; j < c.cnt; j++) {
            const int k = c.k[j];
            ao[k] = ok[j] ? obs__gtao_finish(g, vis[j]) : 1.0f; /* 1: behind the camera */
            if (count)
                count[k] = (float)(ok[j] ? taken[j] : 0);
        }
    }
}

int obs__method_pixels(const obs__frame *f, const float *pos, const float *nrm, const int *px,
                       int m, float *ao, float *count)
{
    if (f->mask_on)
        return 0;
    switch (f->method) {
    case OBS_METHOD_HEMISPHERE:
        hemisphere_pixels(f, pos, nrm, px, m, ao);
        for (int j = 0; count && j < m; j++)
            count[px[j]] = (float)obs__hemisphere_of(f)->count;
        return 1;
    case OBS_METHOD_ANGLE:
        if (obs__angle_of(f)->acos == OBS_ACOS_EXACT)
            return 0; /* acosf: a libm call, not in the lanes */
        angle_pixels(f, pos, nrm, px, m, ao);
        for (int j = 0; count && j < m; j++)
            count[px[j]] = (float)(2 * obs__angle_of(f)->pairs);
        return 1;
    case OBS_METHOD_HBAO:
        hbao_pixels(f, pos, nrm, px, m, ao, count);
        return 1;
    case OBS_METHOD_GTAO:
        gtao_pixels(f, pos, nrm, px, m, ao, count);
        return 1;
    default:
        return 0;
    }
}
