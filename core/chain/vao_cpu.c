/* The CPU twin of the GL passes: the same math, pixel by pixel, in C.
 * Each function mirrors the GLSL function of the same role; keep them in
 * step (tests/unit/core/test_gl_twin.c compares their outputs). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "chain/frame.h"

/* GLSL: px_ndc() in common.glsl */
void obs__px_ndc(const obs__frame *f, int x, int y, float ndc[2])
{
    ndc[0] = ((float)x + 0.5f + f->viewport[0]) / f->viewport[2] * 2.0f - 1.0f;
    ndc[1] = 1.0f - ((float)y + 0.5f + f->viewport[1]) / f->viewport[3] * 2.0f;
}

/* GLSL: view_ray() in common.glsl.  The point seen at NDC (nx, ny) with
 * planar depth d is origin + d * dir (dir.z = -1): the projection solved
 * for view x, y as a 2x2 system that is affine in view z. */
static void view_ray(const float *P, const float ndc[2], float origin[3], float dir[3])
{
    float nx = ndc[0], ny = ndc[1];
    float a = P[0] - nx * P[12], b = P[1] - nx * P[13];
    float c = P[4] - ny * P[12], d = P[5] - ny * P[13];
    float b0x = nx * P[15] - P[3], b0y = ny * P[15] - P[7];
    float b1x = nx * P[14] - P[2], b1y = ny * P[14] - P[6];
    float inv = 1.0f / (a * d - b * c);
    origin[0] = (d * b0x - b * b0y) * inv;
    origin[1] = (a * b0y - c * b0x) * inv;
    origin[2] = 0.0f;
    dir[0] = -(d * b1x - b * b1y) * inv;
    dir[1] = -(a * b1y - c * b1x) * inv;
    dir[2] = -1.0f;
}

/* GLSL: linear_depth() in prep.frag.glsl.  Planar depth from the raw value,
 * 0 for background. */
