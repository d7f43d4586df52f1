/* The pieces of a part file (part.c), shared by the bake's parts
 * (bake/shard.c) and bake-dynamic's (dynamic/dyn_shard.c); each keeps its
 * own layout. */
#ifndef OBSCURA_LEVEL_PART_H
#define OBSCURA_LEVEL_PART_H

#include <stdint.h>
#include <string.h>

#include "level/level.h"

/* Little-endian fields, independent of the host's byte order. */
static inline void obs__le_put32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}
static inline void obs__le_put64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}
static inline uint32_t obs__le_get32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static inline uint64_t obs__le_get64(const unsigned char *p)
{
    return (uint64_t)obs__le_get32(p) | (uint64_t)obs__le_get32(p + 4) << 32;
}
/* The bits of a float or double as an integer, and back. */
static inline uint32_t obs__le_fbits(float f) { uint32_t u; memcpy(&u, &f, 4); return u; }
static inline float obs__le_bitsf(uint32_t u) { float f; memcpy(&f, &u, 4); return f; }
static inline uint64_t obs__le_dbits(double d) { uint64_t u; memcpy(&u, &d, 8); return u; }
static inline double obs__le_bitsd(uint64_t u) { double d; memcpy(&d, &u, 8); return d; }

/* FNV-1a 64: h = obs__bake_fnv(OBS__BAKE_FNV_OFFSET, data, n), chained. */
#define OBS__BAKE_FNV_OFFSET 0xcbf29ce484222325ULL
uint64_t obs__bake_fnv(uint64_t h, const void *data, size_t n);

/* The len bytes at offset, checked against the header's FNV-1a 64;
 * caller frees *out. */
obs_status obs__bake_part_payload(const char *path, size_t offset, size_t len, uint64_t checksum,
                                  unsigned char **out, char err[OBS_ERR_LEN]);

/* What identifies a part among the parts of a split. */
typedef struct obs__bake_part_key {
    const char *path;
    uint32_t index, count;
    uint64_t level; /* the level's fingerprint */
} obs__bake_part_key;
/* Checks that the n parts are every shard of one split of one level,
 * once each (the messages name the parts, the shards missing); fills
 * order[k] with the position in `in` of shard k (n = count entries, on
 * success only: nothing is sized by a header's count). */
obs_status obs__bake_parts_order(const obs__bake_part_key *in, size_t n, size_t *order,
                                 char err[OBS_ERR_LEN]);

/* The fields every part's header starts with (bytes 0 .. 56, each bake's
 * layout in its own file): magic, u32 version, u32 header size, u64 level
 * fingerprint, u32 shard index, u32 shard count, u64 items of the whole
 * level, u64 first item of this part, u64 items of this part; and the
 * part's file, as read (NULL in one being written).  Each bake's part
 * struct starts with one (member r), so that the merge sees every part
 * through it. */
typedef struct obs__part_range {
    uint32_t version, index, count;
    uint64_t level, total, first, n;
    const char *path;
} obs__part_range;
/* Shard index of count over total items, traced from the level with
 * fingerprint level, in a part of the given version. */
obs__part_range obs__part_range_of(uint32_t version, uint64_t level, int index, int count,
                                   size_t total);
/* The type of a header field after the range (little-endian on the
 * file) and of the part struct's member that holds it. */
typedef enum obs__part_type {
    OBS__PART_U32, /* uint32_t */
    OBS__PART_I32, /* int32_t */
    OBS__PART_F32, /* float, its bits */
    OBS__PART_U64, /* uint64_t */
    OBS__PART_F64  /* double, its bits */
} obs__part_type;
/* A field of a part's header after its range: its byte offset, its type,
 * the offset of its member in the part's struct, and for a parameter the
 * name of its row in the bake's parameter table (else NULL): the merge
 * checks those (obs__part_adopt), in the order of the fields. */
typedef struct obs__part_field {
    uint32_t at;
    obs__part_type type;
    size_t member;
    const char *param;
} obs__part_field;
/* What a bake does in place of its trace (bake/shard.c's step,
 * dynamic/dyn_shard.c's): with path, trace shard index of count and
 * write it there (stop is set: the bake ends after the step); with parts
 * (count of them: the bake's part structs, in shard order), read every
 * shard back and go on. */
typedef struct obs__part_job {
    int index, count;
    const char *path;
    const void *parts;
    int stop;
} obs__part_job;

/* The longest header of a part format. */
#define OBS__PART_HEAD_MAX 128u
/* A bake's part file: its magic, the names for the messages (`what` and
 * the command that writes it; `kind` before "version"; `items` its
 * items), its version and header size, the most items a level has, each
 * item's bytes in the payload; its part struct's size (a struct that
 * starts with its obs__part_range) and the header's fields after the
 * range; the bake's parameter table (the rows the fields' `param` name,
 * find and at as obs_bake_param_find and _at) and the offset of its
 * uint64_t mask of the rows given in the parameters' struct. */
