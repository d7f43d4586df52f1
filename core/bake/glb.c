/* The baked level as glTF 2.0 binary (.glb), written with cJSON and one
 * binary buffer (assimp's exporter cannot write custom attributes).  The
 * node graph is the loaded one: names, transforms (as matrices), children,
 * extras.  Each node that holds meshes gets a mesh of its own, one
 * primitive per loaded mesh, since the baked values differ between the
 * instances of a shared mesh.  Attributes: POSITION, NORMAL (when every
 * normal of the mesh is usable), _AO, _AO_SHORT, _AO_LONG (and _AO_LOCAL
 * for an instanced decorator, section 2.2; float scalars;
 * custom attributes begin with '_', glTF 2.0 3.7.2.1), COLOR_0 = _AO as
 * grey when asked; indices as unsigned int.  The materials keep their
 * names, base colours, alpha mode BLEND and sidedness, not their
 * textures.  LODs: MSFT_lod levels of the nodes (lod_nodes). */
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "io/out_file.h"
#include "obscura/bake.h"

#define GL_FLOAT 5126
#define GL_UNSIGNED_INT 5125
#define ARRAY_BUFFER 34962
#define ELEMENT_ARRAY_BUFFER 34963

typedef struct bin {
    unsigned char *data;
    size_t len, cap;
    int failed;
} bin;

static size_t bin_add(bin *b, const void *src, size_t n)
{
    size_t at = (b->len + 3) & ~(size_t)3; /* 4-byte alignment of every view */
    if (at + n > b->cap) {
        size_t cap = b->cap ? b->cap : 1 << 16;
        while (cap < at + n)
            cap *= 2;
        unsigned char *d = realloc(b->data, cap);
        if (!d) {
            b->failed = 1;
            return 0;
        }
        b->data = d;
        b->cap = cap;
    }
    memset(b->data + b->len, 0, at - b->len);
    memcpy(b->data + at, src, n);
    b->len = at + n;
    return at;
}

typedef struct out {
    cJSON *root, *views, *accessors;
    bin b;
    int nacc;
} out;

/* A bufferView and its accessor; returns the accessor's index. */
static int accessor(out *o, const void *data, size_t count, int comps, int ctype, int target,
                    const float *mn, const float *mx)
{
    size_t bytes = count * (size_t)comps * 4;
    size_t off = bin_add(&o->b, data, bytes);
    cJSON *v = cJSON_CreateObject();
    cJSON_AddNumberToObject(v, "buffer", 0);
    cJSON_AddNumberToObject(v, "byteOffset", (double)off);
    cJSON_AddNumberToObject(v, "byteLength", (double)bytes);
    cJSON_AddNumberToObject(v, "target", target);
    cJSON_AddItemToArray(o->views, v);
    cJSON *a = cJSON_CreateObject();
    cJSON_AddNumberToObject(a, "bufferView", o->nacc); /* one view per accessor */
    cJSON_AddNumberToObject(a, "componentType", ctype);
    cJSON_AddNumberToObject(a, "count", (double)count);
    cJSON_AddStringToObject(a, "type", comps == 1 ? "SCALAR" : "VEC3");
    if (mn && mx) {
        cJSON_AddItemToObject(a, "min", cJSON_CreateFloatArray(mn, comps));
        cJSON_AddItemToObject(a, "max", cJSON_CreateFloatArray(mx, comps));
    }
    cJSON_AddItemToArray(o->accessors, a);
    return o->nacc++;
}

static void range(const float *v, size_t n, int comps, float *mn, float *mx)
{
    for (int k = 0; k < comps; k++) {
        mn[k] = INFINITY;
        mx[k] = -INFINITY;
    }
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < comps; k++) {
            mn[k] = fminf(mn[k], v[comps * i + k]);
            mx[k] = fmaxf(mx[k], v[comps * i + k]);
        }
}

/* An instanced decorator's global AO (section 2.2, eq 3; README's bake
 * section): node extras "obscura_instanced", one entry per such
 * primitive, {"primitive": k, "global_ao": [g0, gx, gy, gz],
 * "global_ao_short": [...], "global_ao_long": [...]}; _AO = _AO_LOCAL x
 * (g0 + gx x + gy y + gz z) at the primitive's POSITION (x, y, z).
 * Nothing when the node's own extras are not an object. */