static float linear_depth(const obs__frame *f, float raw, const float dir[3])
{
    if (!(raw > 0.0f) || raw >= OBS__SKY_DEPTH) /* also catches NaN */
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
    view_ray(f->proj, ndc, o, dir);
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
int obs__adaptive_count(const obs__frame *f, const float c[3])
{
    const float *P = f->proj;
    float w = P[12] * c[0] + P[13] * c[1] + P[14] * c[2] + P[15];
    if (!(w > 0.0f))
        return f->samples;
    float X = P[0] * c[0] + P[1] * c[1] + P[2] * c[2] + P[3];
    float Y = P[4] * c[0] + P[5] * c[1] + P[6] * c[2] + P[7];
    float w2 = w * w;
    float j00 = (P[0] * w - X * P[12]) / w2, j01 = (P[1] * w - X * P[13]) / w2;
    float j10 = (P[4] * w - Y * P[12]) / w2, j11 = (P[5] * w - Y * P[13]) / w2;
    float r = 0.5f * f->radius;
    float q = r * r * fabsf(j00 * j11 - j01 * j10) * f->adaptive_k;
    int n = 2;
    while (n < f->samples && q >= (float)n)
        n *= 2;
    return n;
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
float obs__range_falloff(const obs__frame *f, float d, float nz)
{
    if (f->range_normal)
        d *= fabsf(nz); /* the pipe's depth below the flat occluder */
    return f->range_u / fmaxf(f->range_u, d / f->radius); /* eq 4 */
}

/* GLSL: own_plane_depth(), disk_point() in common.glsl */
float obs__own_plane_depth(const float p[3], const float n[3], const float c[3], float r,
                           const float rot[2], float sx, float sy, float zs)
{
    if (!(fabsf(n[2]) > OBS__OWN_PLANE_NZ))
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

/* GLSL: disk_map() in common.glsl */
void obs__disk_map(const obs__frame *f, const float c[3], float r, const float rot[2],
                   obs__disk *m)
{
    const float *P = f->proj, *vp = f->viewport;
    float k0[4], A[4], B[4];
    for (int i = 0; i < 4; i++) {
        const float *row = P + 4 * i;
        k0[i] = row[0] * c[0] + row[1] * c[1] + row[2] * c[2] + row[3];
        float ex = row[0] * r, ey = row[1] * r; /* a step r along view x, y */
        A[i] = rot[0] * ex + rot[1] * ey;
        B[i] = rot[0] * ey - rot[1] * ex;
    }
    float hx = 0.5f * vp[2], hy = 0.5f * vp[3];
    float ox = hx - vp[0], oy = hy - vp[1];
    m->u[0] = hx * A[0] + ox * A[3];
    m->u[1] = hx * B[0] + ox * B[3];
    m->u[2] = hx * k0[0] + ox * k0[3];
    m->v[0] = -hy * A[1] + oy * A[3];
    m->v[1] = -hy * B[1] + oy * B[3];
    m->v[2] = -hy * k0[1] + oy * k0[3];
    m->w[0] = A[3];
    m->w[1] = B[3];
    m->w[2] = k0[3];
}

/* GLSL: disk_px() in common.glsl */
int obs__disk_px(const obs__frame *f, const obs__disk *m, float sx, float sy, int *qx, int *qy)
{
    float sw = m->w[0] * sx + m->w[1] * sy + m->w[2];
    if (!(sw > 0.0f))
        return 0;
    float fu = floorf((m->u[0] * sx + m->u[1] * sy + m->u[2]) / sw);
    float fv = floorf((m->v[0] * sx + m->v[1] * sy + m->v[2]) / sw);
    if (!(fu >= 0.0f && fv >= 0.0f && fu < (float)f->width && fv < (float)f->height))
        return 0;
    *qx = (int)fu;
    *qy = (int)fv;
    return 1;
}

/* GLSL: vao_estimate() in vao.glsl, without colour bleeding */
float obs__vao_estimate(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                        const float p[3], const float n[3], int ns, const float *xy)
{
    float bleed[3];
    return obs__vao_estimate_bleed(f, pos, nrm, NULL, x, y, p, n, ns, xy, bleed);
}

/* GLSL: vao_estimate() in vao.glsl */
float obs__vao_estimate_bleed(const obs__frame *f, const float *pos, const float *nrm,
                              const float *col, int x, int y, const float p[3], const float n[3],
                              int ns, const float *xy, float bleed[3])
{
    const float R = f->radius, r = 0.5f * f->radius;
    /* Centre of the tangent sphere of radius R/2, moved along the normal. */
    float c[3] = {p[0] + n[0] * r, p[1] + n[1] * r, p[2] + n[2] * r};
    const float *rot = f->rot[3 * (x % 3) + (y % 3)];
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
        float l = sqrtf(fmaxf(0.0f, 1.0f - sx * sx - sy * sy));
        float h = r * l; /* half length of the pipe through the sphere */
        int seen = 0;    /* the sample's pixel is on the planes */

        float zs = INFINITY; /* scene depth at the sample's pixel */
        float nz = 1.0f; /* view normal z of the surface there */
        int qx, qy;
        /* The sample on the disk through the centre, perpendicular to view Z. */
        seen = obs__disk_px(f, &disk, sx, sy, &qx, &qy);
        if (seen) {
            size_t k = (size_t)qy * (size_t)f->width + (size_t)qx;
            float d = pos[4 * k + 3];
            if (d > 0.0f) {
                zs = d;
                nz = nrm[3 * k + 2];
                /* a sample on the shaded pixel itself: p's tangent plane */
                if (qx == x && qy == y)
                    zs = obs__own_plane_depth(p, n, c, r, rot, sx, sy, zs);
                if (bleeds) { /* eq 5 with x the surface point at the sample's pixel */
                    c5 = obs__bleed_weight(pos + 4 * k, p, n, R);
                    cx5 = col + 4 * k;
                }
            }
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
        float dz = fminf(fmaxf(zs - front, 0.0f), 2.0f * h);
        if (f->range_check && zs < front) {
            /* Case C with the depth range check, section 4.4, eq 4: the
             * pipe lies d behind the visible surface; the occluder is
             * thick only by the falloff s(d) = u / max(u, d / radius), so
             * the pipe's weight 2h counts as occluded times s(d).  d is
             * taken from the pipe's near end, so s = 1 where case C meets
             * case A (zs = front) and the two join without a step. */
            float sd = obs__range_falloff(f, front - zs, nz);
            dz = 2.0f * h * (1.0f - sd);
        }
        /* A sample off the planes (or behind the camera) says nothing
         * about the scene: it is left out of eq 1's sum and of F alike, so
         * V is estimated from the part of the disk that is seen, instead
         * of counting the unseen part as open (which lightened contact
         * shadows near the image border). */
        if (seen) {
            open += dz;
            F += R * l; /* eq 2: F = R * sum sqrt(1 - x^2 - y^2) */
        }
    }
    for (int j = 0; j < 3; j++)
        bleed[j] = taken > 0.0f ? acc[j] / taken : 1.0f;
    return F > 0.0f ? open / F : 1.0f; /* eq 1: V = (1/F) sum dz_i */
}

static obs_status alloc_image(obs_image *img, int w, int h, int channels, char err[OBS_ERR_LEN])
{
    size_t n;
    if (obs__size_mul3((size_t)w, (size_t)h, (size_t)channels * sizeof(float), &n) != 0)
        return obs__fail(err, OBS_TOO_LARGE, "image %dx%dx%d overflows", w, h, channels);
    img->data = malloc(n);
    if (!img->data)
        return obs__fail(err, OBS_NO_MEMORY, "out of memory for a %dx%d image", w, h);
    img->width = w;
    img->height = h;
    img->channels = channels;
    return OBS_OK;
}

obs_status obs__alloc_result(obs_result *out, int w, int h, unsigned outputs, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    obs_status s = OBS_OK;
    if (outputs & OBS_OUTPUT_AO)
        s = alloc_image(&out->ao, w, h, 1, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_COMPOSITE))
        s = alloc_image(&out->composite, w, h, 4, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_SAMPLE_COUNT))
        s = alloc_image(&out->sample_count, w, h, 1, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_CULL_MASK))
        s = alloc_image(&out->cull_mask, w, h, 1, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_LUMINANCE))
        s = alloc_image(&out->luminance, w, h, 1, err);
    if (s == OBS_OK && (outputs & OBS_OUTPUT_BLEED))
        s = alloc_image(&out->bleed, w, h, 3, err);
    if (s != OBS_OK)
        obs_result_free(out);
    return s;
}

