/* The pinhole camera of a position pass: each pixel's world-space point P
 * and its pixel centre give two equations of the 3x4 camera matrix M
 * (u = m1.X / m3.X, v = m2.X / m3.X).  Solved by the normalised direct
 * linear transform (Hartley & Zisserman, "Multiple View Geometry", 2nd
 * ed., algorithm 4.2 with the normalisation of 4.4.4), refined by
 * Gauss-Newton iterations on the reprojection error, then split into
 * intrinsics and a rotation (RQ by Gram-Schmidt on M's rows).  A P that no
 * pinhole camera explains (fisheye, panoramic, orthographic, P not in
 * world space) is refused with its reprojection error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camera.h"
#include "internal.h"
#include "obscura/io.h"

/* At most this many pixels take part (an even subsample of the rest). */
#define SOLVE_POINTS 20000
/* Fewer usable pixels than this cannot fix 11 unknowns robustly. */
#define SOLVE_MIN_POINTS 64
/* A solved camera whose RMS reprojection error exceeds this is refused. */
#define SOLVE_MAX_RMS_PX 0.5
#define REFINE_ITERATIONS 5
/* RMS reprojection error of the position pass over which a given camera
 * is said to disagree with it. */
#define MAX_REPROJECTION_PX 1.0

typedef struct pt {
    double X[3], u, v;
} pt;

/* Points of the G-buffer with valid depth and a finite P. */
static pt *gather(const obs_gbuffer *gb, const obs_plane *pos, long *count)
{
    long valid = 0;
    int w = gb->width, h = gb->height;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float d = *obs__plane_px(&gb->depth, w, x, y);
            const float *p = obs__plane_px(pos, w, x, y);
            valid += d > 0.0f && d < OBS_BACKGROUND_DEPTH && isfinite(p[0]) && isfinite(p[1]) &&
                     isfinite(p[2]);
        }
    long step = valid > SOLVE_POINTS ? (valid + SOLVE_POINTS - 1) / SOLVE_POINTS : 1, k = 0, n = 0;
    pt *v = malloc(((size_t)valid / (size_t)step + 1) * sizeof *v);
    if (!v)
        return NULL;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float d = *obs__plane_px(&gb->depth, w, x, y);
            const float *p = obs__plane_px(pos, w, x, y);
            if (!(d > 0.0f && d < OBS_BACKGROUND_DEPTH && isfinite(p[0]) && isfinite(p[1]) &&
                  isfinite(p[2])))
                continue;
            if (k++ % step)
                continue;
            v[n] = (pt){{p[0], p[1], p[2]}, x + 0.5 + gb->display_x, y + 0.5 + gb->display_y};
            n++;
        }
    *count = n;
    return v;
}

/* Eigenvector of the smallest eigenvalue of the symmetric n x n matrix a
 * (destroyed), by cyclic Jacobi rotations. */
static void smallest_eigenvector(double *a, int n, double *out)
{
    double v[144];
    for (int i = 0; i < n * n; i++)
        v[i] = i / n == i % n;
    for (int sweep = 0; sweep < 100; sweep++) {
        double off = 0;
        for (int p = 0; p < n; p++)
            for (int q = p + 1; q < n; q++)
                off += a[p * n + q] * a[p * n + q];
        if (off < 1e-30)
            break;
        for (int p = 0; p < n; p++)
            for (int q = p + 1; q < n; q++) {
                double apq = a[p * n + q];
                if (fabs(apq) < 1e-300)
                    continue;
                double theta = (a[q * n + q] - a[p * n + p]) / (2 * apq);
                double t = (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < n; k++) {
                    double akp = a[k * n + p], akq = a[k * n + q];
                    a[k * n + p] = c * akp - s * akq;
                    a[k * n + q] = s * akp + c * akq;
                }
                for (int k = 0; k < n; k++) {
                    double apk = a[p * n + k], aqk = a[q * n + k];
                    a[p * n + k] = c * apk - s * aqk;
                    a[q * n + k] = s * apk + c * aqk;
                }
                for (int k = 0; k < n; k++) {
                    double vkp = v[k * n + p], vkq = v[k * n + q];
                    v[k * n + p] = c * vkp - s * vkq;
                    v[k * n + q] = s * vkp + c * vkq;
                }
            }
    }
    int best = 0;
    for (int i = 1; i < n; i++)
        if (a[i * n + i] < a[best * n + best])
            best = i;
    for (int i = 0; i < n; i++)
        out[i] = v[i * n + best];
}

