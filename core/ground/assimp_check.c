/* What obscura checks around assimp (assimp_read.h), for both loaders
 * (ground/scene.c, level/load.c): a file before it is handed over, the
 * validated scene's faces, assimp's failure as a status and message.  In
 * C: only the importer itself (assimp_read.cpp) is C++. */
#include <assimp/scene.h>
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
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

/* How deep a file's hierarchy (glTF nodes, AC3D objects) may be.  assimp
 * 5.2 reads, converts and post-processes the node tree recursively on the
 * caller's stack: with 8 MiB of stack it crashed (SEGV) between 5000 and
 * 8000 nested AC3D objects and between 8000 and 20000 nested glTF nodes.
 * A quarter of the smallest leaves room for smaller thread stacks; real
 * scenes nest a few levels. */
#define HIERARCHY_MAX 1024

/* How much of a PLY file is searched for the end of its header. */
#define PLY_HEADER_MAX ((size_t)1 << 20)

/* A PLY file (f after its first 4 bytes) whose header ends. */
static obs_status ply_header(const char *path, FILE *f, char err[OBS_ERR_LEN])
{
    size_t n;
    /* assimp 5.2's PLY reader, given a header without its end_header
     * line, reads past its buffer (binary) or never returns (ASCII). */
    char *buf = malloc(PLY_HEADER_MAX + 1);
    if (!buf) /* f is the caller's to close */
        return obs__fail(err, OBS_NO_MEMORY, "%s: PLY header", path);
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

/* What assimp 5.2 takes for glTF 2.0 before it reads a .gltf or .glb: both
 * its glTF readers claim the two extensions, and when both refuse a file
 * assimp offers it to every other reader it has, by content (a damaged .glb
 * reached the OpenGEX reader, which read past its buffer).  So the file
 * must be what the glTF 2.0 specification defines: a .glb starts with the
 * magic "glTF" and version 2 ("GLB File Format Specification"), a .gltf does
 * not; the JSON is one value (its chunk may be padded with spaces, or
 * zeros, which end the text for assimp) and an object whose "asset" holds
 * a "version" string "2..." ("asset" is required).  The document, parsed,
 * goes to *doc. */
static obs_status gltf_document(const char *path, int glb, const char *txt, size_t len,
                                cJSON **doc, char err[OBS_ERR_LEN])
{
    const char *end = NULL;
    *doc = cJSON_ParseWithLengthOpts(txt, len, &end, 0);
    const char *what = NULL;
    if (!*doc) {
        what = "is not JSON";
    } else {
        while (end < txt + len && (*end == ' ' || *end == '\t' || *end == '\r' || *end == '\n'))
            end++;
        const cJSON *asset = cJSON_GetObjectItemCaseSensitive(*doc, "asset");
        const cJSON *version = cJSON_GetObjectItemCaseSensitive(asset, "version");
        if (end < txt + len && *end != '\0')
            what = "has text after its JSON value";
        else if (!cJSON_IsObject(*doc))
            what = "is not a JSON object";
        else if (!cJSON_IsObject(asset))
            what = "has no \"asset\" object";
        else if (!cJSON_IsString(version) || version->valuestring[0] != '2')
            what = "has no \"asset\" \"version\" 2.x";
    }
    if (!what)
        return OBS_OK;
    cJSON_Delete(*doc);
    *doc = NULL;
    return obs__fail(err, OBS_BAD_FILE, "%s: not glTF 2.0: its %s %s", path,
                     glb ? "JSON chunk" : "text", what);
}

/* The first 8 bytes of a file named .gltf or .glb (head, n of them read):
 * a .glb is a glTF binary of version 2, a .gltf is not a binary. */
static obs_status glb_header(const char *path, const unsigned char *head, size_t n, int named_glb,
                             char err[OBS_ERR_LEN])
{
    int magic = n >= 4 && obs__glb_u32(head) == OBS__GLB_MAGIC;
    if (named_glb && !magic)
        return obs__fail(err, OBS_BAD_FILE, "%s: not a glTF binary (a .glb starts with the "
                                            "magic \"glTF\")", path);
    if (!named_glb && magic)
        return obs__fail(err, OBS_BAD_FILE, "%s: a glTF binary named .gltf (name it .glb)", path);
    if (magic && (n < 8 || obs__glb_u32(head + 4) != 2))
        return obs__fail(err, OBS_BAD_FILE, "%s: glTF binary of version %u, not 2", path,
                         n < 8 ? 0u : (unsigned)obs__glb_u32(head + 4));
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
            return obs__fail(err, OBS_BAD_FILE, "%s: glTF binary whose first chunk is not its "
                                                "JSON", path);
    }
    char *txt = malloc(len ? len : 1);
    if (!txt)
        return obs__fail(err, OBS_NO_MEMORY, "%s: %zu bytes of glTF JSON", path, len);
    obs_status st = OBS_OK;
    if (fseek(f, (long)off, SEEK_SET) == 0 && fread(txt, 1, len, f) == len) {
        cJSON *doc = NULL;
        st = gltf_document(path, glb, txt, len, &doc, err);
        if (st == OBS_OK) /* assimp walks the node tree recursively */
            st = obs__glb_forest(path, doc, HIERARCHY_MAX, err);
        cJSON_Delete(doc);
    }
    free(txt);
    return st;
}