static void instanced_extras(cJSON *node, const obs_bake_instance *r, uint32_t n)
{
    static const char *const keys[3] = {"global_ao", "global_ao_short", "global_ao_long"};
    cJSON *list = NULL;
    for (uint32_t k = 0; k < n; k++) {
        if (!r[k].ao_local)
            continue;
        if (!list) {
            cJSON *x = cJSON_GetObjectItem(node, "extras");
            if (!x)
                x = cJSON_AddObjectToObject(node, "extras");
            if (!cJSON_IsObject(x))
                return;
            list = cJSON_AddArrayToObject(x, "obscura_instanced");
        }
        cJSON *e = cJSON_CreateObject();
        cJSON_AddNumberToObject(e, "primitive", k);
        for (int c = 0; c < 3; c++)
            cJSON_AddItemToObject(e, keys[c], cJSON_CreateFloatArray(r[k].global[c], 4));
        cJSON_AddItemToArray(list, e);
    }
}

static cJSON *primitive(out *o, const obs_bake_mesh *m, const obs_bake_instance *r, int color,
                        size_t materials)
{
    float mn[3], mx[3];
    cJSON *p = cJSON_CreateObject(), *at = cJSON_CreateObject();
    range(m->positions, m->vertex_count, 3, mn, mx);
    cJSON_AddNumberToObject(at, "POSITION",
                            accessor(o, m->positions, m->vertex_count, 3, GL_FLOAT, ARRAY_BUFFER,
                                     mn, mx));
    int normals_ok = m->normals != NULL;
    for (size_t v = 0; normals_ok && v < m->vertex_count; v++) {
        const float *n = m->normals + 3 * v;
        normals_ok = fabsf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0f) < 1e-3f;
    }
    if (normals_ok)
        cJSON_AddNumberToObject(at, "NORMAL", accessor(o, m->normals, m->vertex_count, 3, GL_FLOAT,
                                                       ARRAY_BUFFER, NULL, NULL));
    static const char *const names[4] = {"_AO", "_AO_SHORT", "_AO_LONG", "_AO_LOCAL"};
    const float *vals[4] = {r->ao, r->ao_short, r->ao_long, r->ao_local};
    for (int k = 0; k < (r->ao_local ? 4 : 3); k++) {
        range(vals[k], m->vertex_count, 1, mn, mx);
        cJSON_AddNumberToObject(at, names[k], accessor(o, vals[k], m->vertex_count, 1, GL_FLOAT,
                                                       ARRAY_BUFFER, mn, mx));
    }
    if (color) {
        float *c = malloc(m->vertex_count * 3 * sizeof(float));
        if (!c) {
            o->b.failed = 1;
        } else {
            for (size_t v = 0; v < m->vertex_count; v++)
                c[3 * v] = c[3 * v + 1] = c[3 * v + 2] = r->ao[v];
            cJSON_AddNumberToObject(at, "COLOR_0", accessor(o, c, m->vertex_count, 3, GL_FLOAT,
                                                            ARRAY_BUFFER, NULL, NULL));
            free(c);
        }
    }
    cJSON_AddItemToObject(p, "attributes", at);
    cJSON_AddNumberToObject(p, "indices", accessor(o, m->indices, 3 * m->triangle_count, 1,
                                                   GL_UNSIGNED_INT, ELEMENT_ARRAY_BUFFER, NULL,
                                                   NULL));
    if (m->material >= 0 && (size_t)m->material < materials)
        cJSON_AddNumberToObject(p, "material", m->material);
    cJSON_AddNumberToObject(p, "mode", 4);
    return p;
}

/* LODs (obs_bake_result's lod_*): after the scene's nodes, for each node
 * that holds meshes, one node per level with that level's meshes, the
 * same name + "_LOD<l>" and matrix and no children, outside the scene's
 * graph, listed in order in the node's MSFT_lod extension (glTF's
 * vendor extension MSFT_lod: "ids", from high to low detail). */
static void lod_nodes(out *o, const obs_bake_scene *scene, const obs_bake_result *r, int color,
                      cJSON *nodes, cJSON *meshes, cJSON *const *items, int nmesh)
{
    size_t inst = 0, next = scene->node_count;
    for (size_t n = 0; n < scene->node_count; n++) {
        const obs_bake_node *nd = &scene->nodes[n];
        if (!nd->mesh_count)
            continue;
        cJSON *ids = cJSON_CreateArray();
        for (size_t l = 1; l <= r->lod_levels; l++) {
            cJSON *j = cJSON_CreateObject(), *m = cJSON_CreateObject();
            cJSON *prims = cJSON_AddArrayToObject(m, "primitives");
            char name[512];
            snprintf(name, sizeof name, "%.480s_LOD%zu", nd->name ? nd->name : "", l);
            cJSON_AddStringToObject(j, "name", name);
            cJSON *matrix = cJSON_GetObjectItem(items[n], "matrix");
            if (matrix)
                cJSON_AddItemToObject(j, "matrix", cJSON_Duplicate(matrix, 1));
            const obs_bake_mesh *lm = r->lod_meshes + (l - 1) * scene->mesh_count;
            cJSON_AddStringToObject(m, "name", lm[nd->meshes[0]].name);
            for (uint32_t k = 0; k < nd->mesh_count; k++)
                cJSON_AddItemToArray(prims, primitive(o, &lm[nd->meshes[k]],
                                                      &r->lod_instances[(l - 1) * r->instance_count +
                                                                        inst + k],
                                                      color, scene->material_count));
            cJSON_AddItemToArray(meshes, m);
            cJSON_AddNumberToObject(j, "mesh", nmesh++);
            cJSON_AddItemToArray(nodes, j);
            cJSON_AddItemToArray(ids, cJSON_CreateNumber((double)next++));
        }
        cJSON *ext = cJSON_AddObjectToObject(items[n], "extensions");
        cJSON_AddItemToObject(cJSON_AddObjectToObject(ext, "MSFT_lod"), "ids", ids);
        inst += nd->mesh_count;
    }
    cJSON *used = cJSON_AddArrayToObject(o->root, "extensionsUsed");
    cJSON_AddItemToArray(used, cJSON_CreateString("MSFT_lod"));
}

