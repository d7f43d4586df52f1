/* Internal to the multi-layer AO: the prepared nodes and the per-node
 * function shared by the CPU twin (deep_cpu.c) and the GL pass
 * (deep_gl.c, core/shaders/deep.frag.glsl).  Not installed. */
#ifndef OBSCURA_DEEP_INTERNAL_H
#define OBSCURA_DEEP_INTERNAL_H

#include "obscura/deep.h"
#include "chain/frame.h"

/* end of a list's last kept node, a back face, where eq 5 dropped nodes
 * behind it: inside an interval (< 0) like -1, and the list goes on */
#define OBS__DEEP_END_CUT (-2.0f)

typedef struct obs__deep_frame {
    obs__frame f;   /* camera, R, the sample set, the depth range check */
    int m;          /* nodes per pixel */
    int multi;      /* 1: OITAO Algorithm 1 over every node; 0: front node only */
    int thin;       /* 1: thin hulls (eqs 2-4); 0: solid volumes (eq 1) */
    int intervals;  /* 1: end holds the nodes' intervals (deep_intervals on,
                     * the image has facing flags, deep_mode multi) */
    int inside;     /* 1: intervals off, but the facing flags mark the nodes
                     * inside a nearer node's interval (end -1 or
                     * OBS__DEEP_END_CUT, the rest 0), which are no
                     * occluders (methods vaopp, vao, hemisphere; the
                     * image has facing flags, deep_mode multi) */
    float *pos;     /* m planes of 4 floats: view position xyz, planar depth w (0: empty) */
    float *nrm;     /* m planes of 4 floats: view normal xyz, alpha */
    float *nrm3;    /* methods gtao and VAO: the front nodes' view normals,
                     * 3 floats a pixel, the surface that a step or a line
                     * sample past the border continues (border_cpu.c) */
    float *end;     /* m planes of 1 float, the node's extent along its pixel's
                     * ray (obs__deep_intervals): 0 solid behind it (no back
                     * face known), e > 0 solid from its depth to e (a front
                     * face and its matching back face), -1 inside an
                     * interval a nearer node opened (adds nothing),
                     * OBS__DEEP_END_CUT the same for a list's last node
                     * where eq 5 dropped nodes behind it; method gtao:
                     * e = the node's depth for a sheet (obs__deep_sheets) */
    obs_deep_layers layers;
} obs__deep_frame;

/* obs_deep_compress_list and obs_deep_compress with intervals (non-zero:
 * deep_intervals in effect): eq 5's node and, when it is one end of a
 * front face / back face pair matched by the facing flags, its partner
 * are dropped together, so compression never splits an interval
 * (deep_compress.c); intervals 0 is the public functions' behaviour. */
int obs__deep_compress_list(const float *samples, int n, int m, int front_half, int intervals,
                            float zmin, float zmax, float *out);
obs_status obs__deep_compress(const obs_deep_image *d, int m, int front_half, int intervals,
                              obs_deep_layers *out, char err[OBS_ERR_LEN]);

/* Compresses the image and prepares the node planes (the prep pass of
 * every node: view position, then normal from the file or reconstructed
 * from the node plane's positions).  Frees with obs__deep_frame_free(). */
obs_status obs__deep_frame_setup(const obs_deep_image *d, const obs_params *params,
                                 obs__deep_frame *df, char err[OBS_ERR_LEN]);
void obs__deep_frame_free(obs__deep_frame *df);

/* The deep AO out of the frame d was set up from (deep_nodes.c): every
 * kept node's AO into out, from node_ao (m planes of width x height, node
 * k of pixel i at k * npx + i: the GL pass's read-back) or, with node_ao
 * NULL, computed here (obs__deep_node_ao, the CPU twin). */
obs_status obs__deep_ao_pack(const obs_deep_image *d, const obs__deep_frame *df,
                             const float *node_ao, obs_deep_ao *out, char err[OBS_ERR_LEN]);

/* The facing flags of pixel i's kept nodes as intervals (the
 * deep_intervals parameter): front to back, a node met outside every
 * interval opens one if it is a front face (facing +1), which its
 * matching back face closes (the facing count back to 0): end = that back
 * face's depth; every node inside is -1.  A node outside every interval
 * that is not a front face (a back face seen with nothing open: a surface
 * seen from behind; facing unknown) and a front face whose back face the
 * list does not hold (an open mesh, or the back face dropped by eq 5)
 * keep end 0: solid behind them, the range check (eq 4) applying, as
 * without intervals; the nodes behind such a front face are taken on
 * their own, as if it were not there.  z, facing: the count nodes' planar
 * depths and OBS_DEEP_FACING values, front to back; writes end[0 ..
 * count - 1]. */
void obs__deep_intervals(const float *z, const float *facing, int count, float *end);

/* Method gtao's ends (gtao_deep.c): a node obs__deep_intervals left solid
 * behind (end 0) whose facing is known and that has a node behind it in
 * the list is a one-sided surface of an open mesh, a sheet: end = its own
 * depth, an interval of no thickness.  The facing flags say the space
 * behind it is not inside a solid: a back face's outside is behind it, and
 * the node after an unmatched front face is a front face (a back face
 * would have matched it), whose outside, in front of it, is free; the
 * list then shows the surfaces behind, so the sheet is what the ray tracer
 * takes every triangle to be: a surface of no thickness.  The list's last
 * node stays solid behind (nothing behind it is known: a room's
 * one-sided wall).  z, facing, count, end: as obs__deep_intervals, end
 * its output. */
void obs__deep_sheets(const float *z, const float *facing, int count, float *end);

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

/* The clip range (near, far) of the camera's projection, over which eq 5
 * normalises depth (deep_compress.c); the default clip range of
 * parameters near and far when the camera has no projection or one
 * without a usable range. */
void obs__deep_clip_range(const obs_camera *cam, float *near_z, float *far_z);

obs_status obs__deep_result_alloc(obs_deep_result *out, int w, int h, char err[OBS_ERR_LEN]);

#endif
