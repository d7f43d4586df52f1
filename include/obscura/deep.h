/* Deep (A-buffer) input and multi-layer ambient occlusion.
 *
 * A deep scanline EXR holds, per pixel, a list of samples (fragments):
 * depth Z (and ZBack), alpha A, premultiplied colour R, G, B and, when a
 * renderer wrote them, normals.  obscura reads them into a per-pixel
 * A-buffer, compresses each pixel's list to m nodes (OITAO, Bauer et al.,
 * section III-B, eq 5) and computes multi-layer, opacity-based AO over the
 * compressed layers (OITAO Algorithm 1, eqs 1-4) with VAO++'s volumetric
 * estimator (section 3, depth range check of 4.4) as the per-sample
 * occlusion, or with method hemisphere the normal-oriented hemisphere
 * kernel's point samples, or with methods gtao and hbao their horizon
 * search over every node.  See README.md, "Deep input". */
#ifndef OBSCURA_DEEP_H
#define OBSCURA_DEEP_H

#include <stddef.h>
#include <stdint.h>

#include "obscura/io.h"
#include "obscura/obscura.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The values of one deep sample, in this order. */
enum {
    OBS_DEEP_Z,     /* front depth (planar, as the depth_mode parameter says) */
    OBS_DEEP_ZBACK, /* back depth (= Z when the file has no ZBack) */
    OBS_DEEP_R,     /* colour, premultiplied by alpha as OpenEXR's deep data is */
    OBS_DEEP_G,
    OBS_DEEP_B,
    OBS_DEEP_A,     /* opacity (1 when the file has no A) */
    OBS_DEEP_NX,    /* normal (0 when the file has none) */
    OBS_DEEP_NY,
    OBS_DEEP_NZ,
    OBS_DEEP_FACING, /* +1: a front face (entering a solid along the view
                      * ray: its outward side faces the camera), -1: a back
                      * face (leaving it), 0: not known.  Channel "Facing";
                      * `obscura gbuffer --deep` writes it from the
                      * triangle's winding.  With it the multi-layer chain
                      * takes the solid between a front face and its
                      * matching back face as an interval (deep_intervals) */
    OBS_DEEP_CH     /* floats per sample */
};

/* Most samples one pixel may hold, and in all (each is OBS_DEEP_CH
 * floats); a file asking for more is refused before allocation. */
#define OBS_DEEP_MAX_PER_PIXEL 65536
#define OBS_DEEP_MAX_SAMPLES ((uint64_t)1 << 25)

/* A per-pixel A-buffer.  Pixel i = y * width + x holds the samples
 * offset[i] .. offset[i + 1] - 1, sorted by Z front to back (ties keep the
 * file's order). */
typedef struct obs_deep_image {
    int width, height;                 /* the data window */
    int display_x, display_y;          /* as in obs_gbuffer */
    int display_width, display_height;
    uint64_t *offset;                  /* width * height + 1 entries */
    float *samples;                    /* offset[width * height] samples */
    int has_zback, has_alpha, has_color, has_normal, has_facing;
    obs_camera camera;                 /* from worldToCamera/worldToNDC, if any */
    int part;                          /* the part read */
    /* Object masks (obscura/mask.h, obs_deep_read_masks; NULL: none),
     * owned: the receivers weight of each pixel's front sample, width x
     * height; the occluders weight and the object ID (self_only; compared
     * as the float's bits) of every sample, offset[width * height] each,
     * in the samples' order. */
    float *receivers;
    float *occluders, *object_id;
} obs_deep_image;

/* 1 when the file's first deep part is deep data (scanline or tiled),
 * 0 when it has none; an unreadable file is an error. */
obs_status obs_exr_is_deep(const char *path, int *deep, char err[OBS_ERR_LEN]);
/* The same for an EXR in memory (a request body). */
obs_status obs_exr_is_deep_mem(const void *buf, size_t len, int *deep, char err[OBS_ERR_LEN]);

/* Reads the first deep scanline part of an EXR: a pass over the sample
 * count tables (checked: non-negative, cumulative per scanline, within
 * OBS_DEEP_MAX_* and the chunk's size) before any sample memory is
 * allocated, then the samples.  Channels by name: Z (required), ZBack,
 * A, R, G, B, N.X/N.Y/N.Z (or N.R/N.G/N.B) and Facing.  Caller frees with
 * obs_deep_free(). */
