/* CPU twin of VAO's estimator (VAO++ section 3, eq 1 and 2; GLSL:
 * vao.glsl, vao.frag.glsl, common.glsl): the line samples through the
 * tangent sphere, adaptive sampling's count (4.1), the depth range
 * check's falloff (4.4), colour bleeding's gather (4.7) and the
 * conversion of ao_definition rays.  Each function mirrors the GLSL
 * function of the same role; tests/unit/core/test_gl_twin.c compares. */
#include <math.h>
#include <string.h>

#include "chain/frame.h"
#include "chain/mask_weight.h"
#include "chain/vao_cpu.h"


/* GLSL: adaptive_count() in vao.frag.glsl.  Section 4.1: "double the
 * number of samples every time surface area of the sampling disc
 * doubles", 2 samples for a disk of diameter D0 (adaptive_diameter, a
 * fraction of the image height).
 *
 * The disk is c + (dx, dy, 0), |(dx, dy)| <= r = R/2.  Its NDC image has
 * the Jacobian J = d(ndc)/d(dx, dy) at c,
 *   J = [[P00 w - X P30, P01 w - X P31], [P10 w - Y P30, P11 w - Y P31]] / w^2
 * with (X, Y, w) = the clip coordinates of c; its area is pi r^2 |det J|
 * (exact when P30 = P31 = 0, i.e. for every perspective or orthographic
 * camera: the map is then affine at fixed view z).  In pixels that is
 * times (vw/2)(vh/2); the diameter D of the disk of the same area, as a
 * fraction of vh, has D^2 = r^2 |det J| vw / vh, and the area ratio is
 * q = D^2 / D0^2 = r^2 |det J| * adaptive_k.  The count is 2 for q < 2,
 * 4 for 2 <= q < 4, ..., capped at the samples parameter; a centre
 * behind the camera takes the maximum. */
/* the area ratio q and the centre's clip w */
static inline __attribute__((always_inline)) float adaptive_q(const obs__frame *f, float c0,
                                                              float c1, float c2, float *wc)
{
    const float *P = f->proj;
    float w = P[12] * c0 + P[13] * c1 + P[14] * c2 + P[15];
    float X = P[0] * c0 + P[1] * c1 + P[2] * c2 + P[3];
    float Y = P[4] * c0 + P[5] * c1 + P[6] * c2 + P[7];
    float w2 = w * w;
    float j00 = (P[0] * w - X * P[12]) / w2, j01 = (P[1] * w - X * P[13]) / w2;
    float j10 = (P[4] * w - Y * P[12]) / w2, j11 = (P[5] * w - Y * P[13]) / w2;
    float r = 0.5f * f->radius;
    *wc = w;
    return r * r * fabsf(j00 * j11 - j01 * j10) * f->adaptive_k;
}

static inline int count_of_q(const obs__frame *f, float q, float w)
{
    if (!(w > 0.0f))
        return f->samples;
    int n = 2;
    while (n < f->samples && q >= (float)n)
        n *= 2;
    return n;
}

int obs__adaptive_count(const obs__frame *f, const float c[3])
{
    float w, q = adaptive_q(f, c[0], c[1], c[2], &w);
    return count_of_q(f, q, w);
}

/* GLSL: the count in main() of vao.frag.glsl */
int obs__vao_count(const obs__frame *f, const float p[3], const float n[3])
{
    if (!f->adaptive)
        return f->samples;
    const float r = 0.5f * f->radius;
    const float c[3] = {p[0] + n[0] * r, p[1] + n[1] * r, p[2] + n[2] * r};
    return obs__adaptive_count(f, c);
}

float obs__vao_pixel(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                     const float p[3], const float n[3], int *count)
{
    /* Section 4.1: the set of the pixel's count, found in the one table of
     * all sets by its offset (the shader's single uniform array). */
    int ns = obs__vao_count(f, p, n);
    if (count)
        *count = ns;
    const float *xy = f->adaptive ? f->sample_table + 2 * (ns - 2) : f->sample_xy;
    return obs__vao_estimate(f, pos, nrm, x, y, p, n, ns, xy);
}

/* GLSL: range_falloff() in common.glsl */
static inline float range_falloff(const obs__frame *f, float d, float nz)
{
    if (f->range_normal)
        d *= fabsf(nz); /* the pipe's depth below the flat occluder */
    return f->range_u / max_f(f->range_u, d / f->radius); /* eq 4 */
}

float obs__range_falloff(const obs__frame *f, float d, float nz)
{
    return range_falloff(f, d, nz);
}

/* GLSL: own_plane_depth(), disk_point() in common.glsl */
float obs__own_plane_depth(const float p[3], const float n[3], const float c[3], float r,
                           const float rot[2], float sx, float sy, float zs)
{
    if (!(fabsf(n[2]) > OBS_OWN_PLANE_NZ))
        return zs;
    float spx = c[0] + r * (rot[0] * sx - rot[1] * sy);
    float spy = c[1] + r * (rot[1] * sx + rot[0] * sy);
    return -p[2] + (n[0] * (spx - p[0]) + n[1] * (spy - p[1])) / n[2];
}

