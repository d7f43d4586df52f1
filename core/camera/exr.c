/* The camera of an EXR header, read and written.  Read: the attributes
 * are gathered once (header_read), then a table of detectors, one per
 * convention, is tried in this order and the first that knows the camera
 * decides it:
 *   1. worldToCamera + worldToNDC, in the OpenEXR standard's NDC (0..1,
 *      y down) or Arnold's (-1..1, y up), told apart by where the
 *      camera's forward axis lands and cross-checked with the focal
 *      length and film aperture;
 *   2. V-Ray's cameraTransform (camera to world) + cameraFov (horizontal);
 *   3. worldToCamera (or none) with CameraFocalLength and
 *      CameraFilmApertureHorizontal, or cameraFov/CameraFov;
 *   4. worldToCamera alone (no projection).
 * The clip range comes from arnold/camera/near_clip/far_clip,
 * rs/camera/nearPlane/farPlane or cameraNearClip/cameraFarClip when the
 * file has them.  What was used, and what disagreed, goes to the report.
 * Written: worldToCamera and worldToNDC in the standard's NDC, the exact
 * inverse of detector 1 (obs__camera_exr_attrs, obs__exr_camera_matrices). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "camera/camera.h"
#include "internal.h"

/* Camera-space clip range used for a projection when the file has none
 * (an EXR does not define the z row of worldToNDC). */
#define EXR_NEAR 0.1f
#define EXR_FAR 1000.0f

/* Relative disagreement between two fields of view that is reported. */
#define FOV_TOLERANCE 0.01

#define PI 3.14159265358979323846

/* F = diag(1, 1, -1, 1): EXR camera space (+Z forward) to ours (-Z). */
static const float F[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1};

/* What the detectors found; copied into the info's camera fields. */
#define CAMERA_WARNINGS 2
typedef struct report {
    char source[160];  /* the attributes the camera came from ("" none) */
    char check[160];   /* the cross-check of worldToNDC against the lens */
    char clip[64];     /* the clip range's source, "" = the default */
    int arnold;        /* 1: worldToNDC in Arnold's convention */
    int warning_count;
    char warnings[CAMERA_WARNINGS][224];
} report;

/* Every header attribute a detector reads. */
typedef struct header {
    float wtc[16], ndc[16], ctw[16];
    int has_wtc, has_ndc, has_ctw, has_lens, has_clip;
    double t_lens, t_fov; /* tan of the horizontal half-angle each says, 0 = none */
    double n, f;          /* the clip range when has_clip */
    double aspect;        /* the display window's */
    const char *renderer; /* the detected preset, or NULL */
} header;

/* A finite m44f or m44d attribute, as floats in the file's order. */
static int header_m44(exr_const_context_t ctx, int part, const char *name, float m[16])
{
    const exr_attribute_t *a = NULL;
    if (exr_get_attribute_by_name(ctx, part, name, &a) != EXR_ERR_SUCCESS || !a)
        return 0;
    for (int i = 0; i < 16; i++) {
        if (a->type == EXR_ATTR_M44F && a->m44f)
            m[i] = a->m44f->m[i];
        else if (a->type == EXR_ATTR_M44D && a->m44d)
            m[i] = (float)a->m44d->m[i];
        else
            return 0;
        if (!isfinite(m[i]))
            return 0;
    }
    return 1;
}

/* A finite, positive float/double/int attribute. */
static int header_num(exr_const_context_t ctx, int part, const char *name, double *v)
{
    const exr_attribute_t *a = NULL;
    if (exr_get_attribute_by_name(ctx, part, name, &a) != EXR_ERR_SUCCESS || !a)
        return 0;
    if (a->type == EXR_ATTR_FLOAT)
        *v = a->f;
    else if (a->type == EXR_ATTR_DOUBLE)
        *v = a->d;
    else if (a->type == EXR_ATTR_INT)
        *v = a->i;
    else
        return 0;
    return isfinite(*v) && *v > 0.0;
}

