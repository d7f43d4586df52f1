/* The LODs a .glb brings itself (glTF's vendor extension MSFT_lod on
 * nodes: "ids", the nodes of the lower levels, high to low detail), read
 * for the bake's lod stage (lod.c, paper 2.2.1).  assimp 5.2 does not
 * expose MSFT_lod (its importer walks the scene's graph only, and the LOD
 * nodes are outside it), so the JSON chunk is read here with cJSON and
 * the LOD primitives' POSITION, NORMAL and indices from the binary chunk,
 * every offset and size checked first.  The file's nodes are matched with
 * the loaded ones as assimp's importer builds them (the scene's graph
 * depth first, children in order; names checked), and a node's k-th
 * triangle primitive is its k-th loaded mesh (assimp loads meshes as the
 * nodes refer to them, so the file's mesh order cannot be used).  A LOD
 * node must have its node's transform (no LOD moved against its node)
 * and as many primitives as its node's mesh; a mesh instanced by several
 * nodes must get the same LOD from each. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/lod.h"
#include "internal.h"

#define GLB_MAGIC 0x46546C67u
#define CHUNK_JSON 0x4E4F534Au
#define CHUNK_BIN 0x004E4942u

typedef struct file {
    const char *path;
    unsigned char *data;
    size_t size;
    cJSON *doc;
    const unsigned char *bin;
    size_t bin_len;
} file;

static uint32_t u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static int uses_lod(const cJSON *doc)
{
    const cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(doc, "extensionsUsed"))
    if (cJSON_IsString(e) && !strcmp(e->valuestring, "MSFT_lod"))
        return 1;
    return 0;
}

/* 0: not a .glb, or one without MSFT_lod (nothing to read; only its JSON
 * chunk was read); 1: read; -1: error (err set). */
static int file_open(const char *path, file *f, char err[OBS_ERR_LEN])
{
    memset(f, 0, sizeof *f);
    f->path = path;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return obs__fail(err, OBS_IO, "%s: cannot open: %s", path, strerror(errno)), -1;
    unsigned char head[20];
    if (fread(head, 1, 20, fp) != 20 || u32(head) != GLB_MAGIC) {
        fclose(fp);
        return 0;
    }
    uint32_t total = u32(head + 8), jlen = u32(head + 12);
    if (total < 20 || u32(head + 16) != CHUNK_JSON || jlen > total - 20 ||
        !(f->data = malloc(total))) {
        fclose(fp);
        return obs__fail(err, OBS_BAD_FILE, "%s: glTF binary of %u bytes without its JSON chunk",
                         path, total), -1;
    }
    memcpy(f->data, head, 20);
    size_t got = fread(f->data + 20, 1, jlen, fp);
    if (got == jlen && !(f->doc = cJSON_ParseWithLength((const char *)f->data + 20, jlen))) {
        fclose(fp);
        return obs__fail(err, OBS_BAD_FILE, "%s: the JSON chunk does not parse", path), -1;
    }
    if (got == jlen && !uses_lod(f->doc)) {
        fclose(fp);
        return 0;
    }
    got += fread(f->data + 20 + got, 1, total - 20 - got, fp);
    fclose(fp);
    if (got != total - 20)
        return obs__fail(err, OBS_BAD_FILE, "%s: truncated: %zu of %u bytes", path, got + 20,
                         total), -1;
    f->size = total;
    size_t at = 20 + (size_t)jlen;
    if (at + 8 <= total && u32(f->data + at + 4) == CHUNK_BIN) {
        uint32_t blen = u32(f->data + at);
        if (blen > total - at - 8)
            return obs__fail(err, OBS_BAD_FILE, "%s: binary chunk beyond the file", path), -1;
        f->bin = f->data + at + 8;
        f->bin_len = blen;
    }
    return 1;
}

static void file_close(file *f)
{
    cJSON_Delete(f->doc);
    free(f->data);
    memset(f, 0, sizeof *f);
}

static long num(const cJSON *o, const char *name, long def)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, name);
    return cJSON_IsNumber(v) && v->valuedouble >= 0 && v->valuedouble < 4294967296.0
               ? (long)v->valuedouble
               : def;
}

