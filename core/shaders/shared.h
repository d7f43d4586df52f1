/* Constants the C code and the shaders share.  This file is both C and
 * GLSL: the embedding step (tools/embed_shaders.sh) puts it at the head of
 * every embedded shader, and the C side includes it (core/chain/frame.h,
 * core/internal.h), so a pass and its CPU twin read the same number.  Its
 * names carry one underscore after OBS: GLSL reserves "__" for the
 * implementation.  Floats carry the f suffix, which both languages read
 * as the same single-precision value.  Not installed. */
#ifndef OBS_SHARED_H
#define OBS_SHARED_H

/* Raw depth at or beyond this (Blender writes 1e10 for the sky), non-finite
 * or <= 0 is background: no geometry, AO 1, never an occluder. */
#define OBS_BACKGROUND_DEPTH 1e9f

/* Culling pre-pass (VAO++ section 4.2): one low-resolution texel per
 * OBS_CULL_BLOCK x OBS_CULL_BLOCK pixels ("1/8 resolution"), always
 * OBS_CULL_SAMPLES samples; a culling candidate of the careful variant
 * takes at most OBS_CULL_CAREFUL samples. */
#define OBS_CULL_BLOCK 8
#define OBS_CULL_SAMPLES 8
#define OBS_CULL_CAREFUL 4

/* A VAO sample on the shaded pixel itself reads p's tangent plane under
 * its pipe (own_plane_depth) unless |n.z| is at most this (the plane
 * nearly edge-on). */
#define OBS_OWN_PLANE_NZ 0.05f

/* A sample off the planes (border_cpu.c) is continued past the border
 * only while its pixel coordinates are below this in magnitude (farther
 * out it lies near the camera's plane, and an int would not hold it). */
#define OBS_BORDER_MAX_PX 1.0e6f

/* The sample sets of VAO++ 4.5: n = 2, 4, 8, 16, 32, one after the other
 * in one table of OBS_SAMPLE_TABLE_LEN (x, y) pairs (the set of n at pair
 * n - 2), the layout of the shader's single uniform array (4.1). */
#define OBS_MAX_SAMPLES 32
#define OBS_SAMPLE_TABLE_LEN 62 /* 2 + 4 + 8 + 16 + 32 */

/* Largest counts of the comparison methods' parameters: the uniform
 * arrays' sizes in hemisphere.glsl (3 floats a sample), angle.glsl and
 * hbao.glsl. */
#define OBS_MAX_HEMISPHERE 64
#define OBS_MAX_PAIRS 16
#define OBS_MAX_DIRECTIONS 32

/* Largest blur_radius of the parameter table (one blur program per
 * radius, BLUR_RADIUS in blur.frag.glsl; the weights' array size). */
#define OBS_MAX_BLUR 16

#endif
