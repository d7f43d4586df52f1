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

/* Writes head then payload to path.tmp and renames it to path, so that a
 * killed writer leaves no part that looks whole. */
obs_status obs__bake_part_write(const char *path, const unsigned char *head, size_t head_len,
                                const unsigned char *payload, size_t payload_len,
                                char err[OBS_ERR_LEN]);
/* Reads a part's first head_len bytes and checks its 8-byte magic (the
 * message names `what` and the command that writes them) and that the
 * header is whole; *size is the file's size (UINT64_MAX when unknown). */
obs_status obs__bake_part_head(const char *path, const char *magic, const char *what,
                               const char *writer, unsigned char *head, size_t head_len,
                               uint64_t *size, char err[OBS_ERR_LEN]);
/* The len bytes at offset, checked against the header's FNV-1a 64;
 * caller frees *out. */
obs_status obs__bake_part_payload(const char *path, size_t offset, size_t len, uint64_t checksum,
                                  unsigned char **out, char err[OBS_ERR_LEN]);

/* The merges' checks of the parameters parts carry (bake/shard_run.c,
 * dynamic/dyn_shard_run.c), one row of a list X(name, field) each, inside a
 * function with `err` that returns obs_status.  SAME: parts a and b
 * carry the same value, bit for bit.  TAKE: the merge's p->name is part
 * a's unless row `row` of p's table was given (p->set), when the two
 * must agree. */
#define OBS__PART_SAME(a, b, name, field)                                                \
    if (memcmp(&(a)->field, &(b)->field, sizeof(a)->field) != 0)                         \
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s and %s were traced with different " \
                         #name " (%g and %g): they are not parts of one bake", (a)->r.path, \
                         (b)->r.path, (double)(a)->field, (double)(b)->field);
#define OBS__PART_TAKE(p, a, row, name, field)                                           \
    {                                                                                    \
        int row_ = (row);                                                                \
        if (row_ >= 0 && ((p)->set >> row_ & 1)) {                                       \
            if ((p)->name != (a)->field)                                                 \
                return obs__fail(err, OBS_INVALID_ARGUMENT, "the parts were traced with " #name \
                                 " %g; this merge asks for %g (leave it out to take the parts')", \
                                 (double)(a)->field, (double)(p)->name);                 \
        } else {                                                                         \
            (p)->name = (a)->field;                                                      \
            if (row_ >= 0)                                                               \
                (p)->set |= (uint64_t)1 << row_;                                         \
        }                                                                                \
    }

/* What identifies a part among the parts of a split. */
typedef struct obs__bake_part_key {
    const char *path;
    uint32_t index, count;
    uint64_t level; /* the level's fingerprint */
} obs__bake_part_key;
/* Checks that the n parts are every shard of one split of one level,
 * once each (the messages name the parts, the shards missing); fills
 * order[k] with the position in `in` of shard k (count entries). */
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
/* Zeroes the head_len bytes of b and writes magic, head_len and r. */
void obs__part_range_put(unsigned char *b, size_t head_len, const char *magic,
                         const obs__part_range *r);
/* What a reader expects of a part: its magic, the names for the messages
 * (`what` and the command that writes it; `kind` before "version";
 * `items` its items), its version and header size, the most items a level
 * has, each item's bytes in the payload. */
typedef struct obs__part_format {
    const char *magic, *what, *writer, *kind, *items;
    uint32_t version;
    size_t head_len;
    uint64_t max_total, item_bytes;
} obs__part_format;
/* Reads the part's header into b (head_len bytes) and its range into r,
 * checking the magic, version and header size, the range against the
 * split (obs__bake_shard_first) and the file's length against
 * head_len + item_bytes n. */
obs_status obs__part_range_read(const char *path, const obs__part_format *f, unsigned char *b,
                                obs__part_range *r, char err[OBS_ERR_LEN]);
/* The n parts at paths (none: "merge: no parts"), their headers read by
 * read_header into elem-byte structs that start with their
 * obs__part_range, checked to be every shard of one split once
 * (obs__bake_parts_order); *out the headers in shard order (n of them;
 * caller frees). */
obs_status obs__bake_parts_read(const char *const *paths, size_t n, size_t elem,
                                obs_status (*read_header)(const char *path, void *h,
                                                          char err[OBS_ERR_LEN]),
                                void **out, char err[OBS_ERR_LEN]);

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