static void project(const double m[12], const double X[3], double *u, double *v, double *w)
{
    *w = m[8] * X[0] + m[9] * X[1] + m[10] * X[2] + m[11];
    *u = (m[0] * X[0] + m[1] * X[1] + m[2] * X[2] + m[3]) / *w;
    *v = (m[4] * X[0] + m[5] * X[1] + m[6] * X[2] + m[7]) / *w;
}

static void errors(const double m[12], const pt *p, long n, double *rms, double *maxe)
{
    double s = 0, mx = 0;
    for (long i = 0; i < n; i++) {
        double u, v, w;
        project(m, p[i].X, &u, &v, &w);
        double e = (u - p[i].u) * (u - p[i].u) + (v - p[i].v) * (v - p[i].v);
        if (!(w > 0) || !isfinite(e))
            e = 1e12;
        s += e;
        mx = fmax(mx, e);
    }
    *rms = sqrt(s / (double)n);
    *maxe = sqrt(mx);
}

/* Solves A x = b for the n x n system (destroyed); 0 when singular. */
static int solve(double *A, double *b, int n)
{
    for (int c = 0; c < n; c++) {
        int piv = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(A[r * n + c]) > fabs(A[piv * n + c]))
                piv = r;
        if (fabs(A[piv * n + c]) < 1e-300)
            return 0;
        for (int k = 0; k < n; k++) {
            double t = A[c * n + k];
            A[c * n + k] = A[piv * n + k];
            A[piv * n + k] = t;
        }
        double t = b[c];
        b[c] = b[piv];
        b[piv] = t;
        for (int r = c + 1; r < n; r++) {
            double f = A[r * n + c] / A[c * n + c];
            for (int k = c; k < n; k++)
                A[r * n + k] -= f * A[c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (int c = n - 1; c >= 0; c--) {
        for (int k = c + 1; k < n; k++)
            b[c] -= A[c * n + k] * b[k];
        b[c] /= A[c * n + c];
    }
    return 1;
}

/* The normalised DLT: M of the 12 entries, row-major. */
static void dlt(const pt *p, long n, double m[12])
{
    double cX[3] = {0, 0, 0}, cu = 0, cv = 0, sX = 0, su = 0;
    for (long i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++)
            cX[k] += p[i].X[k] / n;
        cu += p[i].u / n;
        cv += p[i].v / n;
    }
    for (long i = 0; i < n; i++) {
        sX += sqrt(pow(p[i].X[0] - cX[0], 2) + pow(p[i].X[1] - cX[1], 2) + pow(p[i].X[2] - cX[2], 2)) / n;
        su += sqrt(pow(p[i].u - cu, 2) + pow(p[i].v - cv, 2)) / n;
    }
    double kX = sX > 0 ? sqrt(3.0) / sX : 1, ku = su > 0 ? sqrt(2.0) / su : 1;
    double ata[144];
    memset(ata, 0, sizeof ata);
    for (long i = 0; i < n; i++) {
        double X[4] = {(p[i].X[0] - cX[0]) * kX, (p[i].X[1] - cX[1]) * kX, (p[i].X[2] - cX[2]) * kX, 1};
        double u = (p[i].u - cu) * ku, v = (p[i].v - cv) * ku;
        double r1[12] = {X[0], X[1], X[2], X[3], 0, 0, 0, 0, -u * X[0], -u * X[1], -u * X[2], -u * X[3]};
        double r2[12] = {0, 0, 0, 0, X[0], X[1], X[2], X[3], -v * X[0], -v * X[1], -v * X[2], -v * X[3]};
        for (int a = 0; a < 12; a++)
            for (int b = 0; b < 12; b++)
                ata[a * 12 + b] += r1[a] * r1[b] + r2[a] * r2[b];
    }
    double mn[12];
    smallest_eigenvector(ata, 12, mn);
    /* M = Tu^-1 Mn TX, Tu: u' = ku (u - cu); TX: X' = kX (X - cX) */
    double TX[16] = {kX, 0, 0, -kX * cX[0], 0, kX, 0, -kX * cX[1], 0, 0, kX, -kX * cX[2], 0, 0, 0, 1};
    double Tinv[9] = {1 / ku, 0, cu, 0, 1 / ku, cv, 0, 0, 1};
    double t[12];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++) {
            t[r * 4 + c] = 0;
            for (int k = 0; k < 4; k++)
                t[r * 4 + c] += mn[r * 4 + k] * TX[k * 4 + c];
        }
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            m[r * 4 + c] = Tinv[r * 3] * t[c] + Tinv[r * 3 + 1] * t[4 + c] + Tinv[r * 3 + 2] * t[8 + c];
}

