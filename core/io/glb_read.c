/* The .glb chunks and accessors, checked (glb_read.h). */
#include "io/glb_read.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

uint32_t obs__glb_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

void obs__glb_free(obs__glb *g)
{
    cJSON_Delete(g->doc);
    free(g->file);
    memset(g, 0, sizeof *g);
}

obs_status obs__glb_find_bin(obs__glb *g, size_t jlen, char err[OBS_ERR_LEN])
{
    size_t at = 20 + ((jlen + 3) & ~(size_t)3); /* chunks are 4-byte aligned */
    if (at + 8 > g->size || obs__glb_u32(g->file + at + 4) != OBS__GLB_CHUNK_BIN)
        return OBS_OK;
    size_t blen = obs__glb_u32(g->file + at);
    if (blen > g->size - at - 8)
        return obs__fail(err, OBS_BAD_FILE, "%s: binary chunk of %zu bytes beyond the file",
                         g->path, blen);
    g->bin = g->file + at + 8;
    g->bin_len = blen;
    return OBS_OK;
}

static const cJSON *item(const cJSON *o, const char *name)
{
    return cJSON_GetObjectItemCaseSensitive(o, name);
}

/* A non-negative integer member, or -1. */
long obs__glb_index_of(const cJSON *o, const char *name)
{
    return obs__glb_index_value(item(o, name));
}

long obs__glb_index_value(const cJSON *v)
{
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= 0.0) || v->valuedouble > 2147483647.0 ||
        v->valuedouble != floor(v->valuedouble))
        return -1;
    return (long)v->valuedouble;
}

obs_status obs__glb_accessor(const obs__glb *g, long idx, int comps, obs__glb_acc *a,
                             const char *what, char err[OBS_ERR_LEN])
{
    const cJSON *accs = item(g->doc, "accessors"), *views = item(g->doc, "bufferViews");
    const cJSON *ac = cJSON_GetArrayItem(accs, (int)idx);
    if (idx < 0 || !cJSON_IsObject(ac))
        return obs__fail(err, OBS_BAD_FILE, "%s: %s: accessor %ld does not exist", g->path, what,
                         idx);
    const cJSON *type = item(ac, "type");
    static const char *const types[] = {NULL, "SCALAR", NULL, "VEC3"};
    if (!cJSON_IsString(type) || strcmp(type->valuestring, types[comps]) != 0)
        return obs__fail(err, OBS_BAD_FILE, "%s: %s: accessor %ld is not %s", g->path, what, idx,
                         types[comps]);
    if (item(ac, "sparse"))
        return obs__fail(err, OBS_UNSUPPORTED, "%s: %s: sparse accessors are not read", g->path,
                         what);
    long count = obs__glb_index_of(ac, "count"), vi = obs__glb_index_of(ac, "bufferView");
    long ctype = obs__glb_index_of(ac, "componentType");
    const cJSON *view = cJSON_GetArrayItem(views, (int)vi);
    if (count < 0 || vi < 0 || !cJSON_IsObject(view))
        return obs__fail(err, OBS_BAD_FILE, "%s: %s: accessor %ld has no count or bufferView",
                         g->path, what, idx);
    size_t csize = ctype == OBS__GLB_BYTE_U ? 1 : ctype == OBS__GLB_SHORT_U ? 2 : 4;
    if (ctype != OBS__GLB_FLOAT && ctype != OBS__GLB_UINT && ctype != OBS__GLB_SHORT_U && ctype != OBS__GLB_BYTE_U)
        return obs__fail(err, OBS_BAD_FILE, "%s: %s: component type %ld", g->path, what, ctype);
    long buf = obs__glb_index_of(view, "buffer");
    const cJSON *b0 = cJSON_GetArrayItem(item(g->doc, "buffers"), 0);
    if (buf != 0 || item(b0, "uri") || !g->bin)
        return obs__fail(err, OBS_UNSUPPORTED, "%s: %s: only the .glb's own binary chunk is "
                                               "read (buffer 0, no uri)", g->path, what);
    long voff = obs__glb_index_of(view, "byteOffset"), vlen = obs__glb_index_of(view, "byteLength");
    long aoff = obs__glb_index_of(ac, "byteOffset"), vstride = obs__glb_index_of(view, "byteStride");
    if (voff < 0)
        voff = 0;
    if (aoff < 0)
        aoff = 0;
    size_t elem = csize * (size_t)comps, stride = vstride > 0 ? (size_t)vstride : elem;
    if (vlen < 0 || (size_t)voff > g->bin_len || (size_t)vlen > g->bin_len - (size_t)voff ||
        stride < elem)
        return obs__fail(err, OBS_BAD_FILE, "%s: %s: bufferView %ld out of range", g->path, what,
                         vi);
    /* the last element must end inside the view */
    if (count > 0 && ((size_t)aoff > (size_t)vlen || (size_t)vlen - (size_t)aoff < elem ||
                      (size_t)(count - 1) > ((size_t)vlen - (size_t)aoff - elem) / stride))
        return obs__fail(err, OBS_BAD_FILE, "%s: %s: accessor %ld (%ld elements) out of range "
                                            "of its view", g->path, what, idx, count);
    a->data = g->bin + voff + aoff;
    a->count = (size_t)count;
    a->stride = stride;
    a->ctype = (int)ctype;
    a->comps = comps;
    return OBS_OK;
}

