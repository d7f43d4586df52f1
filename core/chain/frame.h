/* One frame's resolved setup, shared by the GL passes (as uniforms) and by
 * their CPU twin, plus the twin's per-pixel functions.  Each function here
 * has a GLSL counterpart of the same name in core/shaders/common.glsl (or
 * the pass shader named beside it); tests compare the two. */
#ifndef OBSCURA_FRAME_H
#define OBSCURA_FRAME_H

#include <math.h>
#include "internal.h"
#include "shaders/shared.h" /* constants shared with the shaders */

/* Every OBS_OUTPUT_* bit. */
#define OBS__OUTPUTS_ALL                                                                           \
    (OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE | OBS_OUTPUT_SAMPLE_COUNT | OBS_OUTPUT_CULL_MASK |        \
     OBS_OUTPUT_BLEED | OBS_OUTPUT_LUMINANCE | OBS_OUTPUT_MULTIBOUNCE | OBS_OUTPUT_BENT)

/* k of R = k * D: the paper's kernel width R (hemisphere radius; the
 * tangent sphere has radius R/2) for the ray-traced AO distance D that the
 * radius parameter gives, by ao_definition (bench/QUALITY.md, "How
 * --radius maps to the AO distance"; tools/radius_mapping.py).
 *
 * rays, k = 2: on a floor at distance x from a wall, the rays of length D
 * reach the wall for x < D, and the tangent sphere of radius R/2 = D
 * touches it for x < D: the same support, so the crease profile of the
 * volume fraction can be converted to the ray tracer's one exactly
 * (obs__rays_from_volume).  k = 2 is the smallest k for which that is
 * possible: for k < 2 the volume fraction is 0 where the rays still see
 * the wall.
 *
 * volume, k = 1: the tangent sphere of radius D/2 is the largest sphere
 * inside the ray tracer's hemisphere of radius D that touches p.
 *
 * Applied in one place, obs__frame_setup_common (frame.c), to methods vaopp and
 * vao (the comparison methods take the radius as D). */
/* How many depth modes there are (the prep pass has a program for each). */
#define OBS__DEPTH_MODES (OBS_DEPTH_NORMALIZED - OBS_DEPTH_DEFAULT)

#define OBS__RADIUS_K_RAYS 2.0f
#define OBS__RADIUS_K_VOLUME 1.0f

/* Room for the largest method's state (core/methods/<method>.h, each
 * checked against it with a _Static_assert). */
#define OBS__METHOD_STATE_BYTES 800
typedef union obs__method_state {
    double align;
    unsigned char bytes[OBS__METHOD_STATE_BYTES];
} obs__method_state;

typedef struct obs__frame {
    int width, height;
    float viewport[4];      /* display_x, display_y, display_width, display_height */
    float proj[16];         /* view -> clip, row-major */
    float normal_matrix[9]; /* input normal -> view normal, row-major 3x3 */
    int reconstruct_normals;/* 1: no usable normals, derive them from depth */
    int depth_mode;         /* OBS_DEPTH_PLANAR/RADIAL/NDC */
    float radius;           /* R, the kernel width, in depth units: k * radius / unit_scale
                             * (OBS__RADIUS_K_*); D for the comparison methods */
    int rays;               /* 1: eq 1's V converted to the ray-traced AO (ao_definition rays) */
    int samples;            /* the count of the parameter: adaptive sampling's maximum */
    const float *sample_xy; /* samples * (x, y) on the unit disk */
    const float *sample_table; /* all sets, 62 (x, y) pairs: the set of n at pair n - 2 */
    int adaptive;           /* 1: adaptive sampling (section 4.1) */
    float adaptive_k;       /* vw / (vh * D0^2): disk area ratio = r^2 |det J| * adaptive_k */
    float rot[9][2];        /* (cos, sin) of the 3x3 tile's rotations */
    int range_check;        /* 1: depth range check (section 4.4, eq 4) */
    float range_u;          /* u of eq 4 */
    int range_normal;       /* 1: eq 4's d along the occluder's normal (range_distance) */
    int culling;            /* section 4.2: 0 off, 1 greedy, 2 careful */
    float cull_threshold;   /* an estimate below this shows occlusion: 1 - culling_epsilon */
    int cull_w, cull_h;     /* the low-resolution texture: ceil(width / 8) x ceil(height / 8) */
    int blur_radius;        /* low-pass filter half-width (section 4.6); 0: off */
    int half;               /* 1: the AO at half resolution (ao_resolution half) */
    float blur_w[OBS_MAX_BLUR + 1]; /* Gaussian weight of offset 0..blur_radius */
    int luminance;          /* section 4.3, eq 3: 0 off, 1 Rec. 709 luminance, 2 HSV V */
    float lum_threshold, lum_width, lum_sigma; /* threshold, width, sigma of eq 3 */
    int bleed_step;         /* section 4.7, eq 5: 0 off, else every bleed_step-th sample */
    int method;             /* OBS_METHOD_*: which estimator the AO pass runs */
    /* Object masks (core/mask.c, obs_gbuffer.occluders and object_id,
     * packed, width x height; NULL: none): read at each method's sample
     * site through obs__occluder_weight (chain/mask_weight.h) */
    const float *mask_occl, *mask_id;
    int mask_on;            /* 1: either is set */
    /* 0: one plane (the flat chain); deep input: the planes are per node,
     * node k's at k * mask_plane (width x height each, core/deep) */
    size_t mask_plane;
    /* the method's own values, read by its functions only: their types
     * are in core/methods/<method>.h (obs__gtao_of(f), ...), so the chain
     * needs none of them; in place, so that a frame copies whole
     * (obs__frame_half, the deep frame) */
    obs__method_state ms;
} obs__frame;