static const cJSON *at(const cJSON *doc, const char *array, long i)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(doc, array);
    return i >= 0 && cJSON_IsArray(a) ? cJSON_GetArrayItem(a, (int)i) : NULL;
}

/* Accessor i's elements: count, the byte address of each and its
 * stride, the component type; checked against its view and the chunk. */
typedef struct acc {
    const unsigned char *p;
    size_t count, stride;
    long ctype;
} acc;

static obs_status accessor(const file *f, long i, const char *type, acc *a, const char *what,
                           char err[OBS_ERR_LEN])
{
    const cJSON *ac = at(f->doc, "accessors", i);
    const cJSON *t = ac ? cJSON_GetObjectItemCaseSensitive(ac, "type") : NULL;
    if (!ac || !cJSON_IsString(t) || strcmp(t->valuestring, type))
        return obs__fail(err, OBS_BAD_FILE, "%s: MSFT_lod level: %s accessor %ld is not a %s",
                         f->path, what, i, type);
    const cJSON *v = at(f->doc, "bufferViews", num(ac, "bufferView", -1));
    if (!v || num(v, "buffer", -1) != 0 || !f->bin || cJSON_GetObjectItem(ac, "sparse"))
        return obs__fail(err, OBS_BAD_FILE,
                         "%s: MSFT_lod level: %s accessor %ld not in the binary chunk", f->path,
                         what, i);
    a->ctype = num(ac, "componentType", 0);
    size_t comps = !strcmp(type, "VEC3") ? 3 : 1;
    size_t csize = a->ctype == 5126 || a->ctype == 5125 ? 4 : a->ctype == 5123 ? 2
                   : a->ctype == 5121                   ? 1
                                                        : 0;
    a->count = (size_t)num(ac, "count", 0);
    size_t voff = (size_t)num(v, "byteOffset", 0), vlen = (size_t)num(v, "byteLength", 0);
    size_t aoff = (size_t)num(ac, "byteOffset", 0), elem = comps * csize;
    a->stride = (size_t)num(v, "byteStride", 0);
    if (!a->stride)
        a->stride = elem;
    int bad = !csize || a->stride < elem || voff > f->bin_len || vlen > f->bin_len - voff;
    /* the last element ends inside the view: aoff + (count - 1) stride + elem <= vlen */
    if (!bad && a->count)
        bad = aoff > vlen || elem > vlen - aoff || (a->count - 1) > (vlen - aoff - elem) / a->stride;
    if (bad)
        return obs__fail(err, OBS_BAD_FILE,
                         "%s: MSFT_lod level: %s accessor %ld (%zu elements) beyond its view",
                         f->path, what, i, a->count);
    a->p = f->bin + voff + aoff;
    return OBS_OK;
}

static float getf(const acc *a, size_t i, int k)
{
    float x;
    memcpy(&x, a->p + i * a->stride + 4 * (size_t)k, 4);
    return x;
}

static uint32_t geti(const acc *a, size_t i)
{
    const unsigned char *q = a->p + i * a->stride;
    if (a->ctype == 5121)
        return q[0];
    if (a->ctype == 5123)
        return (uint32_t)q[0] | (uint32_t)q[1] << 8;
    return u32(q);
}

