/* Internal to the EXR reader and writer: channel-map resolution and the
 * capture of OpenEXR's own error messages.  Not installed. */
#ifndef OBSCURA_EXR_INTERNAL_H
#define OBSCURA_EXR_INTERNAL_H

#include <openexr.h>

#include "camera/camera.h"
#include "obscura/io.h"

/* A channel map resolved against one part's channel list: indices into
 * the list, -1 where absent. */
typedef struct obs__channel_match {
    int depth;
    int normal[3];    /* all three or all -1 */
    int color[4];     /* R, G, B all or none; alpha may be -1 alone */
    int position[3];  /* a world-space position pass: all three or all -1 */
    const char *preset; /* "blender", "generic", a renderer's or "explicit" (static) */
    obs_depth_mode depth_mode;     /* the preset's convention; 0: not known */
    obs_normal_space normal_space;
} obs__channel_match;

/* A renderer preset (core/io/presets.c): channel names tried in order
 * (normals and colour as prefixes: P.X/Y/Z or P.R/G/B; "" is the bare
 * R, G, B), its depth and normal conventions, and what in a header names
 * the renderer (attribute-name prefixes; substrings of the software
 * attribute).  Lists end with NULL. */
typedef struct obs__preset {
    const char *name;
    const char *const *depth;
    const char *const *normal;
    const char *const *color;  /* the beauty (--color beauty, the default) */
    const char *const *albedo; /* the diffuse albedo (--color albedo) */
    obs_depth_mode depth_mode;
    obs_normal_space normal_space;
    const char *const *keys;
    const char *const *software;
} obs__preset;

/* The preset named `name`, or NULL (blender and generic are not rows). */
const obs__preset *obs__preset_find(const char *name);
/* Row i of the table, NULL past its end. */
const obs__preset *obs__preset_at(int i);
/* The renderer that wrote part `part` ("blender" or a row's name, static),
 * or NULL; `why` receives what said so. */
const char *obs__preset_detect(exr_const_context_t ctx, int part, char *why, size_t len);

/* obs__channel_map_resolve() with the renderer the header names (NULL:
 * none) tried first when the preset is auto. */
obs_status obs__channel_map_resolve_for(const obs_channel_map *map, const char *detected,
                                        const char *const *names, int count,
                                        obs__channel_match *m, char err[OBS_ERR_LEN]);

/* Resolves `map` (NULL = auto) against the channel names of one part.
 * OBS_OK when the depth was found; OBS_MISSING_CHANNEL when it was not, or
 * when an explicitly named channel is absent (the message names what was
 * looked for and lists `names`, truncated); OBS_INVALID_ARGUMENT for an
 * unknown preset or a partial explicit normal/colour. */
obs_status obs__channel_map_resolve(const obs_channel_map *map,
                                    const char *const *names, int count,
                                    obs__channel_match *m,
                                    char err[OBS_ERR_LEN]);

/* "A, B, C" up to OBS__LIST_CHARS characters, then ", ... (N channels)";
 * `len` should be OBS__LIST_CHARS + 32. */
#define OBS__LIST_CHARS 240
void obs__list_names(const char *const *names, int count, char *buf, size_t len);

/* OpenEXR reports errors through a callback without a user pointer for
 * files it opens itself, so the message is kept per thread: reset before
 * a call, read after a failure.  The handler never prints. */
void obs__exr_msg_reset(void);
const char *obs__exr_msg(void);
void obs__exr_error_handler(exr_const_context_t ctxt, exr_result_t code,
                            const char *msg);

/* The status class of an OpenEXR result code. */
obs_status obs__exr_status(exr_result_t rv);

/* A loop over a part's chunks on the pool (exr_read.c decodes them,
 * exr_write.c encodes them).  Its threads: the caller's count through
 * obs__pool_threads, but no more than one for every 4 chunks, at least
 * one.  Its failure: each thread keeps its own, and the lowest failing
 * chunk's is the part's, whatever the threads' order. */
