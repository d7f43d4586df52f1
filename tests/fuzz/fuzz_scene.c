/* libFuzzer target for the mesh and level loaders: the input's first byte
 * picks a file extension (obj, ply, off, stl, glb, gltf, ac), the rest is
 * written to a file of that name in a private directory and read as
 * `obscura gbuffer` and `obscura reference` read a scene
 * (core/ground/scene.c obs_scene_load, its check included; a .glb also
 * through core/ground/baked.c obs_scene_load_baked, which reads it without
 * assimp) and as `obscura bake` reads a level (core/level/load.c
 * obs_bake_load, a .glb's LODs through lod_file.c), then flattened
 * (core/level/flatten.c obs__bake_flatten: what the BVH, the samples and
 * the fit take).  Whatever a loader returns is touched and freed (ASan and
 * LeakSanitizer check).  Seeds: tests/fuzz/corpus/scene.
 *
 *   make fuzz && build/fuzz/fuzz_scene -max_len=65536 NEW_DIR tests/fuzz/corpus/scene */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "level/level.h"
#include "obscura/bake.h"
#include "obscura/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char *const exts[] = {"obj", "ply", "off", "stl", "glb", "gltf", "ac"};
#define NEXT (sizeof exts / sizeof *exts)

/* At most what a bake may flatten here: a file cannot ask for more work. */
#define MAX_TRIANGLES ((size_t)1 << 20)

static volatile float sink;
static int verbose = -1; /* FUZZ_SCENE_VERBOSE=1: each loader's outcome on stderr */

static void said(const char *who, obs_status st, const char *err)
{
    if (verbose < 0)
        verbose = getenv("FUZZ_SCENE_VERBOSE") != NULL;
    if (verbose)
        fprintf(stderr, "  %s: %s\n", who, st == OBS_OK ? "ok" : err);
}

static void touch_scene(const obs_scene *s)
{
    for (size_t i = 0; i < 3 * s->triangle_count; i++)
        sink += s->positions[3 * (size_t)s->indices[i]] + s->normals[3 * (size_t)s->indices[i]];
    for (size_t m = 0; m < s->mesh_count; m++)
        sink += (float)s->meshes[m].name[0] + (float)s->meshes[m].node[0];
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char dir[64];
    if (!dir[0]) {
        snprintf(dir, sizeof dir, "/tmp/fuzz_scene.XXXXXX");
        if (!mkdtemp(dir))
            abort();
    }
    if (size < 1)
        return 0;
    char path[128];
    snprintf(path, sizeof path, "%s/in.%s", dir, exts[data[0] % NEXT]);
    FILE *f = fopen(path, "wb");
    if (!f)
        abort();
    if (size > 1 && fwrite(data + 1, 1, size - 1, f) != size - 1)
        abort();
    fclose(f);

    char err[OBS_ERR_LEN];
    obs_scene s;
    obs_status st = obs_scene_load(path, &s, err);
    said(exts[data[0] % NEXT], st, err);
    if (st == OBS_OK) {
        touch_scene(&s);
        obs_scene_free(&s);
    }
    if (data[0] % NEXT == 4 && (st = obs_scene_load_baked(path, &s, err), said("baked", st, err), st) == OBS_OK) {
        touch_scene(&s);
        for (size_t v = 0; v < 3 * s.vertex_count; v++)
            sink += s.baked[v];
        obs_scene_free(&s);
    }
    obs_bake_scene b;
    st = obs_bake_load(path, MAX_TRIANGLES, &b, err);
    said("level", st, err);
    if (st == OBS_OK) {
        obs__bake_world w;
        st = obs__bake_flatten(&b, &w, err);
        said("flatten", st, err);
        if (st == OBS_OK) {
            for (size_t t = 0; t < w.triangle_count; t++)
                sink += w.area[t] + w.pos[3 * (size_t)w.tri[3 * t + 2]];
            obs__bake_world_free(&w);
        }
        obs_bake_scene_free(&b);
    }
    unlink(path);
    return 0;
}
