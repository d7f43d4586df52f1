/* A level through assimp with its node graph kept (core/ground/scene.c
 * pre-transforms the vertices, which loses the instancing): meshes in their
 * own space, every node with its name, transform, meshes and glTF extras
 * (assimp 5.2 gives them as the node's metadata), and AC3D's double-sided
 * surfaces, which assimp drops, from the file itself; a .glb's own LODs
 * (MSFT_lod, which assimp does not expose) through lod_file.c. */
#include <assimp/GltfMaterial.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "ground/assimp_read.h"
#include "level/level.h"
#include "internal.h"
#include "obscura/bake.h"

/* The graph is walked with an explicit stack: a file's depth is its own. */
#define MAX_DEPTH 4096

void obs_bake_scene_free(obs_bake_scene *s)
{
    if (!s)
        return;
    for (size_t m = 0; m < s->mesh_count && s->meshes; m++)
        obs__bake_mesh_free(&s->meshes[m]);
    for (size_t n = 0; n < s->node_count && s->nodes; n++) {
        free(s->nodes[n].name);
        free(s->nodes[n].meshes);
        free(s->nodes[n].extras);
    }
    for (size_t m = 0; m < s->material_count && s->materials; m++)
        free(s->materials[m].name);
    obs__bake_lod_file_free(s);
    free(s->file_lod_error);
    free(s->materials);
    free(s->meshes);
    free(s->nodes);
    memset(s, 0, sizeof *s);
}

static cJSON *meta_value(const struct aiMetadataEntry *e)
{
    switch (e->mType) {
    case AI_BOOL: return cJSON_CreateBool(*(const int8_t *)e->mData);
    case AI_INT32: return cJSON_CreateNumber(*(const int32_t *)e->mData);
    case AI_UINT64: return cJSON_CreateNumber((double)*(const uint64_t *)e->mData);
    case AI_FLOAT: return cJSON_CreateNumber(*(const float *)e->mData);
    case AI_DOUBLE: return cJSON_CreateNumber(*(const double *)e->mData);
    case AI_AISTRING: return cJSON_CreateString(((const struct aiString *)e->mData)->data);
    case AI_AIVECTOR3D: {
        const struct aiVector3D *v = e->mData;
        const float f[3] = {v->x, v->y, v->z};
        return cJSON_CreateFloatArray(f, 3);
    }
    case AI_AIMETADATA: {
        const struct aiMetadata *m = e->mData;
        cJSON *o = cJSON_CreateObject();
        for (unsigned i = 0; o && i < m->mNumProperties; i++) {
            cJSON *v = meta_value(&m->mValues[i]);
            if (v)
                cJSON_AddItemToObject(o, m->mKeys[i].data, v);
        }
        return o;
    }
    default: return NULL;
    }
}

/* The node's metadata as JSON text; NULL when it has none. */
static char *extras_json(const struct aiMetadata *m)
{
    if (!m || m->mNumProperties == 0)
        return NULL;
    struct aiMetadataEntry e = {AI_AIMETADATA, (void *)m};
    cJSON *o = meta_value(&e);
    char *txt = o ? cJSON_PrintUnformatted(o) : NULL;
    cJSON_Delete(o);
    return txt;
}

static int material_two_sided(const struct aiScene *sc, unsigned mi)
{
    int two = 0;
    if (mi >= sc->mNumMaterials)
        return 0;
    return aiGetMaterialIntegerArray(sc->mMaterials[mi], AI_MATKEY_TWOSIDED, &two, NULL) ==
               aiReturn_SUCCESS &&
           two != 0;
}

/* What the output keeps of a material; assimp's stand-in for a file
 * without materials is kept too (it is what the meshes refer to). */
static obs_status copy_material(const struct aiMaterial *mat, obs_bake_material *out)
{
    struct aiString s;
    struct aiColor4D c = {0.8f, 0.8f, 0.8f, 1.0f};
    out->name = strdup(aiGetMaterialString(mat, AI_MATKEY_NAME, &s) == aiReturn_SUCCESS ? s.data
                                                                                        : "");
    if (aiGetMaterialColor(mat, AI_MATKEY_BASE_COLOR, &c) != aiReturn_SUCCESS &&
        aiGetMaterialColor(mat, AI_MATKEY_COLOR_DIFFUSE, &c) != aiReturn_SUCCESS)
        c = (struct aiColor4D){0.8f, 0.8f, 0.8f, 1.0f};
    const float rgba[4] = {c.r, c.g, c.b, c.a};
    for (int k = 0; k < 4; k++)
        out->base_color[k] = isfinite(rgba[k]) ? fminf(fmaxf(rgba[k], 0.0f), 1.0f) : 1.0f;
    int two = 0;
    out->double_sided = aiGetMaterialIntegerArray(mat, AI_MATKEY_TWOSIDED, &two, NULL) ==
                            aiReturn_SUCCESS &&
                        two;
    out->blend = aiGetMaterialString(mat, AI_MATKEY_GLTF_ALPHAMODE, &s) == aiReturn_SUCCESS &&
                 !strcmp(s.data, "BLEND");
    return out->name ? OBS_OK : OBS_NO_MEMORY;
}

