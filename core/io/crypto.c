/* Cryptomatte in an EXR header: the layers, their rank channels and their
 * manifests (in the header or in a side-car file), and the hash that makes
 * a name's ID.  Psyop/Cryptomatte, specification/
 * cryptomatte_specification.pdf (v1.2): "Metadata" (the
 * cryptomatte/<key>/ attributes), "Channels" (<name>00.. with two ID and
 * coverage ranks each), "Hashing" (MurmurHash3_32 and the float
 * conversion).  The manifest is JSON (cJSON). */
#include <cjson/cJSON.h>
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "io/crypto.h"
#include "io/exr_internal.h"
#include "obscura/mask.h"

/* Side-car manifests larger than this are refused (a manifest of a
 * million names is about 40 MB). */
#define MAX_MANIFEST_BYTES ((long)256 << 20)

/* ---- MurmurHash3_x86_32 ----------------------------------------------------
 * Austin Appleby's MurmurHash3.cpp (public domain), MurmurHash3_x86_32, as
 * the Cryptomatte specification names it ("Hashing": MurmurHash3_32 of the
 * name's UTF-8 bytes, seed 0).  Blocks are read little-endian byte by
 * byte, so the result does not depend on the host. Debian has it as
 * libmurmurhash (lmmh_x86_32), a runtime library for these 30 lines. */
static uint32_t rotl32(uint32_t x, int r)
{
    return (x << r) | (x >> (32 - r));
}