obs_status obs_deep_read_exr(const char *path, const obs_limits *lim, obs_deep_image *out,
                             char err[OBS_ERR_LEN]);
obs_status obs_deep_read_exr_mem(const void *buf, size_t len, const obs_limits *lim,
                                 obs_deep_image *out, char err[OBS_ERR_LEN]);

/* Frees and zeroes; NULL-safe. */
void obs_deep_free(obs_deep_image *d);

/* Writes a deep scanline EXR (ZIPS, float channels): Z always, ZBack, A,
 * R, G, B, N.X/N.Y/N.Z and Facing as d->has_* say (the names obs_deep_read_exr()
 * reads), the camera as worldToCamera/worldToNDC when d->camera has one.
 * Samples are written in their order (front to back).  Through OpenEXR's
 * C++ library (core/io/exr_deep_write.cpp).  Fails with OBS_IO when the
 * file cannot be written. */
obs_status obs_deep_write_exr(const char *path, const obs_deep_image *d, char err[OBS_ERR_LEN]);
/* One more float channel of a deep EXR: its name, and sample k's value
 * at values[k * stride] (offset[width * height] samples). */
typedef struct obs_deep_channel {
    const char *name;
    const float *values;
    int stride;
} obs_deep_channel;

/* obs_deep_write_exr with n more float channels, one value a sample
 * (written as they are, bits and all: a Cryptomatte ID stays its hash),
 * and string attributes in the header (attrs: name, value, ..., NULL;
 * NULL: none): what `obscura gbuffer --deep --ids` writes, the object ID
 * "id" of each sample and a Cryptomatte layer per sample. */
obs_status obs_deep_write_exr_extra(const char *path, const obs_deep_image *d,
                                    const obs_deep_channel *extra, int n,
                                    const char *const *attrs, char err[OBS_ERR_LEN]);

/* The values of the parameters deep_mode and deep_hull, OBS_DEEP_MULTI
 * and so on, are in obscura/params.h with the others. */

/* ---- list compression (OITAO section III-B) ----------------------------- */

/* At most this many nodes per pixel (parameter deep_layers). */
#define OBS_DEEP_MAX_LAYERS 8

/* One node of a compressed list: OBS_DEEP_CH values of a sample; an empty
 * node has Z = 0 and A = 0 (background). */
typedef struct obs_deep_layers {
    int width, height, m;
    float *node;   /* m planes, node k of pixel i at (k * width * height + i) * OBS_DEEP_CH */
    int *count;    /* valid nodes per pixel, front to back from node 0 */
    float zmin, zmax; /* the depth range eq 5's z is normalised over: the
                       * camera's clip range (near, far) */
    /* the object masks of the image's samples (obs_deep_image.occluders,
     * object_id) carried to the nodes they became: m planes of width x
     * height floats each, node k of pixel i at k * width * height + i
     * (an empty node: weight 1, ID 0); NULL where the image has none */
    float *occluders, *object_id;
} obs_deep_layers;

/* Compresses one list (OITAO section III-B): the n samples (OBS_DEEP_CH
 * floats each, in insertion order) are inserted by depth into an array of
 * m nodes; once more than m were inserted the node j minimising
 * a[j].alpha * (1 - a[j].z) (eq 5) is dropped, searched over every node or,
 * with front_half, over the back half only (j >= m / 2).  z is the depth
 * normalised to [0, 1] over zmin..zmax, the camera's clip range (see
 * deep_compress.c).  Writes the
 * kept nodes front to back to out (m * OBS_DEEP_CH floats) and returns
 * their count. */
int obs_deep_compress_list(const float *samples, int n, int m, int front_half, float zmin,
                           float zmax, float *out);

/* Compresses every pixel of a deep image to m nodes (1 <= m <=
 * OBS_DEEP_MAX_LAYERS); m = 0 keeps up to OBS_DEEP_MAX_LAYERS front
 * nodes unchanged when they fit (no eq 5 needed), i.e. the uncompressed
 * reference for lists up to that length.  Eq 5's z is normalised over the
 * clip range (near, far) of d->camera's projection, or without one over
 * the default clip range of parameters near and far.  Caller frees with
 * obs_deep_layers_free(). */
