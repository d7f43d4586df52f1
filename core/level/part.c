/* The machinery of a part file, shared by the bake's parts (bake/shard.c)
 * and the dynamic-object bake's (dynamic/dyn_shard.c): the split of a
 * count into shards, FNV-1a 64 and the level's fingerprints, the write
 * under PATH.tmp and its rename, the header's magic and the payload's
 * checksum, the parts of one split put in order.  Each bake keeps its own
 * layout (its header's fields and payload) beside its step. */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "internal.h"
#include "level/decor.h"
#include "level/part.h"

#define FNV_OFFSET OBS__BAKE_FNV_OFFSET
#define FNV_PRIME 0x100000001b3ULL

size_t obs__bake_shard_first(size_t total, int index, int count)
{
    /* total * index / count without overflow for any size_t total */
    return total / (size_t)count * (size_t)index + total % (size_t)count * (size_t)index / (size_t)count;
}

obs_status obs__shard_check(int index, int count, const char *path, char err[OBS_ERR_LEN])
{
    if (count < 1 || index < 0 || index >= count)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "shard %d/%d: the index is 0 .. count-1 "
                         "(count at least 1)", index, count);
    if (!path || !*path)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "shard %d/%d: no part file to write", index,
                         count);
    return OBS_OK;
}

obs_status obs__part_check_level(const char *path, uint64_t part_level, uint64_t level,
                                 char err[OBS_ERR_LEN])
{
    if (part_level != level)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%s was traced from another level (or "
                         "another version of it, or with other decorators): fingerprint %016llx, "
                         "this level's %016llx",
                         path, (unsigned long long)part_level, (unsigned long long)level);
    return OBS_OK;
}

/* ---- little-endian fields and the hash (shard.h) ----------------------- */

uint64_t obs__bake_fnv(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++)
        h = (h ^ p[i]) * FNV_PRIME;
    return h;
}

static uint64_t fnv32(uint64_t h, uint32_t v)
{
    unsigned char b[4];
    obs__le_put32(b, v);
    return obs__bake_fnv(h, b, 4);
}

uint64_t obs__bake_level_fingerprint(const obs__bake_world *w)
{
    uint64_t h = obs__bake_fnv(FNV_OFFSET, (const unsigned char *)"obscura level 1", 15);
    h = fnv32(fnv32(h, (uint32_t)w->vertex_count), (uint32_t)w->triangle_count);
    for (size_t i = 0; i < 3 * w->vertex_count; i++)
        h = fnv32(h, obs__le_fbits(w->pos[i]));
    for (size_t i = 0; i < 3 * w->triangle_count; i++)
        h = fnv32(h, w->tri[i]);
    return obs__bake_fnv(h, w->two_sided, w->triangle_count);
}

/* The level's fingerprint with its decorators folded in (section 2.2,
 * decor.c, occl.c; shard.h). */
uint64_t obs__bake_traced_fingerprint(const obs__bake_world *w, const obs__bake_decor *d,
                                      float tree_attenuation)
{
    uint64_t h = obs__bake_level_fingerprint(w);
    if (!d || d->counts[OBS__DECOR_NONE] == d->node_count)
        return h;
    h = obs__bake_fnv(h, (const unsigned char *)"decorators 1", 12);
    for (size_t i = 0; i < w->instance_count; i++) {
        uint32_t n = w->inst[i].node;
        h = fnv32(h, n < d->node_count ? d->node_class[n] : 0);
        h = fnv32(h, n < d->node_count ? obs__le_fbits(d->density[n]) : 0);
    }
    return fnv32(h, obs__le_fbits(tree_attenuation));
}

/* ---- writing and reading a part ----------------------------------------- */

/* Writes head then payload to path.tmp and renames it to path. */
static obs_status write_file(const char *path, const unsigned char *head, size_t head_len,
                             const unsigned char *payload, size_t payload_len, char err[OBS_ERR_LEN])
{
    size_t len = strlen(path);
    char *tmp = malloc(len + 5);
    if (!tmp)
        return obs__fail(err, OBS_NO_MEMORY, "%s: the file name", path);
    memcpy(tmp, path, len);
    memcpy(tmp + len, ".tmp", 5);
    FILE *f = fopen(tmp, "wb");
    int ok = f && fwrite(head, 1, head_len, f) == head_len &&
             (payload_len == 0 || fwrite(payload, 1, payload_len, f) == payload_len);
    int e = errno;
    if (f && fclose(f) != 0 && ok)
        ok = 0, e = errno;
    if (ok && rename(tmp, path) != 0)
        ok = 0, e = errno;
    if (!ok)
        remove(tmp);
    free(tmp);
    return ok ? OBS_OK : obs__fail(err, OBS_IO, "%s: cannot write the part: %s", path, strerror(e));
}

