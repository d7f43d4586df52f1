/* libFuzzer target for the parsers of files a user or a farm hands
 * obscura, other than the EXRs (fuzz_exr.c) and the protocols
 * (fuzz_binary.c).  The input's first byte picks the parser, the rest is
 * the file (written under a temporary directory of the process where
 * the API takes a path):
 *
 *   0  camera JSON             core/camera/json.c    obs_camera_read_json
 *   1  object-mask selector    core/mask.c           obs_mask_plane against
 *                                                    tests/data/small/room_masks.exr
 *                                                    (Cryptomatte layer, IndexOB)
 *   2  a .glb's own LODs       core/level/lod_file.c obs__bake_lod_file_read against
 *                                                    the scene of tests/fuzz/lod_scene.glb
 *   3  dynamic-AO model        core/dynamic/dyn_model.c obs_dyn_model_read (then evaluated)
 *   4  bake part               core/level/part.c with bake/shard.c's format: header,
 *                                                    merge parameters, payload
 *   5  bake-dynamic part       the same with dynamic/dyn_shard.c's format
 *   6  regions file            core/dynamic/dyn_regions.c obs_dyn_regions_parse
 *                                                    (bake-dynamic --regions)
 *   7  decorators file         core/level/decor.c    obs__bake_decor_classify against
 *                                                    the LOD parser's scene (bake --decorators)
 *
 * (the byte is taken modulo 8; OBS_FUZZ_ONLY=N in the environment: parser
 * N whatever the byte, OBS_FUZZ_VERBOSE: each parser's status and message
 * on stderr).  Whatever a parser returns is touched and
 * freed (ASan and LeakSanitizer check).  Seeds: tests/fuzz/corpus/files
 * (tools: tests/fuzz/seed_files.sh).  Run from the repository root (the
 * mask and LOD parsers read their fixed inputs from it):
 *
 *   make fuzz && build/fuzz/fuzz_files NEW_DIR tests/fuzz/corpus/files */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bake/shard.h"
#include "dynamic/dyn_internal.h"
#include "level/decor.h"
#include "obscura/bake.h"
#include "obscura/dynamic.h"
#include "obscura/io.h"
#include "obscura/mask.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

enum { P_CAMERA, P_MASK, P_LOD, P_DYN_MODEL, P_BAKE_PART, P_DYN_PART, P_REGIONS, P_DECOR, P_COUNT };

static char dir[64];
static char file[96];
static unsigned char *mask_exr;
static size_t mask_exr_len;
static obs_bake_scene lod_scene;
static int lod_scene_ok;
static volatile float sink;
static int verbose; /* OBS_FUZZ_VERBOSE set: each parser's status and message on stderr */
static int only = -1; /* OBS_FUZZ_ONLY=N: parser N whatever the first byte (one parser's run) */

/* st as is, told on stderr when verbose (what a seed or a reproducer gets). */
static obs_status told(const char *what, obs_status st, const char *err)
{
    if (verbose)
        fprintf(stderr, "fuzz_files: %s: %s%s%s\n", what, st == OBS_OK ? "ok" : "error",
                st == OBS_OK ? "" : ": ", st == OBS_OK ? "" : err);
    return st;
}

static void cleanup(void)
{
    unlink(file);
    rmdir(dir);
    free(mask_exr);
    if (lod_scene_ok)
        obs_bake_scene_free(&lod_scene);
}