obs_status obs_deep_compress(const obs_deep_image *d, int m, int front_half, obs_deep_layers *out,
                             char err[OBS_ERR_LEN]);
void obs_deep_layers_free(obs_deep_layers *l);

/* ---- multi-layer AO -------------------------------------------------------- */

/* Whether the multi-layer chain reads d's front and back faces as
 * intervals with the resolved parameters p: deep_intervals on, or auto
 * with method gtao; d has facing flags; deep_mode multi. */
int obs_deep_intervals_in_effect(const obs_deep_image *d, const obs_params *p);

/* obs_params_resolve() of `in` as the multi-layer chain runs it on d:
 * with intervals in effect, method gtao's parameters that `in` leaves
 * unset take the rows of OBS_DEEP_GTAO_EXACT (the slice integral as
 * written, converged in steps). */
void obs_deep_params_resolve(const obs_deep_image *d, const obs_params *in, obs_params *out);

typedef struct obs_deep_result {
    obs_image ao_front;  /* 1 channel: AO of the front node of each pixel */
    obs_image ao_blend;  /* 1 channel: per-node AO blended front to back by
                            alpha onto AO 1 (OITAO III, the separated scheme) */
    obs_image composite; /* RGBA: the front-to-back "over" composite of
                            every sample's colour, times ao_blend */
} obs_deep_result;

void obs_deep_result_free(obs_deep_result *r);

/* The result's images as EXR layers, as `obscura ao`, the daemon and its
 * clients write them: with OBS_OUTPUT_AO in `outputs`, AO.Y (ao_blend)
 * and AOFront.Y (ao_front); with OBS_OUTPUT_COMPOSITE, R,G,B,A.  Returns
 * how many (images the result does not hold are left out). */
int obs_deep_result_exr_layers(const obs_deep_result *r, unsigned outputs, obs_exr_layer layers[3]);

/* Multi-layer AO of the deep image on the CPU: compression to the
 * parameters' deep_layers nodes, then OITAO Algorithm 1 with VAO++'s
 * per-sample occlusion (methods vaopp, vao), the hemisphere kernel's
 * (method hemisphere) or the horizon search of methods gtao and hbao
 * (every node at a step's pixel, OITAO's multi-layer HBAO) against every
 * node (or the front one alone with deep_mode single), opacity-weighted
 * (eq 1, or eqs 2-4 with deep_hull thin); with deep_intervals on and
 * facing flags, VAO's line samples take the solid between a front face
 * and its back face as an interval.  Method angle is refused
 * (OBS_INVALID_ARGUMENT, naming the method).  The camera is the image's unless the parameters carry one. */
obs_status obs_deep_run_cpu(const obs_deep_image *d, const obs_params *params,
                            obs_deep_result *out, char err[OBS_ERR_LEN]);

/* obs_deep_run_cpu with the CPU device's options (obscura.h): their
 * deadline (OBS_DEADLINE) and cancel (OBS_CANCELLED), read between rows
 * of the AO, as obs_run_cpu_opts reads them between tiles; log, the
 * memory budget and bands are not used (a deep frame runs whole).  NULL:
 * obs_deep_run_cpu. */
obs_status obs_deep_run_cpu_opts(const obs_deep_image *d, const obs_params *params,
                                 const obs_cpu_options *opt, obs_deep_result *out,
                                 char err[OBS_ERR_LEN]);

/* The same on the GL context: the nodes go to 2D array textures and one
 * fragment pass (core/shaders/deep.frag.glsl) computes the AO; the CPU
 * functions above are its twin. */
obs_status obs_deep_run(obs_ctx *ctx, const obs_deep_image *d, const obs_params *params,
                        obs_deep_result *out, char err[OBS_ERR_LEN]);

/* obs_deep_run that also fills `nodes` with every kept node's AO, as
 * obs_deep_ao_nodes (below, its CPU twin) gives it: the pass stores each
 * node's AO in a layer of an R32F array read back with the planes, so the
 * per-node AO costs no second computation.  Caller frees nodes with
 * obs_deep_ao_free() (cleared on failure). */
