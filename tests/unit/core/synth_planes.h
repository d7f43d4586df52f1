/* Analytic G-buffers of planes for the estimator tests (test_vao_math.c,
 * test_methods.c, test_borders.c): a camera at the origin looking down
 * -Z, orthographic or perspective, and planes {n . p = c}; each pixel
 * sees the nearest plane (the first one on a tie), with planar depth and
 * camera-space normals. */
#ifndef OBS_TEST_SYNTH_PLANES_H
#define OBS_TEST_SYNTH_PLANES_H

#include <math.h>
#include <string.h>

#include "internal.h"

typedef struct sp_plane {
    float n[3], c; /* n . p = c, n towards the camera */
} sp_plane;

/* An orthographic projection of [-half_w, half_w] x [-half_h, half_h]. */
static inline void sp_ortho(float P[16], float half_w, float half_h)
{
    const float n = 0.1f, f = 100.0f;
    memset(P, 0, 16 * sizeof(float));
    P[0] = 1.0f / half_w;
    P[5] = 1.0f / half_h;
    P[10] = -2.0f / (f - n);
    P[11] = -(f + n) / (f - n);
    P[15] = 1.0f;
}

/* A perspective projection with a vertical field of view of fov_y_deg
 * degrees for a w x h image. */
static inline void sp_perspective(float P[16], float fov_y_deg, int w, int h)
{
    const float n = 0.1f, f = 100.0f, t = 1.0f / tanf(fov_y_deg * (float)M_PI / 360.0f);
    memset(P, 0, 16 * sizeof(float));
    P[0] = t * h / w;
    P[5] = t;
    P[10] = -(f + n) / (f - n);
    P[11] = -2.0f * f * n / (f - n);
    P[14] = -1.0f;
}

/* The planes seen by camera P over a w x h window and a band of g more
 * pixels on every side: depth and normal ((w + 2g) x (h + 2g), 1 and 3
 * floats a pixel) and gb's size, planes and camera; gb's display window
 * is left at 0 (the caller's to set). */
static inline void sp_render(float *depth, float *normal, obs_gbuffer *gb, int w, int h, int g,
                             const float P[16], const sp_plane *pl, int count)
{
    int ww = w + 2 * g, hh = h + 2 * g;
    memset(depth, 0, (size_t)ww * hh * sizeof *depth);
    memset(normal, 0, (size_t)ww * hh * 3 * sizeof *normal);
    for (int y = 0; y < hh; y++)
        for (int x = 0; x < ww; x++) {
            float nx = (x - g + 0.5f) / w * 2 - 1, ny = 1 - (y - g + 0.5f) / h * 2;
            float o[3] = {0, 0, 0}, d[3] = {0, 0, -1}, best = 1e10f;
            if (P[14] == 0.0f) { /* orthographic */
                o[0] = nx / P[0];
                o[1] = ny / P[5];
            } else {
                d[0] = nx / P[0];
                d[1] = ny / P[5];
            }
            const float *bn = NULL;
            for (int k = 0; k < count; k++) {
                float den = pl[k].n[0] * d[0] + pl[k].n[1] * d[1] + pl[k].n[2] * d[2];
                if (fabsf(den) < 1e-9f)
                    continue;
                float t = (pl[k].c - (pl[k].n[0] * o[0] + pl[k].n[1] * o[1] + pl[k].n[2] * o[2])) /
                          den;
                if (t > 0 && t < best) {
                    best = t;
                    bn = pl[k].n;
                }
            }
            depth[y * ww + x] = best; /* d.z = -1: t is the planar depth */
            if (bn)
                memcpy(&normal[3 * (y * ww + x)], bn, 3 * sizeof(float));
        }
    *gb = (obs_gbuffer){0};
    gb->width = ww;
    gb->height = hh;
    gb->depth = (obs_plane){depth, 1, 0};
    gb->normal = (obs_plane){normal, 3, 0};
    memcpy(gb->camera.projection, P, 16 * sizeof(float));
    obs__mat4_identity(gb->camera.world_to_camera);
    gb->camera.has_projection = 1;
    gb->camera.has_world_to_camera = 1;
}

#endif