int obs__exr_chunk_threads(int threads, int64_t chunks);
typedef struct obs__exr_chunk_fail {
    int64_t chunk; /* the failing chunk; INT64_MAX: none yet */
    int code;      /* 0: none; the reader's obs_status, the writer's exr_result_t */
    char msg[OBS_ERR_LEN];
} obs__exr_chunk_fail;
/* At a thread's end, under the pool's lock: its failure into the part's
 * when it is at a lower chunk. */
void obs__exr_chunk_fail_keep(obs__exr_chunk_fail *part, const obs__exr_chunk_fail *thread);

/* Fails with the status of `rv`: "<what>: <library message>". */
obs_status obs__exr_fail(char err[OBS_ERR_LEN], exr_result_t rv,
                         const char *what);

/* Fills the renderer, conventions, camera (into gb->camera) and camera
 * warnings of `info` for part `part` read with match `m` (exr_info.c; the
 * camera from core/camera/exr.c). */
void obs__exr_describe(exr_const_context_t ctx, int part, const obs__channel_match *m,
                       obs_gbuffer *gb, obs_exr_info *info);

/* The string value of part's attribute `name`, or NULL when it has none
 * or another type (exr_parts.c and presets.c; inline, so that presets.c
 * links without the part reader: the binary protocol's fuzzer). */
static inline const char *obs__exr_attr_string(exr_const_context_t ctx, int part, const char *name)
{
    const exr_attribute_t *a = NULL;
    if (exr_get_attribute_by_name(ctx, part, name, &a) != EXR_ERR_SUCCESS || !a ||
        a->type != EXR_ATTR_STRING || !a->string || !a->string->str)
        return NULL;
    return a->string->str;
}

/* The parts a G-buffer is read from (core/io/exr_parts.c). */
typedef struct obs__part_set {
    int *part;    /* indices, in the order they are tried */
    int count;
    int by_view;  /* 1: the parts of one view, channels gathered across them */
    char view[64];
    char why[96];
} obs__part_set;

/* The parts map->part or map->view select (see exr_parts.c); a part or
 * view the file lacks is OBS_INVALID_ARGUMENT naming the file's parts.
 * Free with obs__part_set_free(). */
obs_status obs__exr_select_parts(exr_const_context_t ctx, int parts, const obs_channel_map *map,
                                 obs__part_set *s, char err[OBS_ERR_LEN]);
void obs__part_set_free(obs__part_set *s);

/* A file in memory, read through OpenEXR's custom-stream callbacks. */
typedef struct obs__exr_mem {
    const unsigned char *buf;
    size_t len;
} obs__exr_mem;

/* Opens a file (mem == NULL) or a memory buffer for reading, chunk table
 * reconstruction off (a damaged table is an error); *size receives the
 * byte count when known (else -1).  Shared by exr_read.c and exr_deep.c. */
obs_status obs__exr_open(const char *path, const obs__exr_mem *mem, exr_context_t *ctx,
                         int64_t *size, char err[OBS_ERR_LEN]);
/* What a reader does with an open file: read(ctx, size, user, why), its
 * message in why. */
typedef obs_status (*obs__exr_reader)(exr_context_t ctx, int64_t size, void *user,
                                      char why[OBS_ERR_LEN]);
/* Opens path (or mem, as obs__exr_open), reads it with read and closes it:
 * every public reader's frame; a failure is "label: why" in err. */
obs_status obs__exr_read_with(const char *label, const char *path, const obs__exr_mem *mem,
                              obs__exr_reader read, void *user, char err[OBS_ERR_LEN]);
/* A public reader that fills a struct: out (out_size bytes) checked and
 * zeroed, then obs__exr_read_with, and *out released with release (the
 * struct's free function) when that fails.  exr_read.c's G-buffer and
 * exr_deep.c's deep image. */
obs_status obs__exr_read_out(const char *label, const char *path, const obs__exr_mem *mem,
                             obs__exr_reader read, void *user, void *out, size_t out_size,
                             void (*release)(void *out), char err[OBS_ERR_LEN]);

/* n channels (float32, one image each), all from one part that holds
 * channels[0]: one whose "view" attribute is `view` (NULL or "": none),
 * else part `prefer` (-1: none), else the first; in one pass over its
 * chunks; the file
 * at path or len bytes at mem (path then names it).  out: n images, freed
 * by the caller with obs_image_free (none left on failure).  For the
 * object masks' rank channels (core/mask.c); obs_exr_read_channel is n 1. */
