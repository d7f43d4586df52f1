/* Scene loading through assimp's C API: every triangle of the file, in
 * world space, as one indexed mesh. */
#include <assimp/GltfMaterial.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <fnmatch.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "obscura/scene.h"
#include "ground/assimp_read.h"
#include "ground/scene_internal.h"

/* Indices are 32-bit (GL and Embree take them so). */
#define MAX_VERTICES ((size_t)UINT32_MAX)

void obs_scene_free(obs_scene *s)
{
    if (!s)
        return;
    free(s->positions);
    free(s->normals);
    free(s->albedo);
    free(s->indices);
    free(s->opacity);
    free(s->baked);
    for (size_t m = 0; m < s->mesh_count && s->meshes; m++) {
        free(s->meshes[m].name);
        free(s->meshes[m].node);
    }
    free(s->meshes);
    memset(s, 0, sizeof *s);
}

/* " (mesh 'NAME', node 'NODE')" of the mesh that holds triangle t, or "". */
static void mesh_of_triangle(const obs_scene *s, size_t t, char *buf, size_t n)
{
    buf[0] = '\0';
    for (size_t m = 0; m < s->mesh_count && s->meshes; m++)
        if (t >= s->meshes[m].first_triangle &&
            t - s->meshes[m].first_triangle < s->meshes[m].triangle_count) {
            snprintf(buf, n, " (mesh '%s', node '%s')", s->meshes[m].name ? s->meshes[m].name : "",
                     s->meshes[m].node ? s->meshes[m].node : "");
            return;
        }
}

/* mesh_of_triangle of the first triangle that uses vertex v. */
static void mesh_of_vertex(const obs_scene *s, size_t v, char *buf, size_t n)
{
    buf[0] = '\0';
    for (size_t i = 0; i < 3 * s->triangle_count; i++)
        if (s->indices[i] == v) {
            mesh_of_triangle(s, i / 3, buf, n);
            return;
        }
}

obs_status obs_scene_check(obs_scene *s, char err[OBS_ERR_LEN])
{
    char where[160];
    if (!s->positions || !s->indices || s->vertex_count == 0 || s->triangle_count == 0)
        return obs__fail(err, OBS_BAD_FILE, "empty scene: no triangles");
    if (s->vertex_count > MAX_VERTICES)
        return obs__fail(err, OBS_TOO_LARGE, "%zu vertices; at most %zu", s->vertex_count,
                         MAX_VERTICES);
    for (size_t i = 0; i < 3 * s->triangle_count; i++)
        if (s->indices[i] >= s->vertex_count)
            return obs__fail(err, OBS_BAD_FILE, "triangle %zu refers to vertex %u of %zu", i / 3,
                             (unsigned)s->indices[i], s->vertex_count);
    for (int k = 0; k < 3; k++) {
        s->bounds_min[k] = INFINITY;
        s->bounds_max[k] = -INFINITY;
    }
    for (size_t v = 0; v < s->vertex_count; v++) {
        const float *p = s->positions + 3 * v;
        for (int k = 0; k < 3; k++)
            if (!isfinite(p[k])) {
                mesh_of_vertex(s, v, where, sizeof where);
                return obs__fail(err, OBS_BAD_FILE, "vertex %zu%s has a non-finite coordinate", v,
                                 where);
            }
        if (obs_scene_coord_beyond(p)) {
            mesh_of_vertex(s, v, where, sizeof where);
            return obs__fail(err, OBS_BAD_FILE, "vertex %zu%s at (%g, %g, %g): " OBS_SCENE_COORD_RULE,
                             v, where, p[0], p[1], p[2]);
        }
        for (int k = 0; k < 3; k++) {
            s->bounds_min[k] = fminf(s->bounds_min[k], p[k]);
            s->bounds_max[k] = fmaxf(s->bounds_max[k], p[k]);
        }
    }
    /* the bake's rule (level/flatten.c): a scene of degenerate triangles
     * only has no surface to draw or trace */
    for (size_t t = 0; t < s->triangle_count; t++) {
        const uint32_t *i = s->indices + 3 * t;
        float n[3];
        if (obs__tri_normal(s->positions + 3 * (size_t)i[0], s->positions + 3 * (size_t)i[1],
                            s->positions + 3 * (size_t)i[2], n) > 0.0)
            return OBS_OK;
    }
    return obs__fail(err, OBS_BAD_FILE, "all %zu triangles are degenerate (zero area)",
                     s->triangle_count);
}

