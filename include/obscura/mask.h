/* Object masks: Cryptomatte layers, integer ID channels and coverage
 * mattes read from an EXR, and the per-pixel weight planes the parameters
 * receivers, occluders and self_only ask for (README: "Object masks").
 *
 * Cryptomatte as its specification defines it (Psyop/Cryptomatte,
 * specification/cryptomatte_specification.pdf, v1.2): header attributes
 * cryptomatte/<key>/name, hash (MurmurHash3_32), conversion
 * (uint32_to_float32), manifest (JSON: name -> 8 hex digits) or manif_file
 * (a JSON file beside the image); channels <name>00, <name>01, ... each
 * holding two ranks (R: ID, G: coverage, B: ID, A: coverage; or .red,
 * .green, .blue, .alpha), ranked by coverage.  The matte of a set of IDs
 * at a pixel is the sum of the coverage of the ranks whose ID is in it. */
#ifndef OBSCURA_MASK_H
#define OBSCURA_MASK_H

#include <stddef.h>
#include <stdint.h>

#include "obscura/io.h"

#ifdef __cplusplus
extern "C" {
#endif

#define OBS_CRYPTO_MAX_RANK_SETS 16 /* <name>00 .. <name>15: 32 ranks */

typedef struct obs_crypto_layer {
    char key[16];          /* the attribute key (7 hex digits) */
    char name[128];        /* the layer's name: the channel prefix */
    char hash[32];         /* "MurmurHash3_32" */
    char conversion[32];   /* "uint32_to_float32" */
    char manif_file[512];  /* side-car manifest as the header names it ("": in the header) */
    int rank_sets;         /* <name>NN channel sets found (two ranks each) */
    int red_style;         /* 0: .R/.G/.B/.A; 1: .red/.green/.blue/.alpha; 2: .r/.g/.b/.a */
    int entry_count;       /* names in the manifest */
    char **names;          /* entry_count names, UTF-8 as the manifest has them */
    uint32_t *ids;         /* their IDs (the float's bits) */
    char manifest_error[OBS_ERR_LEN]; /* why no manifest ("": read) */
} obs_crypto_layer;

typedef struct obs_crypto_info {
    int part;                  /* the part described */
    int layer_count;
    obs_crypto_layer *layers;
    int id_count;              /* integer ID channels (id, IndexOB, ...) */
    char **id_channels;
} obs_crypto_info;

/* The Cryptomatte layers and ID channels of the first part holding any
 * (or part 0), of the file at path or of len bytes at buf (path then only
 * names it and locates side-car manifests; NULL with buf: side-car
 * manifests cannot be read).  A manifest that cannot be read is not an
 * error here: the layer's manifest_error says why.  Free with
 * obs_crypto_info_free(). */
obs_status obs_crypto_describe(const char *path, const void *buf, size_t len,
                               obs_crypto_info *out, char err[OBS_ERR_LEN]);
void obs_crypto_info_free(obs_crypto_info *info);

/* MurmurHash3_x86_32 (Austin Appleby, MurmurHash3.cpp, public domain). */
uint32_t obs_murmur3_32(const void *key, size_t len, uint32_t seed);
/* The Cryptomatte ID of a name: MurmurHash3_32 of its UTF-8 bytes, seed 0,
 * with bit 23 flipped when the exponent bits are 0 or 255, so the float
 * with these bits is neither denormal, infinite nor NaN (the
 * specification's uint32_to_float32). */
uint32_t obs_crypto_name_id(const char *name);

/* The weight plane of one selector over the G-buffer's data window, one
 * float in [0, 1] per pixel, width x height (the part's data window).
 * Selector forms (README's table):
 *   NAME[,NAME...]      Cryptomatte entries of any layer; * and ? are
 *                       wildcards, \ escapes ',', '*', '?', '\' and '@';
 *                       "@LAYER:" first restricts them to one layer
 *   id:CHANNEL=LIST     integer IDs of a channel, LIST of N or N-M by ','
 *   matte:CHANNEL       a coverage matte channel, clamped to [0, 1]
 *   !SELECTOR           everything but: 1 - the selector's weight (a name
 *                       that starts with '!' is written "\!")
 * *dominant (NULL: not wanted) receives, per pixel, the object the
 * selector's source says is there: the rank-0 ID's float of the
 * Cryptomatte layer (the first one matched), or the ID channel's value;
 * a matte selector has none (it is left NULL). Free with obs_image_free. */
obs_status obs_mask_plane(const char *path, const void *buf, size_t len, const char *selector,
                          const obs_limits *lim, obs_image *weight, obs_image *dominant,
                          char err[OBS_ERR_LEN]);

/* The planes params' receivers, occluders and self_only ask for (nothing
 * when none is set), built from the file f was read from (path, or len
 * bytes at buf) into f->gb.receivers, occluders and object_id; f keeps
 * their storage.  A selector that matches no pixel is a warning in
 * f->info, not an error. */
obs_status obs_gbuffer_read_masks(obs_gbuffer_file *f, const char *path, const void *buf,
                                  size_t len, const obs_params *params, const obs_limits *lim,
                                  char err[OBS_ERR_LEN]);

/* The same for deep input (d read from path, or len bytes at buf):
 * receivers read at each pixel's front sample, into d->receivers;
 * occluders and self_only's objects read at every sample (the selector's
 * channels per sample), into d->occluders and d->object_id, which the
 * list compression carries to the nodes it keeps.  A selector naming a
 * channel the deep part lacks is OBS_MISSING_CHANNEL, the message naming
 * it. */
obs_status obs_deep_read_masks(struct obs_deep_image *d, const char *path, const void *buf,
                               size_t len, const obs_params *params, const obs_limits *lim,
                               char err[OBS_ERR_LEN]);

#ifdef __cplusplus
}
#endif

#endif