/* GLSL: rays_from_volume() in common.glsl */
float obs__rays_from_volume(float ao)
{
    const float pi = 3.14159265358979f;
    float o = 1.0f - fminf(fmaxf(ao, 0.0f), 1.0f); /* occluded fraction of the sphere */
    if (o >= 0.5f)
        return ao; /* deeper than the crease's corner: unchanged */
    /* o = (1 - b)^2 (2 + b) / 4 is the cubic t^3 - 3t^2 + 4o = 0 in
     * t = 1 - b; its root with b in [0, 1] (trigonometric form):
     * b = 2 cos((acos(1 - 2o) + pi) / 3), 1 at o = 0, 0 at o = 1/2. */
    float b = 2.0f * cosf((acosf(1.0f - 2.0f * o) + pi) / 3.0f);
    b = fminf(fmaxf(b, 0.0f), 1.0f);
    /* cosine-weighted rays of length D blocked by the wall at b D */
    float blocked = (acosf(b) - b * sqrtf(fmaxf(0.0f, 1.0f - b * b))) / pi;
    return 1.0f - blocked;
}

/* obs__rays_from_volume in lanes (no libm call): b = 2 cos((acos(1 - 2o)
 * + pi) / 3) is 2 sin(asin(1 - 2o) / 3) (pi/2 - acos y = asin y), and
 * acos(b) = pi/2 - asin(b); sin on [0, pi/6] by its Taylor polynomial to
 * d^7 (the next term is below 1e-8 there).  Not the twin's libm
 * acosf / cosf, so not its bits: within RAYS_LANE_TOL of it for every
 * input (tests/unit/core/test_cpu_simd.c sweeps [0, 1]). */
static inline __attribute__((always_inline)) float rays_lane(float ao)
{
    const float pi = 3.14159265358979f;
    const float o = 1.0f - min_f(max_f(ao, 0.0f), 1.0f);
    const float d = asin_lane(1.0f - 2.0f * o) / 3.0f; /* in (0, pi/6] for o < 1/2 */
    const float d2 = d * d;
    const float sn = d + d * d2 * (-1.6666666667e-1f + d2 * (8.3333333333e-3f + d2 * -1.9841269841e-4f));
    /* b is a number (o is, by the clamp above): plain clamps, and
     * 1 - b^2 >= 0 without one */
    const float b0 = 2.0f * sn, b1 = b0 > 0.0f ? b0 : 0.0f, b = b1 < 1.0f ? b1 : 1.0f;
    const float blocked = (1.57079632679489662f - asin_lane(b) - b * sqrtf(1.0f - b * b)) / pi;
    return o >= 0.5f ? ao : 1.0f - blocked;
}

OBS__LANES
void obs__rays_rows(float *ao, size_t n)
{
    /* the open pixels (AO exactly 1: the background, and the blur of an
     * open neighbourhood, whose sums are then equal) take the twin's value
     * of 1, computed once */
    const float open = obs__rays_from_volume(1.0f);
    for (size_t i0 = 0; i0 < n; i0 += 4096) {
        float *a = ao + i0;
        const int m = n - i0 < 4096 ? (int)(n - i0) : 4096;
#pragma omp simd
        for (int i = 0; i < m; i++)
            a[i] = a[i] == 1.0f ? open : rays_lane(a[i]);
    }
}

/* GLSL: disk_map() in common.glsl; m[0], m[s], ..., m[8 s] = u, v, w
 * (obs__disk).  The rows 0, 1 and 3 of the projection (row 2, z, is not in
 * the map), written out so that the lanes can take it. */
static inline __attribute__((always_inline)) void disk_map(const obs__frame *f, float c0, float c1,
                                                           float c2, float r, float rot0,
                                                           float rot1, float *m, int s)
{
    const float *P = f->proj, *vp = f->viewport;
#define DISK_ROW(i, k0, A, B)                                                                 \
    const float k0 = P[4 * i] * c0 + P[4 * i + 1] * c1 + P[4 * i + 2] * c2 + P[4 * i + 3]; \
    const float A = rot0 * (P[4 * i] * r) + rot1 * (P[4 * i + 1] * r);                     \
    const float B = rot0 * (P[4 * i + 1] * r) - rot1 * (P[4 * i] * r)
    DISK_ROW(0, k00, A0, B0); /* A, B: a step r along the rotated view x, y */
    DISK_ROW(1, k01, A1, B1);
    DISK_ROW(3, k03, A3, B3);
#undef DISK_ROW
    const float hx = 0.5f * vp[2], hy = 0.5f * vp[3];
    const float ox = hx - vp[0], oy = hy - vp[1];
    m[0] = hx * A0 + ox * A3;
    m[1 * s] = hx * B0 + ox * B3;
    m[2 * s] = hx * k00 + ox * k03;
    m[3 * s] = -hy * A1 + oy * A3;
    m[4 * s] = -hy * B1 + oy * B3;
    m[5 * s] = -hy * k01 + oy * k03;
    m[6 * s] = A3;
    m[7 * s] = B3;
    m[8 * s] = k03;
}