/* Primitive prim of a LOD node's mesh as one mesh of the bake. */
static obs_status read_prim(const file *f, const cJSON *prim, const obs_bake_mesh *full, int level,
                            obs_bake_mesh *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    const cJSON *attr = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    acc pos, nrm = {0}, idx = {0};
    obs_status rc = accessor(f, num(attr, "POSITION", -1), "VEC3", &pos, "POSITION", err);
    if (rc == OBS_OK && pos.ctype != 5126)
        rc = obs__fail(err, OBS_BAD_FILE, "%s: MSFT_lod level: POSITION not float", f->path);
    int has_n = cJSON_GetObjectItem(attr, "NORMAL") != NULL;
    if (rc == OBS_OK && has_n &&
        (rc = accessor(f, num(attr, "NORMAL", -1), "VEC3", &nrm, "NORMAL", err)) == OBS_OK &&
        (nrm.ctype != 5126 || nrm.count != pos.count))
        rc = obs__fail(err, OBS_BAD_FILE, "%s: MSFT_lod level: NORMAL not float per vertex",
                       f->path);
    int has_i = cJSON_GetObjectItem(prim, "indices") != NULL;
    if (rc == OBS_OK && has_i &&
        (rc = accessor(f, num(prim, "indices", -1), "SCALAR", &idx, "indices", err)) == OBS_OK &&
        idx.ctype == 5126)
        rc = obs__fail(err, OBS_BAD_FILE, "%s: MSFT_lod level: float indices", f->path);
    if (rc != OBS_OK)
        return rc;
    size_t ni = has_i ? idx.count : pos.count;
    if (ni % 3 || pos.count > UINT32_MAX)
        return obs__fail(err, OBS_BAD_FILE, "%s: MSFT_lod level: %zu indices, not triangles",
                         f->path, ni);
    size_t len = strlen(full->name ? full->name : "") + 16;
    out->name = malloc(len);
    out->positions = malloc(3 * (pos.count ? pos.count : 1) * sizeof(float));
    out->indices = malloc((ni ? ni : 1) * sizeof(uint32_t));
    if (has_n)
        out->normals = malloc(3 * (pos.count ? pos.count : 1) * sizeof(float));
    if (!out->name || !out->positions || !out->indices || (has_n && !out->normals)) {
        obs__bake_mesh_free(out);
        return obs__fail(err, OBS_NO_MEMORY, "%s: MSFT_lod level of %zu vertices", f->path,
                         pos.count);
    }
    snprintf(out->name, len, "%s_LOD%d", full->name ? full->name : "", level);
    for (size_t v = 0; v < pos.count; v++)
        for (int k = 0; k < 3; k++) {
            out->positions[3 * v + k] = getf(&pos, v, k);
            if (has_n)
                out->normals[3 * v + k] = getf(&nrm, v, k);
        }
    for (size_t i = 0; i < ni; i++) {
        uint32_t x = has_i ? geti(&idx, i) : (uint32_t)i;
        if (x >= pos.count) {
            obs__bake_mesh_free(out);
            return obs__fail(err, OBS_BAD_FILE, "%s: MSFT_lod level: index %u of %zu vertices",
                             f->path, x, pos.count);
        }
        out->indices[i] = x;
    }
    for (size_t v = 0; v < 3 * pos.count; v++)
        if (!isfinite(out->positions[v])) {
            obs__bake_mesh_free(out);
            return obs__fail(err, OBS_BAD_FILE, "%s: MSFT_lod level: a position is not finite",
                             f->path);
        }
    out->vertex_count = pos.count;
    out->triangle_count = ni / 3;
    out->material = full->material;
    out->two_sided = full->two_sided;
    return OBS_OK;
}

/* The local transform of a node as glTF text, to compare two nodes':
 * matrix, or translation, rotation, scale (absent: identity). */
static int same_transform(const cJSON *a, const cJSON *b)
{
    static const char *const keys[4] = {"matrix", "translation", "rotation", "scale"};
    for (int k = 0; k < 4; k++) {
        const cJSON *x = cJSON_GetObjectItemCaseSensitive(a, keys[k]);
        const cJSON *y = cJSON_GetObjectItemCaseSensitive(b, keys[k]);
        if ((x == NULL) != (y == NULL) || (x && !cJSON_Compare(x, y, 1)))
            return 0;
    }
    return 1;
}

/* Triangles, strips or fans (assimp triangulates the last two). */
static int is_triangles(const cJSON *prim)
{
    return num(prim, "mode", 4) >= 4;
}

static const cJSON *lod_ids(const cJSON *node)
{
    const cJSON *ids = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(node, "extensions"),
                                         "MSFT_lod"),
        "ids");
    return cJSON_IsArray(ids) ? ids : NULL;
}

