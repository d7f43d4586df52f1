/* A baked level read back for the G-buffer (scene.h, obs_scene_load_baked):
 * glTF 2.0 binary with the per-vertex float attributes _AO, _AO_SHORT and
 * _AO_LONG, as core/bake/glb.c writes them.  assimp cannot carry them
 * (5.2's aiMesh has no place for custom attributes: its glTF importer
 * keeps POSITION, NORMAL, TANGENT, TEXCOORD_n, COLOR_n, JOINTS_n,
 * WEIGHTS_n), so the file is read here with cJSON: the
 * header and chunks, the node graph from the scene's roots (matrix or
 * TRS), each primitive's POSITION, NORMAL, indices and the three
 * attributes, its material's base colour.  Every size and offset is
 * checked against its view and the binary chunk before it is read. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <fnmatch.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "io/glb_read.h"
#include "obscura/scene.h"
#include "ground/scene_internal.h"

/* Depth of the node graph followed (a deeper one is refused: a cycle). */
#define MAX_DEPTH 256
#define MAX_FILE ((size_t)UINT32_MAX)

static const char *const ao_names[3] = {"_AO", "_AO_SHORT", "_AO_LONG"};

static obs_status glb_open(const char *path, obs__glb *g, char err[OBS_ERR_LEN])
{
    memset(g, 0, sizeof *g);
    g->path = path;
    FILE *f = fopen(path, "rb");
    if (!f)
        return obs__fail(err, OBS_IO, "%s: cannot open: %s", path, strerror(errno));
    long n = -1;
    if (fseek(f, 0, SEEK_END) == 0)
        n = ftell(f);
    if (n < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return obs__fail(err, OBS_IO, "%s: cannot read: %s", path, strerror(errno));
    }
    if ((size_t)n > MAX_FILE) {
        fclose(f);
        return obs__fail(err, OBS_TOO_LARGE, "%s: %ld bytes; a .glb holds at most 4 GiB", path, n);
    }
    g->size = (size_t)n;
    g->file = malloc(g->size ? g->size : 1);
    if (!g->file) {
        fclose(f);
        return obs__fail(err, OBS_NO_MEMORY, "%s: %zu bytes", path, g->size);
    }
    size_t got = fread(g->file, 1, g->size, f);
    fclose(f);
    if (got != g->size) {
        obs__glb_free(g);
        return obs__fail(err, OBS_IO, "%s: short read", path);
    }
    const unsigned char *d = g->file;
    if (g->size < 20 || obs__glb_u32(d) != OBS__GLB_MAGIC) {
        obs__glb_free(g);
        return obs__fail(err, OBS_BAD_FILE, "%s: not a glTF binary (.glb)", path);
    }
    /* The header's fields are read before any error frees the file. */
    uint32_t version = obs__glb_u32(d + 4), first = obs__glb_u32(d + 16);
    size_t total = obs__glb_u32(d + 8), jlen = obs__glb_u32(d + 12);
    if (version != 2 || first != OBS__GLB_CHUNK_JSON) {
        obs__glb_free(g);
        return obs__fail(err, OBS_BAD_FILE, "%s: not glTF 2.0 binary (version %u, first chunk "
                                            "not JSON)", path, (unsigned)version);
    }
    if (total > g->size) {
        size_t have = g->size;
        obs__glb_free(g);
        return obs__fail(err, OBS_BAD_FILE, "%s: the header says %zu bytes, the file has %zu "
                                            "(truncated?)", path, total, have);
    }
    if (jlen > total - 20) {
        obs__glb_free(g);
        return obs__fail(err, OBS_BAD_FILE, "%s: JSON chunk of %zu bytes beyond the file", path,
                         jlen);
    }
    g->doc = cJSON_ParseWithLength((const char *)d + 20, jlen);
    if (!g->doc || !cJSON_IsObject(g->doc)) {
        obs__glb_free(g);
        return obs__fail(err, OBS_BAD_FILE, "%s: the JSON chunk does not parse", path);
    }
    g->size = total; /* what follows the header's length is not the file's */
    obs_status st = obs__glb_find_bin(g, jlen, err);
    if (st != OBS_OK)
        obs__glb_free(g);
    return st;
}