/* ---- AC3D (AC3Db, TORCS's .acc) as assimp 5.2's reader walks it ----------
 * The format (one keyword per line): a header "AC3D" plus a version digit,
 * MATERIAL lines, then OBJECT blocks.  An object has optional numvert n
 * (n lines "x y z ..."), optional numsurf n (n surfaces: "SURF flags",
 * "mat m", "refs k" then k lines "vertex-index u v"), and ends with
 * "kids n", followed by its n child OBJECTs.  assimp's reader trusts every
 * count: it reserves what numsurf, refs and kids say before reading them,
 * takes the lines after a short numvert or refs list as more of the same,
 * and reads a triangle strip of fewer than 3 references (flags type 4)
 * before the start of an empty list (SEGV).  So the walk below checks the
 * structure before assimp sees the file. */

struct ac_walk {
    const char *p, *end; /* the next line */
    const char *s;       /* the current line, leading blanks skipped */
    size_t len;          /* its length without the line end */
    unsigned long no;    /* its line number, from 1 */
};

/* The next line that is not blank; 0 at the end of the file. */
static int ac_next(struct ac_walk *w)
{
    while (w->p < w->end) {
        const char *nl = memchr(w->p, '\n', (size_t)(w->end - w->p));
        const char *e = nl ? nl : w->end;
        w->no++;
        w->s = w->p;
        w->p = nl ? nl + 1 : w->end;
        while (w->s < e && (*w->s == ' ' || *w->s == '\t'))
            w->s++;
        w->len = (size_t)(e - w->s);
        while (w->len > 0 && (w->s[w->len - 1] == '\r' || w->s[w->len - 1] == ' ' ||
                              w->s[w->len - 1] == '\t'))
            w->len--;
        if (w->len > 0)
            return 1;
    }
    return 0;
}

/* The current line starts with keyword tok (followed by a blank or its end). */
static int ac_is(const struct ac_walk *w, const char *tok)
{
    size_t n = strlen(tok);
    return w->len >= n && memcmp(w->s, tok, n) == 0 &&
           (w->len == n || w->s[n] == ' ' || w->s[n] == '\t');
}

/* The unsigned number at s (len bytes, after blanks): base 10, or the C
 * prefixes when c_style (SURF's flags); -1 when there is none or it passes
 * 2^32 - 1 (assimp reads 32 bits). */
