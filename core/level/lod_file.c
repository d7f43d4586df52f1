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
#include <sys/stat.h>

#include "level/level.h"
#include "internal.h"
#include "io/glb_read.h"

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
static int file_open(const char *path, obs__glb *f, char err[OBS_ERR_LEN])
{
    memset(f, 0, sizeof *f);
    f->path = path;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return obs__fail(err, OBS_IO, "%s: cannot open: %s", path, strerror(errno)), -1;
    unsigned char head[20];
    if (fread(head, 1, 20, fp) != 20 || obs__glb_u32(head) != OBS__GLB_MAGIC) {
        fclose(fp);
        return 0;
    }
    uint32_t total = obs__glb_u32(head + 8), jlen = obs__glb_u32(head + 12);
    if (total < 20 || obs__glb_u32(head + 16) != OBS__GLB_CHUNK_JSON || jlen > total - 20) {
        fclose(fp);
        return obs__fail(err, OBS_BAD_FILE, "%s: glTF binary of %u bytes without its JSON chunk",
                         path, total), -1;
    }
    /* the file's length, not the header's, sizes the buffer: a damaged
     * header claiming up to 4 GiB allocates no more than the file */
    struct stat sb;
    size_t have = total;
    if (fstat(fileno(fp), &sb) == 0 && sb.st_size >= 20 && (uint64_t)sb.st_size < total)
        have = (size_t)sb.st_size;
    if (!(f->file = malloc(have))) {
        fclose(fp);
        return obs__fail(err, OBS_NO_MEMORY, "%s: glTF binary of %zu bytes", path, have), -1;
    }
    memcpy(f->file, head, 20);
    size_t got = jlen <= have - 20 ? fread(f->file + 20, 1, jlen, fp) : 0;
    if (got == jlen && !(f->doc = cJSON_ParseWithLength((const char *)f->file + 20, jlen))) {
        fclose(fp);
        return obs__fail(err, OBS_BAD_FILE, "%s: the JSON chunk does not parse", path), -1;
    }
    if (got == jlen && !uses_lod(f->doc)) {
        fclose(fp);
        return 0;
    }
    if (got == jlen)
        got += fread(f->file + 20 + got, 1, have - 20 - got, fp);
    fclose(fp);
    if (got != total - 20)
        return obs__fail(err, OBS_BAD_FILE, "%s: truncated: %zu of %u bytes", path, got + 20,
                         total), -1;
    f->size = total;
    if (obs__glb_find_bin(f, jlen, err) != OBS_OK)
        return -1;
    return 1;
}


/* A non-negative integer member of o, or def. */
static long num(const cJSON *o, const char *name, long def)
{
    long v = obs__glb_index_of(o, name);
    return v < 0 ? def : v;
}

static const cJSON *at(const cJSON *doc, const char *array, long i)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(doc, array);
    return i >= 0 && cJSON_IsArray(a) ? cJSON_GetArrayItem(a, (int)i) : NULL;
}


/* Primitive prim of a LOD node's mesh as one mesh of the bake. */
static obs_status read_prim(const obs__glb *f, const cJSON *prim, const obs_bake_mesh *full, int level,
                            obs_bake_mesh *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    const cJSON *attr = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    obs__glb_acc pos, nrm = {0}, idx = {0};
    obs_status rc = obs__glb_accessor(f, num(attr, "POSITION", -1), 3, &pos,
                                      "MSFT_lod level POSITION", err);
    if (rc == OBS_OK && pos.ctype != OBS__GLB_FLOAT)
        rc = obs__fail(err, OBS_BAD_FILE, "%s: MSFT_lod level: POSITION not float", f->path);
    int has_n = cJSON_GetObjectItem(attr, "NORMAL") != NULL;
    if (rc == OBS_OK && has_n &&
        (rc = obs__glb_accessor(f, num(attr, "NORMAL", -1), 3, &nrm, "MSFT_lod level NORMAL",
                                err)) == OBS_OK &&
        (nrm.ctype != OBS__GLB_FLOAT || nrm.count != pos.count))
        rc = obs__fail(err, OBS_BAD_FILE, "%s: MSFT_lod level: NORMAL not float per vertex",
                       f->path);
    int has_i = cJSON_GetObjectItem(prim, "indices") != NULL;
    if (rc == OBS_OK && has_i &&
        (rc = obs__glb_accessor(f, num(prim, "indices", -1), 1, &idx, "MSFT_lod level indices",
                                err)) == OBS_OK &&
        idx.ctype == OBS__GLB_FLOAT)
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
            out->positions[3 * v + k] = obs__glb_float(&pos, v, k);
            if (has_n)
                out->normals[3 * v + k] = obs__glb_float(&nrm, v, k);
        }
    for (size_t i = 0; i < ni; i++) {
        uint32_t x = has_i ? obs__glb_index(&idx, i) : (uint32_t)i;
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
static int match_nodes(const obs__glb *f, const obs_bake_scene *s, long *of)
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
        stack[0] = obs__glb_index_value(cJSON_GetArrayItem(roots, r));
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
            long c = obs__glb_index_value(cJSON_GetArrayItem(ch, (int)k));
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
    obs__glb f;
    int open = file_open(path, &f, err);
    if (open <= 0) {
        obs__glb_free(&f);
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
            long li = obs__glb_index_value(cJSON_GetArrayItem(ids, l - 1));
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
    obs__glb_free(&f);
    return rc;
}

void obs__bake_mesh_free(obs_bake_mesh *m)
{
    if (!m)
        return;
    free(m->name);
    free(m->positions);
    free(m->normals);
    free(m->indices);
    memset(m, 0, sizeof *m);
}

void obs__bake_lod_file_free(obs_bake_scene *s)
{
    for (size_t c = 0; s->file_lods && c < s->file_lod_levels * s->mesh_count; c++)
        obs__bake_mesh_free(&s->file_lods[c]);
    free(s->file_lods);
    s->file_lods = NULL;
    s->file_lod_levels = 0;
}