/* Reads a part's first f->head_len bytes and checks its 8-byte magic and
 * that the header is whole; *size is the file's size (UINT64_MAX when
 * unknown). */
static obs_status read_head(const char *path, const obs__part_format *fm, unsigned char *head,
                            uint64_t *size, char err[OBS_ERR_LEN])
{
    size_t head_len = fm->head_len;
    *size = UINT64_MAX;
    FILE *f = fopen(path, "rb");
    if (!f)
        return obs__fail(err, OBS_IO, "%s: cannot open the part: %s", path, strerror(errno));
    size_t got = fread(head, 1, head_len, f);
    struct stat sb;
    int have_size = fstat(fileno(f), &sb) == 0;
    fclose(f);
    *size = have_size ? (uint64_t)sb.st_size : UINT64_MAX;
    if (got >= 8 && memcmp(head, fm->magic, 8) != 0)
        return obs__fail(err, OBS_BAD_FILE, "%s: not a %s (no '%.8s' magic; '%s' writes "
                         "them)", path, fm->what, fm->magic, fm->writer);
    if (got < head_len)
        return obs__fail(err, OBS_BAD_FILE, "%s: truncated: %zu bytes, shorter than a part's "
                         "header (%zu)", path, got, head_len);
    return OBS_OK;
}

obs_status obs__bake_part_payload(const char *path, size_t offset, size_t len, uint64_t checksum,
                                  unsigned char **out, char err[OBS_ERR_LEN])
{
    *out = NULL;
    unsigned char *p = malloc(len + 1);
    if (!p)
        return obs__fail(err, OBS_NO_MEMORY, "%s: a payload of %zu bytes", path, len);
    FILE *f = fopen(path, "rb");
    int ok = f && fseek(f, (long)offset, SEEK_SET) == 0 && fread(p, 1, len, f) == len;
    if (f)
        fclose(f);
    if (!ok) {
        free(p);
        return obs__fail(err, OBS_IO, "%s: cannot read its payload (%zu bytes)", path, len);
    }
    if (obs__bake_fnv(OBS__BAKE_FNV_OFFSET, p, len) != checksum) {
        free(p);
        return obs__fail(err, OBS_BAD_FILE, "%s: damaged: its payload does not match the header's "
                         "checksum", path);
    }
    *out = p;
    return OBS_OK;
}

/* ---- the parts of one split ----------------------------------------------- */

/* A part's shard index and its position among the parts given, sorted by
 * index then position. */
typedef struct shard_at {
    uint32_t index;
    size_t pos;
} shard_at;

static int shard_at_cmp(const void *a, const void *b)
{
    const shard_at *x = a, *y = b;
    if (x->index != y->index)
        return x->index < y->index ? -1 : 1;
    return (x->pos > y->pos) - (x->pos < y->pos);
}