/* The file's node of each loaded node: the scene's graph depth first,
 * children in order, as assimp's importer builds it (under a root of its
 * own when the scene has several); -1 for that root.  0 when the two do
 * not line up (count, names, primitives against the node's meshes). */
static int match_nodes(const file *f, const obs_bake_scene *s, long *of)
{
    const cJSON *scenes = cJSON_GetObjectItemCaseSensitive(f->doc, "scenes");
    const cJSON *sc = cJSON_GetArrayItem(scenes, (int)num(f->doc, "scene", 0));
    const cJSON *roots = cJSON_GetObjectItemCaseSensitive(sc, "nodes");
    int nroots = cJSON_IsArray(roots) ? cJSON_GetArraySize(roots) : 0;
    if (nroots == 0)
        return 0;
    size_t count = 0;
    if (nroots > 1)
        of[count++] = -1;
    /* an explicit stack of (node, next child) */
    enum { DEPTH = 4096 };
    long *stack = malloc(2 * DEPTH * sizeof *stack);
    if (!stack)
        return 0;
    int ok = 1;
    for (int r = 0; r < nroots && ok; r++) {
        int sp = 0;
        stack[0] = (long)cJSON_GetNumberValue(cJSON_GetArrayItem(roots, r));
        stack[1] = 0;
        if (count >= s->node_count || !at(f->doc, "nodes", stack[0])) {
            ok = 0;
            break;
        }
        of[count++] = stack[0];
        while (sp >= 0 && ok) {
            const cJSON *ch = cJSON_GetObjectItemCaseSensitive(at(f->doc, "nodes", stack[2 * sp]),
                                                               "children");
            long k = stack[2 * sp + 1]++;
            if (!cJSON_IsArray(ch) || k >= cJSON_GetArraySize(ch)) {
                sp--;
                continue;
            }
            long c = (long)cJSON_GetNumberValue(cJSON_GetArrayItem(ch, (int)k));
            if (sp + 1 >= DEPTH || count >= s->node_count || !at(f->doc, "nodes", c)) {
                ok = 0;
                break;
            }
            of[count++] = c;
            sp++;
            stack[2 * sp] = c;
            stack[2 * sp + 1] = 0;
        }
    }
    free(stack);
    if (!ok || count != s->node_count)
        return 0;
    for (size_t n = 0; n < count; n++) {
        if (of[n] < 0)
            continue;
        const cJSON *jn = at(f->doc, "nodes", of[n]);
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(jn, "name");
        if (cJSON_IsString(name) && *name->valuestring && strcmp(name->valuestring, s->nodes[n].name))
            return 0;
        /* the node's triangle primitives are its meshes, in order */
        const cJSON *prims = cJSON_GetObjectItemCaseSensitive(
            at(f->doc, "meshes", num(jn, "mesh", -1)), "primitives");
        uint32_t tris = 0;
        const cJSON *pr;
        cJSON_ArrayForEach(pr, prims) tris += num(pr, "mode", 4) >= 4;
        if (tris < s->nodes[n].mesh_count)
            return 0;
    }
    return 1;
}