void obs__disk_map(const obs__frame *f, const float c[3], float r, const float rot[2],
                   obs__disk *m)
{
    float t[9];
    disk_map(f, c[0], c[1], c[2], r, rot[0], rot[1], t, 1);
    memcpy(m->u, t, 3 * sizeof(float));
    memcpy(m->v, t + 3, 3 * sizeof(float));
    memcpy(m->w, t + 6, 3 * sizeof(float));
}

/* The pixel coordinates (floored) the disk map sends sample (sx, sy) to;
 * 0 behind the camera (w <= 0). */
static inline int disk_uv(const obs__disk *m, float sx, float sy, float *fu, float *fv)
{
    float sw = m->w[0] * sx + m->w[1] * sy + m->w[2];
    if (!(sw > 0.0f))
        return 0;
    *fu = floorf((m->u[0] * sx + m->u[1] * sy + m->u[2]) / sw);
    *fv = floorf((m->v[0] * sx + m->v[1] * sy + m->v[2]) / sw);
    return 1;
}

/* GLSL: disk_px() in common.glsl */
static inline int disk_px(const obs__frame *f, const obs__disk *m, float sx, float sy, int *qx,
                          int *qy)
{
    float fu, fv;
    if (!disk_uv(m, sx, sy, &fu, &fv))
        return 0;
    if (!(fu >= 0.0f && fv >= 0.0f && fu < (float)f->width && fv < (float)f->height))
        return 0;
    *qx = (int)fu;
    *qy = (int)fv;
    return 1;
}

int obs__disk_px(const obs__frame *f, const obs__disk *m, float sx, float sy, int *qx, int *qy)
{
    return disk_px(f, m, sx, sy, qx, qy);
}

/* GLSL: the branch of vao_estimate() in vao.glsl for a sample off the
 * planes (border_cpu.c), and deep_border() in deep.frag.glsl: 1 and *zs,
 * *nz of the surface continued past the border (*zs left as it is, open,
 * where that is background), *bk (when not NULL) the pixel index of the
 * pixel b continued; 0 where the sample is left out of eq 1 (behind the
 * camera, or no estimate). */
int obs__disk_border(const obs__frame *f, const float *pos, const float *nrm, const obs__disk *m,
                     int x, int y, float sx, float sy, float *zs, float *nz, size_t *bk)
{
    float fu, fv;
    if (!disk_uv(m, sx, sy, &fu, &fv))
        return 0;
    float pt[4];
    int got = obs__border_point(f, pos, nrm, x, y, fu, fv, pt, nz, bk);
    if (got > 0)
        *zs = pt[3];
    return got >= 0;
}

/* GLSL: vao_estimate() in vao.glsl, without colour bleeding */
float obs__vao_estimate(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                        const float p[3], const float n[3], int ns, const float *xy)
{
    float bleed[3];
    return obs__vao_estimate_bleed(f, pos, nrm, NULL, x, y, p, n, ns, xy, bleed);
}

/* GLSL: vao_estimate() in vao.glsl.  The scene at a sample's pixel k:
 * its depth at d[ds * k], its view normal's z at nz[ns_ * k] (the prep
 * planes, or the CPU device's packed plane of the two), its position at
 * pos + 4 k (for bleeding only). */