typedef struct obs_deep_ao obs_deep_ao;
obs_status obs_deep_run_nodes(obs_ctx *ctx, const obs_deep_image *d, const obs_params *params,
                              obs_deep_result *out, obs_deep_ao *nodes, char err[OBS_ERR_LEN]);

/* ---- deep AO out (obscura ao --output deep) ------------------------------ */

/* The values of one node of a deep AO, in this order. */
enum { OBS_DEEP_AO_Z, OBS_DEEP_AO_ZBACK, OBS_DEEP_AO_A, OBS_DEEP_AO_AO, OBS_DEEP_AO_CH };

/* The AO of every node the list compression kept (OITAO III-B), as a deep
 * image: pixel i holds the nodes offset[i] .. offset[i + 1] - 1 front to
 * back, each OBS_DEEP_AO_CH floats: the node's Z and ZBack as the input
 * has them, its alpha, and its AO (1 = open, not premultiplied).
 * Flattened front to back, sum of T_k A_k AO_k plus the T left (open),
 * it is obs_deep_result's ao_blend before the blur. */
struct obs_deep_ao {
    int width, height;                 /* the input's data window */
    int display_x, display_y, display_width, display_height;
    uint64_t *offset;                  /* width * height + 1 entries */
    float *node;                       /* offset[width * height] nodes */
    obs_camera camera;                 /* the input's */
};

/* The per-node AO of the deep image on the CPU (the twin of obs_deep_run's
 * per-node pass, core/deep/deep_nodes.c), the parameters as
 * obs_deep_run_cpu takes them.  Caller frees with obs_deep_ao_free(). */
obs_status obs_deep_ao_nodes(const obs_deep_image *d, const obs_params *params, obs_deep_ao *out,
                             char err[OBS_ERR_LEN]);
void obs_deep_ao_free(obs_deep_ao *a);

/* The work a deep frame asks for, in samples, for obsd --max-cost and
 * other admission checks: obs_frame_cost's (width x height x the method's
 * samples per pixel x deep_layers^2), plus on the CPU device (cpu 1) with
 * OBS_OUTPUT_DEEP in `outputs` the per-node AO that obs_deep_ao_nodes
 * computes apart from obs_deep_run_cpu: every kept node, min(its pixel's
 * samples, deep_layers), times the method's samples per pixel x
 * deep_layers, the pass's own unit per node.  On GL (cpu 0)
 * obs_deep_run_nodes keeps the nodes' AO from the pass: nothing added.
 * Parameters as obs_deep_run takes them (NULL: defaults); 0 without an
 * image. */
unsigned long long obs_deep_frame_cost(const obs_deep_image *d, const obs_params *params,
                                       unsigned outputs, int cpu);

/* Writes the deep AO as a two-part EXR through OpenEXR's C++ deep API
 * (core/io/exr_deep_ao_write.cpp): part "deep", deep scanline (ZIPS,
 * float), channels A, AO.Y (premultiplied by A, as deep colour is in
 * OpenEXR: Nuke's DeepRead, DeepToImage and oiiotool --flatten give the
 * AO over black with alpha), Z and ZBack; part "flat", scanline (ZIP,
 * float), AO.Y (the flat AO: `flat`, e.g. ao_blend) and AOFront.Y (the
 * front node's, `front`); either image may be NULL.  Both parts carry
 * the windows, the camera as worldToCamera/worldToNDC and
 * obscura/version.  Those compressions are OBS_EXR_ZIP_DEFAULT's (zip);
 * any other names both parts' (zip is ZIPS in the deep part: deep data
 * takes none, rle or zips; piz and dwaa are OBS_UNSUPPORTED). */
obs_status obs_deep_ao_write_exr(const char *path, const obs_deep_ao *a, const obs_image *flat,
                                 const obs_image *front, obs_exr_compression compression, char err[OBS_ERR_LEN]);
/* The same file into memory (obscurad's answer to output=deep); caller
 * frees *out with obs_bytes_free(). */
obs_status obs_deep_ao_write_exr_mem(const obs_deep_ao *a, const obs_image *flat, const obs_image *front,
                                     obs_exr_compression compression, obs_bytes *out, char err[OBS_ERR_LEN]);

#ifdef __cplusplus
}
#endif

#endif