static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    unsigned char *buf = NULL;
    long n = -1;
    if (f && fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) > 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (buf = malloc((size_t)n)) && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    if (f)
        fclose(f);
    *len = buf ? (size_t)n : 0;
    return buf;
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    char err[OBS_ERR_LEN] = "";
    verbose = getenv("OBS_FUZZ_VERBOSE") != NULL;
    const char *o = getenv("OBS_FUZZ_ONLY");
    if (o && *o)
        only = atoi(o) % P_COUNT;
    snprintf(dir, sizeof dir, "/tmp/obs_fuzz_files.XXXXXX");
    if (!mkdtemp(dir)) {
        perror("fuzz_files: mkdtemp");
        abort();
    }
    snprintf(file, sizeof file, "%s/input", dir);
    const char *exr = getenv("OBS_FUZZ_MASK_EXR");
    mask_exr = slurp(exr ? exr : "tests/data/small/room_masks.exr", &mask_exr_len);
    const char *glb = getenv("OBS_FUZZ_LOD_SCENE");
    lod_scene_ok = obs_bake_load(glb ? glb : "tests/fuzz/lod_scene.glb", 0, &lod_scene,
                                 err) == OBS_OK;
    if (!mask_exr || !lod_scene_ok)
        fprintf(stderr, "fuzz_files: run from the repository root (%s%s); those parsers get "
                        "no fixed input\n", mask_exr ? "" : "no room_masks.exr ",
                lod_scene_ok ? "" : err);
    if (lod_scene_ok)
        obs__bake_lod_file_free(&lod_scene); /* each input brings its own */
    atexit(cleanup);
    return 0;
}

static int write_input(const uint8_t *data, size_t size)
{
    FILE *f = fopen(file, "wb");
    if (!f)
        return 0;
    int ok = fwrite(data, 1, size, f) == size;
    return fclose(f) == 0 && ok;
}

static void camera(void)
{
    char err[OBS_ERR_LEN];
    obs_camera cam;
    int w = 0, h = 0;
    if (told("camera JSON", obs_camera_read_json(file, &cam, &w, &h, err), err) == OBS_OK)
        for (int i = 0; i < 16; i++)
            sink += cam.world_to_camera[i] + cam.projection[i] + (float)(w + h);
}

static void mask(const char *sel)
{
    char err[OBS_ERR_LEN];
    if (!mask_exr)
        return;
    const obs_limits lim = {.threads = 1};
    obs_image w, dom;
    if (told("mask selector", obs_mask_plane(NULL, mask_exr, mask_exr_len, sel, &lim, &w, &dom, err), err) ==
        OBS_OK) {
        for (size_t i = 0; i < (size_t)w.width * (size_t)w.height; i++)
            sink += w.data[i] + (dom.data ? dom.data[i] : 0.0f);
        obs_image_free(&w);
        obs_image_free(&dom);
    }
}

static void lod(void)
{
    char err[OBS_ERR_LEN];
    if (!lod_scene_ok)
        return;
    if (told("LOD file", obs__bake_lod_file_read(file, &lod_scene, err), err) == OBS_OK) {
        for (size_t c = 0; c < lod_scene.file_lod_levels * lod_scene.mesh_count; c++) {
            const obs_bake_mesh *m = &lod_scene.file_lods[c];
            for (size_t t = 0; t < 3 * m->triangle_count; t++)
                sink += m->positions[3 * m->indices[t]];
        }
        obs__bake_lod_file_free(&lod_scene);
    }
}

static void dyn_model(void)
{
    char err[OBS_ERR_LEN];
    obs_dyn_model m;
    if (told("dynamic model", obs_dyn_model_read(file, &m, err), err) != OBS_OK)
        return;
    /* each region's corners and centre, and a point outside every box */
    const float n[3] = {0, 1, 0};
    float ao[3];
    for (size_t r = 0; r < m.region_count; r++) {
        const obs_dyn_box *b = &m.regions[r].box;
        float c[3] = {(b->lo[0] + b->hi[0]) / 2, (b->lo[1] + b->hi[1]) / 2, (b->lo[2] + b->hi[2]) / 2};
        obs_dyn_eval(&m, b->lo, n, OBS_DYN_QUADRATIC, ao);
        obs_dyn_eval(&m, c, n, OBS_DYN_LINEAR, ao);
        sink += ao[0] + ao[1] + ao[2];
    }
    const float far[3] = {1e6f, -1e6f, 1e6f};
    obs_dyn_blender bl = {0};
    obs_dyn_blend_step(&bl, &m, far, n, OBS_DYN_LINEAR, 0.1f, 0.5f, ao);
    for (size_t e = 0; e < 2 * m.edge_count; e++)
        sink += (float)m.edge[e];
    sink += ao[2];
    obs_dyn_model_free(&m);
}