static inline float estimate(const obs__frame *f, const float *pos, const float *nrm,
                             const float *d_at, int ds,
                             const float *nz_at, int nzs, const float *col, int x, int y,
                             const float p[3], const float n[3], int ns, const float *xy,
                             float bleed[3], float bent[3])
{
    const float R = f->radius, r = 0.5f * f->radius;
    /* Centre of the tangent sphere of radius R/2, moved along the normal. */
    float c[3] = {p[0] + n[0] * r, p[1] + n[1] * r, p[2] + n[2] * r};
    const float *rot = f->rot[obs__tile_index(f, x, y)];
    obs__disk disk;
    obs__disk_map(f, c, r, rot, &disk);
    float open = 0.0f, F = 0.0f;
    float acc[3] = {0.0f, 0.0f, 0.0f}, taken = 0.0f; /* section 4.7 */

    for (int i = 0; i < ns; i++) {
        /* Section 4.7: "every second or fourth sample"; the sets are
         * z-ordered, so those still cover the disk evenly. */
        int bleeds = col && f->bleed_step > 0 && i % f->bleed_step == 0;
        float c5 = 0.0f; /* eq 5's c(x); 0 (white) without a surface there */
        const float *cx5 = NULL;
        float sx = xy[2 * i], sy = xy[2 * i + 1];
        float l = sqrtf(max_f(0.0f, 1.0f - sx * sx - sy * sy));
        float h = r * l; /* half length of the pipe through the sphere */
        int seen = 0;    /* the sample's pixel is on the planes */

        float zs = INFINITY; /* scene depth at the sample's pixel */
        float nz = 1.0f; /* view normal z of the surface there */
        int qx = x, qy = y;
        /* The sample on the disk through the centre, perpendicular to view Z. */
        seen = disk_px(f, &disk, sx, sy, &qx, &qy);
        if (seen) {
            size_t k = (size_t)qy * (size_t)f->width + (size_t)qx;
            float d = d_at[(size_t)ds * k];
            if (d > 0.0f) {
                zs = d;
                nz = nz_at[(size_t)nzs * k];
                /* a sample on the shaded pixel itself: p's tangent plane */
                if (qx == x && qy == y)
                    zs = obs__own_plane_depth(p, n, c, r, rot, sx, sy, zs);
                if (bleeds) { /* eq 5 with x the surface point at the sample's pixel */
                    c5 = obs__bleed_weight(pos + 4 * k, p, n, R);
                    cx5 = col + 4 * k;
                }
            }
        } else {
            seen = obs__disk_border(f, pos, nrm, &disk, x, y, sx, sy, &zs, &nz, NULL);
        }
        if (bleeds) {
            /* "We use c(x) to linearly interpolate between the white
             * color and the sampled color." */
            for (int j = 0; j < 3; j++)
                acc[j] += cx5 ? 1.0f + c5 * (cx5[j] - 1.0f) : 1.0f;
            taken += 1.0f;
        }
        /* Unoccluded length of the pipe (cases A, B, C of section 3):
         * the pipe spans depths [-c.z - h, -c.z + h]. */
        float front = -c[2] - h;
        float dz = min_f(max_f(zs - front, 0.0f), 2.0f * h);
        const float om = obs__occluder_weight(f, x, y, qx, qy); /* object masks */
        if (f->range_check && zs < front) {
            /* Case C with the depth range check, section 4.4, eq 4: the
             * pipe lies d behind the visible surface; the occluder is
             * thick only by the falloff s(d) = u / max(u, d / radius), so
             * the pipe's weight 2h counts as occluded times s(d).  d is
             * taken from the pipe's near end, so s = 1 where case C meets
             * case A (zs = front) and the two join without a step. */
            float sd = range_falloff(f, front - zs, nz);
            dz = 2.0f * h * (1.0f - sd);
        }
        dz += (2.0f * h - dz) * (1.0f - om); /* the occluded length times the mask (om 1: dz) */
        /* A sample off the planes reads the surface continued past the
         * border (border_cpu.c derives it); one behind the camera, or
         * without that estimate, says nothing about the scene: it is left
         * out of eq 1's sum and of F alike. */
        if (seen) {
            open += dz;
            F += R * l; /* eq 2: F = R * sum sqrt(1 - x^2 - y^2) */
            if (bent) /* OBS_OUTPUT_BENT: the open part's centroid (obs__vao_estimate_bent) */
                obs__vao_bent_sample(c, r, rot, sx, sy, h, dz, p, bent);
        }
    }
    for (int j = 0; j < 3; j++)
        bleed[j] = taken > 0.0f ? acc[j] / taken : 1.0f;
    return F > 0.0f ? open / F : 1.0f; /* eq 1: V = (1/F) sum dz_i */
}

float obs__vao_estimate_bleed(const obs__frame *f, const float *pos, const float *nrm,
                              const float *col, int x, int y, const float p[3], const float n[3],
                              int ns, const float *xy, float bleed[3])
{
    return estimate(f, pos, nrm, pos + 3, 4, nrm + 2, 3, col, x, y, p, n, ns, xy, bleed, NULL);
}

/* The unoccluded length *dz of the pipe of half length h (centre depth
 * -c2) of a sample off the planes (obs__disk_border), as estimate() takes it;
 * 0 where the sample is left out of eq 1. */
static int border_dz(const obs__frame *f, const float *pos, const float *nrm, const obs__disk *m,
                     int x, int y, float sx, float sy, float c2, float h, float *dz)
{
    float zs = INFINITY, nz = 1.0f;
    if (!obs__disk_border(f, pos, nrm, m, x, y, sx, sy, &zs, &nz, NULL))
        return 0;
    const float front = -c2 - h;
    float d = min_f(max_f(zs - front, 0.0f), 2.0f * h);
    if (f->range_check && zs < front)
        d = 2.0f * h * (1.0f - range_falloff(f, front - zs, nz));
    *dz = d;
    return 1;
}

