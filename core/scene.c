/* Scene loading through assimp's C API: every triangle of the file, in
 * world space, as one indexed mesh. */
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "scene.h"

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
    memset(s, 0, sizeof *s);
}

obs_status obs_scene_check(obs_scene *s, char err[OBS_ERR_LEN])
{
    if (!s->positions || !s->indices || s->vertex_count == 0 || s->triangle_count == 0)
        return obs__fail(err, OBS_BAD_FILE, "empty scene: no triangles");
    if (s->vertex_count > MAX_VERTICES)
        return obs__fail(err, OBS_TOO_LARGE, "%zu vertices; at most %zu", s->vertex_count,
                         MAX_VERTICES);
    for (int k = 0; k < 3; k++) {
        s->bounds_min[k] = INFINITY;
        s->bounds_max[k] = -INFINITY;
    }
    for (size_t v = 0; v < s->vertex_count; v++)
        for (int k = 0; k < 3; k++) {
            float x = s->positions[3 * v + k];
            if (!isfinite(x))
                return obs__fail(err, OBS_BAD_FILE, "vertex %zu has a non-finite coordinate", v);
            s->bounds_min[k] = fminf(s->bounds_min[k], x);
            s->bounds_max[k] = fmaxf(s->bounds_max[k], x);
        }
    for (size_t i = 0; i < 3 * s->triangle_count; i++)
        if (s->indices[i] >= s->vertex_count)
            return obs__fail(err, OBS_BAD_FILE, "triangle %zu refers to vertex %u of %zu", i / 3,
                             (unsigned)s->indices[i], s->vertex_count);
    return OBS_OK;
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

static int triangle_mesh(const struct aiMesh *m)
{
    return m && m->mNumVertices > 0 && m->mNumFaces > 0 &&
           (m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE);
}

obs_status obs_scene_load(const char *path, obs_scene *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return obs__fail(err, OBS_IO, "%s: cannot open: %s", path, strerror(errno));
    fclose(fp);

    const unsigned flags = aiProcess_Triangulate | aiProcess_PreTransformVertices |
                           aiProcess_SortByPType | aiProcess_GenNormals |
                           aiProcess_FindInvalidData;
    const struct aiScene *sc = aiImportFile(path, flags);
    if (!sc)
        return obs__fail(err, OBS_BAD_FILE, "%s: not a mesh assimp can read: %s", path,
                         aiGetErrorString());

    obs_status st = OBS_OK;
    size_t nv = 0, nt = 0;
    int any_albedo = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        if (!triangle_mesh(m))
            continue;
        nv += m->mNumVertices;
        for (unsigned f = 0; f < m->mNumFaces; f++)
            nt += m->mFaces[f].mNumIndices == 3;
        float rgb[3];
        any_albedo |= m->mMaterialIndex < sc->mNumMaterials &&
                      material_albedo(sc->mMaterials[m->mMaterialIndex], rgb);
    }
    if (nt == 0) {
        st = obs__fail(err, OBS_BAD_FILE, "%s: empty scene: no triangles (%u meshes)", path,
                       sc->mNumMeshes);
        goto fail;
    }
    if (nv > MAX_VERTICES) {
        st = obs__fail(err, OBS_TOO_LARGE, "%s: %zu vertices; at most %zu", path, nv,
                       MAX_VERTICES);
        goto fail;
    }
    size_t vbytes, ibytes;
    if (obs__size_mul3(nv, 3, sizeof(float), &vbytes) || obs__size_mul3(nt, 3, sizeof(uint32_t), &ibytes)) {
        st = obs__fail(err, OBS_TOO_LARGE, "%s: mesh too large", path);
        goto fail;
    }
    out->positions = malloc(vbytes);
    out->normals = malloc(vbytes);
    out->albedo = any_albedo ? malloc(vbytes) : NULL;
    out->indices = malloc(ibytes);
    if (!out->positions || !out->normals || !out->indices || (any_albedo && !out->albedo)) {
        st = obs__fail(err, OBS_NO_MEMORY, "%s: %zu vertices, %zu triangles", path, nv, nt);
        goto fail;
    }

    size_t v0 = 0, t = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        if (!triangle_mesh(m))
            continue;
        float rgb[3] = {0, 0, 0};
        if (any_albedo && !(m->mMaterialIndex < sc->mNumMaterials &&
                            material_albedo(sc->mMaterials[m->mMaterialIndex], rgb)))
            rgb[0] = rgb[1] = rgb[2] = 0.8f; /* a mesh without a colour among coloured ones */
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
                memcpy(out->albedo + 3 * (v0 + v), rgb, sizeof rgb);
        }
        for (unsigned f = 0; f < m->mNumFaces; f++) {
            const struct aiFace *fc = &m->mFaces[f];
            if (fc->mNumIndices != 3)
                continue;
            for (int k = 0; k < 3; k++)
                out->indices[3 * t + k] = (uint32_t)(v0 + fc->mIndices[k]);
            t++;
        }
        v0 += m->mNumVertices;
    }
    out->vertex_count = nv;
    out->triangle_count = nt;
    if ((st = obs_scene_check(out, err)) != OBS_OK) {
        char msg[OBS_ERR_LEN];
        snprintf(msg, sizeof msg, "%s", err ? err : "");
        obs__fail(err, st, "%s: %s", path, msg);
        goto fail;
    }
    aiReleaseImport(sc);
    return OBS_OK;

fail:
    aiReleaseImport(sc);
    obs_scene_free(out);
    return st;
}