float obs__glb_float(const obs__glb_acc *a, size_t i, int k)
{
    float v;
    memcpy(&v, a->data + i * a->stride + 4 * (size_t)k, 4);
    return v;
}

uint32_t obs__glb_index(const obs__glb_acc *a, size_t i)
{
    const unsigned char *p = a->data + i * a->stride;
    if (a->ctype == OBS__GLB_BYTE_U)
        return p[0];
    if (a->ctype == OBS__GLB_SHORT_U)
        return (uint32_t)p[0] | (uint32_t)p[1] << 8;
    return obs__glb_u32(p);
}

/* glTF's node graph a forest, as the specification asks: no node the
 * child of two nodes (or twice of one), no scene root a child.  assimp
 * 5.2's glTF importer copies a node once per path to it (a DAG of 40
 * levels asks for 2^40 nodes) and recurses around a cycle without end,
 * and a walk of the graph (baked.c) would visit every path.  With
 * max_depth > 0 also no node deeper than max_depth levels, walked up from
 * each node with the depths found so far kept (a cycle never ends, so it
 * is refused too).  Child indices out of range are the reader's to
 * refuse. */
obs_status obs__glb_forest(const char *path, const cJSON *doc, int max_depth,
                           char err[OBS_ERR_LEN])
{
    const cJSON *nodes = item(doc, "nodes"), *nd, *c, *sc;
    int n = cJSON_GetArraySize(nodes);
    if (n <= 0)
        return OBS_OK;
    long *parent = malloc(2 * (size_t)n * sizeof *parent), *depth = parent + n;
    if (!parent)
        return obs__fail(err, OBS_NO_MEMORY, "%s: %d nodes", path, n);
    for (int i = 0; i < n; i++)
        parent[i] = depth[i] = -1;
    obs_status st = OBS_OK;
    long i = 0;
    cJSON_ArrayForEach(nd, nodes)
    {
        cJSON_ArrayForEach(c, item(nd, "children"))
        {
            long k = obs__glb_index_value(c);
            if (k < 0 || k >= n)
                continue;
            if (parent[k] >= 0) {
                st = obs__fail(err, OBS_BAD_FILE, "%s: glTF node %ld is the child of more than "
                                                  "one node (the node graph must be a forest)",
                               path, k);
                goto done;
            }
            parent[k] = i;
        }
        i++;
    }
    cJSON_ArrayForEach(sc, item(doc, "scenes"))
    {
        cJSON_ArrayForEach(c, item(sc, "nodes"))
        {
            long k = obs__glb_index_value(c);
            if (k >= 0 && k < n && parent[k] >= 0) {
                st = obs__fail(err, OBS_BAD_FILE, "%s: glTF node %ld is a scene's root and a "
                                                  "child (a cycle?)",
                               path, k);
                goto done;
            }
        }
    }
    for (long k = 0; max_depth > 0 && k < n; k++) {
        long j = k, steps = 0;
        while (j >= 0 && depth[j] < 0 && steps <= max_depth) {
            j = parent[j];
            steps++;
        }
        long d = (j >= 0 ? depth[j] : -1) + steps;
        if (steps > max_depth || d > max_depth) {
            st = obs__fail(err, OBS_BAD_FILE, "%s: glTF node %ld is deeper than %d levels in "
                                              "the node tree (or in a cycle)",
                           path, k, max_depth);
            goto done;
        }
        for (j = k; j >= 0 && depth[j] < 0; j = parent[j])
            depth[j] = d--;
    }
done:
    free(parent);
    return st;
}