static int identity(const float m[16])
{
    for (int i = 0; i < 16; i++)
        if (m[i] != (i % 5 == 0 ? 1.0f : 0.0f))
            return 0;
    return 1;
}

static obs_status write_file(const char *path, const char *json, const bin *b,
                             char err[OBS_ERR_LEN])
{
    size_t jlen = strlen(json), jpad = (jlen + 3) & ~(size_t)3, bpad = (b->len + 3) & ~(size_t)3;
    uint64_t total = 12 + 8 + (uint64_t)jpad + 8 + bpad;
    if (total > UINT32_MAX)
        return obs__fail(err, OBS_TOO_LARGE, "%s: %llu bytes; a .glb holds at most 4 GiB", path,
                         (unsigned long long)total);
    /* under a hidden temporary name, renamed when whole (io/out_file.h):
     * a cancelled farm task leaves no half .glb under the final name */
    obs__out_file file;
    FILE *f = fopen(obs__out_begin(&file, path), "wb");
    if (!f)
        return obs__out_end(&file, obs__fail(err, OBS_IO, "%s: cannot write: %s", path,
                                              strerror(errno)), err);
    uint32_t head[5] = {0x46546C67u, 2u, (uint32_t)total, (uint32_t)jpad, 0x4E4F534Au};
    uint32_t bhead[2] = {(uint32_t)bpad, 0x004E4942u};
    int ok = fwrite(head, 4, 5, f) == 5 && fwrite(json, 1, jlen, f) == jlen;
    for (size_t i = jlen; ok && i < jpad; i++)
        ok = fputc(' ', f) != EOF;
    ok = ok && fwrite(bhead, 4, 2, f) == 2 && (b->len == 0 || fwrite(b->data, 1, b->len, f) == b->len);
    for (size_t i = b->len; ok && i < bpad; i++)
        ok = fputc(0, f) != EOF;
    if (fclose(f) != 0)
        ok = 0;
    return obs__out_end(&file, ok ? OBS_OK : obs__fail(err, OBS_IO, "%s: write failed: %s", path,
                                                       strerror(errno)), err);
}