typedef struct obs__part_format {
    const char *magic, *what, *writer, *kind, *items;
    uint32_t version;
    size_t head_len;
    uint64_t max_total, item_bytes;
    size_t part_size;
    const obs__part_field *fields;
    size_t field_count;
    const obs_table_row *(*param_find)(const char *name);
    const obs_table_row *(*param_at)(int i);
    size_t params_given;
} obs__part_format;
/* Writes the part (f->part_size bytes) to path as f lays it out: the
 * header (zeroes, the magic, the header size, the range, f's fields),
 * then the payload; under path.tmp, renamed to path, so that a killed
 * writer leaves no part that looks whole. */
obs_status obs__part_write(const char *path, const obs__part_format *f, const void *part,
                           const unsigned char *payload, size_t payload_len,
                           char err[OBS_ERR_LEN]);
/* Zeroes part (f->part_size bytes) and reads the header of the part at
 * path into it, checking the magic (the message names f->what and
 * f->writer) and that the header is whole, the version and header size,
 * the range
 * against the split (obs__bake_shard_first) and the file's length
 * against head_len + item_bytes n. */
obs_status obs__part_header_read(const char *path, const obs__part_format *f, void *part,
                                 char err[OBS_ERR_LEN]);
/* The n parts at paths (none: "merge: no parts"), their headers read
 * (obs__part_header_read) and checked to be every shard of one split
 * once (obs__bake_parts_order); *out the parts in shard order (n of
 * them; caller frees). */
obs_status obs__bake_parts_read(const char *const *paths, size_t n, const obs__part_format *f,
                                void **out, char err[OBS_ERR_LEN]);
/* A merge's parameters p (the bake's parameters struct) from its n parts
 * (shard order), f's parameter fields in order: every part carries part
 * 0's value, bit for bit (then same(a, b, err), when given, holds for
 * part 0 and each other); a parameter given to the merge (its row's bit
 * in p's mask) equals the parts', one not given takes theirs and is
 * marked given; a value outside its row's range is a damaged header
 * (OBS_BAD_FILE: the header has no checksum). */
obs_status obs__part_adopt(const obs__part_format *f, const void *parts, size_t n, void *p,
                           obs_status (*same)(const void *a, const void *b, char err[OBS_ERR_LEN]),
                           char err[OBS_ERR_LEN]);

/* A bake's entry points, written once for both (bake/bake.c with P bake,
 * U BAKE; dynamic/dyn_bake.c with P dyn, U DYN; after their STEPS; the
 * file needs string.h), over its public types obs_P_desc (with
 * `params`), obs_P_params, obs_P_result (with `stats`), obs_P_stats:
 *   obs_P_stage_name(stage): the stage's name in OBS_U_STAGE_LIST (rows
 *   X(name, doc)), "?" out of range;
 *   obs__P_run_job(scene, desc, job, result, err): the result zeroed,
 *   desc's parameters resolved (obs_P_params_resolve), then STEPS(scene,
 *   desc, params, job, result, err), job (NULL: none) in place of the
 *   trace; a failed result freed (obs_P_result_free) but for its stats
 *   (what ran, how long);
 *   RUN(scene, desc, result, err): the public bake, obs__P_run_job
 *   without a job. */