/* OpenGL's z row for a perspective projection over near..far. */
static void set_z_row(float p[16], int persp, float n, float f)
{
    p[8] = p[9] = 0.0f;
    p[10] = persp ? -(f + n) / (f - n) : -2.0f / (f - n);
    p[11] = persp ? -2.0f * f * n / (f - n) : -(f + n) / (f - n);
}

/* Q = Nc Mc^-1: EXR camera space (column vectors, +Z forward) to the
 * homogeneous NDC of worldToNDC, scaled so that w is z (perspective) or 1
 * (orthographic).  0 when the matrices do not make a camera. */
static int exr_q(const float wtc[16], const float ndc[16], float q[16], int *persp)
{
    float mc[16], inv[16], nc[16];
    obs__mat4_transpose(wtc, mc);
    if (obs__mat4_invert(mc, inv) != 0)
        return 0;
    obs__mat4_transpose(ndc, nc);
    obs__mat4_mul(nc, inv, q);
    const float *w = q + 12;
    /* the matrices are floats and the inversion loses a few digits with a
     * far translation (23 units: w's x, y terms of 1e-6) */
    double eps = 1e-4 * (fabs(w[0]) + fabs(w[1]) + fabs(w[2]) + fabs(w[3]));
    int flat_xy = fabs(w[0]) <= eps && fabs(w[1]) <= eps;
    *persp = flat_xy && fabs(w[3]) <= eps && w[2] != 0.0f;
    double s = *persp ? w[2] : flat_xy && fabs(w[2]) <= eps && w[3] != 0.0f ? w[3] : 1.0;
    for (int i = 0; i < 16; i++)
        q[i] = (float)(q[i] / s);
    return 1;
}

/* Where EXR camera point (x, 0, 1) lands in NDC (x and y). */
static void ndc_of(const float q[16], float x, double out[2])
{
    float v[4] = {x, 0.0f, 1.0f, 1.0f}, r[4];
    obs__mat4_apply(q, v, r);
    out[0] = r[0] / r[3];
    out[1] = r[1] / r[3];
}

/* Our projection from Q (camera space of ours: Q F).  The standard's NDC:
 *   x_clip = 2 q_x - q_w, y_clip = q_w - 2 q_y;
 * Arnold's (driver_exr writes its screen space, -1..1 with y up):
 *   x_clip = q_x, y_clip = q_y.  w_clip = q_w either way. */
static void projection_from_q(const float q_exr[16], int arnold, obs_camera *cam)
{
    float q[16];
    obs__mat4_mul(q_exr, F, q);
    float *p = cam->projection;
    for (int j = 0; j < 4; j++) {
        p[0 + j] = arnold ? q[0 + j] : 2.0f * q[0 + j] - q[12 + j];
        p[4 + j] = arnold ? q[4 + j] : q[12 + j] - 2.0f * q[4 + j];
        p[8 + j] = 0.0f;
        p[12 + j] = q[12 + j]; /* w = z_exr = -z_ours */
    }
    cam->has_projection = 1;
}

/* A centred perspective projection of horizontal half-angle tangent tx
 * over a display of aspect w/h. */
static void projection_from_tan_x(double tx, double aspect, obs_camera *cam)
{
    memset(cam->projection, 0, sizeof cam->projection);
    cam->projection[0] = (float)(1.0 / tx);
    cam->projection[5] = (float)(aspect / tx);
    cam->projection[14] = -1.0f;
    cam->has_projection = 1;
}


static void add_warning(report *r, const char *fmt, double a, double b)
{
    if (r->warning_count >= CAMERA_WARNINGS)
        return;
    snprintf(r->warnings[r->warning_count++], sizeof r->warnings[0], fmt, a, b);
}

/* The clip range's attribute pairs, tried in order. */
static const char *const CLIP[][2] = {
    {"arnold/camera/near_clip", "arnold/camera/far_clip"},
    {"rs/camera/nearPlane", "rs/camera/farPlane"},
    {"cameraNearClip", "cameraFarClip"},
};