/* Gauss-Newton on the reprojection error, m[11] held (M's scale). */
static void refine(double m[12], const pt *p, long n)
{
    for (int it = 0; it < REFINE_ITERATIONS; it++) {
        double JtJ[121], Jtr[11];
        memset(JtJ, 0, sizeof JtJ);
        memset(Jtr, 0, sizeof Jtr);
        for (long i = 0; i < n; i++) {
            double u, v, w;
            project(m, p[i].X, &u, &v, &w);
            if (!(w > 0))
                continue;
            double X[4] = {p[i].X[0], p[i].X[1], p[i].X[2], 1}, ju[11], jv[11];
            for (int k = 0; k < 11; k++)
                ju[k] = jv[k] = 0;
            for (int k = 0; k < 4; k++) {
                ju[k] = X[k] / w;
                jv[4 + k] = X[k] / w;
                if (8 + k < 11) {
                    ju[8 + k] = -u * X[k] / w;
                    jv[8 + k] = -v * X[k] / w;
                }
            }
            double ru = p[i].u - u, rv = p[i].v - v;
            for (int a = 0; a < 11; a++) {
                Jtr[a] += ju[a] * ru + jv[a] * rv;
                for (int b = 0; b < 11; b++)
                    JtJ[a * 11 + b] += ju[a] * ju[b] + jv[a] * jv[b];
            }
        }
        if (!solve(JtJ, Jtr, 11))
            return;
        for (int k = 0; k < 11; k++)
            m[k] += Jtr[k];
    }
}

obs_status obs_camera_reprojection(const obs_gbuffer *gb, const obs_plane *pos,
                                   const obs_camera *cam, double *rms, double *max_err,
                                   char err[OBS_ERR_LEN])
{
    long n = 0;
    int dw = gb->display_width > 0 ? gb->display_width : gb->width;
    int dh = gb->display_height > 0 ? gb->display_height : gb->height;
    pt *p = gather(gb, pos, &n);
    if (!p)
        return obs__fail(err, OBS_NO_MEMORY, "position pass of %dx%d", gb->width, gb->height);
    if (n < SOLVE_MIN_POINTS) {
        free(p);
        return obs__fail(err, OBS_NO_CAMERA, "the position pass has %ld usable pixels", n);
    }
    /* pixel = viewport(projection * world_to_camera * X) as a 3x4 matrix */
    float pw[16];
    obs__mat4_mul(cam->projection, cam->world_to_camera, pw);
    double m[12];
    for (int c = 0; c < 4; c++) {
        m[0 + c] = 0.5 * dw * (pw[c] + pw[12 + c]);
        m[4 + c] = 0.5 * dh * (pw[12 + c] - pw[4 + c]);
        m[8 + c] = pw[12 + c];
    }
    errors(m, p, n, rms, max_err);
    free(p);
    return OBS_OK;
}

