/* Samples that fall off the planes (issue 32, "Borders"): what VAO++'s
 * line samples (vao_cpu.c) and gtao's horizon steps (methods/gtao.c) read
 * there.  GLSL: border_px(), plane_point() in common.glsl, called from
 * vao.glsl and gtao.glsl.
 *
 * Past the planes the frame shows nothing, and both ways of ignoring that
 * bias a band along the border.  Counting the sample as open (gtao before)
 * lightens a crease that crosses the border.  Leaving it out and dividing
 * eq 1 by the weights of the samples that remain (VAO++ before) keeps an
 * open plane at 1, but takes the unseen part of the disk to be occluded
 * like the seen part, which holds only where the geometry is symmetric
 * about the border: a crease meeting the border at a slant puts more or
 * less of its occluder into the part that is dropped.
 *
 * Here the surface is continued past the border.  A sample at pixel q off
 * the planes reads the tangent plane (position and view normal of the
 * prep pass) of the last pixel b on the planes along the segment from the
 * shaded pixel to q, where q's pixel-centre ray meets it.  What that gets
 * right, from the construction alone:
 *  - a plane, whatever its tilt and the camera, is its own tangent plane:
 *    q reads what a larger frame would hold there, so an open plane at the
 *    border gives the interior's AO (1), for both estimators;
 *  - surfaces meeting along lines through the shaded point (a crease
 *    through it, crossing the border at any angle): a segment from the
 *    shaded pixel stays on one side of every line through it, so b lies on
 *    q's own surface and q reads that surface: the AO at the border is the
 *    AO away from it.
 * What it cannot know is geometry the border hides entirely (an object
 * just off the image); a crease not through the shaded point is continued
 * straight from where the segment leaves the image.  Where b is background
 * the sample reads background (open, as one on the planes would); where
 * b's plane does not face q's ray in front of the camera (edge-on, a
 * normal turned away) the sample is left out as before.
 *
 * The planes are the EXR's whole data window (exr_read.c; viewport[] is
 * the display window), so a guard band the renderer wrote beyond the
 * display window is read as data, and only samples beyond it are
 * continued. */
#include <math.h>

#include "chain/frame.h"

/* GLSL: border_px() in common.glsl.  The last pixel on the planes along
 * the segment from pixel (x, y)'s centre to pixel (qx, qy)'s (off the
 * planes): the segment's exit from [0, width) x [0, height), floored and
 * kept on the planes. */
void obs__border_px(const obs__frame *f, int x, int y, float qx, float qy, int *bx, int *by)
{
    float w = (float)f->width, h = (float)f->height;
    float sx = (float)x + 0.5f, sy = (float)y + 0.5f;
    float du = qx + 0.5f - sx, dv = qy + 0.5f - sy;
    float t = 1.0f;
    if (du > 0.0f)
        t = fminf(t, (w - sx) / du);
    else if (du < 0.0f)
        t = fminf(t, -sx / du);
    if (dv > 0.0f)
        t = fminf(t, (h - sy) / dv);
    else if (dv < 0.0f)
        t = fminf(t, -sy / dv);
    *bx = (int)fminf(fmaxf(floorf(sx + t * du), 0.0f), w - 1.0f);
    *by = (int)fminf(fmaxf(floorf(sy + t * dv), 0.0f), h - 1.0f);
}

/* GLSL: plane_point() in common.glsl.  Where the view ray of pixel
 * (qx, qy) meets the plane through b with normal nb: out = the view point,
 * out[3] its planar depth; 0 (and out[3] = 0) where the plane does not
 * face the ray (edge-on or turned away) or meets it behind the camera. */
int obs__plane_point(const obs__frame *f, float qx, float qy, const float b[3], const float nb[3],
                     float out[4])
{
    float ndc[2], o[3], dir[3];
    out[0] = out[1] = out[2] = out[3] = 0.0f;
    obs__px_ndc(f, (int)qx, (int)qy, ndc);
    obs__view_ray(f->proj, ndc, o, dir);
    float den = nb[0] * dir[0] + nb[1] * dir[1] + nb[2] * dir[2];
    if (!(den < 0.0f))
        return 0;
    float d = (nb[0] * (b[0] - o[0]) + nb[1] * (b[1] - o[1]) + nb[2] * (b[2] - o[2])) / den;
    if (!(d > 0.0f && d < OBS_BACKGROUND_DEPTH))
        return 0;
    out[0] = o[0] + d * dir[0];
    out[1] = o[1] + d * dir[1];
    out[2] = -d;
    out[3] = d;
    return 1;
}

/* The point a sample at pixel (qx, qy) off the planes reads for the pixel
 * (x, y) (the header above): 1 and out (view point, planar depth), *nz the
 * view normal's z there; 0 where b is background (the sample is open);
 * -1 where there is no estimate (the sample is left out).  *bk (when not
 * NULL): b's pixel index, where the result is not -1. */
int obs__border_point(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                      float qx, float qy, float out[4], float *nz, size_t *bk)
{
    int bx, by;
    if (!(fabsf(qx) < OBS_BORDER_MAX_PX && fabsf(qy) < OBS_BORDER_MAX_PX))
        return -1; /* a sample near the camera's plane: no pixel to speak of */
    obs__border_px(f, x, y, qx, qy, &bx, &by);
    size_t k = (size_t)by * (size_t)f->width + (size_t)bx;
    if (bk)
        *bk = k;
    const float *b = pos + 4 * k, *nb = nrm + 3 * k;
    if (!(b[3] > 0.0f))
        return 0;
    *nz = nb[2];
    return obs__plane_point(f, qx, qy, b, nb, out) ? 1 : -1;
}