static uint32_t fmix32(uint32_t h)
{
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

uint32_t obs_murmur3_32(const void *key, size_t len, uint32_t seed)
{
    const unsigned char *data = key;
    const size_t nblocks = len / 4;
    const uint32_t c1 = 0xcc9e2d51u, c2 = 0x1b873593u;
    uint32_t h1 = seed;
    for (size_t i = 0; i < nblocks; i++) {
        const unsigned char *b = data + 4 * i;
        uint32_t k1 = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 |
                      (uint32_t)b[3] << 24;
        k1 *= c1;
        k1 = rotl32(k1, 15);
        k1 *= c2;
        h1 ^= k1;
        h1 = rotl32(h1, 13);
        h1 = h1 * 5 + 0xe6546b64u;
    }
    const unsigned char *tail = data + nblocks * 4;
    uint32_t k1 = 0;
    switch (len & 3) {
    case 3: k1 ^= (uint32_t)tail[2] << 16; /* fall through */
    case 2: k1 ^= (uint32_t)tail[1] << 8;  /* fall through */
    case 1:
        k1 ^= tail[0];
        k1 *= c1;
        k1 = rotl32(k1, 15);
        k1 *= c2;
        h1 ^= k1;
    }
    h1 ^= (uint32_t)len;
    return fmix32(h1);
}

uint32_t obs_crypto_name_id(const char *name)
{
    uint32_t h = obs_murmur3_32(name, strlen(name), 0);
    /* uint32_to_float32: an exponent of 0 (denormal) or 255 (inf, NaN) is
     * moved by flipping its lowest bit */
    uint32_t e = (h >> 23) & 255u;
    if (e == 0 || e == 255)
        h ^= 1u << 23;
    return h;
}

/* ---- the manifest ------------------------------------------------------- */

/* JSON object name -> hex ID into L; 0, or -1 with why in L's error. */
static int parse_manifest(obs_crypto_layer *L, const char *text, const char *where)
{
    cJSON *root = cJSON_Parse(text);
    int rc = -1;
    if (!root || !cJSON_IsObject(root)) {
        snprintf(L->manifest_error, sizeof L->manifest_error,
                 "Cryptomatte layer '%s': the manifest (%s) is not a JSON object", L->name,
                 where);
        goto done;
    }
    int n = cJSON_GetArraySize(root);
    L->names = calloc((size_t)n + 1, sizeof *L->names);
    L->ids = calloc((size_t)n + 1, sizeof *L->ids);
    if (!L->names || !L->ids) {
        snprintf(L->manifest_error, sizeof L->manifest_error, "out of memory: manifest of %d names", n);
        goto done;
    }
    const cJSON *e;
    cJSON_ArrayForEach(e, root)
    {
        const char *hex = cJSON_GetStringValue(e);
        char *end = NULL;
        unsigned long v = hex ? strtoul(hex, &end, 16) : 0;
        if (!hex || !*hex || strlen(hex) > 8 || *end || !isxdigit((unsigned char)hex[0])) {
            snprintf(L->manifest_error, sizeof L->manifest_error,
                     "Cryptomatte layer '%s': manifest (%s) entry '%.128s' is not an ID of 1 "
                     "to 8 hex digits",
                     L->name, where, e->string ? e->string : "");
            goto done;
        }
        if (!(L->names[L->entry_count] = strdup(e->string ? e->string : ""))) {
            snprintf(L->manifest_error, sizeof L->manifest_error, "out of memory: manifest name");
            goto done;
        }
        L->ids[L->entry_count++] = (uint32_t)v;
    }
    rc = 0;
done:
    cJSON_Delete(root);
    return rc;
}

/* The side-car file: relative to the image's folder (the specification:
 * "relative to the directory of the image"). */
static void read_sidecar(obs_crypto_layer *L, const char *image_path)
{
    char file[1200];
    if (!image_path) {
        snprintf(L->manifest_error, sizeof L->manifest_error,
                 "Cryptomatte layer '%.100s': its manifest is in a side-car file '%.160s', which "
                 "cannot be read for an image sent as a request body (put the manifest in "
                 "the header)",
                 L->name, L->manif_file);
        return;
    }
    const char *slash = strrchr(image_path, '/');
    if (L->manif_file[0] == '/' || !slash)
        snprintf(file, sizeof file, "%s", L->manif_file);
    else
        snprintf(file, sizeof file, "%.*s/%s", (int)(slash - image_path), image_path,
                 L->manif_file);
    FILE *fp = fopen(file, "rb");
    if (!fp) {
        snprintf(L->manifest_error, sizeof L->manifest_error,
                 "Cryptomatte layer '%.100s': its side-car manifest '%.100s' (manif_file) is "
                 "missing: %.160s not found; put it beside the image",
                 L->name, L->manif_file, file);
        return;
    }
    char *text = NULL;
    long size = -1;
    if (fseek(fp, 0, SEEK_END) == 0)
        size = ftell(fp);
    if (size < 0 || size > MAX_MANIFEST_BYTES || fseek(fp, 0, SEEK_SET) != 0 ||
        !(text = malloc((size_t)size + 1)) || fread(text, 1, (size_t)size, fp) != (size_t)size) {
        snprintf(L->manifest_error, sizeof L->manifest_error,
                 "Cryptomatte layer '%.100s': side-car manifest %.200s unreadable or over %ld bytes",
                 L->name, file, MAX_MANIFEST_BYTES);
    } else {
        text[size] = 0;
        parse_manifest(L, text, file);
    }
    free(text);
    fclose(fp);
}

/* ---- the header --------------------------------------------------------- */

/* The layer of key in info, added when new; NULL when out of memory. */
static obs_crypto_layer *layer_of(obs_crypto_info *info, const char *key, size_t klen)
{
    for (int i = 0; i < info->layer_count; i++)
        if (strlen(info->layers[i].key) == klen && !strncmp(info->layers[i].key, key, klen))
            return &info->layers[i];
    obs_crypto_layer *v = realloc(info->layers, (size_t)(info->layer_count + 1) * sizeof *v);
    if (!v)
        return NULL;
    info->layers = v;
    obs_crypto_layer *L = &v[info->layer_count++];
    memset(L, 0, sizeof *L);
    snprintf(L->key, sizeof L->key, "%.*s", (int)(klen < 15 ? klen : 15), key);
    return L;
}

int obs__crypto_is_id_channel(const char *name)
{
    static const char *const ids[] = {"id", "ID", "IndexOB", "IndexMA", "object_id",
                                      "objectId", "ObjectID", "RenderID", NULL};
    /* the last component, or the one before a one-letter channel (Blender's
     * ViewLayer.IndexOB.X) */
    char buf[256];
    snprintf(buf, sizeof buf, "%s", name);
    char *dot = strrchr(buf, '.');
    if (dot && strlen(dot + 1) == 1 && dot != buf) {
        *dot = 0;
        dot = strrchr(buf, '.');
    }
    const char *last = dot ? dot + 1 : buf;
    for (int i = 0; ids[i]; i++)
        if (!strcmp(last, ids[i]))
            return 1;
    return 0;
}

/* The channel name of rank set s, component c (0 R .. 3 A) of L: .R/.G/.B/.A
 * as the specification names them, .red/.green/.blue/.alpha (Nuke), or
 * .r/.g/.b/.a (Blender's multilayer EXR writes its Cryptomatte passes in
 * lower case, e.g. ViewLayer.CryptoObject00.r). */
void obs__crypto_channel(const obs_crypto_layer *L, int s, int c, char *buf, size_t len)
{
    static const char *const styles[3][4] = {
        {"R", "G", "B", "A"}, {"red", "green", "blue", "alpha"}, {"r", "g", "b", "a"}};
    int k = L->red_style >= 0 && L->red_style < 3 ? L->red_style : 0;
    snprintf(buf, len, "%s%02d.%s", L->name, s, styles[k][c]);
}

static int has_channel(const exr_attr_chlist_t *cl, const char *name)
{
    for (int i = 0; i < cl->num_channels; i++)
        if (!strcmp(cl->entries[i].name.str, name))
            return 1;
    return 0;
}

typedef struct {
    const char *path;
    obs_crypto_info *info;
} describe_job;

static obs_status describe_part(exr_context_t ctx, int part, describe_job *j, char why[OBS_ERR_LEN])
{
    obs_crypto_info *info = j->info;
    int32_t count = 0;
    exr_result_t rv = exr_get_attribute_count(ctx, part, &count);
    if (rv != EXR_ERR_SUCCESS)
        return obs__exr_fail(why, rv, "attribute count");
    for (int32_t i = 0; i < count; i++) {
        const exr_attribute_t *a = NULL;
        if (exr_get_attribute_by_index(ctx, part, EXR_ATTR_LIST_FILE_ORDER, i, &a) !=
                EXR_ERR_SUCCESS ||
            !a || a->type != EXR_ATTR_STRING || !a->string || !a->string->str)
            continue;
        if (strncmp(a->name, "cryptomatte/", 12))
            continue;
        const char *key = a->name + 12, *slash = strchr(key, '/');
        if (!slash)
            continue;
        obs_crypto_layer *L = layer_of(info, key, (size_t)(slash - key));
        if (!L)
            return obs__fail(why, OBS_NO_MEMORY, "Cryptomatte layers");
        const char *field = slash + 1, *v = a->string->str;
        if (!strcmp(field, "name"))
            snprintf(L->name, sizeof L->name, "%s", v);
        else if (!strcmp(field, "hash"))
            snprintf(L->hash, sizeof L->hash, "%s", v);
        else if (!strcmp(field, "conversion"))
            snprintf(L->conversion, sizeof L->conversion, "%s", v);
        else if (!strcmp(field, "manif_file"))
            snprintf(L->manif_file, sizeof L->manif_file, "%s", v);
        else if (!strcmp(field, "manifest") && !L->names)
            parse_manifest(L, v, "header");
    }
    const exr_attr_chlist_t *cl = NULL;
    if ((rv = exr_get_channels(ctx, part, &cl)) != EXR_ERR_SUCCESS)
        return obs__exr_fail(why, rv, "channel list");
    for (int i = 0; i < info->layer_count; i++) {
        obs_crypto_layer *L = &info->layers[i];
        char ch[160];
        for (L->red_style = 0; L->red_style < 3; L->red_style++) {
            obs__crypto_channel(L, 0, 0, ch, sizeof ch);
            if (has_channel(cl, ch))
                break;
        }
        if (L->red_style == 3)
            L->red_style = 0;
        for (L->rank_sets = 0; L->rank_sets < OBS_CRYPTO_MAX_RANK_SETS; L->rank_sets++) {
            int all = 1;
            for (int c = 0; c < 4 && all; c++) {
                obs__crypto_channel(L, L->rank_sets, c, ch, sizeof ch);
                all = has_channel(cl, ch);
            }
            if (!all)
                break;
        }
        if (!L->name[0])
            snprintf(L->manifest_error, sizeof L->manifest_error,
                     "Cryptomatte key '%s' has no cryptomatte/%s/name", L->key, L->key);
        else if (strcmp(L->hash, "MurmurHash3_32") || strcmp(L->conversion, "uint32_to_float32"))
            snprintf(L->manifest_error, sizeof L->manifest_error,
                     "Cryptomatte layer '%s': hash '%s' and conversion '%s' (known: "
                     "MurmurHash3_32, uint32_to_float32)",
                     L->name, L->hash, L->conversion);
        else if (!L->names && !L->manifest_error[0] && L->manif_file[0])
            read_sidecar(L, j->path);
        else if (!L->names && !L->manifest_error[0])
            snprintf(L->manifest_error, sizeof L->manifest_error,
                     "Cryptomatte layer '%s' has neither a manifest nor a manif_file", L->name);
    }
    for (int i = 0; i < cl->num_channels; i++) {
        const char *n = cl->entries[i].name.str;
        if (!obs__crypto_is_id_channel(n))
            continue;
        char **v = realloc(info->id_channels, (size_t)(info->id_count + 1) * sizeof *v);
        if (!v)
            return obs__fail(why, OBS_NO_MEMORY, "ID channels");
        info->id_channels = v;
        if (!(v[info->id_count] = strdup(n)))
            return obs__fail(why, OBS_NO_MEMORY, "ID channels");
        info->id_count++;
    }
    return OBS_OK;
}

static obs_status describe_reader(exr_context_t ctx, int64_t size, void *user,
                                  char why[OBS_ERR_LEN])
{
    describe_job *j = user;
    int parts = 0;
    (void)size;
    exr_result_t rv = exr_get_count(ctx, &parts);
    if (rv != EXR_ERR_SUCCESS)
        return obs__exr_fail(why, rv, "part count");
    /* the first part with Cryptomatte attributes or ID channels, else 0 */
    for (int p = 0; p < parts; p++) {
        obs_status st = describe_part(ctx, p, j, why);
        if (st != OBS_OK)
            return st;
        j->info->part = p;
        if (j->info->layer_count || j->info->id_count || p == parts - 1)
            break;
    }
    return OBS_OK;
}

obs_status obs_crypto_describe(const char *path, const void *buf, size_t len,
                               obs_crypto_info *out, char err[OBS_ERR_LEN])
{
    if (!out || (!path && !buf))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_crypto_describe: NULL argument");
    memset(out, 0, sizeof *out);
    const obs__exr_mem mem = {buf, len};
    describe_job j = {buf ? NULL : path, out};
    obs_status st = obs__exr_read_with(path ? path : "EXR", buf ? NULL : path, buf ? &mem : NULL,
                                       describe_reader, &j, err);
    if (st != OBS_OK)
        obs_crypto_info_free(out);
    return st;
}

void obs_crypto_info_free(obs_crypto_info *info)
{
    if (!info)
        return;
    for (int i = 0; i < info->layer_count; i++) {
        obs_crypto_layer *L = &info->layers[i];
        for (int k = 0; k < L->entry_count; k++)
            free(L->names[k]);
        free(L->names);
        free(L->ids);
    }
    free(info->layers);
    for (int i = 0; i < info->id_count; i++)
        free(info->id_channels[i]);
    free(info->id_channels);
    memset(info, 0, sizeof *info);
}