int obs__camera_check_position(const obs_gbuffer *gb, const obs_params *p, char *msg,
                               size_t len)
{
    obs_camera cam;
    char err[OBS_ERR_LEN];
    double rms, maxe;
    if (!gb->position.data || obs__camera_resolve(gb, p, &cam, err) != OBS_OK ||
        !cam.has_world_to_camera ||
        obs_camera_reprojection(gb, &gb->position, &cam, &rms, &maxe, err) != OBS_OK ||
        rms <= MAX_REPROJECTION_PX)
        return 0;
    snprintf(msg, len, "the camera disagrees with the position pass: it projects P "
             "%.3g px (RMS, max %.3g px) from the pixel centres", rms, maxe);
    return 1;
}

obs_status obs_camera_solve_position(const obs_gbuffer *gb, const obs_plane *pos, obs_camera *cam,
                                     double *rms_out, char err[OBS_ERR_LEN])
{
    long n = 0;
    double m[12], rms, maxe;
    int dw = gb->display_width > 0 ? gb->display_width : gb->width;
    int dh = gb->display_height > 0 ? gb->display_height : gb->height;
    if (!pos || !pos->data || pos->channels < 3)
        return obs__fail(err, OBS_NO_CAMERA, "no position pass (3 channels) to solve the camera from");
    pt *p = gather(gb, pos, &n);
    if (!p)
        return obs__fail(err, OBS_NO_MEMORY, "position pass of %dx%d", gb->width, gb->height);
    if (n < SOLVE_MIN_POINTS) {
        free(p);
        return obs__fail(err, OBS_NO_CAMERA, "the position pass has %ld usable pixels; %d are needed "
                         "to solve the camera", n, SOLVE_MIN_POINTS);
    }
    dlt(p, n, m);
    /* the sign that puts the points in front (w > 0) */
    double w0 = m[8] * p[0].X[0] + m[9] * p[0].X[1] + m[10] * p[0].X[2] + m[11];
    double s = 1.0 / sqrt(m[8] * m[8] + m[9] * m[9] + m[10] * m[10]);
    if (!isfinite(s) || s > 1e12) {
        free(p);
        return obs__fail(err, OBS_NO_CAMERA, "the position pass is not consistent with a pinhole "
                         "camera: its best 3x4 camera is affine (an orthographic camera?)");
    }
    for (int i = 0; i < 12; i++)
        m[i] *= w0 < 0 ? -s : s;
    refine(m, p, n);
    errors(m, p, n, &rms, &maxe);
    free(p);
    if (rms_out)
        *rms_out = rms;
    if (!(rms <= SOLVE_MAX_RMS_PX))
        return obs__fail(err, OBS_NO_CAMERA, "the position pass is not consistent with a pinhole "
                         "camera: reprojection error RMS %.3g px, max %.3g px over %ld pixels "
                         "(limit %.2g px RMS; a fisheye, panoramic or orthographic camera, or P not "
                         "in world space?)", rms, maxe, n, SOLVE_MAX_RMS_PX);

    /* M = K [R | t] with K upper triangular, R's rows r1 (right), r2
     * (down), r3 (forward): Gram-Schmidt from the third row up. */
    double sc = 1.0 / sqrt(m[8] * m[8] + m[9] * m[9] + m[10] * m[10]);
    for (int i = 0; i < 12; i++)
        m[i] *= sc;
    const double *a1 = m, *a2 = m + 4, *r3 = m + 8;
    double cy = a2[0] * r3[0] + a2[1] * r3[1] + a2[2] * r3[2];
    double r2[3] = {a2[0] - cy * r3[0], a2[1] - cy * r3[1], a2[2] - cy * r3[2]};
    double fy = sqrt(r2[0] * r2[0] + r2[1] * r2[1] + r2[2] * r2[2]);
    for (int k = 0; k < 3; k++)
        r2[k] /= fy;
    double cx = a1[0] * r3[0] + a1[1] * r3[1] + a1[2] * r3[2];
    double sk = a1[0] * r2[0] + a1[1] * r2[1] + a1[2] * r2[2];
    double r1[3] = {a1[0] - sk * r2[0] - cx * r3[0], a1[1] - sk * r2[1] - cx * r3[1],
                    a1[2] - sk * r2[2] - cx * r3[2]};
    double fx = sqrt(r1[0] * r1[0] + r1[1] * r1[1] + r1[2] * r1[2]);
    for (int k = 0; k < 3; k++)
        r1[k] /= fx;
    double det = r1[0] * (r2[1] * r3[2] - r2[2] * r3[1]) - r1[1] * (r2[0] * r3[2] - r2[2] * r3[0]) +
                 r1[2] * (r2[0] * r3[1] - r2[1] * r3[0]);
    if (det < 0)
        return obs__fail(err, OBS_NO_CAMERA, "the position pass is mirrored (a left-handed camera): "
                         "no pinhole camera of ours sees it");
    /* t = K^-1 b */
    double tz = m[11], ty = (m[7] - cy * tz) / fy, tx = (m[3] - sk * ty - cx * tz) / fx;

    /* ours: x right, y up, z backward = diag(1, -1, -1) of (r1, r2, r3) */
    memset(cam, 0, sizeof *cam);
    const double *rows[3] = {r1, r2, r3};
    const double t3[3] = {tx, ty, tz}, sign[3] = {1, -1, -1};
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            cam->world_to_camera[r * 4 + c] = (float)(sign[r] * rows[r][c]);
        cam->world_to_camera[r * 4 + 3] = (float)(sign[r] * t3[r]);
    }
    cam->world_to_camera[15] = 1.0f;
    float *P = cam->projection;
    P[0] = (float)(2 * fx / dw);
    P[1] = (float)(-2 * sk / dw);
    P[2] = (float)(-(2 * cx / dw - 1));
    P[5] = (float)(2 * fy / dh);
    P[6] = (float)(-(1 - 2 * cy / dh));
    P[14] = -1.0f;
    /* the default clip range of a header camera */
    P[10] = -(1000.0f + 0.1f) / (1000.0f - 0.1f);
    P[11] = -2.0f * 1000.0f * 0.1f / (1000.0f - 0.1f);
    cam->has_world_to_camera = cam->has_projection = 1;
    cam->source = OBS_CAMERA_EXR_HEADER;
    return OBS_OK;
}

obs_status obs_gbuffer_solve_camera(obs_gbuffer_file *f, const obs_params *params,
                                    char err[OBS_ERR_LEN])
{
    obs_params p;
    double rms = 0;
    obs_camera cam;
    obs_params_resolve(params, &p);
    if (f->gb.camera.has_projection || p.fov_y > 0.0f || p.fov_x > 0.0f ||
        (p.focal_length > 0.0f && p.aperture > 0.0f))
        return OBS_OK; /* a camera is given: sanity checks it against P */
    if (!f->gb.position.data)
        return obs__fail(err, OBS_NO_CAMERA, "no camera to solve: the file has no position pass "
                         "(P.X/Y/Z, Position.X/Y/Z or <layer>.Position.X/Y/Z)");
    obs_status st = obs_camera_solve_position(&f->gb, &f->gb.position, &cam, &rms, err);
    if (st != OBS_OK)
        return st;
    f->gb.camera = cam;
    snprintf(f->info.camera_source, sizeof f->info.camera_source,
             "solved from the position pass %s (DLT + refinement)", f->info.position[0]);
    snprintf(f->info.camera_check, sizeof f->info.camera_check,
             "reprojection error RMS %.3g px", rms);
    return OBS_OK;
}