void obs_result_free(obs_result *r)
{
    if (!r)
        return;
    obs_image_free(&r->ao);
    obs_image_free(&r->composite);
    obs_image_free(&r->sample_count);
    obs_image_free(&r->cull_mask);
    obs_image_free(&r->luminance);
    obs_image_free(&r->bleed);
}

/* GLSL: composite.frag.glsl.  Section 5: "applied to resulting image
 * simply by multiplication by occlusion values": colour x AO, and x the
 * bleed term (section 4.7) when bleeding is on; grey AO when there is no
 * colour. */
static void composite_pixel(const float *color, float ao, const float *bleed, float out[4])
{
    if (!color) {
        out[0] = out[1] = out[2] = ao;
        out[3] = 1.0f;
        return;
    }
    for (int k = 0; k < 3; k++)
        out[k] = bleed ? color[k] * ao * bleed[k] : color[k] * ao;
    out[3] = color[3];
}

obs_status obs_run_cpu(const obs_gbuffer *gb, const obs_params *params, unsigned outputs,
                       obs_result *out, char err[OBS_ERR_LEN])
{
    obs_params p;
    obs__frame f;
    float *pos = NULL, *nrm = NULL, *ao = NULL, *tmp = NULL, *est = NULL, *col = NULL,
          *bleed = NULL;
    obs_status s;

    memset(out, 0, sizeof *out);
    if (!(outputs & OBS__OUTPUTS_ALL))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no output requested");
    obs_params_resolve(params, &p);
    s = obs__frame_setup(NULL, gb, &p, &f, err);
    if (s != OBS_OK)
        return s;

    size_t npx = (size_t)f.width * (size_t)f.height;
    pos = malloc(npx * 4 * sizeof(float));
    nrm = malloc(npx * 3 * sizeof(float));
    ao = malloc(npx * sizeof(float));
    tmp = malloc(npx * sizeof(float));
    est = malloc((size_t)f.cull_w * (size_t)f.cull_h * sizeof(float));
    /* colour, packed RGBA, for sections 4.3 and 4.7; the bleed term */
    if (f.luminance || f.bleed_step)
        col = malloc(npx * 4 * sizeof(float));
    bleed = malloc(npx * 3 * sizeof(float));
    if (!pos || !nrm || !ao || !tmp || !est || !bleed || ((f.luminance || f.bleed_step) && !col)) {
        s = obs__fail(err, OBS_NO_MEMORY, "out of memory for a %dx%d frame", f.width, f.height);
        goto fail;
    }
    s = obs__alloc_result(out, f.width, f.height, outputs, err);
    if (s != OBS_OK)
        goto fail;

    /* prep pass */
    for (int y = 0; y < f.height; y++)
        for (int x = 0; x < f.width; x++)
            obs__prep_position(&f, *obs__plane_px(&gb->depth, f.width, x, y), x, y,
                               pos + 4 * ((size_t)y * f.width + x));
    for (int y = 0; y < f.height; y++)
        for (int x = 0; x < f.width; x++) {
            const float *in = gb->normal.data ? obs__plane_px(&gb->normal, f.width, x, y) : NULL;
            obs__prep_normal(&f, pos, in, x, y, nrm + 3 * ((size_t)y * f.width + x));
        }
    if (col)
        for (int y = 0; y < f.height; y++)
            for (int x = 0; x < f.width; x++)
                memcpy(col + 4 * ((size_t)y * f.width + x), obs__plane_px(&gb->color, f.width, x, y),
                       4 * sizeof(float));
    /* culling pre-pass (section 4.2) */
    if (f.culling)
        obs__cull_prepass(&f, pos, nrm, est);
    /* AO pass */
    float *count = out->sample_count.data, *mask = out->cull_mask.data;
    for (int y = 0; y < f.height; y++)
        for (int x = 0; x < f.width; x++) {
            size_t i = (size_t)y * f.width + x;
            int n = 0, culled = 0;
            float *b = bleed + 3 * i;
            ao[i] = 1.0f;
            b[0] = b[1] = b[2] = 1.0f;
            if (f.method > OBS_METHOD_VAO) {
                /* a comparison method in place of the VAO estimator */
                ao[i] = obs__method_pixel(&f, pos, nrm, x, y, &n);
            } else if (pos[4 * i + 3] > 0.0f) {
                /* Section 4.2: a culling candidate gets AO 1 (greedy) or
                 * at most the 4-sample set (careful). */
                culled = f.culling && obs__cull_candidate(&f, est, x, y);
                if (!culled) {
                    /* section 4.1: the set of the pixel's count */
                    n = obs__vao_count(&f, pos + 4 * i, nrm + 3 * i);
                    const float *xy = f.adaptive ? f.sample_table + 2 * (n - 2) : f.sample_xy;
                    ao[i] = obs__vao_estimate_bleed(&f, pos, nrm, col, x, y, pos + 4 * i,
                                                    nrm + 3 * i, n, xy, b);
                } else if (f.culling == 2) {
                    n = obs__vao_count(&f, pos + 4 * i, nrm + 3 * i);
                    n = n < OBS__CULL_CAREFUL ? n : OBS__CULL_CAREFUL;
                    const float *xy = f.sample_table + 2 * (n - 2);
                    ao[i] = obs__vao_estimate_bleed(&f, pos, nrm, col, x, y, pos + 4 * i,
                                                    nrm + 3 * i, n, xy, b);
                }
            }
            if (count)
                count[i] = (float)n;
            if (mask)
                mask[i] = (float)culled;
        }
    /* low-pass filter (section 4.6), then composite */
    obs__blur(&f, pos, ao, tmp);
    /* the finishing pass (luminance.frag.glsl), after the blur: the
     * conversion of ao_definition rays (not linear: applied to the
     * filtered estimate), then luminance sensitivity (section 4.3, eq 3):
     * the blur is depth-aware only and would carry a bright pixel's
     * suppression onto its dark neighbours (and their occlusion onto it) */
    if (f.rays)
        for (size_t i = 0; i < npx; i++)
            ao[i] = obs__rays_from_volume(ao[i]);
    for (size_t i = 0; out->luminance.data && i < npx; i++)
        out->luminance.data[i] = f.luminance ? obs__luminance_factor(&f, col + 4 * i) : 1.0f;
    if (f.luminance)
        for (size_t i = 0; i < npx; i++)
            ao[i] = obs__luminance_ao(&f, ao[i], col + 4 * i);
    if (out->ao.data)
        memcpy(out->ao.data, ao, npx * sizeof(float));
    if (out->bleed.data)
        memcpy(out->bleed.data, bleed, npx * 3 * sizeof(float));
    if (out->composite.data)
        for (int y = 0; y < f.height; y++)
            for (int x = 0; x < f.width; x++) {
                size_t i = (size_t)y * f.width + x;
                composite_pixel(gb->color.data ? obs__plane_px(&gb->color, f.width, x, y) : NULL,
                                ao[i], f.bleed_step ? bleed + 3 * i : NULL,
                                out->composite.data + 4 * i);
            }
    free(pos);
    free(nrm);
    free(ao);
    free(tmp);
    free(est);
    free(col);
    free(bleed);
    return OBS_OK;

fail:
    free(pos);
    free(nrm);
    free(ao);
    free(tmp);
    free(est);
    free(col);
    free(bleed);
    obs_result_free(out);
    return s;
}