static long long ac_uint(const char *s, size_t len, int c_style)
{
    char num[24];
    size_t i = 0, n = 0;
    while (i < len && (s[i] == ' ' || s[i] == '\t'))
        i++;
    while (i < len && n + 1 < sizeof num && s[i] != ' ' && s[i] != '\t')
        num[n++] = s[i++];
    num[n] = '\0';
    if (n == 0 || num[0] < '0' || num[0] > '9')
        return -1;
    char *e;
    errno = 0;
    unsigned long long v = strtoull(num, &e, c_style ? 0 : 10);
    if (errno || e == num || v > 0xffffffffull)
        return -1;
    return (long long)v;
}

/* The count after keyword tok on the current line. */
static long long ac_count(const struct ac_walk *w, const char *tok)
{
    return ac_uint(w->s + strlen(tok), w->len - strlen(tok), 0);
}

/* The current line holds at least k numbers (a vertex: x y z). */
static int ac_numbers(const struct ac_walk *w, int k)
{
    char buf[256];
    size_t n = w->len < sizeof buf - 1 ? w->len : sizeof buf - 1;
    memcpy(buf, w->s, n);
    buf[n] = '\0';
    char *q = buf;
    for (int i = 0; i < k; i++) {
        char *e;
        (void)strtod(q, &e);
        if (e == q)
            return 0;
        q = e;
    }
    return 1;
}

#define AC_FAIL(...) obs__fail(err, OBS_BAD_FILE, __VA_ARGS__)

/* One surface, the current line its SURF: its type, its references within
 * the object's nvert vertices (checked by the caller once all are known:
 * max_ref) and material (max_mat).  Leaves w on the line after it; *more is
 * 0 at the end of the file. */
static obs_status ac_surface(const char *path, struct ac_walk *w, long long *max_ref,
                             long long *max_mat, long long *corners, int *more,
                             char err[OBS_ERR_LEN])
{
    static const char *const type_name[] = {"polygon", "closed line", "line", "", "triangle strip"};
    static const int min_refs[] = {1, 2, 2, 0, 3};
    unsigned long at = w->no;
    long long flags = ac_uint(w->s + 4, w->len - 4, 1);
    if (flags < 0)
        return AC_FAIL("%s: line %lu: SURF without its flags (AC3D)", path, at);
    unsigned type = (unsigned)flags & 0xf;
    if (type > 4 || type == 3)
        return AC_FAIL("%s: line %lu: surface type %u is none of AC3D's (0 polygon, 1 closed "
                       "line, 2 line, 4 triangle strip)", path, at, type);
    long long refs = 0;
    int have_refs = 0;
    while ((*more = ac_next(w))) {
        if (ac_is(w, "mat")) {
            long long m = ac_count(w, "mat");
            if (m < 0)
                return AC_FAIL("%s: line %lu: mat without its material index (AC3D)", path, w->no);
            if (m > *max_mat)
                *max_mat = m;
        } else if (ac_is(w, "refs")) {
            long long k = ac_count(w, "refs");
            if (k < 0)
                return AC_FAIL("%s: line %lu: refs without its count (AC3D)", path, w->no);
            have_refs = 1;
            for (long long i = 0; i < k; i++) {
                if (!ac_next(w))
                    return AC_FAIL("%s: line %lu: refs %lld, but the file ends after %lld of them "
                                   "(AC3D, truncated?)", path, at, k, i);
                long long v = ac_uint(w->s, w->len, 0);
                if (v < 0)
                    return AC_FAIL("%s: line %lu: refs %lld, but this line is not its vertex "
                                   "reference %lld (AC3D)", path, w->no, k, i);
                if (v > *max_ref)
                    *max_ref = v;
            }
            refs += k;
        } else {
            break;
        }
    }
    if (!have_refs)
        return AC_FAIL("%s: line %lu: surface without its refs line (AC3D)", path, at);
    if (refs < min_refs[type])
        return AC_FAIL("%s: line %lu: a %s of %lld vertex references (AC3D needs at least %d)",
                       path, at, type_name[type], refs, min_refs[type]);
    *corners += refs;
    return OBS_OK;
}

/* The file's objects and their counts; buf holds the whole file (size
 * bytes). */