static obs_status copy_mesh(const char *path, const struct aiScene *sc, unsigned i,
                            obs_bake_mesh *out, char err[OBS_ERR_LEN])
{
    const struct aiMesh *m = sc->mMeshes[i];
    size_t nt = 0;
    for (unsigned f = 0; f < m->mNumFaces; f++)
        nt += m->mFaces[f].mNumIndices == 3;
    out->vertex_count = m->mNumVertices;
    out->triangle_count = nt;
    out->two_sided = material_two_sided(sc, m->mMaterialIndex);
    out->material = m->mMaterialIndex < sc->mNumMaterials ? (int)m->mMaterialIndex : -1;
    if (!(out->name = strdup(m->mName.data)))
        return obs__fail(err, OBS_NO_MEMORY, "%s: mesh names", path);
    out->positions = malloc((m->mNumVertices ? m->mNumVertices : 1) * 3 * sizeof(float));
    out->indices = malloc((nt ? nt : 1) * 3 * sizeof(uint32_t));
    out->normals = m->mNormals ? malloc((m->mNumVertices ? m->mNumVertices : 1) * 3 * sizeof(float))
                               : NULL;
    if (!out->positions || !out->indices || (m->mNormals && !out->normals))
        return obs__fail(err, OBS_NO_MEMORY, "%s: mesh %u of %u vertices", path, i,
                         m->mNumVertices);
    for (unsigned v = 0; v < m->mNumVertices; v++) {
        float *p = out->positions + 3 * (size_t)v;
        p[0] = m->mVertices[v].x;
        p[1] = m->mVertices[v].y;
        p[2] = m->mVertices[v].z;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
            return obs__fail(err, OBS_BAD_FILE, "%s: mesh %u '%s': vertex %u is (%g, %g, %g), not finite",
                             path, i, m->mName.data, v, (double)p[0], (double)p[1], (double)p[2]);
        if (out->normals) {
            float *n = out->normals + 3 * (size_t)v;
            float x = m->mNormals[v].x, y = m->mNormals[v].y, z = m->mNormals[v].z;
            float len = sqrtf(x * x + y * y + z * z);
            int ok = isfinite(len) && len > 1e-12f;
            n[0] = ok ? x / len : 0.0f;
            n[1] = ok ? y / len : 0.0f;
            n[2] = ok ? z / len : 0.0f;
        }
    }
    size_t t = 0;
    for (unsigned f = 0; f < m->mNumFaces; f++) {
        const struct aiFace *fc = &m->mFaces[f];
        if (fc->mNumIndices != 3)
            continue;
        for (int k = 0; k < 3; k++) {
            if (fc->mIndices[k] >= m->mNumVertices)
                return obs__fail(err, OBS_BAD_FILE,
                                 "%s: mesh %u '%s': face %u refers to vertex %u of %u", path, i,
                                 m->mName.data, f, fc->mIndices[k], m->mNumVertices);
            out->indices[3 * t + k] = fc->mIndices[k];
        }
        t++;
    }
    return OBS_OK;
}

/* aiMatrix4x4 is row-major with column vectors, as obscura's matrices. */
static void to_mat(const struct aiMatrix4x4 *a, float m[16])
{
    const float v[16] = {a->a1, a->a2, a->a3, a->a4, a->b1, a->b2, a->b3, a->b4,
                         a->c1, a->c2, a->c3, a->c4, a->d1, a->d2, a->d3, a->d4};
    memcpy(m, v, sizeof v);
}

static void mat_mul(const float a[16], const float b[16], float out[16])
{
    float r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            float s = 0.0f;
            for (int k = 0; k < 4; k++)
                s += a[4 * i + k] * b[4 * k + j];
            r[4 * i + j] = s;
        }
    memcpy(out, r, sizeof r);
}

static size_t count_nodes(const struct aiNode *root, char err[OBS_ERR_LEN], int *depth_err)
{
    const struct aiNode *stack[MAX_DEPTH];
    unsigned next[MAX_DEPTH];
    size_t n = 1;
    int sp = 0;
    stack[0] = root;
    next[0] = 0;
    while (sp >= 0) {
        const struct aiNode *nd = stack[sp];
        if (next[sp] >= nd->mNumChildren) {
            sp--;
            continue;
        }
        const struct aiNode *c = nd->mChildren[next[sp]++];
        if (!c)
            continue;
        if (sp + 1 >= MAX_DEPTH) {
            obs__fail(err, OBS_UNSUPPORTED, "node graph deeper than %d", MAX_DEPTH);
            *depth_err = 1;
            return 0;
        }
        n++;
        stack[++sp] = c;
        next[sp] = 0;
    }
    return n;
}