#define OBS__BAKE_ENTRY(P, U, RUN, STEPS)                                                       \
    const char *obs_##P##_stage_name(int stage)                                                 \
    {                                                                                           \
        static const char *const names[] = {OBS_##U##_STAGE_LIST(OBS__STAGE_NAME_ROW)};         \
        return stage >= 0 && stage < OBS_##U##_STAGE_COUNT ? names[stage] : "?";                \
    }                                                                                           \
    obs_status obs__##P##_run_job(const obs_bake_scene *scene, const obs_##P##_desc *desc,     \
                                  obs__part_job *job, obs_##P##_result *out,                    \
                                  char err[OBS_ERR_LEN])                                        \
    {                                                                                           \
        obs_##P##_params p;                                                                     \
        memset(out, 0, sizeof *out);                                                            \
        obs_##P##_params_resolve(desc ? &desc->params : NULL, &p);                              \
        obs_status rc = STEPS(scene, desc, &p, job, out, err);                                  \
        if (rc != OBS_OK) {                                                                     \
            obs_##P##_stats keep = out->stats;                                                  \
            obs_##P##_result_free(out);                                                         \
            out->stats = keep;                                                                  \
        }                                                                                       \
        return rc;                                                                              \
    }                                                                                           \
    obs_status RUN(const obs_bake_scene *scene, const obs_##P##_desc *desc,                    \
                   obs_##P##_result *out, char err[OBS_ERR_LEN])                                \
    {                                                                                           \
        return obs__##P##_run_job(scene, desc, NULL, out, err);                                 \
    }
#define OBS__STAGE_NAME_ROW(name, doc) #name,

/* The public shard and merge of a bake that shards, written once for
 * both (bake/shard_run.c, dynamic/dyn_shard_run.c; the file needs
 * stdlib.h and string.h):
 *   SHARD(scene, desc, index, count, path, stats, err): the arguments
 *   checked (obs__shard_check), then the bake's steps RUN(scene, desc,
 *   job, result, err) (its OBS__BAKE_ENTRY's RUN_JOB) with the job of
 *   tracing shard index of count into path; *stats (when not NULL) the
 *   result's stats, the result freed (RESULT_FREE);
 *   MERGE(scene, desc, paths, n, result, err): the parts read (FORMAT,
 *   obs__bake_parts_read), their parameters taken into a copy of *desc
 *   (obs__part_adopt, with SAME), then RUN with the job of reading them
 *   back; *desc (when not NULL) gets the parameters taken.
 * DESC, RESULT and STATS are the bake's types; DESC has `params`, RESULT
 * `stats`. */
#define OBS__PART_DRIVERS(SHARD, MERGE, DESC, RESULT, STATS, RUN, RESULT_FREE, FORMAT, SAME)  \
    obs_status SHARD(const obs_bake_scene *scene, const DESC *desc, int index, int count,      \
                     const char *path, STATS *st, char err[OBS_ERR_LEN])                       \
    {                                                                                           \
        if (st)                                                                                 \
            memset(st, 0, sizeof *st);                                                          \
        obs_status rc = obs__shard_check(index, count, path, err);                              \
        if (rc != OBS_OK)                                                                       \
            return rc;                                                                          \
        obs__part_job job = {.index = index, .count = count, .path = path};                     \
        RESULT r;                                                                               \
        rc = RUN(scene, desc, &job, &r, err);                                                   \
        if (st)                                                                                 \
            *st = r.stats;                                                                      \
        RESULT_FREE(&r);                                                                        \
        return rc;                                                                              \
    }                                                                                           \
    obs_status MERGE(const obs_bake_scene *scene, DESC *desc, const char *const *paths,        \
                     size_t n, RESULT *out, char err[OBS_ERR_LEN])                              \
    {                                                                                           \
        memset(out, 0, sizeof *out);                                                            \
        void *parts = NULL;                                                                     \
        obs_status rc = obs__bake_parts_read(paths, n, &(FORMAT), &parts, err);                 \
        DESC d = desc ? *desc : (DESC){0};                                                      \
        if (rc == OBS_OK)                                                                       \
            rc = obs__part_adopt(&(FORMAT), parts, n, &d.params, SAME, err);                    \
        if (rc == OBS_OK) {                                                                     \
            obs__part_job job = {.index = 0, .count = (int)n, .parts = parts};                  \
            rc = RUN(scene, &d, &job, out, err);                                                \
            if (desc)                                                                           \
                desc->params = d.params;                                                        \
        }                                                                                       \
        free(parts);                                                                            \
        return rc;                                                                              \
    }

/* A merge's part (at path) traced from this level: its fingerprint
 * part_level is the level's, level (obs__bake_traced_fingerprint). */
obs_status obs__part_check_level(const char *path, uint64_t part_level, uint64_t level,
                                 char err[OBS_ERR_LEN]);
/* A shard's arguments: index in 0 .. count-1, a part file to write. */
obs_status obs__shard_check(int index, int count, const char *path, char err[OBS_ERR_LEN]);
/* The first sample of shard index of count over total samples: shard i
 * traces [first(i), first(i + 1)); first(count) = total. */
size_t obs__bake_shard_first(size_t total, int index, int count);
/* FNV-1a 64 of the flattened level (positions, triangles, sidedness),
 * independent of the host's byte order. */
uint64_t obs__bake_level_fingerprint(const obs__bake_world *w);
/* The same with the decorators folded in (each instance's class, the
 * shrubs' densities, tree_attenuation: they decide the traced values as
 * the geometry does), so that a part traced with other decorators reads
 * as another level; d NULL or without decorators: the level's own.
 * obscura bake's parts and bake-dynamic's carry it. */
struct obs__bake_decor;
uint64_t obs__bake_traced_fingerprint(const obs__bake_world *w, const struct obs__bake_decor *d,
                                      float tree_attenuation);
#endif