static obs_status ac_objects(const char *path, const char *buf, size_t size,
                             uint64_t max_faces, char err[OBS_ERR_LEN])
{
    double total = 0.0; /* triangles of the objects walked, subdivided */
    struct ac_walk w = {buf, buf + size, NULL, 0, 0};
    if (!ac_next(&w) || w.len < 4 || memcmp(w.s, "AC3D", 4) != 0)
        return AC_FAIL("%s: not an AC3D file (its first line is not AC3D and a version)", path);
    long long materials = 0, max_mat = -1;
    long long pending[HIERARCHY_MAX + 1]; /* children still to come, per level */
    int levels = 0;
    int more = ac_next(&w);
    while (more) {
        if (ac_is(&w, "MATERIAL")) {
            materials++;
            more = ac_next(&w);
            continue;
        }
        if (!ac_is(&w, "OBJECT")) {
            more = ac_next(&w); /* assimp skips what it does not know */
            continue;
        }
        /* One object, the current line its OBJECT: a child of the
         * innermost object still owed children, if any. */
        while (levels > 0 && pending[levels - 1] == 0)
            levels--;
        if (levels > 0)
            pending[levels - 1]--;
        unsigned long at = w.no;
        long long nvert = 0, max_ref = -1, nsurf = 0, corners = 0, subdiv = 0;
        int kids = 0;
        more = ac_next(&w);
        while (more && !kids) {
            if (ac_is(&w, "numvert")) {
                long long n = ac_count(&w, "numvert");
                if (n < 0)
                    return AC_FAIL("%s: line %lu: numvert without its count (AC3D)", path, w.no);
                unsigned long line = w.no;
                for (long long i = 0; i < n; i++) {
                    if (!ac_next(&w))
                        return AC_FAIL("%s: line %lu: numvert %lld, but the file ends after %lld "
                                       "vertices (AC3D, truncated?)", path, line, n, i);
                    if (!ac_numbers(&w, 3))
                        return AC_FAIL("%s: line %lu: numvert %lld, but line %lu is not a "
                                       "vertex x y z (AC3D)", path, line, n, w.no);
                }
                nvert += n;
                more = ac_next(&w);
            } else if (ac_is(&w, "numsurf")) {
                long long n = ac_count(&w, "numsurf");
                if (n < 0)
                    return AC_FAIL("%s: line %lu: numsurf without its count (AC3D)", path, w.no);
                unsigned long line = w.no;
                more = ac_next(&w);
                for (long long i = 0; i < n; i++) {
                    if (!more || !ac_is(&w, "SURF"))
                        return AC_FAIL("%s: line %lu: numsurf %lld, but surface %lld %s (AC3D)",
                                       path, line, n, i,
                                       more ? "does not start with SURF" : "is past the end");
                    obs_status st = ac_surface(path, &w, &max_ref, &max_mat, &corners, &more, err);
                    if (st != OBS_OK)
                        return st;
                }
                nsurf += n;
            } else if (ac_is(&w, "subdiv")) {
                subdiv = ac_count(&w, "subdiv");
                if (subdiv < 0)
                    return AC_FAIL("%s: line %lu: subdiv without its level (AC3D)", path, w.no);
                more = ac_next(&w);
            } else if (ac_is(&w, "kids")) {
                long long n = ac_count(&w, "kids");
                /* each child is at least a line "OBJECT" */
                if (n < 0)
                    return AC_FAIL("%s: line %lu: kids without its count (AC3D)", path, w.no);
                if ((unsigned long long)n > (size_t)(w.end - w.p) / 7)
                    return AC_FAIL("%s: line %lu: kids %lld: more children than the %zu bytes "
                                   "after it could hold (AC3D)", path, w.no, n,
                                   (size_t)(w.end - w.p));
                if (n > 0 && levels == HIERARCHY_MAX)
                    return AC_FAIL("%s: line %lu: objects nested deeper than %d levels (AC3D)",
                                   path, w.no, HIERARCHY_MAX);
                if (n > 0)
                    pending[levels++] = n;
                kids = 1;
                more = ac_next(&w);
                if (n > 0 && more && !ac_is(&w, "OBJECT"))
                    return AC_FAIL("%s: line %lu: kids %lld, but the next line is no OBJECT "
                                   "(AC3D)", path, w.no - 1, n);
            } else {
                more = ac_next(&w);
            }
        }
        if (max_ref >= nvert)
            return AC_FAIL("%s: line %lu: a surface refers to vertex %lld of an object of %lld "
                           "vertices (AC3D)", path, at, max_ref, nvert);
        /* assimp subdivides the object subdiv times (Catmull-Clark): the
         * first level turns each n-gon into n quads, each further level
         * each quad into 4, and a quad is 2 triangles */
        double tris = subdiv > 0 ? 2.0 * (double)corners * pow(4.0, (double)(subdiv - 1))
                                 : (double)nsurf;
        total += tris;
        if (subdiv > 0 && total > (double)max_faces)
            return obs__fail(err, OBS_TOO_LARGE,
                             "%s: line %lu: subdiv %lld of an object of %lld surfaces makes "
                             "%.4g triangles; with the objects before it more than the %llu "
                             "allowed (a bake's max_triangles, else assimp's 32-bit face "
                             "count; AC3D: assimp subdivides while it reads the file)", path, at, subdiv, nsurf, total,
                             (unsigned long long)max_faces);
    }
    if (max_mat >= (materials ? materials : 1))
        return AC_FAIL("%s: a surface uses material %lld of the file's %lld MATERIAL lines "
                       "(AC3D)", path, max_mat, materials);
    return OBS_OK;
}