obs_status obs__scene_check_file(obs_scene *s, const char *path, char err[OBS_ERR_LEN])
{
    obs_status st = obs_scene_check(s, err);
    if (st != OBS_OK) {
        char msg[OBS_ERR_LEN];
        snprintf(msg, sizeof msg, "%s", err ? err : "");
        obs__fail(err, st, "%s: %s", path, msg);
    }
    return st;
}

/* The diffuse (or PBR base) colour of a material, unless it is assimp's
 * stand-in for a file without materials. */
static int material_albedo(const struct aiMaterial *mat, float rgb[3])
{
    struct aiString name;
    struct aiColor4D c;
    if (!mat)
        return 0;
    if (aiGetMaterialString(mat, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS &&
        strcmp(name.data, AI_DEFAULT_MATERIAL_NAME) == 0)
        return 0;
    if (aiGetMaterialColor(mat, AI_MATKEY_BASE_COLOR, &c) != aiReturn_SUCCESS &&
        aiGetMaterialColor(mat, AI_MATKEY_COLOR_DIFFUSE, &c) != aiReturn_SUCCESS)
        return 0;
    rgb[0] = c.r;
    rgb[1] = c.g;
    rgb[2] = c.b;
    return 1;
}

/* A material's opacity: glTF's base colour alpha when its alphaMode is
 * BLEND (OPAQUE and MASK render opaque), else AI_MATKEY_OPACITY (OBJ's
 * d, FBX's, ...); 1 when the material says nothing. */
static float material_opacity(const struct aiMaterial *mat)
{
    struct aiString s;
    struct aiColor4D c;
    float o = 1.0f;
    if (!mat)
        return 1.0f;
    if (aiGetMaterialString(mat, AI_MATKEY_NAME, &s) == aiReturn_SUCCESS &&
        strcmp(s.data, AI_DEFAULT_MATERIAL_NAME) == 0)
        return 1.0f;
    if (aiGetMaterialString(mat, AI_MATKEY_GLTF_ALPHAMODE, &s) == aiReturn_SUCCESS) {
        if (strcmp(s.data, "BLEND") != 0 ||
            aiGetMaterialColor(mat, AI_MATKEY_BASE_COLOR, &c) != aiReturn_SUCCESS)
            return 1.0f;
        o = c.a;
    } else if (aiGetMaterialFloat(mat, AI_MATKEY_OPACITY, &o) != aiReturn_SUCCESS) {
        return 1.0f;
    }
    return isfinite(o) ? fminf(fmaxf(o, 0.0f), 1.0f) : 1.0f;
}

/* The name of the first node (depth first) that holds mesh i. */
static const char *node_name_of(const struct aiNode *n, unsigned i)
{
    if (!n)
        return NULL;
    for (unsigned k = 0; k < n->mNumMeshes; k++)
        if (n->mMeshes[k] == i)
            return n->mName.data;
    for (unsigned c = 0; c < n->mNumChildren; c++) {
        const char *r = node_name_of(n->mChildren[c], i);
        if (r)
            return r;
    }
    return NULL;
}

static int triangle_mesh(const struct aiMesh *m)
{
    return m && m->mNumVertices > 0 && m->mNumFaces > 0 &&
           (m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE);
}

/* What the triangle meshes of the file hold together: the sizes of the
 * scene's arrays, and whether any has a colour or is not opaque. */
typedef struct scene_size {
    size_t nv, nt, nmesh;
    int any_albedo, any_opacity;
} scene_size;

static scene_size measure(const struct aiScene *sc)
{
    scene_size z = {0};
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        if (!triangle_mesh(m))
            continue;
        z.nmesh++;
        z.any_opacity |= m->mMaterialIndex < sc->mNumMaterials &&
                         material_opacity(sc->mMaterials[m->mMaterialIndex]) < 1.0f;
        z.nv += m->mNumVertices;
        for (unsigned f = 0; f < m->mNumFaces; f++)
            z.nt += m->mFaces[f].mNumIndices == 3;
        float rgb[3];
        z.any_albedo |= m->mMaterialIndex < sc->mNumMaterials &&
                        material_albedo(sc->mMaterials[m->mMaterialIndex], rgb);
    }
    return z;
}