obs_status obs_bake_write_glb(const char *path, const obs_bake_scene *scene,
                              const obs_bake_result *r, int color, char err[OBS_ERR_LEN])
{
    out o = {0};
    obs_status st = OBS_OK;
    char *json = NULL;
    o.root = cJSON_CreateObject();
    cJSON *asset = cJSON_AddObjectToObject(o.root, "asset");
    cJSON_AddStringToObject(asset, "version", "2.0");
    cJSON_AddStringToObject(asset, "generator", "obscura bake " OBS_VERSION);
    cJSON_AddNumberToObject(o.root, "scene", 0);
    cJSON *scenes = cJSON_AddArrayToObject(o.root, "scenes");
    cJSON *sc = cJSON_CreateObject();
    cJSON_AddItemToArray(scenes, sc);
    cJSON *roots = cJSON_AddArrayToObject(sc, "nodes");
    cJSON *nodes = cJSON_AddArrayToObject(o.root, "nodes");
    cJSON *meshes = cJSON_AddArrayToObject(o.root, "meshes");
    o.accessors = cJSON_AddArrayToObject(o.root, "accessors");
    o.views = cJSON_AddArrayToObject(o.root, "bufferViews");
    if (!o.root || !roots || !nodes || !meshes || !o.accessors || !o.views) {
        st = obs__fail(err, OBS_NO_MEMORY, "%s: glTF document", path);
        goto done;
    }
    cJSON **items = calloc(scene->node_count ? scene->node_count : 1, sizeof *items);
    if (!items) {
        st = obs__fail(err, OBS_NO_MEMORY, "%s: glTF nodes", path);
        goto done;
    }
    size_t inst = 0;
    int nmesh = 0; /* cJSON_GetArraySize walks the list: counted here */
    for (size_t n = 0; n < scene->node_count; n++) {
        const obs_bake_node *nd = &scene->nodes[n];
        cJSON *j = items[n] = cJSON_CreateObject();
        cJSON_AddItemToArray(nodes, j);
        cJSON_AddStringToObject(j, "name", nd->name);
        if (!identity(nd->local)) {
            float cm[16]; /* glTF matrices are column-major */
            for (int a = 0; a < 4; a++)
                for (int b = 0; b < 4; b++)
                    cm[4 * b + a] = nd->local[4 * a + b];
            cJSON_AddItemToObject(j, "matrix", cJSON_CreateFloatArray(cm, 16));
        }
        if (nd->parent < 0)
            cJSON_AddItemToArray(roots, cJSON_CreateNumber((double)n));
        else {
            cJSON *parent = items[nd->parent], *ch = cJSON_GetObjectItem(parent, "children");
            if (!ch)
                ch = cJSON_AddArrayToObject(parent, "children");
            cJSON_AddItemToArray(ch, cJSON_CreateNumber((double)n));
        }
        cJSON *x = nd->extras ? cJSON_Parse(nd->extras) : NULL;
        if (r->node_ao && n < r->node_count && !isnan(r->node_ao[3 * n])) {
            /* a small decorator's one scalar (section 2.2.1) */
            if (!cJSON_IsObject(x)) {
                cJSON_Delete(x);
                x = cJSON_CreateObject();
            }
            static const char *const keys[3] = {"_AO", "_AO_SHORT", "_AO_LONG"};
            for (int k = 0; k < 3; k++) {
                cJSON_DeleteItemFromObjectCaseSensitive(x, keys[k]);
                cJSON_AddNumberToObject(x, keys[k], r->node_ao[3 * n + k]);
            }
        }
        if (x)
            cJSON_AddItemToObject(j, "extras", x);
        if (nd->mesh_count) {
            cJSON *m = cJSON_CreateObject(), *prims = cJSON_AddArrayToObject(m, "primitives");
            cJSON_AddStringToObject(m, "name", scene->meshes[nd->meshes[0]].name);
            for (uint32_t k = 0; k < nd->mesh_count; k++, inst++) {
                if (inst >= r->instance_count || r->instances[inst].node != n ||
                    r->instances[inst].mesh != nd->meshes[k]) {
                    free(items);
                    cJSON_Delete(m);
                    st = obs__fail(err, OBS_INVALID_ARGUMENT,
                                   "%s: the bake result does not belong to this scene", path);
                    goto done;
                }
                cJSON_AddItemToArray(prims, primitive(&o, &scene->meshes[nd->meshes[k]],
                                                      &r->instances[inst], color,
                                                      scene->material_count));
            }
            cJSON_AddItemToArray(meshes, m);
            cJSON_AddNumberToObject(j, "mesh", nmesh++);
            instanced_extras(j, r->instances + (inst - nd->mesh_count), nd->mesh_count);
        }
    }
    if (r->lod_levels && r->lod_meshes && r->lod_instances)
        lod_nodes(&o, scene, r, color, nodes, meshes, items, nmesh);
    free(items);
    if (scene->material_count) {
        cJSON *mats = cJSON_AddArrayToObject(o.root, "materials");
        for (size_t i = 0; i < scene->material_count; i++) {
            const obs_bake_material *mt = &scene->materials[i];
            cJSON *j = cJSON_CreateObject(), *pbr = cJSON_AddObjectToObject(j, "pbrMetallicRoughness");
            cJSON_AddStringToObject(j, "name", mt->name);
            cJSON_AddItemToObject(pbr, "baseColorFactor", cJSON_CreateFloatArray(mt->base_color, 4));
            cJSON_AddNumberToObject(pbr, "metallicFactor", 0);
            if (mt->double_sided)
                cJSON_AddBoolToObject(j, "doubleSided", 1);
            if (mt->blend)
                cJSON_AddStringToObject(j, "alphaMode", "BLEND");
            cJSON_AddItemToArray(mats, j);
        }
    }
    cJSON *buffers = cJSON_AddArrayToObject(o.root, "buffers"), *buf = cJSON_CreateObject();
    cJSON_AddNumberToObject(buf, "byteLength", (double)((o.b.len + 3) & ~(size_t)3));
    cJSON_AddItemToArray(buffers, buf);
    if (o.b.failed || !(json = cJSON_PrintUnformatted(o.root))) {
        st = obs__fail(err, OBS_NO_MEMORY, "%s: glTF buffer of %zu bytes", path, o.b.len);
        goto done;
    }
    st = write_file(path, json, &o.b, err);
done:
    free(json);
    free(o.b.data);
    cJSON_Delete(o.root);
    return st;
}