/* The frame's values as the shaders read them: the uniform block Frame
 * of common.glsl, layout std140, mirrored member for member (a vec2 or a
 * float of an array takes 16 bytes, a row_major mat3 three vec4 rows).
 * Filled once per frame (obs__frame_block_fill) and uploaded to one
 * buffer that every pass of the chain and the deep pass bind; the test
 * in tests/unit/core/test_frame_block.c checks these offsets against
 * the ones GL reports. */
typedef struct obs__frame_block {
    float proj[16];            /* layout(row_major) mat4 u_proj */
    float viewport[4];         /* vec4 u_viewport */
    float normal_matrix[3][4]; /* layout(row_major) mat3 u_normal_matrix */
    int32_t size[2];           /* ivec2 u_size */
    int32_t cull_size[2];      /* ivec2 u_cull_size */
    float radius;              /* u_radius */
    float range_u;             /* u_range_u */
    int32_t range_normal;      /* u_range_normal */
    int32_t count;             /* u_count: the samples parameter */
    float adaptive_k;          /* u_adaptive_k */
    int32_t culling;           /* u_culling */
    float cull_threshold;      /* u_cull_threshold */
    int32_t bleed_step;        /* u_bleed_step */
    int32_t luminance;         /* u_luminance */
    float lum_threshold, lum_width, lum_sigma; /* u_lum_threshold, _width, _sigma */
    float rot[9][4];           /* vec2 u_rot[9] */
    float samples[OBS_SAMPLE_TABLE_LEN][4]; /* vec2 u_samples[OBS_SAMPLE_TABLE_LEN] */
    float blur_w[OBS_MAX_BLUR + 1][4];     /* float u_blur_w[OBS_MAX_BLUR + 1] */
} obs__frame_block;

/* The block of frame f. */
void obs__frame_block_fill(const obs__frame *f, obs__frame_block *b);

/* Resolves camera, parameters and normal handling for one frame: every
 * value but the method's own (obs__frame_setup in methods/methods.h adds
 * those). */
obs_status obs__frame_setup_common(obs_ctx *log_ctx, const obs_gbuffer *gb,
                                   const obs_params *resolved, obs__frame *f,
                                   char err[OBS_ERR_LEN]);

/* ---- half resolution (ao_resolution half; half_cpu.c) ------------------- */

/* OBS_INVALID_ARGUMENT when the frame cannot give an output asked for
 * (half resolution: the per-pixel debug planes). */
obs_status obs__frame_check_outputs(const obs__frame *f, unsigned outputs, char err[OBS_ERR_LEN]);

/* The frame of the AO and blur passes at half resolution: the same camera
 * over ceil(width / 2) x ceil(height / 2) pixels, half pixel (x, y)
 * covering full pixels 2x..2x+1, 2y..2y+1 (the viewport halved). */
void obs__frame_half(const obs__frame *f, obs__frame *hf);

/* The full-resolution pixel that half pixel (hx, hy) takes its position,
 * normal and depth from: of its 2x2 block's pixels with a surface, the
 * nearest (planar depth) where hx + hy is even, the farthest where it is
 * odd, the first in row order on a tie; -1 when all four are background.
 * pos: the full frame's prep positions (4 floats a pixel, w the planar
 * depth).  GLSL: prep.frag.glsl with OBS_HALF (the prep of the chosen
 * pixel, straight from the raw planes). */
