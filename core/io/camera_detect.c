/* The camera of an EXR from whatever its header has, in this order:
 *   1. worldToCamera + worldToNDC, in the OpenEXR standard's NDC (0..1,
 *      y down) or Arnold's (-1..1, y up), told apart by where the
 *      camera's forward axis lands and cross-checked with the focal
 *      length and film aperture;
 *   2. V-Ray's cameraTransform (camera to world) + cameraFov (horizontal);
 *   3. worldToCamera (or none) with CameraFocalLength and
 *      CameraFilmApertureHorizontal, or cameraFov/CameraFov.
 * The clip range comes from arnold/camera/near_clip/far_clip,
 * rs/camera/nearPlane/farPlane or cameraNearClip/cameraFarClip when the
 * file has them.  What was used, and what disagreed, goes to the report. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/exr_internal.h"
#include "internal.h"

/* Camera-space clip range used for a projection when the file has none
 * (an EXR does not define the z row of worldToNDC). */
#define EXR_NEAR 0.1f
#define EXR_FAR 1000.0f

/* Relative disagreement between two fields of view that is reported. */
#define FOV_TOLERANCE 0.01

static const float F[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1};

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

static void add_warning(obs__camera_report *r, const char *fmt, double a, double b)
{
    if (r->warning_count >= OBS__CAMERA_WARNINGS)
        return;
    snprintf(r->warnings[r->warning_count++], sizeof r->warnings[0], fmt, a, b);
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

void obs__exr_read_camera_report(exr_const_context_t ctx, int part, const char *renderer,
                                 obs_camera *cam, obs__camera_report *rep)
{
    float wtc[16], ndc[16], ctw[16];
    double focal = 0, aperture = 0, fov = 0, n = 0, f = 0;
    exr_attr_box2i_t disp;
    memset(&disp, 0, sizeof disp);
    obs__camera_report local;
    if (!rep)
        rep = &local;
    memset(rep, 0, sizeof *rep);
    memset(cam, 0, sizeof *cam);
    obs__mat4_identity(cam->world_to_camera);

    exr_get_display_window(ctx, part, &disp);
    double dw = (double)disp.max.x - disp.min.x + 1, dh = (double)disp.max.y - disp.min.y + 1;
    double aspect = dw > 0 && dh > 0 ? dw / dh : 1.0;
    int has_wtc = header_m44(ctx, part, "worldToCamera", wtc);
    int has_ndc = has_wtc && header_m44(ctx, part, "worldToNDC", ndc);
    int has_lens = header_num(ctx, part, "CameraFocalLength", &focal) &&
                   header_num(ctx, part, "CameraFilmApertureHorizontal", &aperture);
    int has_fov = header_num(ctx, part, "cameraFov", &fov) || header_num(ctx, part, "CameraFov", &fov);
    int has_clip = (header_num(ctx, part, "arnold/camera/near_clip", &n) &&
                    header_num(ctx, part, "arnold/camera/far_clip", &f)) ||
                   (header_num(ctx, part, "rs/camera/nearPlane", &n) &&
                    header_num(ctx, part, "rs/camera/farPlane", &f)) ||
                   (header_num(ctx, part, "cameraNearClip", &n) &&
                    header_num(ctx, part, "cameraFarClip", &f));
    if (has_clip && !(f > n))
        has_clip = 0;
    /* tan of the horizontal half-angle each source says */
    double t_lens = has_lens ? aperture / (2.0 * focal) : 0.0;
    double t_fov = has_fov && fov < 180.0 ? tan(fov * 3.14159265358979323846 / 360.0) : 0.0;
    int persp = 1;

    if (has_wtc) {
        float mc[16];
        obs__mat4_transpose(wtc, mc);
        obs__mat4_mul(F, mc, cam->world_to_camera);
        cam->has_world_to_camera = 1;
        cam->source = OBS_CAMERA_EXR_HEADER;
    }
    float q[16];
    if (has_ndc && exr_q(wtc, ndc, q, &persp)) {
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
        double t_meta = has_lens ? t_lens : t_fov;
        snprintf(rep->source, sizeof rep->source, "worldToCamera + worldToNDC (%s NDC: the "
                 "forward axis lands at (%.3g, %.3g))", arnold ? "Arnold's -1..1" : "OpenEXR standard",
                 c[0], c[1]);
        rep->arnold = arnold;
        if (t_meta > 0.0 && persp) {
            double rel = fabs(t_ndc - t_meta) / t_meta, rel_other = fabs(t_other - t_meta) / t_meta;
            snprintf(rep->check, sizeof rep->check,
                     "%s: horizontal fov %.4g deg from worldToNDC, %.4g deg from %s",
                     rel <= FOV_TOLERANCE ? "agrees" : "DISAGREES",
                     360.0 / 3.14159265358979323846 * atan(t_ndc),
                     360.0 / 3.14159265358979323846 * atan(t_meta),
                     has_lens ? "CameraFocalLength/CameraFilmApertureHorizontal" : "cameraFov");
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
        if (renderer && strcmp(renderer, "arnold") == 0 && !arnold)
            add_warning(rep, "the header names Arnold but worldToNDC is in the OpenEXR "
                        "standard's convention (forward axis at %.3g, %.3g)", c[0], c[1]);
        projection_from_q(q, arnold, cam);
    } else if (header_m44(ctx, part, "cameraTransform", ctw) && (t_fov > 0.0 || t_lens > 0.0)) {
        /* V-Ray: camera to world (Imath row vectors), camera looking down
         * -Z with +Y up, as ours; cameraFov is horizontal. */
        float m[16];
        obs__mat4_transpose(ctw, m);
        if (obs__mat4_invert(m, cam->world_to_camera) == 0) {
            cam->has_world_to_camera = 1;
            cam->source = OBS_CAMERA_EXR_HEADER;
            projection_from_tan_x(t_fov > 0.0 ? t_fov : t_lens, aspect, cam);
            snprintf(rep->source, sizeof rep->source, "cameraTransform + %s (V-Ray)",
                     t_fov > 0.0 ? "cameraFov (horizontal)" : "focal length/aperture");
            if (t_fov > 0.0 && t_lens > 0.0 && fabs(t_fov - t_lens) / t_lens > FOV_TOLERANCE)
                add_warning(rep, "the camera metadata disagrees with itself: cameraFov's "
                            "half-angle tangent %.4g, the focal length/aperture's %.4g",
                            t_fov, t_lens);
        } else {
            obs__mat4_identity(cam->world_to_camera);
        }
    } else if (t_lens > 0.0 || t_fov > 0.0) {
        projection_from_tan_x(t_lens > 0.0 ? t_lens : t_fov, aspect, cam);
        cam->source = OBS_CAMERA_EXR_HEADER;
        snprintf(rep->source, sizeof rep->source, "%s%s",
                 has_wtc ? "worldToCamera + " : "",
                 t_lens > 0.0 ? "CameraFocalLength/CameraFilmApertureHorizontal" : "cameraFov (horizontal)");
        if (t_fov > 0.0 && t_lens > 0.0 && fabs(t_fov - t_lens) / t_lens > FOV_TOLERANCE)
            add_warning(rep, "the camera metadata disagrees with itself: cameraFov's half-angle "
                        "tangent %.4g, the focal length/aperture's %.4g", t_fov, t_lens);
    } else if (has_wtc) {
        snprintf(rep->source, sizeof rep->source, "worldToCamera only (no projection)");
    }
    if (cam->has_projection)
        set_z_row(cam->projection, persp, has_clip ? (float)n : EXR_NEAR,
                  has_clip ? (float)f : EXR_FAR);
    if (cam->has_projection && has_clip)
        snprintf(rep->clip, sizeof rep->clip, "%g..%g from the header", n, f);
}

void obs__exr_read_camera(exr_const_context_t ctx, int part, obs_camera *cam)
{
    obs__exr_read_camera_report(ctx, part, NULL, cam, NULL);
}

void obs__exr_describe(exr_const_context_t ctx, int part, const obs__channel_match *m,
                       obs_gbuffer *gb, obs_exr_info *info)
{
    obs__camera_report rep;
    const char *renderer = obs__preset_detect(ctx, part, info->renderer_why,
                                              sizeof info->renderer_why);
    snprintf(info->renderer, sizeof info->renderer, "%s", renderer ? renderer : "");
    info->depth_mode = m->depth_mode;
    info->normal_space = m->normal_space;
    obs__exr_read_camera_report(ctx, part, renderer, &gb->camera, &rep);
    snprintf(info->camera_source, sizeof info->camera_source, "%s", rep.source);
    snprintf(info->camera_check, sizeof info->camera_check, "%s", rep.check);
    snprintf(info->camera_clip, sizeof info->camera_clip, "%s", rep.clip);
    info->camera_arnold = rep.arnold;
    for (int i = 0; i < rep.warning_count && info->warning_count < OBS_EXR_WARNINGS; i++)
        snprintf(info->warnings[info->warning_count++], sizeof info->warnings[0], "%s",
                 rep.warnings[i]);
}
