/* What obscura checks around assimp (assimp_read.h), for both loaders
 * (ground/scene.c, level/load.c): a file before it is handed over, the
 * validated scene's faces, assimp's failure as a status and message.  In
 * C: only the importer itself (assimp_read.cpp) is C++. */
#include <assimp/scene.h>
#include <cjson/cJSON.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "ground/assimp_read.h"
#include "internal.h"
#include "io/glb_read.h"

obs_status obs__assimp_fail(const char *path, const char *what, const char *msg,
                            char err[OBS_ERR_LEN])
{
    if (msg && strstr(msg, "bad_alloc")) {
        if (err)
            snprintf(err, OBS_ERR_LEN, "%s: assimp ran out of memory reading it (a count in the "
                                       "file larger than the file holds?)", path);
        return OBS_TOO_LARGE;
    }
    if (err)
        snprintf(err, OBS_ERR_LEN, "%s: not %s assimp can read: %s", path, what,
                 msg && *msg ? msg : "unknown error");
    return OBS_BAD_FILE;
}

/* How much of a PLY file is searched for the end of its header. */
#define PLY_HEADER_MAX ((size_t)1 << 20)

/* A PLY file (f after its first 4 bytes) whose header ends. */
static obs_status ply_header(const char *path, FILE *f, char err[OBS_ERR_LEN])
{
    size_t n;
    /* assimp 5.2's PLY reader, given a header without its end_header
     * line, reads past its buffer (binary) or never returns (ASCII). */
    char *buf = malloc(PLY_HEADER_MAX + 1);
    if (!buf) {
        fclose(f);
        return obs__fail(err, OBS_NO_MEMORY, "%s: PLY header", path);
    }
    n = fread(buf, 1, PLY_HEADER_MAX, f);
    buf[n] = '\0';
    int found = 0;
    for (char *line = buf; !found && line < buf + n;) {
        char *end = memchr(line, '\n', (size_t)(buf + n - line));
        size_t len = end ? (size_t)(end - line) : (size_t)(buf + n - line);
        while (len > 0 && (line[len - 1] == '\r' || line[len - 1] == ' ' || line[len - 1] == '\t'))
            len--;
        found = len == 10 && memcmp(line, "end_header", 10) == 0;
        if (!end)
            break;
        line = end + 1;
    }
    free(buf);
    if (!found)
        return obs__fail(err, OBS_BAD_FILE, "%s: a PLY header without its end_header line%s "
                                            "(damaged or truncated)",
                         path, n == PLY_HEADER_MAX ? " in its first MiB" : "");
    return OBS_OK;
}

/* The JSON of a .glb (f after its first 4 bytes) or a .gltf (whole), of
 * size bytes, checked by obs__glb_forest; what does not parse is assimp's to
 * refuse. */
static obs_status gltf_json(const char *path, FILE *f, int glb, size_t size,
                            char err[OBS_ERR_LEN])
{
    size_t off = 0, len = size;
    if (glb) {
        /* assimp 5.2 allocates a chunk's length before it compares it
         * with the file (4 GiB asked by a damaged 1 KiB file) */
        unsigned char h[24];
        if (fread(h, 1, 16, f) != 16)
            return OBS_OK;
        size_t total = obs__glb_u32(h + 4);
        len = obs__glb_u32(h + 8);
        off = 20;
        if (total > size || len > size - 20)
            return obs__fail(err, OBS_BAD_FILE, "%s: glTF binary of %zu bytes whose header says "
                                                "%zu and its JSON chunk %zu (truncated or "
                                                "damaged)",
                             path, size, total, len);
        size_t at = 20 + ((len + 3) & ~(size_t)3);
        if (at + 8 <= size && fseek(f, (long)at, SEEK_SET) == 0 && fread(h + 16, 1, 8, f) == 8 &&
            obs__glb_u32(h + 16) > size - at - 8)
            return obs__fail(err, OBS_BAD_FILE, "%s: glTF binary chunk of %u bytes past the end "
                                                "of the file (%zu bytes)",
                             path, (unsigned)obs__glb_u32(h + 16), size);
        if (obs__glb_u32(h + 12) != OBS__GLB_CHUNK_JSON)
            return OBS_OK;
    }
    char *txt = malloc(len ? len : 1);
    if (!txt)
        return obs__fail(err, OBS_NO_MEMORY, "%s: %zu bytes of glTF JSON", path, len);
    obs_status st = OBS_OK;
    if (fseek(f, (long)off, SEEK_SET) == 0 && fread(txt, 1, len, f) == len) {
        cJSON *doc = cJSON_ParseWithLength(txt, len);
        if (doc)
            st = obs__glb_forest(path, doc, err);
        cJSON_Delete(doc);
    }
    free(txt);
    return st;
}

obs_status obs__assimp_precheck(const char *path, char err[OBS_ERR_LEN])
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return obs__fail(err, OBS_IO, "%s: cannot open: %s", path, strerror(errno));
    unsigned char head[4] = {0};
    size_t n = fread(head, 1, 4, f);
    obs_status st = OBS_OK;
    size_t plen = strlen(path);
    /* assimp takes any file that starts "ply" (either case) for PLY when
     * its extension's reader refuses it. */
    if (n >= 3 && !strncasecmp((const char *)head, "ply", 3)) {
        st = ply_header(path, f, err);
    } else if ((n == 4 && obs__glb_u32(head) == OBS__GLB_MAGIC) ||
               (plen >= 5 && !strcasecmp(path + plen - 5, ".gltf"))) {
        long size = -1;
        if (fseek(f, 0, SEEK_END) == 0)
            size = ftell(f);
        if (size >= 20 && fseek(f, 4, SEEK_SET) == 0)
            st = gltf_json(path, f, obs__glb_u32(head) == OBS__GLB_MAGIC, (size_t)size, err);
    }
    fclose(f);
    return st;
}

obs_status obs__assimp_faces(const char *path, const struct aiScene *sc, char err[OBS_ERR_LEN])
{
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        for (unsigned f = 0; f < m->mNumFaces; f++)
            if (m->mFaces[f].mNumIndices == 0)
                return obs__fail(err, OBS_BAD_FILE, "%s: mesh %u '%s': face %u has no vertices",
                                 path, i, m->mName.data, f);
    }
    return OBS_OK;
}