long obs__half_source(const obs__frame *f, const float *pos, int hx, int hy);

/* The object masks of half pixel h (occluders weight into hw[h], object
 * into hid[h]; NULL, or the full frame without that mask: not written):
 * those of full pixel k, the one obs__half_source picked for it.  The
 * half frame's mask_occl and mask_id then point at hw and hid. */
void obs__half_masks(const obs__frame *f, long k, size_t h, float *hw, float *hid);

/* The AO of full pixel (x, y) from the half-resolution AO `hao`: the
 * joint bilateral upsample, up.frag.glsl.  The
 * four half pixels around the pixel's centre, each weighted by its
 * bilinear weight times max(0, n . n_q), n the pixel's view normal;
 * a half pixel without a surface, or whose planar depth is more than R
 * from the pixel's (the blur's threshold, section 4.6), is left out; when
 * all are, the one nearest in depth gives its AO.  1 for background. */
float obs__half_upsample(const obs__frame *f, const obs__frame *hf, const float *pos,
                         const float *nrm, const float *hpos, const float *hnrm,
                         const float *hao, int x, int y);

/* ---- per-pixel twins (GLSL: common.glsl, prep.frag, vao.frag) ----------- */

/* The place of pixel (x, y) in the 3x3 rotation tile (VAO++ 4.5), counted
 * from the display window's corner (viewport[0..1] is the data window's
 * offset in it), so that a crop gets the whole frame's rotations (GLSL:
 * tile_index in common.glsl). */
static inline int obs__tile_index(const obs__frame *f, int x, int y)
{
    int dx = x + (int)floorf(f->viewport[0]), dy = y + (int)floorf(f->viewport[1]);
    int tx = dx - 3 * (int)floorf((float)dx / 3.0f), ty = dy - 3 * (int)floorf((float)dy / 3.0f);
    return 3 * tx + ty;
}

/* Pixel centre (x, y) of the planes -> NDC of the display window (GLSL:
 * px_ndc() in common.glsl).  Inline: method gtao on deep intervals takes
 * it, with obs__view_ray, for every step's column (methods/gtao_deep.c). */
static inline void obs__px_ndc(const obs__frame *f, int x, int y, float ndc[2])
{
    ndc[0] = ((float)x + 0.5f + f->viewport[0]) / f->viewport[2] * 2.0f - 1.0f;
    ndc[1] = 1.0f - ((float)y + 0.5f + f->viewport[1]) / f->viewport[3] * 2.0f;
}

/* The view ray of NDC (nx, ny): the point with planar depth d is
 * origin + d * dir, dir.z = -1 (GLSL: view_ray() in common.glsl): the
 * projection solved for view x, y as a 2x2 system that is affine in view
 * z. */
static inline void obs__view_ray(const float *P, const float ndc[2], float origin[3], float dir[3])
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

/* Samples off the planes (border_cpu.c, which derives them): the last
 * pixel (bx, by) on the planes along the segment from pixel (x, y) to the
 * pixel (qx, qy) off them; the point of pixel (qx, qy)'s ray on the plane
 * through b with normal nb (1, or 0 where there is none); and the point a
 * sample there reads for pixel (x, y): 1 and out, *nz; 0 background (open);
 * -1 no estimate (left out). */
void obs__border_px(const obs__frame *f, int x, int y, float qx, float qy, int *bx, int *by);
int obs__plane_point(const obs__frame *f, float qx, float qy, const float b[3], const float nb[3],
                     float out[4]);
int obs__border_point(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                      float qx, float qy, float out[4], float *nz, size_t *bk);

/* View-space position of the point seen at pixel (x, y): the prep pass.
 * out = (x, y, z, d) with d the planar depth; (0,0,0,0) for background. */
void obs__prep_position(const obs__frame *f, float raw_depth, int x, int y, float out[4]);

/* View-space unit normal of pixel (x, y) from the input normal (or, with
 * reconstruct_normals, from the neighbouring positions in `pos`, 4 floats
 * per pixel as obs__prep_position writes them). */
void obs__prep_normal(const obs__frame *f, const float *pos, const float *in_normal, int x, int y,
                      float out[3]);

/* Adaptive sampling, VAO++ section 4.1 (GLSL: adaptive_count() in
 * vao.frag.glsl): the sample count for a tangent sphere centred at the
 * view-space point c, from the screen area of its disk of radius R/2. */