/* The scene's arrays for z's sizes, after checking them. */
static obs_status allocate(const char *path, const struct aiScene *sc, const scene_size *z,
                           obs_scene *out, char err[OBS_ERR_LEN])
{
    if (z->nt == 0)
        return obs__fail(err, OBS_BAD_FILE, "%s: empty scene: no triangles (%u meshes)", path,
                         sc->mNumMeshes);
    if (z->nv > MAX_VERTICES)
        return obs__fail(err, OBS_TOO_LARGE, "%s: %zu vertices; at most %zu", path, z->nv,
                         MAX_VERTICES);
    size_t vbytes, ibytes;
    if (obs__size_mul3(z->nv, 3, sizeof(float), &vbytes) ||
        obs__size_mul3(z->nt, 3, sizeof(uint32_t), &ibytes))
        return obs__fail(err, OBS_TOO_LARGE, "%s: mesh too large", path);
    out->positions = malloc(vbytes);
    out->normals = malloc(vbytes);
    out->albedo = z->any_albedo ? malloc(vbytes) : NULL;
    out->indices = malloc(ibytes);
    out->opacity = z->any_opacity ? malloc(z->nt * sizeof(float)) : NULL;
    out->meshes = calloc(z->nmesh, sizeof *out->meshes);
    if (!out->positions || !out->normals || !out->indices || (z->any_albedo && !out->albedo) ||
        (z->any_opacity && !out->opacity) || !out->meshes)
        return obs__fail(err, OBS_NO_MEMORY, "%s: %zu vertices, %zu triangles", path, z->nv,
                         z->nt);
    return OBS_OK;
}

/* Mesh m's vertices from v0 on: positions, unit normals, colour rgb. */
static void copy_vertices(const struct aiMesh *m, size_t v0, const float rgb[3], obs_scene *out)
{
    for (unsigned v = 0; v < m->mNumVertices; v++) {
        float *p = out->positions + 3 * (v0 + v), *n = out->normals + 3 * (v0 + v);
        p[0] = m->mVertices[v].x;
        p[1] = m->mVertices[v].y;
        p[2] = m->mVertices[v].z;
        /* GenNormals fills absent normals; FindInvalidData may still
         * leave a zero or NaN one, which the rasteriser replaces by
         * the triangle's own. */
        n[0] = n[1] = n[2] = 0.0f;
        if (m->mNormals) {
            float x = m->mNormals[v].x, y = m->mNormals[v].y, z = m->mNormals[v].z;
            float len = sqrtf(x * x + y * y + z * z);
            if (isfinite(len) && len > 1e-12f) {
                n[0] = x / len;
                n[1] = y / len;
                n[2] = z / len;
            }
        }
        if (out->albedo)
            memcpy(out->albedo + 3 * (v0 + v), rgb, 3 * sizeof *rgb);
    }
}

/* The file's mesh i as the scene's next mesh: its vertices from *v0 and
 * triangles from *t on (both advanced past it). */
static obs_status copy_mesh(const char *path, const struct aiScene *sc, unsigned i, int any_albedo,
                            obs_scene *out, size_t *v0, size_t *t, char err[OBS_ERR_LEN])
{
    const struct aiMesh *m = sc->mMeshes[i];
    float rgb[3] = {0, 0, 0};
    if (any_albedo && !(m->mMaterialIndex < sc->mNumMaterials &&
                        material_albedo(sc->mMaterials[m->mMaterialIndex], rgb)))
        rgb[0] = rgb[1] = rgb[2] = 0.8f; /* a mesh without a colour among coloured ones */
    float opacity = m->mMaterialIndex < sc->mNumMaterials
                        ? material_opacity(sc->mMaterials[m->mMaterialIndex])
                        : 1.0f;
    obs_scene_mesh *mesh = &out->meshes[out->mesh_count++];
    const char *node = node_name_of(sc->mRootNode, i);
    mesh->first_triangle = *t;
    if (!(mesh->name = strdup(m->mName.data)) || !(mesh->node = strdup(node ? node : "")))
        return obs__fail(err, OBS_NO_MEMORY, "%s: mesh names", path);
    copy_vertices(m, *v0, rgb, out);
    for (unsigned f = 0; f < m->mNumFaces; f++) {
        const struct aiFace *fc = &m->mFaces[f];
        if (fc->mNumIndices != 3)
            continue;
        for (int k = 0; k < 3; k++)
            out->indices[3 * *t + k] = (uint32_t)(*v0 + fc->mIndices[k]);
        if (out->opacity)
            out->opacity[*t] = opacity;
        (*t)++;
    }
    mesh->triangle_count = *t - mesh->first_triangle;
    *v0 += m->mNumVertices;
    return OBS_OK;
}

/* Every mesh under some node: PreTransformVertices, keeping the
 * hierarchy, takes each mesh's transform from the node that holds it and
 * reads a null one for a mesh no node holds (a damaged file: an AC3D
 * object with vertices and no surface count). */