/* An AC3D file (f at its start, size bytes) walked by ac_objects. */
static obs_status ac3d_structure(const char *path, FILE *f, size_t size, uint64_t max_faces,
                                 char err[OBS_ERR_LEN])
{
    char *buf = malloc(size ? size : 1);
    if (!buf)
        return obs__fail(err, OBS_NO_MEMORY, "%s: %zu bytes of AC3D", path, size);
    obs_status st = fseek(f, 0, SEEK_SET) == 0 && fread(buf, 1, size, f) == size
                        ? ac_objects(path, buf, size, max_faces, err)
                        : obs__fail(err, OBS_IO, "%s: cannot read it", path);
    free(buf);
    return st;
}

/* ---- OFF: the counts in its header against the file's size ---------------
 * An OFF file starts with an optional keyword ([ST][C][N][4][n]OFF, 'n'
 * followed by the dimension), then the vertex, face and edge counts, then
 * the vertices and the faces, each at least a number and a separator.
 * assimp 5.2's OFF reader allocates what the counts say before it reads
 * anything (45 GB asked by a damaged file of 258 bytes). */

/* Past blanks, line ends and '#' comments from buf[*at] (size bytes). */
static void off_skip(const char *buf, size_t size, size_t *at)
{
    size_t i = *at;
    for (;;) {
        while (i < size && (buf[i] == ' ' || buf[i] == '\t' || buf[i] == '\r' || buf[i] == '\n'))
            i++;
        if (i >= size || buf[i] != '#')
            break;
        while (i < size && buf[i] != '\n')
            i++;
    }
    *at = i;
}

/* The decimal digits at buf[*at] as assimp reads a count (0 when there are
 * none), *at moved past them; -1 past 2^32 - 1. */
static long long off_uint(const char *buf, size_t size, size_t *at)
{
    unsigned long long v = 0;
    int over = 0;
    for (; *at < size && buf[*at] >= '0' && buf[*at] <= '9'; ++*at)
        if (!over && (v = v * 10 + (unsigned)(buf[*at] - '0')) > 0xffffffffull)
            over = 1;
    return over ? -1 : (long long)v;
}

/* The header read as assimp 5.2 reads it: the keyword's letters one by
 * one (they may run into the counts), then the counts. */