static void header_read(exr_const_context_t ctx, int part, const char *renderer, header *h)
{
    double focal = 0, aperture = 0, fov = 0;
    exr_attr_box2i_t disp;
    memset(&disp, 0, sizeof disp);
    memset(h, 0, sizeof *h);
    h->renderer = renderer;
    exr_get_display_window(ctx, part, &disp);
    double dw = (double)disp.max.x - disp.min.x + 1, dh = (double)disp.max.y - disp.min.y + 1;
    h->aspect = dw > 0 && dh > 0 ? dw / dh : 1.0;
    h->has_wtc = header_m44(ctx, part, "worldToCamera", h->wtc);
    h->has_ndc = h->has_wtc && header_m44(ctx, part, "worldToNDC", h->ndc);
    h->has_ctw = header_m44(ctx, part, "cameraTransform", h->ctw);
    h->has_lens = header_num(ctx, part, "CameraFocalLength", &focal) &&
                  header_num(ctx, part, "CameraFilmApertureHorizontal", &aperture);
    int has_fov = header_num(ctx, part, "cameraFov", &fov) || header_num(ctx, part, "CameraFov", &fov);
    for (size_t i = 0; i < sizeof CLIP / sizeof CLIP[0] && !h->has_clip; i++)
        h->has_clip = header_num(ctx, part, CLIP[i][0], &h->n) &&
                      header_num(ctx, part, CLIP[i][1], &h->f);
    if (h->has_clip && !(h->f > h->n))
        h->has_clip = 0;
    h->t_lens = h->has_lens ? aperture / (2.0 * focal) : 0.0;
    h->t_fov = has_fov && fov < 180.0 ? tan(fov * PI / 360.0) : 0.0;
}

/* A detector: 1 when the header's camera is its convention (cam and rep
 * filled, *persp 0 for an orthographic projection), 0 to try the next. */
typedef int (*detector)(const header *h, obs_camera *cam, report *rep, int *persp);

/* 1. worldToCamera + worldToNDC, standard or Arnold NDC. */
static int detect_ndc(const header *h, obs_camera *cam, report *rep, int *persp)
{
    float q[16];
    if (!h->has_ndc || !exr_q(h->wtc, h->ndc, q, persp))
        return 0;
    /* Where the forward axis lands: (0.5, 0.5) in the standard's NDC,
     * (0, 0) in Arnold's (for a centred camera). */
    double c[2], e[2];
    ndc_of(q, 0.0f, c);
    ndc_of(q, 0.01f, e);
    double d_std = hypot(c[0] - 0.5, c[1] - 0.5), d_arn = hypot(c[0], c[1]);
    int arnold = d_arn < d_std;
    /* NDC units per unit of x/z: 1/(2 tan) in the standard's, 1/tan
     * in Arnold's; the file's focal length and aperture say which. */
    double slope = fabs(e[0] - c[0]) / 0.01;
    double t_ndc = arnold ? 1.0 / slope : 0.5 / slope;
    double t_other = arnold ? 0.5 / slope : 1.0 / slope;
    double t_meta = h->has_lens ? h->t_lens : h->t_fov;
    snprintf(rep->source, sizeof rep->source, "worldToCamera + worldToNDC (%s NDC: the "
             "forward axis lands at (%.3g, %.3g))", arnold ? "Arnold's -1..1" : "OpenEXR standard",
             c[0], c[1]);
    rep->arnold = arnold;
    if (t_meta > 0.0 && *persp) {
        double rel = fabs(t_ndc - t_meta) / t_meta, rel_other = fabs(t_other - t_meta) / t_meta;
        snprintf(rep->check, sizeof rep->check,
                 "%s: horizontal fov %.4g deg from worldToNDC, %.4g deg from %s",
                 rel <= FOV_TOLERANCE ? "agrees" : "DISAGREES", 360.0 / PI * atan(t_ndc),
                 360.0 / PI * atan(t_meta),
                 h->has_lens ? "CameraFocalLength/CameraFilmApertureHorizontal" : "cameraFov");
        if (rel > FOV_TOLERANCE && rel_other <= FOV_TOLERANCE)
            add_warning(rep, "the camera metadata disagrees with itself: worldToNDC's field "
                        "of view matches the focal length/aperture only in the other NDC "
                        "convention (%.3g vs %.3g); the forward axis decided",
                        t_ndc, t_meta);
        else if (rel > FOV_TOLERANCE)
            add_warning(rep, "the camera metadata disagrees with itself: worldToNDC's "
                        "horizontal half-angle tangent %.4g, the focal length/aperture's "
                        "%.4g", t_ndc, t_meta);
    } else {
        snprintf(rep->check, sizeof rep->check, "no focal length, aperture or fov to check against");
    }
    if (h->renderer && strcmp(h->renderer, "arnold") == 0 && !arnold)
        add_warning(rep, "the header names Arnold but worldToNDC is in the OpenEXR "
                    "standard's convention (forward axis at %.3g, %.3g)", c[0], c[1]);
    projection_from_q(q, arnold, cam);
    return 1;
}