/* The part's header read as a merge reads it (alone, and given twice:
 * the split's checks), its parameters adopted, its payload read. */
static void part(const obs__part_format *f, int bake)
{
    char err[OBS_ERR_LEN];
    const char *paths[2] = {file, file};
    void *parts = NULL;
    if (obs__bake_parts_read(paths, 2, f, &parts, err) == OBS_OK)
        free(parts);
    if (told(f->what, obs__bake_parts_read(paths, 1, f, &parts, err), err) != OBS_OK)
        return;
    const obs__part_range *r = parts;
    uint64_t checksum;
    if (bake) {
        obs_bake_params p = {0};
        told("its parameters", obs__part_adopt(f, parts, 1, &p, NULL, err), err);
        checksum = ((const obs__bake_part *)parts)->checksum;
    } else {
        obs_dyn_params p = {0};
        told("its parameters", obs__part_adopt(f, parts, 1, &p, NULL, err), err);
        checksum = ((const obs__dyn_part *)parts)->checksum;
    }
    unsigned char *payload;
    size_t len = (size_t)(f->item_bytes * r->n);
    if (told("its payload", obs__bake_part_payload(file, f->head_len, len, checksum, &payload, err),
             err) == OBS_OK) {
        for (size_t i = 0; i < len; i += 97)
            sink += payload[i];
        free(payload);
    }
    free(parts);
}

static void regions(const char *text)
{
    char err[OBS_ERR_LEN];
    obs_dyn_regions rg;
    if (told("regions file", obs_dyn_regions_parse(text, &rg, err), err) != OBS_OK)
        return;
    for (size_t r = 0; r < rg.count; r++)
        sink += rg.box[r].lo[0] + rg.box[r].hi[2];
    for (size_t e = 0; e < 2 * rg.edge_count; e++)
        sink += (float)rg.edge[e];
    obs_dyn_regions_free(&rg);
}

static void decorators(const char *text)
{
    char err[OBS_ERR_LEN];
    if (!lod_scene_ok)
        return;
    obs_bake_params p;
    obs_bake_params_resolve(NULL, &p);
    obs__bake_decor d;
    if (told("decorators file", obs__bake_decor_classify(&lod_scene, &p, text, &d, err), err) !=
        OBS_OK)
        return;
    for (size_t n = 0; n < d.node_count; n++)
        sink += (float)d.node_class[n] + d.density[n];
    obs__bake_decor_free(&d);
}

/* The input as a NUL-terminated string (caller frees). */
static char *text_of(const uint8_t *data, size_t size)
{
    char *t = malloc(size + 1);
    if (t) {
        memcpy(t, data, size);
        t[size] = '\0';
    }
    return t;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    int which = only >= 0 ? only : data[0] % P_COUNT;
    data++, size--;
    if (which == P_MASK || which == P_REGIONS || which == P_DECOR) {
        char *text = text_of(data, size);
        if (text && which == P_MASK)
            mask(text);
        else if (text && which == P_REGIONS)
            regions(text);
        else if (text)
            decorators(text);
        free(text);
        return 0;
    }
    if (!write_input(data, size))
        return 0;
    switch (which) {
    case P_CAMERA: camera(); break;
    case P_LOD: lod(); break;
    case P_DYN_MODEL: dyn_model(); break;
    case P_BAKE_PART: part(&obs__bake_part_format, 1); break;
    default: part(&obs__dyn_part_format, 0); break;
    }
    return 0;
}