int obs__adaptive_count(const obs__frame *f, const float c[3]);

/* Volumetric AO of the point p with normal n at pixel (x, y), eq 1 and 2
 * of VAO++ section 3; `pos` and `nrm` are the prep pass's position and
 * view normal planes (4 and 3 floats per pixel).  The count of samples
 * taken goes to *count when count is not NULL. */
float obs__vao_pixel(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                     const float p[3], const float n[3], int *count);

/* The sample count pixel (x, y) takes without culling: the samples
 * parameter, or the adaptive count (section 4.1) of its tangent sphere. */
int obs__vao_count(const obs__frame *f, const float p[3], const float n[3]);

/* The volumetric AO estimator of obs__vao_pixel with an explicit set:
 * the ns samples at xy (GLSL: vao_estimate() in vao.glsl). */
float obs__vao_estimate(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                        const float p[3], const float n[3], int ns, const float *xy);

/* The samples' pixels (GLSL: disk_map(), disk_px() in common.glsl).  The
 * disk c + r (dx, dy, 0), (dx, dy) a sample (sx, sy) turned by rot (cos,
 * sin), lies in the plane z = c.z, so its pixel coordinates are a
 * projective map of (sx, sy): u = (U.s) / (W.s), v = (V.s) / (W.s) with
 * s = (sx, sy, 1), set up once per pixel.  obs__disk_px gives the pixel
 * obs__view_to_px gives for the sample's view-space point, up to rounding
 * at pixel borders; 0 when behind the camera or off the planes. */
typedef struct obs__disk {
    float u[3], v[3], w[3];
} obs__disk;
void obs__disk_map(const obs__frame *f, const float c[3], float r, const float rot[2],
                   obs__disk *m);
int obs__disk_px(const obs__frame *f, const obs__disk *m, float sx, float sy, int *qx, int *qy);
/* A sample (sx, sy) of the disk off the planes: the surface of the planes
 * pos, nrm (stride 4 and 3) continued past the border (border_cpu.c):
 * 1 and *zs, *nz there (*zs left as it is, open, where that is
 * background), *bk (when not NULL) the index of the pixel continued; 0:
 * left out (behind the camera, or no estimate). */
int obs__disk_border(const obs__frame *f, const float *pos, const float *nrm, const obs__disk *m,
                     int x, int y, float sx, float sy, float *zs, float *nz, size_t *bk);

/* The depth range check's falloff (VAO++ 4.4, eq 4): s(d) = u / max(u,
 * d / R) for a pipe d behind its occluder along view Z; with
 * f->range_normal, d |nz|, the pipe's depth below the occluding surface
 * whose view normal has z component nz (GLSL: range_falloff() in
 * common.glsl). */
float obs__range_falloff(const obs__frame *f, float d, float nz);

/* The planar depth of the tangent plane at p (normal n) under the pipe of
 * the disk's sample (sx, sy), for eq 1's dz: what a sample on the shaded
 * pixel itself reads instead of the depth at the pixel's centre zs, which
 * is p's; zs itself when |n[2]| <= OBS_OWN_PLANE_NZ (GLSL:
 * own_plane_depth(p, n, disk_point(c, r, rot, sx, sy), zs) in
 * common.glsl). */
float obs__own_plane_depth(const float p[3], const float n[3], const float c[3], float r,
                           const float rot[2], float sx, float sy, float zs);

/* ao_definition rays (GLSL: rays_from_volume() in common.glsl):
 * the AO a ray tracer gives with rays of length D for the AO ao of the
 * tangent sphere of radius D (R = 2 D), through the floor-wall crease,
 * where both are known in closed form: a wall at distance x = b D from p
 * fills (1 - b)^2 (2 + b) / 4 of the sphere and blocks
 * (acos b - b sqrt(1 - b^2)) / pi of the cosine-weighted rays.  The
 * first is inverted for b, the second returned as AO; both are 1/2 at the
 * corner (b = 0), and an occlusion over 1/2 is returned unchanged. */
float obs__rays_from_volume(float ao);

/* Culling pre-pass, VAO++ section 4.2 (GLSL: cull.frag.glsl), CPU twin
 * in cull_cpu.c.  The low-resolution AO: texel (i, j) of cull_w x cull_h
 * (written to est) is the 8-sample AO of the pixel at the block's centre,
 * (min(8i + 4, width - 1), min(8j + 4, height - 1)); 1 for background. */
void obs__cull_prepass(const obs__frame *f, const float *pos, const float *nrm, float *est);

