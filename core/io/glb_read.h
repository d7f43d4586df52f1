/* Reading a glTF 2.0 binary (.glb) that obscura bake wrote or a level
 * brings: the binary chunk and accessors, every offset and size checked
 * against the chunk.  Shared by the two readers that assimp cannot serve
 * (it drops custom attributes and MSFT_lod): core/ground/baked.c (a
 * baked level's _AO, _AO_SHORT, _AO_LONG) and core/level/lod_file.c (a
 * file's own LODs).  Each opens the file its own way (the LOD reader
 * stops after the JSON chunk when the file has no MSFT_lod). */
#ifndef OBSCURA_IO_GLB_READ_H
#define OBSCURA_IO_GLB_READ_H

#include <cjson/cJSON.h>
#include <stddef.h>
#include <stdint.h>

#include "obscura/status.h"

#define OBS__GLB_MAGIC 0x46546C67u
#define OBS__GLB_CHUNK_JSON 0x4E4F534Au
#define OBS__GLB_CHUNK_BIN 0x004E4942u
/* accessor component types */
#define OBS__GLB_BYTE_U 5121
#define OBS__GLB_SHORT_U 5123
#define OBS__GLB_UINT 5125
#define OBS__GLB_FLOAT 5126

typedef struct obs__glb {
    const char *path;
    unsigned char *file; /* the whole file (or its head), malloc'd */
    size_t size;
    cJSON *doc;          /* the JSON chunk */
    const unsigned char *bin; /* the binary chunk, NULL when none */
    size_t bin_len;
} obs__glb;

uint32_t obs__glb_u32(const unsigned char *p);
void obs__glb_free(obs__glb *g);
/* The binary chunk after a JSON chunk of jlen bytes, if the file has one:
 * g->bin, g->bin_len; an error when it claims more than the file holds. */
obs_status obs__glb_find_bin(obs__glb *g, size_t jlen, char err[OBS_ERR_LEN]);
/* A non-negative integer member of o, or -1. */
long obs__glb_index_of(const cJSON *o, const char *name);
/* The same of a value (an array's element; NULL: -1). */
long obs__glb_index_value(const cJSON *v);
/* OBS_OK when the glTF document's node graph is a forest (no node the
 * child of two nodes, no scene root a child) and, with max_depth > 0, no
 * node deeper than max_depth levels (nor in a cycle); else OBS_BAD_FILE
 * naming the node (path: the file, for the message). */
obs_status obs__glb_forest(const char *path, const cJSON *doc, int max_depth,
                           char err[OBS_ERR_LEN]);

/* One accessor's elements in the binary chunk. */
typedef struct obs__glb_acc {
    const unsigned char *data;
    size_t count, stride;
    int ctype, comps;
} obs__glb_acc;

/* Accessor idx of g as comps (1: SCALAR, 3: VEC3) components; what names
 * it in messages.  OBS_BAD_FILE for a missing, mistyped or out-of-range
 * one, OBS_UNSUPPORTED for a sparse one or another buffer than the
 * binary chunk. */
obs_status obs__glb_accessor(const obs__glb *g, long idx, int comps, obs__glb_acc *a,
                             const char *what, char err[OBS_ERR_LEN]);
float obs__glb_float(const obs__glb_acc *a, size_t i, int k);
uint32_t obs__glb_index(const obs__glb_acc *a, size_t i); /* an unsigned integer element */

#endif