/* estimate() without colour bleeding, its samples in SIMD lanes
 * (#pragma omp simd, gcc -fopenmp-simd): each sample's pixel, depth and
 * pipe length computed in every lane with selects in place of branches,
 * the same operations on the same values as estimate(), then eq 1's sums
 * taken in the samples' order, so the result is estimate()'s, bit for
 * bit. */
/* always inlined: into each of the clones of its caller (OBS__LANES) */
static inline __attribute__((always_inline)) float estimate_lanes(const obs__frame *f, const float *pos,
                                                                  const float *nrm, const float *dnz, int x, int y,
                                   const float p[3], const float n[3], int ns, const float *xy)
{
    const float R = f->radius, r = 0.5f * f->radius;
    const float c[3] = {p[0] + n[0] * r, p[1] + n[1] * r, p[2] + n[2] * r};
    const float *rot = f->rot[obs__tile_index(f, x, y)];
    obs__disk m;
    obs__disk_map(f, c, r, rot, &m);
    const float fw = (float)f->width, fh = (float)f->height;
    const int w = f->width, range = f->range_check, by_normal = f->range_normal;
    const float u = f->range_u;
    /* own_plane_depth()'s terms that do not depend on the sample */
    const int own_plane = fabsf(n[2]) > OBS_OWN_PLANE_NZ;
    float dzs[32], ls[32];
    int seens[32];
#pragma omp simd
    for (int i = 0; i < ns; i++) {
        const float sx = xy[2 * i], sy = xy[2 * i + 1];
        const float l = sqrtf(max_f(0.0f, 1.0f - sx * sx - sy * sy));
        const float h = r * l;
        /* disk_px() */
        const float sw = m.w[0] * sx + m.w[1] * sy + m.w[2];
        const float fu = floor_lane((m.u[0] * sx + m.u[1] * sy + m.u[2]) / sw);
        const float fv = floor_lane((m.v[0] * sx + m.v[1] * sy + m.v[2]) / sw);
        const int seen = (sw > 0.0f) & (fu >= 0.0f) & (fv >= 0.0f) & (fu < fw) & (fv < fh);
        /* off the planes: the shaded pixel's own (read, then left out), a
         * pixel a band of rows holds (bands_run.c) */
        const int qx = seen ? (int)fu : x, qy = seen ? (int)fv : y;
        const int k = qy * w + qx; /* < 2^28 (the frame's size limit) */
        const float d = dnz[2 * k], nzk = dnz[2 * k + 1];
        const int hit = seen & (d > 0.0f);
        /* own_plane_depth() on the shaded pixel itself */
        const float spx = c[0] + r * (rot[0] * sx - rot[1] * sy);
        const float spy = c[1] + r * (rot[1] * sx + rot[0] * sy);
        const float own = -p[2] + (n[0] * (spx - p[0]) + n[1] * (spy - p[1])) / n[2];
        const int self = hit & (qx == x) & (qy == y) & own_plane;
        const float zs = self ? own : hit ? d : INFINITY;
        const float nz = hit ? nzk : 1.0f;
        const float front = -c[2] - h;
        const float dz_ab = min_f(max_f(zs - front, 0.0f), 2.0f * h);
        /* range_falloff(), eq 4 */
        const float dd = by_normal ? (front - zs) * fabsf(nz) : front - zs;
        const float sd = u / max_f(u, dd / R);
        const float dz_c = 2.0f * h * (1.0f - sd);
        dzs[i] = range & (zs < front) ? dz_c : dz_ab;
        ls[i] = l;
        seens[i] = seen;
    }
    /* a sample off the planes reads the surface continued past the border
     * (obs__disk_border, border_cpu.c), one by one, its pipe as estimate()
     * takes it */
    for (int i = 0; i < ns; i++)
        if (!seens[i])
            seens[i] = border_dz(f, pos, nrm, &m, x, y, xy[2 * i], xy[2 * i + 1], c[2], r * ls[i],
                                 &dzs[i]);
    float open = 0.0f, F = 0.0f;
    for (int i = 0; i < ns; i++)
        if (seens[i]) {
            open += dzs[i];
            F += R * ls[i]; /* eq 2 */
        }
    return F > 0.0f ? open / F : 1.0f; /* eq 1 */
}

OBS__LANES
float obs__vao_estimate_dnz(const obs__frame *f, const float *pos, const float *nrm,
                            const float *dnz, const float *col, int x, int y, const float p[3],
                            const float n[3], int ns, const float *xy, float bleed[3])
{
    /* bleeding, and object masks (not in the lanes): the reference loop */
    if ((col && f->bleed_step > 0) || f->mask_on)
        return estimate(f, pos, nrm, dnz, 2, dnz + 1, 2, col, x, y, p, n, ns, xy, bleed, NULL);
    bleed[0] = bleed[1] = bleed[2] = 1.0f;
    return estimate_lanes(f, pos, nrm, dnz, x, y, p, n, ns, xy);
}