static int has_suffix(const char *s, const char *tail)
{
    size_t n = strlen(s), m = strlen(tail);
    return n >= m && !strcasecmp(s + n - m, tail);
}

/* AC3D's double-sided flag (SURF 0x20) as assimp 5.2 does not pass it on:
 * read from the file itself.  assimp makes one node per OBJECT, in the
 * file's order (depth first, the world object first), so node i is OBJECT
 * i; an object whose surfaces are mostly double-sided makes its meshes
 * double-sided (AC3D meshes belong to one node each).  Nothing is changed
 * when the counts disagree.  Returns the number of objects marked. */
static size_t ac3d_two_sided(const char *path, obs_bake_scene *s)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    size_t cap = s->node_count, obj = 0;
    int *two = calloc(cap ? cap : 1, sizeof *two), *one = calloc(cap ? cap : 1, sizeof *one);
    char line[512];
    int ok = two && one;
    while (ok && fgets(line, sizeof line, f)) {
        if (!strncmp(line, "OBJECT ", 7)) {
            if (++obj > cap)
                ok = 0;
        } else if (!strncmp(line, "SURF ", 5) && obj > 0) {
            unsigned long flags = strtoul(line + 5, NULL, 0);
            if (flags & 0x20u)
                two[obj - 1]++;
            else
                one[obj - 1]++;
        }
    }
    fclose(f);
    size_t marked = 0;
    if (ok && obj == s->node_count)
        for (size_t n = 0; n < s->node_count; n++) {
            if (two[n] <= one[n])
                continue;
            marked++;
            for (uint32_t k = 0; k < s->nodes[n].mesh_count; k++)
                s->meshes[s->nodes[n].meshes[k]].two_sided = 1;
        }
    free(two);
    free(one);
    return marked;
}

/* The file's materials and meshes, in its order; at least one triangle. */
static obs_status copy_meshes(const char *path, const struct aiScene *sc, obs_bake_scene *out,
                              char err[OBS_ERR_LEN])
{
    out->meshes = calloc(sc->mNumMeshes, sizeof *out->meshes);
    if (!out->meshes)
        return obs__fail(err, OBS_NO_MEMORY, "%s: %u meshes", path, sc->mNumMeshes);
    out->mesh_count = sc->mNumMeshes;
    if (sc->mNumMaterials && !(out->materials = calloc(sc->mNumMaterials, sizeof *out->materials)))
        return obs__fail(err, OBS_NO_MEMORY, "%s: %u materials", path, sc->mNumMaterials);
    for (unsigned i = 0; i < sc->mNumMaterials; i++) {
        out->material_count = i + 1;
        if (copy_material(sc->mMaterials[i], &out->materials[i]) != OBS_OK)
            return obs__fail(err, OBS_NO_MEMORY, "%s: material names", path);
    }
    size_t stored = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        obs_status st = copy_mesh(path, sc, i, &out->meshes[i], err);
        if (st != OBS_OK)
            return st;
        stored += out->meshes[i].triangle_count;
    }
    if (stored == 0)
        return obs__fail(err, OBS_BAD_FILE, "%s: no triangles (%u meshes of points or lines)",
                         path, sc->mNumMeshes);
    return OBS_OK;
}

/* Node o, the file's nd under parent (-1: the root): its matrices, name,
 * extras and the meshes with triangles it instances, counted into the
 * scene's instances and flattened triangles. */
static obs_status copy_node(const char *path, const struct aiScene *sc, const struct aiNode *nd,
                            int parent, size_t max_triangles, obs_bake_scene *out,
                            obs_bake_node *o, char err[OBS_ERR_LEN])
{
    o->parent = parent;
    to_mat(&nd->mTransformation, o->local);
    if (o->parent >= 0)
        mat_mul(out->nodes[o->parent].world, o->local, o->world);
    else
        memcpy(o->world, o->local, sizeof o->world);
    o->name = strdup(nd->mName.data);
    o->extras = extras_json(nd->mMetaData);
    o->meshes = malloc((nd->mNumMeshes ? nd->mNumMeshes : 1) * sizeof *o->meshes);
    if (!o->name || !o->meshes)
        return obs__fail(err, OBS_NO_MEMORY, "%s: nodes", path);
    for (unsigned k = 0; k < nd->mNumMeshes; k++) {
        unsigned mi = nd->mMeshes[k];
        if (mi >= sc->mNumMeshes)
            return obs__fail(err, OBS_BAD_FILE, "%s: node '%s' refers to mesh %u of %u", path,
                             nd->mName.data, mi, sc->mNumMeshes);
        if (out->meshes[mi].triangle_count == 0)
            continue; /* points or lines */
        o->meshes[o->mesh_count++] = mi;
        out->instance_count++;
        out->world_triangles += out->meshes[mi].triangle_count;
    }
    if (max_triangles && out->world_triangles > max_triangles)
        return obs__fail(err, OBS_TOO_LARGE,
                         "%s: more than %zu triangles once instances are flattened "
                         "(max_triangles)",
                         path, max_triangles);
    return OBS_OK;
}