static obs_status meshes_placed(const char *path, const struct aiScene *sc,
                                char err[OBS_ERR_LEN])
{
    if (!sc->mRootNode)
        return obs__fail(err, OBS_BAD_FILE, "%s: no node graph", path);
    unsigned char *held = calloc(sc->mNumMeshes ? sc->mNumMeshes : 1, 1);
    size_t cap = 64, sp = 0;
    const struct aiNode **stack = malloc(cap * sizeof *stack);
    if (!held || !stack) {
        free(held);
        free(stack);
        return obs__fail(err, OBS_NO_MEMORY, "%s: node graph", path);
    }
    stack[sp++] = sc->mRootNode;
    obs_status st = OBS_OK;
    while (sp > 0 && st == OBS_OK) {
        const struct aiNode *n = stack[--sp];
        for (unsigned k = 0; k < n->mNumMeshes; k++)
            if (n->mMeshes[k] < sc->mNumMeshes)
                held[n->mMeshes[k]] = 1;
        for (unsigned c = 0; c < n->mNumChildren && st == OBS_OK; c++) {
            if (!n->mChildren[c])
                continue;
            if (sp == cap) {
                const struct aiNode **more = realloc(stack, 2 * cap * sizeof *stack);
                if (!more)
                    st = obs__fail(err, OBS_NO_MEMORY, "%s: node graph", path);
                else
                    stack = more, cap *= 2;
            }
            if (st == OBS_OK)
                stack[sp++] = n->mChildren[c];
        }
    }
    for (unsigned i = 0; i < sc->mNumMeshes && st == OBS_OK; i++)
        if (!held[i])
            st = obs__fail(err, OBS_BAD_FILE, "%s: mesh %u '%s' is under no node of the file "
                                              "(a damaged file?)",
                           path, i, sc->mMeshes[i]->mName.data);
    free(held);
    free(stack);
    return st;
}

/* Every vertex in world space (the file's nodes applied), finite. */
static obs_status finite_vertices(const char *path, const struct aiScene *sc,
                                  char err[OBS_ERR_LEN])
{
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        for (unsigned v = 0; v < m->mNumVertices; v++) {
            const struct aiVector3D p = m->mVertices[v];
            if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
                return obs__fail(err, OBS_BAD_FILE,
                                 "%s: mesh %u '%s': vertex %u is (%g, %g, %g) in world space, "
                                 "not finite (in the file, or its node's transform overflows)",
                                 path, i, m->mName.data, v, (double)p.x, (double)p.y, (double)p.z);
        }
    }
    return OBS_OK;
}

/* The file through assimp, flattened, each mesh kept apart. */
static obs_status import(const char *path, obs__assimp **imp, const struct aiScene **sc,
                         char err[OBS_ERR_LEN])
{
    /* no triangle limit here: what assimp's 32-bit face counts hold */
    obs_status st = obs__assimp_precheck(path, UINT32_MAX, err);
    if (st != OBS_OK)
        return st;
    /* Read and validated first, nothing else: ValidateDataStructure
     * refuses an importer's inconsistent output (a face without indices,
     * an index past its mesh's vertices, a node naming a mesh that is not
     * there) before assimp's own preprocessing or copy_mesh reads it out
     * of bounds.  Then the steps in two calls, in assimp's own order (its
     * step list runs PreTransformVertices, Triangulate and SortByPType
     * before FindInvalidData and GenNormals): the world-space vertices are
     * checked in between, as FindInvalidData would drop a mesh with a NaN
     * or infinite vertex (the file's, or its node's transform overflowing)
     * without a word. */
    const unsigned place = aiProcess_Triangulate | aiProcess_PreTransformVertices |
                           aiProcess_SortByPType;
    const unsigned clean = aiProcess_FindInvalidData | aiProcess_GenNormals;
    char msg[OBS_ERR_LEN] = "";
    /* Keep the meshes apart (PreTransformVertices otherwise joins those
     * of one material): their names select opacities. */
    *sc = NULL;
    if (!(*imp = obs__assimp_read(path, 1, msg)))
        return obs__assimp_fail(path, "a mesh", msg, err);
    st = meshes_placed(path, obs__assimp_scene(*imp), err);
    if (st == OBS_OK)
        st = obs__assimp_faces(path, obs__assimp_scene(*imp), err);
    if (st == OBS_OK && !obs__assimp_apply(*imp, place, msg))
        st = obs__assimp_fail(path, "a mesh", msg, err);
    if (st == OBS_OK)
        st = finite_vertices(path, obs__assimp_scene(*imp), err);
    /* FindInvalidData also drops a mesh whose vertices all coincide. */
    if (st == OBS_OK && !(*sc = obs__assimp_apply(*imp, clean, msg)))
        st = strstr(msg, "No meshes remaining")
                 ? obs__fail(err, OBS_BAD_FILE, "%s: no mesh left once assimp drops the invalid "
                                                "ones (each mesh's vertices all at one point?)",
                             path)
                 : obs__assimp_fail(path, "a mesh", msg, err);
    if (st != OBS_OK) {
        obs__assimp_free(*imp);
        *imp = NULL;
        *sc = NULL;
    }
    return st;
}

