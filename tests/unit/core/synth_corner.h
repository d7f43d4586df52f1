/* A synthetic G-buffer for the colour tests (luminance sensitivity,
 * colour bleeding): a perspective camera at the origin looking down -Z at
 * a floor y = -1 meeting a back wall z = -SC_WALL; planar depth, camera-space
 * normals, and a colour plane the test fills per pixel. */
#ifndef OBS_TEST_SYNTH_CORNER_H
#define OBS_TEST_SYNTH_CORNER_H

#include <math.h>
#include <string.h>

#include "chain/frame.h"

#define SC_W 96
#define SC_H 72
#define SC_WALL 2.5f /* the wall's distance: floor rows near it are 0.1 apart in depth */

typedef struct sc_scene {
    float depth[SC_W * SC_H];
    float normal[SC_W * SC_H * 3];
    float color[SC_W * SC_H * 4];
    int wall[SC_W * SC_H]; /* 1: the pixel sees the wall, 0: the floor */
    obs_gbuffer gb;
} sc_scene;

static void sc_render(sc_scene *s)
{
    const float n = 0.1f, f = 100.0f, t = 1.0f / tanf(60.0f * (float)M_PI / 360.0f);
    float P[16] = {0};
    P[0] = t * SC_H / SC_W;
    P[5] = t;
    P[10] = -(f + n) / (f - n);
    P[11] = -2.0f * f * n / (f - n);
    P[14] = -1.0f;
    memset(s, 0, sizeof *s);
    for (int y = 0; y < SC_H; y++)
        for (int x = 0; x < SC_W; x++) {
            size_t i = (size_t)y * SC_W + x;
            /* the ray (., dy, -1): the floor at depth -1/dy (dy < 0), else the wall */
            float dy = (1 - (y + 0.5f) / SC_H * 2) / P[5];
            float depth = SC_WALL;
            int wall = 1;
            if (dy < 0.0f && -1.0f / dy < SC_WALL) {
                depth = -1.0f / dy;
                wall = 0;
            }
            s->depth[i] = depth;
            s->wall[i] = wall;
            s->normal[3 * i + (wall ? 2 : 1)] = 1.0f;
            for (int k = 0; k < 4; k++)
                s->color[4 * i + k] = 1.0f;
        }
    s->gb.width = SC_W;
    s->gb.height = SC_H;
    s->gb.depth = (obs_plane){s->depth, 1, 0};
    s->gb.normal = (obs_plane){s->normal, 3, 0};
    s->gb.color = (obs_plane){s->color, 4, 0};
    memcpy(s->gb.camera.projection, P, sizeof P);
    obs__mat4_identity(s->gb.camera.world_to_camera);
    s->gb.camera.has_projection = 1;
    s->gb.camera.has_world_to_camera = 1;
}

#endif