/* cameraFov's disagreement with the focal length/aperture, when both. */
static void check_fov_lens(const header *h, report *rep)
{
    if (h->t_fov > 0.0 && h->t_lens > 0.0 && fabs(h->t_fov - h->t_lens) / h->t_lens > FOV_TOLERANCE)
        add_warning(rep, "the camera metadata disagrees with itself: cameraFov's half-angle "
                    "tangent %.4g, the focal length/aperture's %.4g", h->t_fov, h->t_lens);
}

/* 2. V-Ray: camera to world (Imath row vectors), camera looking down -Z
 * with +Y up, as ours; cameraFov is horizontal.  A singular transform
 * still decides (no camera), as the lens alone would misplace it. */
static int detect_vray(const header *h, obs_camera *cam, report *rep, int *persp)
{
    (void)persp;
    if (!h->has_ctw || !(h->t_fov > 0.0 || h->t_lens > 0.0))
        return 0;
    float m[16];
    obs__mat4_transpose(h->ctw, m);
    if (obs__mat4_invert(m, cam->world_to_camera) != 0) {
        obs__mat4_identity(cam->world_to_camera);
        return 1;
    }
    cam->has_world_to_camera = 1;
    cam->source = OBS_CAMERA_EXR_HEADER;
    projection_from_tan_x(h->t_fov > 0.0 ? h->t_fov : h->t_lens, h->aspect, cam);
    snprintf(rep->source, sizeof rep->source, "cameraTransform + %s (V-Ray)",
             h->t_fov > 0.0 ? "cameraFov (horizontal)" : "focal length/aperture");
    check_fov_lens(h, rep);
    return 1;
}

/* 3. The lens (focal length and aperture) or a horizontal fov. */
static int detect_lens(const header *h, obs_camera *cam, report *rep, int *persp)
{
    (void)persp;
    if (!(h->t_lens > 0.0 || h->t_fov > 0.0))
        return 0;
    projection_from_tan_x(h->t_lens > 0.0 ? h->t_lens : h->t_fov, h->aspect, cam);
    cam->source = OBS_CAMERA_EXR_HEADER;
    snprintf(rep->source, sizeof rep->source, "%s%s", h->has_wtc ? "worldToCamera + " : "",
             h->t_lens > 0.0 ? "CameraFocalLength/CameraFilmApertureHorizontal"
                             : "cameraFov (horizontal)");
    check_fov_lens(h, rep);
    return 1;
}

/* 4. worldToCamera with nothing that gives a projection. */
static int detect_wtc_only(const header *h, obs_camera *cam, report *rep, int *persp)
{
    (void)cam;
    (void)persp;
    if (!h->has_wtc)
        return 0;
    snprintf(rep->source, sizeof rep->source, "worldToCamera only (no projection)");
    return 1;
}