obs_status obs__bake_parts_order(const obs__bake_part_key *in, size_t n, size_t *order,
                                 char err[OBS_ERR_LEN])
{
    uint32_t count = in[0].count;
    if (n > count)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "%zu parts given for a split into %u shards "
                         "(%s): one is given twice, or belongs to another split", n, count,
                         in[0].path);
    for (size_t i = 1; i < n; i++) {
        if (in[i].count != count)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "%s is shard %u/%u, %s shard %u/%u: "
                             "parts of different splits", in[0].path, in[0].index, count,
                             in[i].path, in[i].index, in[i].count);
        if (in[i].level != in[0].level)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "%s and %s were traced from different "
                             "levels (fingerprints %016llx and %016llx)", in[0].path, in[i].path,
                             (unsigned long long)in[0].level, (unsigned long long)in[i].level);
    }
    /* the n parts sorted by index: a shard given twice is two neighbours,
     * the missing ones the gaps (n entries, whatever count a damaged
     * header claims) */
    shard_at *by = malloc(n * sizeof *by);
    if (!by)
        return obs__fail(err, OBS_NO_MEMORY, "%zu parts", n);
    for (size_t i = 0; i < n; i++)
        by[i] = (shard_at){in[i].index, i};
    qsort(by, n, sizeof *by, shard_at_cmp);
    obs_status rc = OBS_OK;
    for (size_t k = 1; rc == OBS_OK && k < n; k++)
        if (by[k].index == by[k - 1].index)
            rc = obs__fail(err, OBS_INVALID_ARGUMENT, "shard %u/%u given twice: %s and %s",
                           by[k].index, count, in[by[k - 1].pos].path, in[by[k].pos].path);
    if (rc == OBS_OK && n < count) {
        char list[256] = "";
        size_t len = 0, shown = 0, missing = (size_t)count - n;
        uint32_t next = 0; /* the first index not yet looked at */
        for (size_t k = 0; k <= n && len + 16 < sizeof list; k++) {
            uint32_t upto = k < n ? by[k].index : count;
            for (; next < upto && len + 16 < sizeof list; next++, shown++)
                len += (size_t)snprintf(list + len, sizeof list - len, "%s%u", shown ? ", " : "",
                                        next);
            next = upto + (k < n);
        }
        rc = obs__fail(err, OBS_INVALID_ARGUMENT, "%zu of %u shards missing (%s%s): a merge needs "
                       "every shard of the split once", missing, count, list,
                       shown < missing ? ", ..." : "");
    }
    for (size_t k = 0; rc == OBS_OK && k < n; k++)
        order[by[k].index] = by[k].pos;
    free(by);
    return rc;
}

/* ---- the range every header starts with --------------------------------- */

obs__part_range obs__part_range_of(uint32_t version, uint64_t level, int index, int count,
                                   size_t total)
{
    size_t first = obs__bake_shard_first(total, index, count);
    return (obs__part_range){.version = version, .index = (uint32_t)index, .count = (uint32_t)count,
                             .level = level, .total = total, .first = first,
                             .n = obs__bake_shard_first(total, index + 1, count) - first};
}

/* Zeroes the head_len bytes of b and writes magic, head_len and r. */
static void range_put(unsigned char *b, size_t head_len, const char *magic, const obs__part_range *r)
{
    memset(b, 0, head_len);
    memcpy(b, magic, 8);
    obs__le_put32(b + 8, r->version);
    obs__le_put32(b + 12, (uint32_t)head_len);
    obs__le_put64(b + 16, r->level);
    obs__le_put32(b + 24, r->index);
    obs__le_put32(b + 28, r->count);
    obs__le_put64(b + 32, r->total);
    obs__le_put64(b + 40, r->first);
    obs__le_put64(b + 48, r->n);
}

/* Reads the part's header into b (head_len bytes) and its range into r,
 * with obs__part_header_read's checks. */
static obs_status range_read(const char *path, const obs__part_format *f, unsigned char *b,
                             obs__part_range *r, char err[OBS_ERR_LEN])
{
    uint64_t size;
    r->path = path;
    obs_status rc = read_head(path, f, b, &size, err);
    if (rc != OBS_OK)
        return rc;
    r->version = obs__le_get32(b + 8);
    if (r->version != f->version || obs__le_get32(b + 12) != f->head_len)
        return obs__fail(err, OBS_UNSUPPORTED, "%s: %s version %u (header %u bytes); this "
                         "obscura reads version %u", path, f->kind, r->version,
                         obs__le_get32(b + 12), f->version);
    r->level = obs__le_get64(b + 16);
    r->index = obs__le_get32(b + 24);
    r->count = obs__le_get32(b + 28);
    r->total = obs__le_get64(b + 32);
    r->first = obs__le_get64(b + 40);
    r->n = obs__le_get64(b + 48);
    if (r->count == 0 || r->index >= r->count || r->count > (uint32_t)INT32_MAX ||
        r->total > f->max_total ||
        r->first != obs__bake_shard_first((size_t)r->total, (int)r->index, (int)r->count) ||
        r->first + r->n != obs__bake_shard_first((size_t)r->total, (int)r->index + 1, (int)r->count))
        return obs__fail(err, OBS_BAD_FILE, "%s: damaged header: shard %u/%u of %llu %s "
                         "cannot hold %s %llu .. %llu", path, r->index, r->count,
                         (unsigned long long)r->total, f->items, f->items,
                         (unsigned long long)r->first, (unsigned long long)(r->first + r->n));
    uint64_t want = f->head_len + f->item_bytes * r->n;
    if (size != UINT64_MAX && size != want)
        return obs__fail(err, OBS_BAD_FILE, "%s: %s: %llu bytes, its header promises %llu (%llu "
                         "%s)", path, size < want ? "truncated" : "longer than a part",
                         (unsigned long long)size, (unsigned long long)want,
                         (unsigned long long)r->n, f->items);
    return OBS_OK;
}