static const cJSON *item(const cJSON *o, const char *name)
{
    return cJSON_GetObjectItemCaseSensitive(o, name);
}

/* The node's local matrix (row-major, column vectors): `matrix`
 * (column-major in glTF) or T * R * S. */
static void local_matrix(const cJSON *node, float m[16])
{
    obs__mat4_identity(m);
    const cJSON *mat = item(node, "matrix");
    if (cJSON_IsArray(mat) && cJSON_GetArraySize(mat) == 16) {
        for (int k = 0; k < 16; k++)
            m[4 * (k % 4) + k / 4] = (float)cJSON_GetArrayItem(mat, k)->valuedouble;
        return;
    }
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    const cJSON *jt = item(node, "translation"), *jr = item(node, "rotation"),
                *js = item(node, "scale");
    for (int k = 0; k < 3; k++) {
        if (cJSON_GetArraySize(jt) == 3)
            t[k] = cJSON_GetArrayItem(jt, k)->valuedouble;
        if (cJSON_GetArraySize(js) == 3)
            s[k] = cJSON_GetArrayItem(js, k)->valuedouble;
    }
    if (cJSON_GetArraySize(jr) == 4)
        for (int k = 0; k < 4; k++)
            q[k] = cJSON_GetArrayItem(jr, k)->valuedouble;
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                      {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                      {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            m[4 * i + j] = (float)(r[i][j] * s[j]);
        m[4 * i + 3] = (float)t[i];
    }
}

/* What the walk over the nodes builds. */
typedef struct build {
    const obs__glb *g;
    obs_scene *s;
    int count_only;      /* first pass: sizes */
    size_t nv, nt, nmesh;
    int any_material;
    int has[3];          /* static primitives with _AO, _AO_SHORT, _AO_LONG */
    int prims;           /* static primitives */
    /* dynamic objects (obs_scene_load_baked_dynamic): allowed, the
     * pattern on node names, the nodes it matched, the nodes marked
     * (by the pattern or their extras) */
    int dynamic;
    const char *pattern;
    size_t marked;
} build;

static obs_status primitive(build *b, const cJSON *prim, const char *mname, const char *nname,
                            int pi, const float world[16], int dyn, char err[OBS_ERR_LEN])
{
    const obs__glb *g = b->g;
    char what[300];
    snprintf(what, sizeof what, "mesh '%s' (node '%s') primitive %d", mname, nname, pi);
    long mode = obs__glb_index_of(prim, "mode");
    if (item(prim, "mode") && mode != 4)
        return OBS_OK; /* points and lines have no surface */
    const cJSON *attrs = item(prim, "attributes");
    obs__glb_acc pos, nrm, ind, ao[3];
    obs_status st;
    if ((st = obs__glb_accessor(g, obs__glb_index_of(attrs, "POSITION"), 3, &pos, what, err)) != OBS_OK)
        return st;
    if (pos.ctype != OBS__GLB_FLOAT)
        return obs__fail(err, OBS_BAD_FILE, "%s: %s: POSITION is not float", g->path, what);
    int have[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) {
        if (!item(attrs, ao_names[k]))
            continue;
        if ((st = obs__glb_accessor(g, obs__glb_index_of(attrs, ao_names[k]), 1, &ao[k], what, err)) != OBS_OK)
            return st;
        if (ao[k].ctype != OBS__GLB_FLOAT || ao[k].count != pos.count)
            return obs__fail(err, OBS_BAD_FILE, "%s: %s: %s is not one float per vertex",
                             g->path, what, ao_names[k]);
        have[k] = 1;
    }
    if (!have[0] && !dyn)
        return obs__fail(err, OBS_MISSING_CHANNEL,
                         b->dynamic ? "%s: %s has no _AO attribute and is not marked dynamic (by "
                                      "the pattern on node names or glTF node extras "
                                      "\"obscura_dynamic\": true)"
                                    : "%s: %s has no _AO attribute (not a level baked by obscura "
                                      "bake?)",
                         g->path, what);
    int has_n = item(attrs, "NORMAL") != NULL;
    if (has_n && ((st = obs__glb_accessor(g, obs__glb_index_of(attrs, "NORMAL"), 3, &nrm, what, err)) != OBS_OK))
        return st;
    if (has_n && (nrm.ctype != OBS__GLB_FLOAT || nrm.count != pos.count))
        has_n = 0; /* unusable: the rasteriser takes the face's */
    int has_i = item(prim, "indices") != NULL;
    if (has_i && (st = obs__glb_accessor(g, obs__glb_index_of(prim, "indices"), 1, &ind, what, err)) != OBS_OK)
        return st;
    if (has_i && ind.ctype == OBS__GLB_FLOAT)
        return obs__fail(err, OBS_BAD_FILE, "%s: %s: float indices", g->path, what);
    size_t ni = has_i ? ind.count : pos.count;
    if (ni % 3 != 0)
        return obs__fail(err, OBS_BAD_FILE, "%s: %s: %zu indices, not triangles", g->path, what,
                         ni);
    if (pos.count > (size_t)UINT32_MAX - b->nv)
        return obs__fail(err, OBS_TOO_LARGE, "%s: more than 2^32 vertices", g->path);
    if (b->count_only) {
        for (int k = 0; k < 3 && !dyn; k++)
            b->has[k] += have[k];
        b->prims += !dyn;
        b->nv += pos.count;
        b->nt += ni / 3;
        b->nmesh++;
        b->any_material |= obs__glb_index_of(prim, "material") >= 0;
        return OBS_OK;
    }

    obs_scene *s = b->s;
    float nm[16], inv[16];
    if (obs__mat4_invert(world, inv) != 0)
        obs__mat4_identity(inv); /* a singular node: its normals stay */
    obs__mat4_transpose(inv, nm);
    float rgb[3] = {0.8f, 0.8f, 0.8f};
    const cJSON *mat = cJSON_GetArrayItem(item(g->doc, "materials"), (int)obs__glb_index_of(prim, "material"));
    const cJSON *bc = item(item(mat, "pbrMetallicRoughness"), "baseColorFactor");
    if (obs__glb_index_of(prim, "material") >= 0 && cJSON_GetArraySize(bc) >= 3)
        for (int k = 0; k < 3; k++)
            rgb[k] = (float)cJSON_GetArrayItem(bc, k)->valuedouble;
    for (size_t v = 0; v < pos.count; v++) {
        float p[4] = {obs__glb_float(&pos, v, 0), obs__glb_float(&pos, v, 1), obs__glb_float(&pos, v, 2), 1.0f},
              wp[4];
        obs__mat4_apply(world, p, wp);
        float *dp = s->positions + 3 * (b->nv + v), *dn = s->normals + 3 * (b->nv + v);
        memcpy(dp, wp, 3 * sizeof(float));
        dn[0] = dn[1] = dn[2] = 0.0f;
        if (has_n) {
            float n4[4] = {obs__glb_float(&nrm, v, 0), obs__glb_float(&nrm, v, 1), obs__glb_float(&nrm, v, 2), 0},
                  wn[4];
            obs__mat4_apply(nm, n4, wn);
            float len = sqrtf(wn[0] * wn[0] + wn[1] * wn[1] + wn[2] * wn[2]);
            if (isfinite(len) && len > 1e-12f)
                for (int k = 0; k < 3; k++)
                    dn[k] = wn[k] / len;
        }
        float *db = s->baked + 3 * (b->nv + v);
        for (int k = 0; k < 3; k++)
            db[k] = have[k] && !dyn ? obs__glb_float(&ao[k], v, 0) : 1.0f;
        if (s->albedo)
            memcpy(s->albedo + 3 * (b->nv + v), rgb, sizeof rgb);
    }
    for (size_t i = 0; i < ni; i++) {
        uint32_t ix = has_i ? obs__glb_index(&ind, i) : (uint32_t)i;
        if (ix >= pos.count)
            return obs__fail(err, OBS_BAD_FILE, "%s: %s: index %u of %zu vertices", g->path, what,
                             (unsigned)ix, pos.count);
        s->indices[3 * b->nt + i] = (uint32_t)b->nv + ix;
    }
    obs_scene_mesh *me = &s->meshes[s->mesh_count++];
    me->first_triangle = b->nt;
    me->triangle_count = ni / 3;
    me->dynamic = dyn;
    if (!(me->name = strdup(mname)) || !(me->node = strdup(nname)))
        return obs__fail(err, OBS_NO_MEMORY, "%s: mesh names", g->path);
    b->nv += pos.count;
    b->nt += ni / 3;
    return OBS_OK;
}

/* A node marked dynamic: its name matches the pattern, or its extras
 * say "obscura_dynamic": true. */
static int marked_dynamic(build *b, const cJSON *node, const char *nname)
{
    if (!b->dynamic)
        return 0;
    int by_name = b->pattern && fnmatch(b->pattern, nname, 0) == 0;
    int by_extras = cJSON_IsTrue(item(item(node, "extras"), "obscura_dynamic"));
    if (b->count_only)
        b->marked += by_name || by_extras;
    return by_name || by_extras;
}

static obs_status walk(build *b, long n, const float parent[16], int depth, int dyn,
                       char err[OBS_ERR_LEN])
{
    const cJSON *node = cJSON_GetArrayItem(item(b->g->doc, "nodes"), (int)n);
    if (n < 0)
        return obs__fail(err, OBS_BAD_FILE, "%s: a node index that is not a whole number from 0 "
                                            "to 2^31-1", b->g->path);
    if (!cJSON_IsObject(node))
        return obs__fail(err, OBS_BAD_FILE, "%s: node %ld does not exist", b->g->path, n);
    if (depth > MAX_DEPTH)
        return obs__fail(err, OBS_BAD_FILE, "%s: the node graph is deeper than %d (a cycle?)",
                         b->g->path, MAX_DEPTH);
    float local[16], world[16];
    local_matrix(node, local);
    obs__mat4_mul(parent, local, world);
    const cJSON *nm = item(node, "name");
    const char *nname = cJSON_IsString(nm) ? nm->valuestring : "";
    dyn = marked_dynamic(b, node, nname) || dyn; /* a dynamic node's children move with it */
    long mi = obs__glb_index_of(node, "mesh");
    obs_status st;
    if (item(node, "mesh")) {
        const cJSON *mesh = cJSON_GetArrayItem(item(b->g->doc, "meshes"), (int)mi);
        if (mi < 0 || !cJSON_IsObject(mesh))
            return obs__fail(err, OBS_BAD_FILE, "%s: node '%s': mesh %ld does not exist",
                             b->g->path, nname, mi);
        const cJSON *mn = item(mesh, "name"), *prim;
        const char *mname = cJSON_IsString(mn) ? mn->valuestring : "";
        int pi = 0;
        cJSON_ArrayForEach(prim, item(mesh, "primitives"))
            if ((st = primitive(b, prim, mname, nname, pi++, world, dyn, err)) != OBS_OK)
                return st;
    }
    const cJSON *c;
    cJSON_ArrayForEach(c, item(node, "children"))
        if ((st = walk(b, obs__glb_index_value(c), world, depth + 1, dyn, err)) != OBS_OK)
            return st;
    return OBS_OK;
}

static obs_status walk_scene(build *b, char err[OBS_ERR_LEN])
{
    long si = obs__glb_index_of(b->g->doc, "scene");
    const cJSON *sc = cJSON_GetArrayItem(item(b->g->doc, "scenes"), (int)(si < 0 ? 0 : si)), *r;
    float id[16];
    obs__mat4_identity(id);
    /* a forest, so that the walk visits each node once (a DAG's paths
     * are exponential in its depth) */
    obs_status st = obs__glb_forest(b->g->path, b->g->doc, 0, err); /* walk() bounds the depth */
    cJSON_ArrayForEach(r, item(sc, "nodes"))
        if (st == OBS_OK)
            st = walk(b, obs__glb_index_value(r), id, 0, 0, err);
    return st;
}

int obs_scene_file_is_baked(const char *path)
{
    obs__glb g;
    if (glb_open(path, &g, NULL) != OBS_OK)
        return 0;
    int baked = 0;
    const cJSON *mesh, *prim;
    cJSON_ArrayForEach(mesh, item(g.doc, "meshes"))
        cJSON_ArrayForEach(prim, item(mesh, "primitives"))
            baked |= item(item(prim, "attributes"), "_AO") != NULL;
    obs__glb_free(&g);
    return baked;
}

/* Whether some node of the file has a name matching the pattern. */
static int pattern_matches(const obs__glb *g, const char *pattern)
{
    const cJSON *n;
    cJSON_ArrayForEach(n, item(g->doc, "nodes"))
    {
        const cJSON *nm = item(n, "name");
        if (fnmatch(pattern, cJSON_IsString(nm) ? nm->valuestring : "", 0) == 0)
            return 1;
    }
    return 0;
}

/* The names of the file's nodes, for a pattern that matched none. */
static void node_names(const obs__glb *g, char *buf, size_t len)
{
    size_t at = 0;
    int k = 0;
    const cJSON *n;
    buf[0] = '\0';
    cJSON_ArrayForEach(n, item(g->doc, "nodes"))
    {
        const cJSON *nm = item(n, "name");
        const char *s = cJSON_IsString(nm) ? nm->valuestring : "";
        if (at + strlen(s) + 8 >= len) {
            snprintf(buf + at, len - at, ", ...");
            return;
        }
        at += (size_t)snprintf(buf + at, len - at, "%s'%s'", k++ ? ", " : "", s);
    }
}

static obs_status load(const char *path, int dynamic, const char *pattern, obs_scene *out,
                       size_t *marked, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    if (marked)
        *marked = 0;
    obs__glb g;
    obs_status st = glb_open(path, &g, err);
    if (st != OBS_OK)
        return st;
    build b = {.g = &g, .s = out, .count_only = 1, .dynamic = dynamic, .pattern = pattern};
    if (pattern && !pattern_matches(&g, pattern)) {
        char names[200];
        node_names(&g, names, sizeof names);
        st = obs__fail(err, OBS_INVALID_ARGUMENT, "%s: no node's name matches '%s' (the nodes: "
                                                  "%s)", path, pattern, names);
        goto fail;
    }
    if ((st = walk_scene(&b, err)) != OBS_OK)
        goto fail;
    if (marked)
        *marked = b.marked;
    if (b.nt == 0) {
        st = obs__fail(err, OBS_BAD_FILE, "%s: empty scene: no triangles", path);
        goto fail;
    }
    size_t vbytes, ibytes;
    if (obs__size_mul3(b.nv, 3, sizeof(float), &vbytes) ||
        obs__size_mul3(b.nt, 3, sizeof(uint32_t), &ibytes)) {
        st = obs__fail(err, OBS_TOO_LARGE, "%s: mesh too large", path);
        goto fail;
    }
    out->positions = malloc(vbytes);
    out->normals = malloc(vbytes);
    out->baked = malloc(vbytes);
    out->albedo = b.any_material ? malloc(vbytes) : NULL;
    out->indices = malloc(ibytes);
    out->meshes = calloc(b.nmesh, sizeof *out->meshes);
    if (!out->positions || !out->normals || !out->baked || (b.any_material && !out->albedo) ||
        !out->indices || !out->meshes) {
        st = obs__fail(err, OBS_NO_MEMORY, "%s: %zu vertices, %zu triangles", path, b.nv, b.nt);
        goto fail;
    }
    /* _AO_SHORT and _AO_LONG count where every primitive has them */
    out->baked_mask = 1u | (b.has[1] == b.prims ? 2u : 0u) | (b.has[2] == b.prims ? 4u : 0u);
    build b2 = {.g = &g, .s = out, .dynamic = dynamic, .pattern = pattern};
    if ((st = walk_scene(&b2, err)) != OBS_OK)
        goto fail;
    out->vertex_count = b2.nv;
    out->triangle_count = b2.nt;
    if ((st = obs__scene_check_file(out, path, err)) != OBS_OK)
        goto fail;
    obs__glb_free(&g);
    return OBS_OK;
fail:
    obs__glb_free(&g);
    obs_scene_free(out);
    return st;
}

obs_status obs_scene_load_baked(const char *path, obs_scene *out, char err[OBS_ERR_LEN])
{
    return load(path, 0, NULL, out, NULL, err);
}

obs_status obs_scene_load_baked_dynamic(const char *path, const char *dynamic_nodes,
                                        obs_scene *out, size_t *marked, char err[OBS_ERR_LEN])
{
    return load(path, 1, dynamic_nodes, out, marked, err);
}