static obs_status off_counts(const char *path, FILE *f, char err[OBS_ERR_LEN])
{
    long end = -1;
    if (fseek(f, 0, SEEK_END) == 0)
        end = ftell(f);
    if (end < 0 || fseek(f, 0, SEEK_SET) != 0)
        return OBS_OK; /* assimp's to refuse */
    char buf[4096];
    size_t size = fread(buf, 1, sizeof buf, f), at = 0;
    off_skip(buf, size, &at);
    if (at + 2 <= size && buf[at] == 'S' && buf[at + 1] == 'T')
        at += 2;
    at += at < size && buf[at] == 'C';
    at += at < size && buf[at] == 'N';
    at += at < size && buf[at] == '4';
    int dim = at < size && buf[at] == 'n';
    at += dim;
    if (at + 3 <= size && memcmp(buf + at, "OFF", 3) == 0) {
        at += 3;
        off_skip(buf, size, &at);
        if (dim) {
            (void)off_uint(buf, size, &at);
            off_skip(buf, size, &at);
        }
    }
    off_skip(buf, size, &at);
    long long nv = off_uint(buf, size, &at);
    off_skip(buf, size, &at);
    long long nf = off_uint(buf, size, &at);
    off_skip(buf, size, &at);
    (void)off_uint(buf, size, &at); /* the edge count */
    if (at == size && size == sizeof buf)
        return obs__fail(err, OBS_BAD_FILE, "%s: an OFF header longer than %zu bytes", path,
                         sizeof buf);
    unsigned long long rest = (unsigned long long)end - at;
    if (nv < 0 || nf < 0)
        return obs__fail(err, OBS_BAD_FILE, "%s: an OFF header count past 2^32 - 1", path);
    if ((unsigned long long)nv + (unsigned long long)nf > rest / 2)
        return obs__fail(err, OBS_BAD_FILE, "%s: OFF header of %lld vertices and %lld faces, "
                                            "more than the %llu bytes after it hold (each is "
                                            "at least a number and a separator)",
                         path, nv, nf, rest);
    return OBS_OK;
}

obs_status obs__assimp_precheck(const char *path, uint64_t max_faces, char err[OBS_ERR_LEN])
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return obs__fail(err, OBS_IO, "%s: cannot open: %s", path, strerror(errno));
    unsigned char head[8] = {0};
    size_t n = fread(head, 1, 8, f);
    obs_status st = OBS_OK;
    /* assimp takes any file that starts "ply" (either case) for PLY when
     * its extension's reader refuses it. */
    const char *ext = strrchr(path, '.');
    if (n >= 3 && !strncasecmp((const char *)head, "ply", 3)) {
        st = ply_header(path, f, err);
    } else if ((n >= 4 && obs__glb_u32(head) == OBS__GLB_MAGIC) ||
               (ext && (!strcasecmp(ext, ".gltf") || !strcasecmp(ext, ".glb")))) {
        long size = -1;
        if (fseek(f, 0, SEEK_END) == 0)
            size = ftell(f);
        if (ext && (!strcasecmp(ext, ".gltf") || !strcasecmp(ext, ".glb")))
            st = glb_header(path, head, n, !strcasecmp(ext, ".glb"), err);
        if (st == OBS_OK && size >= 0 && size < 20)
            st = obs__fail(err, OBS_BAD_FILE, "%s: %ld bytes, too short for glTF 2.0", path, size);
        else if (st == OBS_OK && size >= 20 && fseek(f, 4, SEEK_SET) == 0)
            st = gltf_json(path, f, obs__glb_u32(head) == OBS__GLB_MAGIC, (size_t)size, err);
    } else if ((n >= 4 && !memcmp(head, "AC3D", 4)) ||
               (ext && (!strcasecmp(ext, ".ac") || !strcasecmp(ext, ".acc") ||
                        !strcasecmp(ext, ".ac3d")))) {
        long size = -1;
        if (fseek(f, 0, SEEK_END) == 0)
            size = ftell(f);
        if (size >= 0)
            st = ac3d_structure(path, f, (size_t)size, max_faces, err);
    } else if (ext && !strcasecmp(ext, ".off")) {
        st = off_counts(path, f, err);
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