/* ---- the fields after the range, and the merge's parameters ------------- */

/* The field's member in part, as a double (exact for every type but
 * the 64-bit integers, which are no parameters). */
static double member_value(const void *part, const obs__part_field *fd)
{
    const unsigned char *m = (const unsigned char *)part + fd->member;
    uint32_t u32;
    int32_t i32;
    float f32;
    uint64_t u64;
    double f64;
    switch (fd->type) {
    case OBS__PART_U32: memcpy(&u32, m, 4); return u32;
    case OBS__PART_I32: memcpy(&i32, m, 4); return i32;
    case OBS__PART_F32: memcpy(&f32, m, 4); return f32;
    case OBS__PART_U64: memcpy(&u64, m, 8); return (double)u64;
    default: memcpy(&f64, m, 8); return f64;
    }
}

static size_t type_size(obs__part_type t)
{
    return t == OBS__PART_U64 || t == OBS__PART_F64 ? 8 : 4;
}

/* The header's fields after the range, between the part's members and b. */
static void fields_put(unsigned char *b, const obs__part_format *f, const void *part)
{
    for (size_t i = 0; i < f->field_count; i++) {
        const obs__part_field *fd = &f->fields[i];
        const unsigned char *m = (const unsigned char *)part + fd->member;
        uint32_t u32;
        uint64_t u64;
        if (type_size(fd->type) == 4) {
            memcpy(&u32, m, 4); /* the bits of a float, or the integer */
            obs__le_put32(b + fd->at, u32);
        } else {
            memcpy(&u64, m, 8);
            obs__le_put64(b + fd->at, u64);
        }
    }
}

static void fields_get(const unsigned char *b, const obs__part_format *f, void *part)
{
    for (size_t i = 0; i < f->field_count; i++) {
        const obs__part_field *fd = &f->fields[i];
        unsigned char *m = (unsigned char *)part + fd->member;
        if (type_size(fd->type) == 4) {
            uint32_t u32 = obs__le_get32(b + fd->at);
            memcpy(m, &u32, 4);
        } else {
            uint64_t u64 = obs__le_get64(b + fd->at);
            memcpy(m, &u64, 8);
        }
    }
}

obs_status obs__part_write(const char *path, const obs__part_format *f, const void *part,
                           const unsigned char *payload, size_t payload_len,
                           char err[OBS_ERR_LEN])
{
    unsigned char head[OBS__PART_HEAD_MAX];
    range_put(head, f->head_len, f->magic, part);
    fields_put(head, f, part);
    return write_file(path, head, f->head_len, payload, payload_len, err);
}

obs_status obs__part_header_read(const char *path, const obs__part_format *f, void *part,
                                 char err[OBS_ERR_LEN])
{
    unsigned char b[OBS__PART_HEAD_MAX];
    memset(part, 0, f->part_size);
    obs_status rc = range_read(path, f, b, part, err);
    if (rc == OBS_OK)
        fields_get(b, f, part);
    return rc;
}