obs_status obs__bake_lod_file_read(const char *path, obs_bake_scene *s, char err[OBS_ERR_LEN])
{
    file f;
    int open = file_open(path, &f, err);
    if (open <= 0) {
        file_close(&f);
        return open == 0 ? OBS_OK : OBS_BAD_FILE;
    }
    obs_status rc = OBS_OK;
    long *of = NULL, *from = NULL; /* from: per (level, mesh), the primitive its LOD came from */
    int levels = 0;
    const cJSON *n;
    cJSON_ArrayForEach(n, cJSON_GetObjectItemCaseSensitive(f.doc, "nodes"))
    {
        const cJSON *ids = lod_ids(n);
        if (ids && cJSON_GetArraySize(ids) > levels)
            levels = cJSON_GetArraySize(ids);
    }
    if (levels == 0)
        goto done;
    if (levels > OBS_BAKE_MAX_LODS)
        levels = OBS_BAKE_MAX_LODS;
    size_t cells = (size_t)levels * s->mesh_count;
    of = malloc((s->node_count ? s->node_count : 1) * sizeof *of);
    from = malloc((cells ? cells : 1) * sizeof *from);
    s->file_lods = calloc(cells + 1, sizeof *s->file_lods);
    if (!of || !from || !s->file_lods) {
        rc = obs__fail(err, OBS_NO_MEMORY, "%s: %d LOD levels", path, levels);
        goto done;
    }
    s->file_lod_levels = (size_t)levels;
    for (size_t c = 0; c < cells; c++)
        from[c] = -1;
    if (!match_nodes(&f, s, of)) {
        rc = obs__fail(err, OBS_BAD_FILE,
                       "%s: MSFT_lod: the file's nodes do not line up with the loaded ones",
                       path);
        goto done;
    }
    for (size_t nd = 0; nd < s->node_count; nd++) {
        const cJSON *jn = of[nd] >= 0 ? at(f.doc, "nodes", of[nd]) : NULL;
        const cJSON *ids = lod_ids(jn);
        if (!ids || !s->nodes[nd].mesh_count)
            continue;
        const cJSON *prims = cJSON_GetObjectItemCaseSensitive(
            at(f.doc, "meshes", num(jn, "mesh", -1)), "primitives");
        for (int l = 1; l <= levels && l <= cJSON_GetArraySize(ids); l++) {
            long li = (long)cJSON_GetNumberValue(cJSON_GetArrayItem(ids, l - 1));
            const cJSON *ln = at(f.doc, "nodes", li);
            long lj = ln ? num(ln, "mesh", -1) : -1;
            const cJSON *lprims =
                cJSON_GetObjectItemCaseSensitive(at(f.doc, "meshes", lj), "primitives");
            if (!cJSON_IsArray(lprims) ||
                cJSON_GetArraySize(lprims) != cJSON_GetArraySize(prims)) {
                rc = obs__fail(err, OBS_BAD_FILE,
                               "%s: node '%s': MSFT_lod level %d (node %ld) has no mesh of %d "
                               "primitives like its node's",
                               path, s->nodes[nd].name, l, li, cJSON_GetArraySize(prims));
                goto done;
            }
            if (!same_transform(jn, ln)) {
                rc = obs__fail(err, OBS_BAD_FILE,
                               "%s: node '%s': MSFT_lod level %d (node %ld) has another "
                               "transform than its node: not supported",
                               path, s->nodes[nd].name, l, li);
                goto done;
            }
            uint32_t k = 0; /* the node's k-th mesh: its k-th triangle primitive */
            for (int pi = 0; pi < cJSON_GetArraySize(prims) && k < s->nodes[nd].mesh_count; pi++) {
                if (!is_triangles(cJSON_GetArrayItem(prims, pi)))
                    continue;
                uint32_t m = s->nodes[nd].meshes[k++];
                const cJSON *lp = cJSON_GetArrayItem(lprims, pi);
                if (!is_triangles(lp))
                    continue;
                size_t c = (size_t)(l - 1) * s->mesh_count + m;
                long key = lj * 65536 + pi;
                if (from[c] == key)
                    continue; /* another instance of the mesh, the same LOD */
                if (from[c] >= 0) {
                    rc = obs__fail(err, OBS_BAD_FILE,
                                   "%s: mesh '%s' has two different MSFT_lod level %d meshes "
                                   "(one per node is not supported)",
                                   path, s->meshes[m].name, l);
                    goto done;
                }
                if ((rc = read_prim(&f, lp, &s->meshes[m], l, &s->file_lods[c], err)) != OBS_OK)
                    goto done;
                from[c] = key;
            }
        }
    }
done:
    if (rc != OBS_OK)
        obs__bake_lod_file_free(s);
    free(of);
    free(from);
    file_close(&f);
    return rc;
}

void obs__bake_lod_file_free(obs_bake_scene *s)
{
    for (size_t c = 0; s->file_lods && c < s->file_lod_levels * s->mesh_count; c++)
        obs__bake_mesh_free(&s->file_lods[c]);
    free(s->file_lods);
    s->file_lods = NULL;
    s->file_lod_levels = 0;
}