obs_status obs__exr_read_channels(const char *path, const obs__exr_mem *mem, int prefer,
                                  const char *view, const char *const *channels, int n, const obs_limits *lim,
                                  obs_image *out, char err[OBS_ERR_LEN]);

/* The value of `channel` at the front sample (least Z) of each pixel of
 * the first deep part (0 where a pixel has none), float32 (core/io/exr_deep.c:
 * the deep reader's checks, the channel read in the place of R); for
 * object masks on deep input (core/mask.c). */
obs_status obs__deep_read_front(const char *path, const obs__exr_mem *mem, const char *channel,
                                const obs_limits *lim, obs_image *out, char err[OBS_ERR_LEN]);
/* The same for every sample: `channel` of each sample of the first deep
 * part, in the order obs_deep_read_exr() gives the samples (pixel by
 * pixel, front to back), as an image of offset[width * height] x 1 (a
 * file without samples: 1 x 1, its value 0); for the occluders and
 * self_only masks of deep input (core/mask.c). */
obs_status obs__deep_read_samples(const char *path, const obs__exr_mem *mem, const char *channel,
                                  const obs_limits *lim, obs_image *out, char err[OBS_ERR_LEN]);

/* ---- output parts (exr_write.c, exr_append.c, exr_header.c) ------------ */

/* One channel an output part writes: `base` is its value at the data
 * window's first pixel, rows `line_stride` bytes apart. */
typedef struct obs__wchan {
    const char *name;
    exr_pixel_type_t type;       /* in the file */
    exr_perceptual_treatment_t plinear;
    const uint8_t *base;
    int32_t pixel_stride, line_stride;
    exr_pixel_type_t user_type;  /* in memory */
    int32_t user_bytes;
} obs__wchan;

/* One scanline part of an output file. */
typedef struct obs__wpart {
    const char *name;            /* the part's name (multi-part files), or NULL */
    int src_part;                /* the input part whose attributes it carries, -1: none */
    exr_compression_t compression;
    exr_attr_box2i_t dw, disp;
    obs__wchan *ch;
    int nch;
} obs__wpart;

/* Attributes of the storage layout, which the writer sets itself:
 * channels, compression, windows, lineOrder, tiles, chunkCount, type,
 * name, version (exr_header.c). */
int obs__exr_attr_is_layout(const char *name);

/* Copies every attribute of the input part `src_part` into the output
 * part, but the layout's and those named in `skip` (NULL-ended, may be
 * NULL); an attribute the output already has takes the input's value.
 * On failure *failed names the attribute. */
exr_result_t obs__exr_copy_attrs(exr_context_t out, int part, exr_const_context_t src, int src_part,
                                 const char *const *skip, const char **failed);

/* 1 when an attribute of the part has a name or type name longer than 31
 * characters (the output needs the long-name flag). */
int obs__exr_attrs_long_names(exr_const_context_t src, int src_part);

/* The input's flat parts decoded for --append (exr_append.c): every
 * channel in its own pixel type, one obs__wpart per part of the input,
 * then `layers` (float, written as `type`) added to part `src_part`.
 * Refuses deep and subsampled parts and a layer channel named like an
 * input channel of its part.  *bufs holds the pixels; the caller frees
 * every parts[i].ch, *parts and *bufs with obs__exr_append_free(). */
obs_status obs__exr_append_parts(exr_const_context_t src, int64_t file_size, int src_part,
                                 const obs_exr_layer *layers, int layer_count, exr_pixel_type_t type,
                                 obs__wpart **parts, int *nparts, void **bufs, char err[OBS_ERR_LEN]);
void obs__exr_append_free(obs__wpart *parts, int nparts, void *bufs);

/* check_part() of exr_read.c: the part's storage, compression, sampling,
 * windows (against `lim`) and chunk table checked; its data window. */
obs_status obs__exr_check_part(exr_const_context_t ctx, int part, int64_t file_size, const obs_limits *lim,
                               exr_attr_box2i_t *dw, char err[OBS_ERR_LEN]);

#endif