/* The node graph, depth first, parents first. */
static obs_status copy_nodes(const char *path, const struct aiScene *sc, size_t max_triangles,
                             obs_bake_scene *out, char err[OBS_ERR_LEN])
{
    int depth_err = 0;
    size_t nn = count_nodes(sc->mRootNode, err, &depth_err);
    if (depth_err)
        return OBS_UNSUPPORTED;
    out->nodes = calloc(nn, sizeof *out->nodes);
    if (!out->nodes)
        return obs__fail(err, OBS_NO_MEMORY, "%s: %zu nodes", path, nn);
    const struct aiNode *stack[MAX_DEPTH];
    int ids[MAX_DEPTH];
    unsigned next[MAX_DEPTH];
    int sp = 0;
    stack[0] = sc->mRootNode;
    next[0] = 0;
    ids[0] = 0;
    size_t count = 0;
    for (;;) {
        const struct aiNode *nd = stack[sp];
        if (next[sp] == 0) {
            /* first visit */
            obs_bake_node *o = &out->nodes[count];
            ids[sp] = (int)count++;
            out->node_count = count; /* what obs_bake_scene_free releases on failure */
            obs_status st = copy_node(path, sc, nd, sp ? ids[sp - 1] : -1, max_triangles, out, o,
                                      err);
            if (st != OBS_OK)
                return st;
        }
        if (next[sp] < nd->mNumChildren && count < nn) {
            const struct aiNode *c = nd->mChildren[next[sp]++];
            if (!c)
                continue;
            sp++;
            stack[sp] = c;
            next[sp] = 0;
            continue;
        }
        if (sp == 0)
            break;
        sp--;
    }
    out->node_count = count;
    return OBS_OK;
}

obs_status obs_bake_load(const char *path, size_t max_triangles, obs_bake_scene *out,
                         char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    /* max_triangles 0: no limit but assimp's own (32-bit face counts) */
    uint64_t most = max_triangles ? (uint64_t)max_triangles : UINT32_MAX;
    obs_status pre = obs__assimp_precheck(path, most, err);
    if (pre != OBS_OK)
        return pre;
    /* No joining, no pre-transform: the soup, the graph and the mesh
     * order stay the file's.  Read and validated first (an importer's
     * inconsistent output refused before assimp's own preprocessing
     * reads it), the faces checked, then triangulated (assimp_read.h). */
    char msg[OBS_ERR_LEN] = "";
    obs__assimp *imp = obs__assimp_read(path, 0, msg);
    if (!imp)
        return obs__assimp_fail(path, "a level", msg, err);
    const struct aiScene *sc = obs__assimp_scene(imp);
    obs_status st = obs__assimp_faces(path, sc, err);
    if (st == OBS_OK && !(sc = obs__assimp_apply(imp, aiProcess_Triangulate, msg)))
        st = obs__assimp_fail(path, "a level", msg, err);
    if (st != OBS_OK) {
        obs__assimp_free(imp);
        return st;
    }
    if (!sc->mRootNode || sc->mNumMeshes == 0) {
        st = obs__fail(err, OBS_BAD_FILE, "%s: no triangles (no meshes)", path);
        goto fail;
    }
    if ((st = copy_meshes(path, sc, out, err)) != OBS_OK ||
        (st = copy_nodes(path, sc, max_triangles, out, err)) != OBS_OK)
        goto fail;
    if (out->world_triangles == 0) {
        st = obs__fail(err, OBS_BAD_FILE, "%s: no triangles under the scene's nodes", path);
        goto fail;
    }
    if (has_suffix(path, ".ac") || has_suffix(path, ".acc"))
        ac3d_two_sided(path, out);
    obs__assimp_free(imp);
    /* The file's own LODs (lod_file.c); a reason they cannot be read is
     * kept for the bake to name if it is asked for LODs. */
    char lerr[OBS_ERR_LEN] = "";
    if (obs__bake_lod_file_read(path, out, lerr) != OBS_OK && !(out->file_lod_error = strdup(lerr))) {
        obs_bake_scene_free(out);
        return obs__fail(err, OBS_NO_MEMORY, "%s: LODs", path);
    }
    return OBS_OK;
fail:
    obs__assimp_free(imp);
    obs_bake_scene_free(out);
    return st;
}