obs_status obs_scene_load(const char *path, obs_scene *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    obs__assimp *imp = NULL;
    const struct aiScene *sc = NULL;
    obs_status st = import(path, &imp, &sc, err);
    if (st != OBS_OK)
        return st;
    scene_size z = measure(sc);
    st = allocate(path, sc, &z, out, err);
    size_t v0 = 0, t = 0;
    for (unsigned i = 0; st == OBS_OK && i < sc->mNumMeshes; i++)
        if (triangle_mesh(sc->mMeshes[i]))
            st = copy_mesh(path, sc, i, z.any_albedo, out, &v0, &t, err);
    if (st != OBS_OK)
        goto fail;
    out->vertex_count = z.nv;
    out->triangle_count = z.nt;
    if ((st = obs__scene_check_file(out, path, err)) != OBS_OK)
        goto fail;
    obs__assimp_free(imp);
    return OBS_OK;

fail:
    obs__assimp_free(imp);
    obs_scene_free(out);
    return st;
}

obs_status obs_scene_set_opacity(obs_scene *s, const char *spec, char err[OBS_ERR_LEN])
{
    if (!s || !s->indices || s->triangle_count == 0)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "opacity: empty scene");
    if (!spec || !*spec)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "opacity: empty spec (expected A or NAME=A)");
    const char *eq = strrchr(spec, '='), *num = eq ? eq + 1 : spec;
    char *end;
    errno = 0;
    double a = strtod(num, &end);
    if (end == num || *end || errno || !(a >= 0.0 && a <= 1.0))
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "opacity '%s': expected A or NAME=A with A a number from 0 to 1", spec);
    if (eq == spec)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "opacity '%s': empty mesh name", spec);
    size_t namelen = eq ? (size_t)(eq - spec) : 0;
    char *pattern = NULL;
    if (eq && !(pattern = strndup(spec, namelen)))
        return obs__fail(err, OBS_NO_MEMORY, "opacity '%s'", spec);
    if (!s->opacity) {
        if (!(s->opacity = malloc(s->triangle_count * sizeof(float)))) {
            free(pattern);
            return obs__fail(err, OBS_NO_MEMORY, "opacity of %zu triangles", s->triangle_count);
        }
        for (size_t t = 0; t < s->triangle_count; t++)
            s->opacity[t] = 1.0f;
    }
    size_t hit = 0;
    if (!pattern) {
        for (size_t t = 0; t < s->triangle_count; t++)
            s->opacity[t] = (float)a;
        hit = 1;
    }
    for (size_t m = 0; pattern && m < s->mesh_count; m++) {
        const obs_scene_mesh *me = &s->meshes[m];
        if (fnmatch(pattern, me->name, 0) != 0 && fnmatch(pattern, me->node, 0) != 0)
            continue;
        for (size_t t = 0; t < me->triangle_count; t++)
            s->opacity[me->first_triangle + t] = (float)a;
        hit++;
    }
    if (hit == 0) {
        /* Name the meshes there are (as many as fit). */
        char list[OBS_ERR_LEN / 2] = "";
        size_t used = 0;
        for (size_t m = 0; m < s->mesh_count && used + 8 < sizeof list; m++) {
            const obs_scene_mesh *me = &s->meshes[m];
            int n = strcmp(me->name, me->node) && *me->node
                        ? snprintf(list + used, sizeof list - used, "%s'%s' (node '%s')",
                                   m ? ", " : "", me->name, me->node)
                        : snprintf(list + used, sizeof list - used, "%s'%s'", m ? ", " : "",
                                   me->name);
            if (n < 0 || (size_t)n >= sizeof list - used) {
                snprintf(list + used, sizeof list - used, ", ...");
                break;
            }
            used += (size_t)n;
        }
        obs__fail(err, OBS_INVALID_ARGUMENT, "opacity '%s': no mesh is named '%s'; the meshes: %s",
                  spec, pattern, s->mesh_count ? list : "(none: a scene built in memory)");
        free(pattern);
        return OBS_INVALID_ARGUMENT;
    }
    free(pattern);
    return OBS_OK;
}