obs_status obs__bake_parts_read(const char *const *paths, size_t n, const obs__part_format *f,
                                void **out, char err[OBS_ERR_LEN])
{
    size_t elem = f->part_size;
    *out = NULL;
    if (n == 0 || !paths)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "merge: no parts");
    unsigned char *heads = calloc(n, elem), *ordered = NULL;
    obs__bake_part_key *keys = calloc(n, sizeof *keys);
    size_t *order = NULL;
    obs_status rc = heads && keys ? OBS_OK : obs__fail(err, OBS_NO_MEMORY, "%zu parts", n);
    for (size_t i = 0; rc == OBS_OK && i < n; i++)
        if ((rc = obs__part_header_read(paths[i], f, heads + i * elem, err)) == OBS_OK) {
            const obs__part_range *r = (const void *)(heads + i * elem);
            keys[i] = (obs__bake_part_key){r->path, r->index, r->count, r->level};
        }
    /* n entries: the order checks that the parts are the count shards */
    if (rc == OBS_OK && (!(ordered = calloc(n, elem)) || !(order = calloc(n, sizeof *order))))
        rc = obs__fail(err, OBS_NO_MEMORY, "%zu parts", n);
    if (rc == OBS_OK)
        rc = obs__bake_parts_order(keys, n, order, err);
    for (size_t k = 0; rc == OBS_OK && k < n; k++)
        memcpy(ordered + k * elem, heads + order[k] * elem, elem);
    free(order);
    free(keys);
    free(heads);
    if (rc == OBS_OK)
        *out = ordered;
    else
        free(ordered);
    return rc;
}

/* The merge's value of a parameter row in p, and v into it (the parts'
 * parameters are rows of an int or a float). */
static int int_row(const obs_table_row *row)
{
    return row->type == OBS_TABLE_INT || row->type == OBS_TABLE_WHOLE;
}

static double param_value(const void *p, const obs_table_row *row)
{
    const unsigned char *m = (const unsigned char *)p + row->offset;
    int i;
    float x;
    if (int_row(row)) {
        memcpy(&i, m, sizeof i);
        return i;
    }
    memcpy(&x, m, sizeof x);
    return x;
}

static void param_store(void *p, const obs_table_row *row, double v)
{
    unsigned char *m = (unsigned char *)p + row->offset;
    if (int_row(row)) { /* converted as the row's type only: v is in its range */
        int i = (int)v;
        memcpy(m, &i, sizeof i);
    } else {
        float x = (float)v;
        memcpy(m, &x, sizeof x);
    }
}

obs_status obs__part_adopt(const obs__part_format *f, const void *parts, size_t n, void *p,
                           obs_status (*same)(const void *a, const void *b, char err[OBS_ERR_LEN]),
                           char err[OBS_ERR_LEN])
{
    const unsigned char *a = parts;
    const obs__part_range *ra = parts;
    for (size_t i = 1; i < n; i++) {
        const unsigned char *b = a + i * f->part_size;
        const obs__part_range *rb = (const void *)b;
        for (size_t k = 0; k < f->field_count; k++) {
            const obs__part_field *fd = &f->fields[k];
            if (fd->param && memcmp(a + fd->member, b + fd->member, type_size(fd->type)) != 0)
                return obs__fail(err, OBS_INVALID_ARGUMENT, "%s and %s were traced with different "
                                 "%s (%g and %g): they are not parts of one bake", ra->path,
                                 rb->path, fd->param, member_value(a, fd), member_value(b, fd));
        }
        obs_status rc = same ? same(a, b, err) : OBS_OK;
        if (rc != OBS_OK)
            return rc;
    }
    uint64_t *given = (uint64_t *)(void *)((unsigned char *)p + f->params_given);
    for (size_t k = 0; k < f->field_count; k++) {
        const obs__part_field *fd = &f->fields[k];
        const obs_table_row *row = fd->param ? f->param_find(fd->param) : NULL;
        if (!row)
            continue;
        int bit = (int)(row - f->param_at(0));
        double v = member_value(a, fd);
        /* the header has no checksum: a value its row refuses is damage */
        if (!(v >= row->min && v <= row->max))
            return obs__fail(err, OBS_BAD_FILE, "%s: damaged header: %s %g, outside %g .. %g",
                             ra->path, fd->param, v, row->min, row->max);
        if (*given >> bit & 1) {
            if (param_value(p, row) != v)
                return obs__fail(err, OBS_INVALID_ARGUMENT, "the parts were traced with %s %g; "
                                 "this merge asks for %g (leave it out to take the parts')",
                                 fd->param, v, param_value(p, row));
        } else {
            param_store(p, row, v);
            *given |= (uint64_t)1 << bit;
        }
    }
    return OBS_OK;
}