/* GL_LINEAR fetch of the low-resolution AO at the full-resolution
 * position (px, py) (pixel corners are integers), clamped to the edge. */
float obs__cull_fetch(const obs__frame *f, const float *est, int px, int py);

/* 1 when none of the four corners of pixel (x, y) shows occlusion: the
 * pixel is a culling candidate (GLSL: cull_candidate() in vao.frag.glsl). */
int obs__cull_candidate(const obs__frame *f, const float *est, int x, int y);

/* obs__cull_candidate for every pixel of the tile [x0, x1) x [y0, y1),
 * 1 or 0 at cand[(y - y0) * (x1 - x0) + x - x0]; each pixel corner's
 * fetch once (a corner is shared by four pixels).  Tiles up to
 * OBS__CULL_TILE_MAX pixels wide take that form, wider ones the test
 * pixel by pixel. */
#define OBS__CULL_TILE_MAX 256
void obs__cull_candidates(const obs__frame *f, const float *est, int x0, int x1, int y0, int y1,
                          unsigned char *cand);

/* The estimator of obs__vao_estimate that also gathers colour bleeding
 * (VAO++ section 4.7, eq 5; GLSL: vao_estimate() in vao.glsl): with
 * f->bleed_step > 0, bleed gets the mean over every bleed_step-th sample
 * of white mixed towards the colour at the sample's pixel by c(x); else
 * (1, 1, 1).  col: 4 floats (RGBA) per pixel; NULL: no bleeding. */
/* The VAO estimator's bent normal (OBS_OUTPUT_BENT; vao_bent_cpu.c): the
 * centroid of the tangent sphere's open volume seen from p, summed over
 * the samples into bent[3] (not normalised; 0 when every pipe is closed);
 * returns the AO as obs__vao_estimate.  GLSL: vao_bent_sample() in
 * vao.glsl, in vao_estimate(). */
float obs__vao_estimate_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                             const float p[3], const float n[3], int ns, const float *xy,
                             float bent[3]);
void obs__vao_bent_sample(const float c[3], float r, const float rot[2], float sx, float sy, float h,
                          float dz, const float p[3], float bent[3]);
float obs__vao_estimate_bleed(const obs__frame *f, const float *pos, const float *nrm,
                              const float *col, int x, int y, const float p[3], const float n[3],
                              int ns, const float *xy, float bleed[3]);

/* Eq 5 of VAO++ section 4.7 (GLSL: bleed_weight() in vao.glsl): the
 * indirect contribution c(x) of the surface point x to the point p with
 * normal n, for the AO radius R. */
float obs__bleed_weight(const float x[3], const float p[3], const float n[3], float R);

/* Luminance sensitivity, VAO++ section 4.3, eq 3 (GLSL:
 * luminance_factor() in luminance.frag.glsl): the factor of eq 3 for a
 * pixel of colour rgb, 1 keeps its occlusion, 0 removes it; and the AO
 * after the correction, 1 - (1 - ao) * factor.  f->luminance must be
 * non-zero. */
float obs__luminance_factor(const obs__frame *f, const float rgb[3]);
float obs__luminance_ao(const obs__frame *f, float ao, const float rgb[3]);

/* Low-pass filter, VAO++ section 4.6 (GLSL: blur.frag.glsl): one pass of
 * the depth-aware cross-bilateral Gaussian along (dx, dy) at pixel (x, y)
 * of the AO plane `ao`; `pos` gives each pixel's view depth (w). */
float obs__blur_pixel(const obs__frame *f, const float *pos, const float *ao, int x, int y, int dx,
                      int dy);

/* ---- what the comparison methods share (core/methods/) ------------------ */

/* The pixel whose planes hold the view-space point s: 1 and (qx, qy) when s
 * projects into the image in front of the camera, else 0 (GLSL:
 * view_to_px() in method.glsl). */
int obs__view_to_px(const obs__frame *f, const float s[3], int *qx, int *qy);

/* The radius r (depth units) projected at the view point p, in pixels:
 * the square root of the projected area of a disk of radius r
 * perpendicular to the view axis (as obs__adaptive_count measures it);
 * 0 behind the camera (GLSL: radius_px() in method.glsl; prep_cpu.c). */
float obs__radius_px(const obs__frame *f, const float p[3], float r);

/* Both passes over the whole plane, horizontal then vertical, in place in
 * `ao`; `tmp` holds width * height floats. */
void obs__blur(const obs__frame *f, const float *pos, float *ao, float *tmp);

#endif
