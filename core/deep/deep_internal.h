/* Internal to the multi-layer AO: the prepared nodes and the per-node
 * function shared by the CPU twin (deep_cpu.c) and the GL pass
 * (deep_gl.c, core/shaders/deep.frag.glsl).  Not installed. */
#ifndef OBSCURA_DEEP_INTERNAL_H
#define OBSCURA_DEEP_INTERNAL_H

#include "obscura/deep.h"
#include "chain/frame.h"

typedef struct obs__deep_frame {
    obs__frame f;   /* camera, R, the sample set, the depth range check */
    int m;          /* nodes per pixel */
    int multi;      /* 1: OITAO Algorithm 1 over every node; 0: front node only */
    int thin;       /* 1: thin hulls (eqs 2-4); 0: solid volumes (eq 1) */
    float *pos;     /* m planes of 4 floats: view position xyz, planar depth w (0: empty) */
    float *nrm;     /* m planes of 4 floats: view normal xyz, alpha */
    obs_deep_layers layers;
} obs__deep_frame;

/* Compresses the image and prepares the node planes (the prep pass of
 * every node: view position, then normal from the file or reconstructed
 * from the node plane's positions).  Frees with obs__deep_frame_free(). */
obs_status obs__deep_frame_setup(const obs_deep_image *d, const obs_params *params,
                                 obs__deep_frame *df, char err[OBS_ERR_LEN]);
void obs__deep_frame_free(obs__deep_frame *df);

/* The AO (1 = open) of node k at pixel (x, y): OITAO Algorithm 1 with
 * VAO++'s pipe through the tangent sphere as GetAO (with f.method
 * hemisphere: the hemisphere kernel's point samples, the flat chain's
 * obs__hemisphere_estimate over the nodes), eq 1 or eqs 2-4 (GLSL:
 * node_ao() in deep.frag.glsl). */
float obs__deep_node_ao(const obs__deep_frame *df, int x, int y, int k);

/* The per-node AO of pixel (x, y) blended front to back by alpha onto
 * AO 1 (OITAO III, separated scheme); *front gets node 0's AO (1 when the
 * pixel is empty).  GLSL: main() of deep.frag.glsl. */
float obs__deep_pixel(const obs__deep_frame *df, int x, int y, float *front);

/* Fills out's composite: the front-to-back "over" of every sample's
 * (premultiplied) colour, times ao_blend; out->ao_blend must be filled. */
void obs__deep_composite(const obs_deep_image *d, obs_deep_result *out);

obs_status obs__deep_result_alloc(obs_deep_result *out, int w, int h, char err[OBS_ERR_LEN]);

#endif