float obs__vao_estimate_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                             const float p[3], const float n[3], int ns, const float *xy,
                             float bent[3])
{
    float bleed[3];
    bent[0] = bent[1] = bent[2] = 0.0f;
    return estimate(f, pos, nrm, pos + 3, 4, nrm + 2, 3, NULL, x, y, p, n, ns, xy, bleed, bent);
}

/* Section 4.1's count of each of the m pixels px[] (obs__vao_count), the
 * pixels in SIMD lanes. */
OBS__LANES
void obs__vao_counts(const obs__frame *f, const float *pos, const float *nrm, const int *px, int m,
                     int *n)
{
    const float r = 0.5f * f->radius;
    if (!f->adaptive) {
        for (int j = 0; j < m; j++)
            n[j] = f->samples;
        return;
    }
    for (int j0 = 0; j0 < m; j0 += 64) {
        const int cnt = m - j0 < 64 ? m - j0 : 64;
        float q[64], w[64];
#pragma omp simd
        for (int j = 0; j < cnt; j++) {
            const int k = px[j0 + j]; /* < 2^28 (the frame's size limit): 4 k fits */
            const float c0 = pos[4 * k] + nrm[3 * k] * r, c1 = pos[4 * k + 1] + nrm[3 * k + 1] * r;
            const float c2 = pos[4 * k + 2] + nrm[3 * k + 2] * r;
            q[j] = adaptive_q(f, c0, c1, c2, &w[j]);
        }
        for (int j = 0; j < cnt; j++)
            n[j0 + j] = count_of_q(f, q[j], w[j]);
    }
}

/* The pixels of obs__vao_estimate_pixels in one chunk of lanes: one
 * vector of AVX-512, two of AVX2. */
#define PX_LANES 16
#define DM(q) dm[(q) * PX_LANES + j] /* term q of lane j's disk map */

/* border_dz() of n samples off the planes in lanes, entry e the sample
 * mi[e] of chunk lane ml[e] (disk map dm, pixel xs, ys, centre depth c2):
 * obs__border_point, obs__border_px and obs__plane_point (border_cpu.c)
 * as selects, the same floats; seen[e] 0 where the sample is left out of
 * eq 1, else its unoccluded length in dz[e]. */
OBS__LANES __attribute__((noinline)) static void border_lanes(
    const obs__frame *f, const float *pos, const float *nrm, const float *P, const float *vp,
    const float *dm, const int *xs, const int *ys, const float *c2, const float *hs,
    const float *xy, const int *ml, const int *mi, int n, float *dz, int *seen)
{
    const float fw = (float)f->width, fh = (float)f->height, R = f->radius, u = f->range_u;
    const int w = f->width, range = f->range_check, by_normal = f->range_normal;
#pragma omp simd
    for (int e = 0; e < n; e++) {
        const int j = ml[e], i = mi[e];
        const float sx = xy[2 * i], sy = xy[2 * i + 1], h = hs[i];
        /* disk_uv() */
        const float sw =
            dm[6 * PX_LANES + j] * sx + dm[7 * PX_LANES + j] * sy + dm[8 * PX_LANES + j];
        const float fu =
            floor_lane((dm[j] * sx + dm[PX_LANES + j] * sy + dm[2 * PX_LANES + j]) / sw);
        const float fv = floor_lane(
            (dm[3 * PX_LANES + j] * sx + dm[4 * PX_LANES + j] * sy + dm[5 * PX_LANES + j]) / sw);
        const int near = (fabsf(fu) < OBS_BORDER_MAX_PX) & (fabsf(fv) < OBS_BORDER_MAX_PX);
        /* obs__border_px() */
        const float px0 = (float)xs[j] + 0.5f, py0 = (float)ys[j] + 0.5f;
        const float du = fu + 0.5f - px0, dv = fv + 0.5f - py0;
        const float tu = du > 0.0f ? (fw - px0) / du : du < 0.0f ? -px0 / du : 1.0f;
        const float t1 = min_num(1.0f, tu); /* tu, tv: numbers */
        const float tv = dv > 0.0f ? (fh - py0) / dv : dv < 0.0f ? -py0 / dv : t1;
        const float t = min_num(t1, tv);
        const int bx = (int)min_num(max_num(floor_lane(px0 + t * du), 0.0f), fw - 1.0f);
        const int by = (int)min_num(max_num(floor_lane(py0 + t * dv), 0.0f), fh - 1.0f);
        const int k = (by * w + bx) & -near; /* not a select: gcc gathers by pointers */
        const float b0 = pos[4 * k], b1 = pos[4 * k + 1], b2 = pos[4 * k + 2];
        const float b3 = pos[4 * k + 3];
        const float nb0 = nrm[3 * k], nb1 = nrm[3 * k + 1], nb2 = nrm[3 * k + 2];
        /* obs__plane_point(): obs__px_ndc() of the sample's pixel, obs__view_ray() */
        /* (float)(int)fu is fu: an integer under OBS_BORDER_MAX_PX where used */
        const float nx = (fu + 0.5f + vp[0]) / vp[2] * 2.0f - 1.0f;
        const float ny = 1.0f - (fv + 0.5f + vp[1]) / vp[3] * 2.0f;
        const float a = P[0] - nx * P[12], b = P[1] - nx * P[13];
        const float c = P[4] - ny * P[12], d = P[5] - ny * P[13];
        const float b0x = nx * P[15] - P[3], b0y = ny * P[15] - P[7];
        const float b1x = nx * P[14] - P[2], b1y = ny * P[14] - P[6];
        const float inv = 1.0f / (a * d - b * c);
        const float o0 = (d * b0x - b * b0y) * inv, o1 = (a * b0y - c * b0x) * inv;
        const float dir0 = -(d * b1x - b * b1y) * inv, dir1 = -(a * b1y - c * b1x) * inv;
        const float den = nb0 * dir0 + nb1 * dir1 + nb2 * -1.0f;
        const float dp = (nb0 * (b0 - o0) + nb1 * (b1 - o1) + nb2 * (b2 - 0.0f)) / den;
        const int fg = b3 > 0.0f; /* else background: the sample is open */
        const int got = (den < 0.0f) & (dp > 0.0f) & (dp < OBS_BACKGROUND_DEPTH);
        const float zs = fg ? dp : INFINITY;
        const float nz = fg ? nb2 : 1.0f;
        seen[e] = (sw > 0.0f) & near & ((fg == 0) | got);
        /* the pipe, as estimate() takes it */
        const float front = -c2[j] - h;
        const float dz_ab = min_f(max_f(zs - front, 0.0f), 2.0f * h);
        const float dd = by_normal ? (front - zs) * fabsf(nz) : front - zs;
        const float sd = u / max_f(u, dd / R);
        const float dz_c = 2.0f * h * (1.0f - sd);
        dz[e] = range & (zs < front) ? dz_c : dz_ab;
    }
}