static const detector DETECTORS[] = {detect_ndc, detect_vray, detect_lens, detect_wtc_only};

static void read_report(exr_const_context_t ctx, int part, const char *renderer, obs_camera *cam,
                        report *rep)
{
    header h;
    int persp = 1;
    header_read(ctx, part, renderer, &h);
    memset(rep, 0, sizeof *rep);
    memset(cam, 0, sizeof *cam);
    obs__mat4_identity(cam->world_to_camera);
    if (h.has_wtc) {
        float mc[16];
        obs__mat4_transpose(h.wtc, mc);
        obs__mat4_mul(F, mc, cam->world_to_camera);
        cam->has_world_to_camera = 1;
        cam->source = OBS_CAMERA_EXR_HEADER;
    }
    for (size_t i = 0; i < sizeof DETECTORS / sizeof DETECTORS[0]; i++)
        if (DETECTORS[i](&h, cam, rep, &persp))
            break;
    if (cam->has_projection)
        set_z_row(cam->projection, persp, h.has_clip ? (float)h.n : EXR_NEAR,
                  h.has_clip ? (float)h.f : EXR_FAR);
    if (cam->has_projection && h.has_clip)
        snprintf(rep->clip, sizeof rep->clip, "%g..%g from the header", h.n, h.f);
}

void obs__camera_read_header(exr_const_context_t ctx, int part, const char *renderer,
                             obs_camera *cam, obs_exr_info *info)
{
    report rep;
    read_report(ctx, part, renderer, cam, &rep);
    if (!info)
        return;
    snprintf(info->camera_source, sizeof info->camera_source, "%s", rep.source);
    snprintf(info->camera_check, sizeof info->camera_check, "%s", rep.check);
    snprintf(info->camera_clip, sizeof info->camera_clip, "%s", rep.clip);
    info->camera_arnold = rep.arnold;
    for (int i = 0; i < rep.warning_count && info->warning_count < OBS_EXR_WARNINGS; i++)
        snprintf(info->warnings[info->warning_count++], sizeof info->warnings[0], "%s",
                 rep.warnings[i]);
}

/* The inverse of detector 1 in the standard's NDC.  With F = diag(1,1,-1,1),
 * W = world_to_camera and P = projection:
 *   worldToCamera = (F W)^T
 *   q = (x_clip + w_clip)/2, (w_clip - y_clip)/2, z_clip, w_clip  (rows of Q)
 *   worldToNDC = (Q W)^T */
void obs__exr_camera_matrices(const obs_camera *cam, float wtc[16], float ndc[16])
{
    float fw[16], q[16], qw[16];
    const float *p = cam->projection;

    obs__mat4_mul(F, cam->world_to_camera, fw);
    obs__mat4_transpose(fw, wtc);
    for (int j = 0; j < 4; j++) {
        q[0 + j] = 0.5f * (p[0 + j] + p[12 + j]);
        q[4 + j] = 0.5f * (p[12 + j] - p[4 + j]);
        q[8 + j] = p[8 + j];
        q[12 + j] = p[12 + j];
    }
    obs__mat4_mul(q, cam->world_to_camera, qw);
    obs__mat4_transpose(qw, ndc);
}

int obs__camera_exr_attrs(const obs_camera *cam, obs__camera_attr attrs[OBS__CAMERA_ATTRS])
{
    if (!cam || !cam->has_world_to_camera)
        return 0;
    if (attrs) {
        attrs[0].name = OBS__CAMERA_ATTR_WTC;
        attrs[1].name = "worldToNDC";
        obs__exr_camera_matrices(cam, attrs[0].m, attrs[1].m);
    }
    return cam->has_projection ? 2 : 1;
}

void obs__exr_read_camera(exr_const_context_t ctx, int part, obs_camera *cam)
{
    obs__camera_read_header(ctx, part, NULL, cam, NULL);
}