/* estimate_lanes() of m pixels at once: a chunk of PX_LANES pixels in the
 * lanes, each sample's arithmetic for all of them (the pixels' own terms,
 * the disk map among them, in lanes too), eq 1's sums per lane in the
 * samples' order, so each pixel's result is estimate_lanes()'s, bit for
 * bit.  What a pixel's samples share is computed once: the pipes' half
 * lengths and, for a pixel all of whose samples fall on the planes, eq 2's
 * F.  The samples off the planes (the surface continued past the border,
 * border_cpu.c) are taken afterwards, in lanes over a list of them
 * (border_lanes), and their pixels' sums redone in the samples' order. */
OBS__LANES
void obs__vao_estimate_pixels(const obs__frame *f, const float *pos, const float *nrm,
                              const float *dnz, const int *px, int m, int ns, const float *xy,
                              float *ao)
{
    const float R = f->radius, r = 0.5f * f->radius;
    const float fw = (float)f->width, fh = (float)f->height;
    const int w = f->width, range = f->range_check, by_normal = f->range_normal;
    const float u = f->range_u;
    float ls[32], hs[32], F = 0.0f, rots[18], P[16], vp[4];
    memcpy(rots, f->rot, sizeof rots);
    memcpy(P, f->proj, sizeof P);
    memcpy(vp, f->viewport, sizeof vp);
    for (int i = 0; i < ns; i++) {
        const float sx = xy[2 * i], sy = xy[2 * i + 1];
        const float l = sqrtf(max_f(0.0f, 1.0f - sx * sx - sy * sy));
        ls[i] = l;
        hs[i] = r * l;
        F += R * l; /* eq 2: F = R * sum sqrt(1 - x^2 - y^2) */
    }
    for (int j0 = 0; j0 < m; j0 += PX_LANES) {
        const int cnt = m - j0 < PX_LANES ? m - j0 : PX_LANES;
        float p0[PX_LANES], p1[PX_LANES], p2[PX_LANES], n0[PX_LANES], n1[PX_LANES],
            n2[PX_LANES], c0[PX_LANES], c1[PX_LANES], c2[PX_LANES], ro0[PX_LANES],
            ro1[PX_LANES], dm[9 * PX_LANES], open[PX_LANES], dzs[32][PX_LANES];
        int kk[PX_LANES], ti[PX_LANES], xs[PX_LANES], ys[PX_LANES], ownp[PX_LANES],
            miss[PX_LANES], seen_at[32][PX_LANES];
        int ml[32 * PX_LANES], mi[32 * PX_LANES], bseen[32 * PX_LANES]; /* off the planes */
        float bdz[32 * PX_LANES];
        /* lanes past the m pixels repeat the first */
        for (int j = 0; j < PX_LANES; j++) {
            kk[j] = px[j0 + (j < cnt ? j : 0)];
            xs[j] = kk[j] % w;
            ys[j] = kk[j] / w;
            ti[j] = obs__tile_index(f, xs[j], ys[j]);
        }
        /* the pixels' own terms */
#pragma omp simd
        for (int j = 0; j < PX_LANES; j++) {
            const int k = kk[j]; /* < 2^28 (the frame's size limit): 4 k fits */
            p0[j] = pos[4 * k];
            p1[j] = pos[4 * k + 1];
            p2[j] = pos[4 * k + 2];
            n0[j] = nrm[3 * k];
            n1[j] = nrm[3 * k + 1];
            n2[j] = nrm[3 * k + 2];
            c0[j] = p0[j] + n0[j] * r;
            c1[j] = p1[j] + n1[j] * r;
            c2[j] = p2[j] + n2[j] * r;
            ro0[j] = rots[2 * ti[j]];
            ro1[j] = rots[2 * ti[j] + 1];
            disk_map(f, c0[j], c1[j], c2[j], r, ro0[j], ro1[j], dm + j, PX_LANES);
            ownp[j] = fabsf(n2[j]) > OBS_OWN_PLANE_NZ;
            open[j] = 0.0f;
            miss[j] = 0;
        }
        for (int i = 0; i < ns; i++) {
            const float sx = xy[2 * i], sy = xy[2 * i + 1], h = hs[i];
#pragma omp simd
            for (int j = 0; j < PX_LANES; j++) {
                /* disk_px() */
                const float sw = DM(6) * sx + DM(7) * sy + DM(8);
                const float fu = floor_lane((DM(0) * sx + DM(1) * sy + DM(2)) / sw);
                const float fv = floor_lane((DM(3) * sx + DM(4) * sy + DM(5)) / sw);
                const int seen =
                    (sw > 0.0f) & (fu >= 0.0f) & (fv >= 0.0f) & (fu < fw) & (fv < fh);
                const int qx = (int)fu & -seen, qy = (int)fv & -seen; /* 0 off the planes */
                const int k = qy * w + qx;
                const float d = dnz[2 * k], nzk = dnz[2 * k + 1];
                const int hit = seen & (d > 0.0f);
                /* own_plane_depth() on the shaded pixel itself */
                const float spx = c0[j] + r * (ro0[j] * sx - ro1[j] * sy);
                const float spy = c1[j] + r * (ro1[j] * sx + ro0[j] * sy);
                const float own =
                    -p2[j] + (n0[j] * (spx - p0[j]) + n1[j] * (spy - p1[j])) / n2[j];
                const int self = hit & (qx == xs[j]) & (qy == ys[j]) & ownp[j];
                const float zs = self ? own : hit ? d : INFINITY;
                const float nz = hit ? nzk : 1.0f;
                const float front = -c2[j] - h;
                const float dz_ab = min_f(max_f(zs - front, 0.0f), 2.0f * h);
                /* range_falloff(), eq 4 */
                const float dd = by_normal ? (front - zs) * fabsf(nz) : front - zs;
                const float sd = u / max_f(u, dd / R);
                const float dz_c = 2.0f * h * (1.0f - sd);
                const float dz = range & (zs < front) ? dz_c : dz_ab;
                open[j] += dz;
                dzs[i][j] = dz;
                seen_at[i][j] = seen;
                miss[j] |= !seen;
            }
        }
        /* the samples off the planes (the surface continued past the
         * border), in lanes over a list of them */
        int nb = 0;
        for (int j = 0; j < cnt; j++)
            for (int i = 0; miss[j] && i < ns; i++)
                if (!seen_at[i][j]) {
                    ml[nb] = j;
                    mi[nb++] = i;
                }
        if (nb > 0)
            border_lanes(f, pos, nrm, P, vp, dm, xs, ys, c2, hs, xy, ml, mi, nb, bdz, bseen);
        for (int e = 0; e < nb; e++) {
            dzs[mi[e]][ml[e]] = bdz[e];
            seen_at[mi[e]][ml[e]] = bseen[e];
        }
        for (int j = 0; j < cnt; j++) {
            if (!miss[j]) {
                ao[kk[j]] = F > 0.0f ? open[j] / F : 1.0f; /* eq 1 */
                continue;
            }
            /* the sums again in the samples' order, the ones left out skipped */
            float o = 0.0f, Fp = 0.0f;
            for (int i = 0; i < ns; i++) {
                if (!seen_at[i][j])
                    continue;
                o += dzs[i][j];
                Fp += R * ls[i]; /* eq 2 */
            }
            ao[kk[j]] = Fp > 0.0f ? o / Fp : 1.0f; /* eq 1 */
        }
    }
}
