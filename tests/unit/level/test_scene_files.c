/* Damaged and hostile mesh files (tests/data/levels/bad) through both
 * assimp loaders: obs_scene_load (gbuffer, reference: core/ground/scene.c)
 * and obs_bake_load (bake: core/level/load.c), then the bake's flattening.
 * Each case is one fuzz_scene found or the CLI check made by hand; before
 * the fixes they crashed (SEGV) or lost a mesh without a word. */
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "level/bake_testutil.h"
#include "level/level.h"
#include "obscura/scene.h"

#define BAD TESTDATA "/levels/bad/"

static void scene_fails(const char *file, obs_status want, const char *words)
{
    obs_scene s;
    char err[OBS_ERR_LEN] = "";
    obs_status st = obs_scene_load(file, &s, err);
    print_message("scene %s: %s\n", file, err);
    assert_int_equal(st, want);
    assert_non_null(strstr(err, file));
    assert_non_null(strstr(err, words));
    assert_null(s.positions);
}

static void level_fails(const char *file, obs_status want, const char *words)
{
    obs_bake_scene b;
    char err[OBS_ERR_LEN] = "";
    obs_status st = obs_bake_load(file, 0, &b, err);
    print_message("level %s: %s\n", file, err);
    assert_int_equal(st, want);
    assert_non_null(strstr(err, file));
    assert_non_null(strstr(err, words));
    assert_null(b.nodes);
}

/* Both loaders refuse file as OBS_BAD_FILE, with words in the message. */
static void both_fail(const char *file, const char *words)
{
    scene_fails(file, OBS_BAD_FILE, words);
    level_fails(file, OBS_BAD_FILE, words);
}

/* text in a new file named from path (a mkstemps template ending in XXXXXX
 * and the extension), path filled in. */
static void temp_file(char *path, const char *text)
{
    int fd = mkstemps(path, (int)strlen(strrchr(path, '.')));
    assert_true(fd >= 0);
    size_t n = strlen(text);
    assert_int_equal(write(fd, text, n), (ssize_t)n);
    close(fd);
}

static void level_loads(const char *file, obs_bake_scene *b)
{
    char err[OBS_ERR_LEN] = "";
    if (obs_bake_load(file, 0, b, err) != OBS_OK)
        fail_msg("%s: %s", file, err);
}

/* An OFF file whose face list runs into other text: assimp's OFF reader
 * leaves a face without indices, which its own scene preprocessing then
 * read (SEGV).  Validated first, it is refused. */
static void test_face_without_indices(void **state)
{
    (void)state;
    both_fail(BAD "face_without_indices.off", "mIndices is nullptr");
}

/* A binary PLY whose faces list no vertices: ValidateDataStructure lets
 * them through, assimp's Triangulate then aborts (an assertion in
 * Debian's build).  Checked between the read and the steps. */
static void test_face_no_vertices(void **state)
{
    (void)state;
    both_fail(BAD "face_no_vertices.ply", "face 0 has no vertices");
}

/* A .glb of 1 KiB whose JSON chunk claims 4 GiB: assimp's glTF reader
 * allocated the claimed length first (out of memory under the fuzzer's
 * limit).  Its chunks are now checked against the file before. */
static void test_glb_chunk_past_end(void **state)
{
    (void)state;
    scene_fails(BAD "glb_json_past_end.glb", OBS_BAD_FILE, "its JSON chunk 4294902660");
    level_fails(BAD "glb_json_past_end.glb", OBS_BAD_FILE, "(truncated or damaged)");
}

/* A PLY header without its end_header line: assimp's PLY reader read
 * past its buffer (binary: SEGV) or never returned (ASCII).  Refused
 * before assimp sees it. */
static void test_ply_without_end_header(void **state)
{
    (void)state;
    both_fail(BAD "ply_no_end_header.ply", "without its end_header line");
    both_fail(BAD "ply_no_end_header_ascii.ply", "without its end_header line");
    /* assimp reads any file that starts "ply" as PLY when its extension's
     * reader refuses it (found as a .glb by fuzz_scene) */
    char path[] = "/tmp/obs_plyglb_XXXXXX.glb";
    temp_file(path, "plyF\nformat binary_little_endian 1.0\nelement vertex 3\n");
    both_fail(path, "without its end_header line");
    unlink(path);
}

/* A .glb whose node graph is a DAG of 40 levels, each node twice the
 * child of the one above: the baked reader walked every path (2^40,
 * a hang), assimp's glTF importer copies each (out of memory).  The
 * graph must be a forest: refused by both (obs__glb_forest, glb_read.c). */
static void test_node_dag(void **state)
{
    (void)state;
    const char *f = BAD "node_dag.glb";
    obs_scene s;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_scene_load_baked(f, &s, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "glTF node 1 is the child of more than one node"));
    both_fail(f, "glTF node 1 is the child of more than one node");
}

/* A child index of 1e300: converted to long, undefined behaviour
 * (UBSan in fuzz_scene); now read as a glTF index, refused. */
static void test_node_index_not_integer(void **state)
{
    (void)state;
    obs_scene s;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_scene_load_baked(BAD "node_index_1e300.glb", &s, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "a node index that is not a whole number"));
}

/* A NaN vertex: FindInvalidData dropped its mesh (the only one: "No
 * meshes remaining"; the second of two: the scene loaded without it).
 * Both loaders name the mesh and the vertex. */
static void test_nan_vertex(void **state)
{
    (void)state;
    scene_fails(BAD "nan_vertex.obj", OBS_BAD_FILE, "vertex 1 is (nan, 0, 0)");
    both_fail(BAD "nan_second_mesh.obj", "mesh 1 'bad': vertex 0");
}

/* Node transforms whose product overflows (scale 1e30 under 1e30): the
 * pre-transformed mesh is infinite, and was dropped as the NaN one.  The
 * level keeps each mesh in its own space; its flattening refuses. */
static void test_transform_overflow(void **state)
{
    (void)state;
    const char *f = BAD "transform_overflow.gltf";
    scene_fails(f, OBS_BAD_FILE, "not finite (in the file, or its node's transform overflows)");
    obs_bake_scene b;
    char err[OBS_ERR_LEN] = "";
    level_loads(f, &b);
    obs__bake_world w;
    assert_int_equal(obs__bake_flatten(&b, &w, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "node 'a', mesh 'box'"));
    assert_non_null(strstr(err, "transform overflows"));
    obs_bake_scene_free(&b);
}

/* Finite coordinates of +-3e38 (hostile but loadable): each is a float,
 * their sums and products are not.  Both loaders refuse them by the
 * bound of obscura's scenes (OBS_SCENE_MAX_COORD), naming the vertex;
 * before, gbuffer and reference drew and traced nothing without a word,
 * and the flattening called the identity transform an overflow (it
 * tested the sum of the coordinates). */
static void test_coordinates_beyond_bound(void **state)
{
    (void)state;
    const char *f = BAD "coords_3e38.obj";
    scene_fails(f, OBS_BAD_FILE, "vertex 0 (mesh 'defaultobject', node 'defaultobject') at "
                                 "(-3e+38, -3e+38, 0): a coordinate beyond +-1e9");
    obs_bake_scene b;
    char err[OBS_ERR_LEN] = "";
    level_loads(f, &b);
    obs__bake_world w;
    assert_int_equal(obs__bake_flatten(&b, &w, err), OBS_BAD_FILE);
    print_message("flatten: %s\n", err);
    assert_non_null(strstr(err, "vertex 0 at (-3e+38, -3e+38, 0) in world space: a coordinate "
                                "beyond +-1e9"));
    assert_null(strstr(err, "transform overflows"));
    obs_bake_scene_free(&b);

    /* the bound itself is taken, a step beyond it is not */
    float pos[9] = {-1e9f, 0, 0, 1e9f, 0, 0, 0, 1e9f, -1e9f};
    uint32_t idx[3] = {0, 1, 2};
    obs_scene m = {.vertex_count = 3, .positions = pos, .triangle_count = 1, .indices = idx};
    assert_int_equal(obs_scene_check(&m, err), OBS_OK);
    pos[8] = nextafterf(-1e9f, -INFINITY);
    assert_int_equal(obs_scene_check(&m, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "vertex 2 at"));
}

/* Every triangle degenerate (collinear points): the bake refused such a
 * scene, gbuffer and reference drew an empty image without a word;
 * obs_scene_check refuses it as the bake does (level/flatten.c's rule,
 * obs__tri_normal). */
static void test_all_degenerate(void **state)
{
    (void)state;
    scene_fails(BAD "degenerate.obj", OBS_BAD_FILE, "all 2 triangles are degenerate");
    float pos[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
    uint32_t idx[3] = {0, 1, 2};
    char err[OBS_ERR_LEN] = "";
    obs_scene m = {.vertex_count = 3, .positions = pos, .triangle_count = 1, .indices = idx};
    assert_int_equal(obs_scene_check(&m, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "degenerate"));
    pos[8] = 3; /* off the line */
    assert_int_equal(obs_scene_check(&m, err), OBS_OK);
}

/* An AC3D object with vertices and no surface count: assimp keeps its
 * points as a mesh under no node, and PreTransformVertices (hierarchy
 * kept) read a null transform for it (SEGV).  The scene refuses it by
 * name; the level bakes the meshes under its nodes (4 of the 5). */
static void test_mesh_under_no_node(void **state)
{
    (void)state;
    const char *f = BAD "no_numsurf.ac";
    scene_fails(f, OBS_BAD_FILE, "mesh 3 '' is under no node");
    obs_bake_scene b;
    level_loads(f, &b);
    assert_int_equal(b.mesh_count, 5);
    assert_int_equal(b.instance_count, 4);
    assert_int_equal(b.world_triangles, 4);
    obs_bake_scene_free(&b);
}

/* reference --obscurance reads the level with no limit (as the bake
 * does before its own check) and flattened it for the occluders without
 * one: a small file instancing a mesh many times asked for memory sized
 * by the product.  max_triangles now bounds that flattening too. */
static void test_occluders_bounded(void **state)
{
    (void)state;
    obs_bake_scene b;
    level_loads(TESTDATA "/levels/aalborg_cut.acc", &b);
    size_t len = 0;
    char *trees = (char *)obs_test_slurp(TESTDATA "/levels/aalborg_cut.trees.json", &len);
    assert_non_null(trees);
    trees[len] = '\0'; /* obs_test_slurp leaves room for it */
    obs_bake_params bp = {0};
    bt_set(&bp, "max-triangles", "100");
    obs_bake_occluders *o = NULL;
    char warning[OBS_ERR_LEN], err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bake_occluders_new(&b, &bp, trees, &o, warning, err), OBS_TOO_LARGE);
    assert_non_null(strstr(err, "811 triangles once flattened; max_triangles is 100"));
    assert_null(o);
    bt_set(&bp, "max-triangles", "811");
    assert_int_equal(obs_bake_occluders_new(&b, &bp, trees, &o, warning, err), OBS_OK);
    assert_non_null(o);
    obs_bake_occluders_free(o);
    free(trees);
    obs_bake_scene_free(&b);
}

/* Each mesh's vertices at one point: FindInvalidData drops them all;
 * said so, rather than assimp's bare "No meshes remaining". */
static void test_all_at_one_point(void **state)
{
    (void)state;
    char path[] = "/tmp/obs_onepoint_XXXXXX.obj";
    temp_file(path, "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n");
    scene_fails(path, OBS_BAD_FILE, "vertices all at one point");
    unlink(path);
}

/* A PLY header declaring 2^31 vertices in a file of 178 bytes: assimp
 * sizes its arrays by the count and runs out of memory; both loaders say
 * so (OBS_TOO_LARGE).  Run in a child whose address space is capped, so
 * the answer does not depend on the machine's memory; not under ASan
 * (its shadow memory needs the address space, and its allocator aborts
 * rather than throw). */
static void test_huge_declared_count(void **state)
{
    (void)state;
#if defined(__SANITIZE_ADDRESS__)
    skip();
#else
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        long pages = 0;
        FILE *st = fopen("/proc/self/statm", "r");
        if (st && fscanf(st, "%ld", &pages) == 1) {
            rlim_t cap = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + ((rlim_t)1 << 30);
            struct rlimit rl = {cap, cap};
            setrlimit(RLIMIT_AS, &rl);
        }
        if (st)
            fclose(st);
        const char *f = BAD "huge_vertex_count.ply";
        char err[OBS_ERR_LEN] = "";
        obs_scene s;
        obs_bake_scene b;
        int ok = obs_scene_load(f, &s, err) == OBS_TOO_LARGE && strstr(err, "out of memory");
        if (!ok)
            fprintf(stderr, "scene: %s\n", err);
        int ok2 = obs_bake_load(f, 0, &b, err) == OBS_TOO_LARGE && strstr(err, "out of memory");
        if (!ok2)
            fprintf(stderr, "level: %s\n", err);
        _exit(ok && ok2 ? 0 : 1);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
#endif
}

/* An AC3D triangle strip (SURF type 4) of no references among polygons:
 * assimp 5.2's AC3D reader counts it as -2 faces and reads its empty list
 * from entry 0 on (SEGV, fuzz_scene).  The structure is walked first. */
static void test_ac3d_strip_without_refs(void **state)
{
    (void)state;
    both_fail(BAD "strip_no_refs.ac", "a triangle strip of 0 vertex references");
}

/* An AC3D object subdivided k times (Catmull-Clark, while assimp reads
 * the file): its quad makes 2 * 4 * 4^(k - 1) triangles.  subdiv 12 made
 * assimp take 7.2 GB, past 60 s, before the bake's max_triangles could
 * refuse the level; now the precheck counts them first: subdiv 8 (131072
 * triangles) loads under max_triangles 131072 and is refused under 131071
 * (OBS_TOO_LARGE, without assimp reading it), and subdiv 20 (2.2e12) is
 * refused by the scene loader too (past 32-bit face counts). */
static void test_ac3d_subdiv(void **state)
{
    (void)state;
    static const char fmt[] = "AC3Db\nMATERIAL \"m\" rgb 1 1 1 amb 0.2 0.2 0.2 emis 0 0 0 spec 0 0 0 "
                              "shi 1 trans 0\nOBJECT poly\nsubdiv %d\nnumvert 4\n0 0 0\n1 0 0\n"
                              "1 1 0\n0 1 0\nnumsurf 1\nSURF 0x10\nmat 0\nrefs 4\n0 0 0\n1 0 0\n"
                              "2 0 0\n3 0 0\nkids 0\n";
    char text[512], path[64], err[OBS_ERR_LEN] = "";
    obs_bake_scene b;
    snprintf(text, sizeof text, fmt, 8);
    snprintf(path, sizeof path, "%s", "/tmp/obs_subdivXXXXXX.ac");
    temp_file(path, text);
    assert_int_equal(obs_bake_load(path, 131071, &b, err), OBS_TOO_LARGE);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "subdiv 8"));
    assert_non_null(strstr(err, "1.311e+05 triangles"));
    assert_int_equal(obs_bake_load(path, 131072, &b, err), OBS_OK);
    obs_bake_scene_free(&b);
    unlink(path);
    snprintf(text, sizeof text, fmt, 20);
    snprintf(path, sizeof path, "%s", "/tmp/obs_subdivXXXXXX.ac");
    temp_file(path, text);
    scene_fails(path, OBS_TOO_LARGE, "subdiv 20");
    level_fails(path, OBS_TOO_LARGE, "subdiv 20");
    unlink(path);
}

/* Files of the given texts (each with the words its error must hold),
 * named by template (as temp_file's), each refused by both loaders. */
struct bad_text {
    const char *text, *words;
};

static void texts_fail(const char *template, const struct bad_text *bad, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        char path[64];
        snprintf(path, sizeof path, "%s", template);
        temp_file(path, bad[i].text);
        both_fail(path, bad[i].words);
        unlink(path);
    }
}

/* Counts an AC3D file does not hold: each walked before assimp reserves
 * what they say or reads the next lines as more of the same. */
static void test_ac3d_counts(void **state)
{
    (void)state;
    static const struct bad_text bad[] = {
        {"AC3Db\nOBJECT poly\nnumvert 4\n0 0 0\n1 0 0\n0 1 0\nkids 0\n", "line 7 is not a vertex"},
        {"AC3Db\nOBJECT poly\nnumvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 2\nSURF 0x0\nmat 0\n"
         "refs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n", "surface 1 does not start with SURF"},
        {"AC3Db\nOBJECT poly\nnumvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 1\nSURF 0x0\nmat 0\n"
         "refs 3\n0 0 0\n1 0 0\n3 0 0\nkids 0\n", "refers to vertex 3 of an object of 3"},
        {"AC3Db\nOBJECT poly\nnumvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 1\nSURF 0x0\nmat 1\n"
         "refs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n", "material 1 of the file's 0"},
        {"AC3Db\nOBJECT world\nkids 4000000000\nOBJECT poly\nkids 0\n", "more children than"},
    };
    texts_fail("/tmp/obs_ac3d_XXXXXX.acc", bad, sizeof bad / sizeof *bad);
}

/* A file named .glb that is no glTF binary (its first bytes name an
 * OpenGEX structure): assimp's two glTF readers refuse it, assimp then
 * offers it to its every reader by content, and its OpenGEX reader read
 * past its buffer (ASan) or never returned.  A .glb must start "glTF", a
 * .gltf be glTF 2.0 JSON. */
static void test_gltf_not_gltf(void **state)
{
    (void)state;
    both_fail(BAD "not_glb_opengex.glb", "a .glb starts with the magic");
    static const struct bad_text bad[] = {
        {"{\"asset\": {\"version\": \"2.0\"}} Metric IndexArray", "text after its JSON value"},
        {"{\"asset\": {\"version\": \"1.0\"}, \"IndexArray\": 1}", "\"version\" 2.x"},
        {"{\"scenes\": [], \"IndexArray\": {}}", "no \"asset\" object"},
        {"Metric {float {1.0}} IndexArray {}", "is not JSON"},
    };
    texts_fail("/tmp/obs_gltf_XXXXXX.gltf", bad, sizeof bad / sizeof *bad);
}

/* OFF header counts past 32 bits, or past what the file could hold:
 * assimp 5.2 allocates what they say before reading (45 GB asked by a
 * 258-byte file, fuzz_scene under ASan). */
static void test_off_counts(void **state)
{
    (void)state;
    both_fail(BAD "off_count_past_32_bits.off", "count past 2^32 - 1");
    both_fail(BAD "off_counts_past_file.off", "more than the 27 bytes after it hold");
}

/* A hierarchy 1100 levels deep, as AC3D objects and as glTF nodes: assimp
 * 5.2 walks it recursively and crashed (stack overflow) some thousands of
 * levels down; both are refused past 1024 levels. */
static void test_deep_hierarchy(void **state)
{
    (void)state;
    enum { LEVELS = 1100 };
    static const char quad[] = "OBJECT poly\nnumvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 1\n"
                               "SURF 0x0\nmat 0\nrefs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n";
    char *text = malloc(LEVELS * 32 + 4096);
    assert_non_null(text);
    size_t n = (size_t)sprintf(text, "AC3Db\n");
    for (int i = 0; i < LEVELS; i++)
        n += (size_t)sprintf(text + n, "OBJECT group\nkids 1\n");
    sprintf(text + n, "%s", quad);
    char ac[] = "/tmp/obs_deep_XXXXXX.ac3d";
    temp_file(ac, text);
    both_fail(ac, "nested deeper than 1024 levels");
    unlink(ac);

    n = (size_t)sprintf(text, "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], "
                              "\"nodes\": [");
    for (int i = 0; i < LEVELS; i++)
        n += (size_t)sprintf(text + n, "{\"children\": [%d]}, ", i + 1);
    sprintf(text + n, "{}]}");
    char gltf[] = "/tmp/obs_deep_XXXXXX.gltf";
    temp_file(gltf, text);
    both_fail(gltf, "deeper than 1024 levels");
    unlink(gltf);
    free(text);
}

/* The fuzz_scene seeds that are whole files: each loads in both loaders
 * and flattens (a seed that stopped loading would fuzz only the errors). */
static void test_valid_seeds_load(void **state)
{
    (void)state;
    static const char *const good[] = {"cube_obj", "cube_ply_ascii", "cube_ply_bin",
                                       "cube_off", "cube_stl_ascii", "cube_stl_bin",
                                       "cube_gltf", "cube_glb", "quads_ac"};
    static const char *const exts[] = {"obj", "ply", "off", "stl", "glb", "gltf", "ac"};
    for (size_t i = 0; i < sizeof good / sizeof *good; i++) {
        char src[256], path[64];
        snprintf(src, sizeof src, "tests/fuzz/corpus/scene/%s", good[i]);
        size_t len = 0;
        unsigned char *d = obs_test_slurp(src, &len);
        assert_non_null(d);
        assert_true(len > 1 && d[0] < sizeof exts / sizeof *exts);
        snprintf(path, sizeof path, "/tmp/obs_seed_%d.%s", (int)getpid(), exts[d[0]]);
        FILE *f = fopen(path, "wb");
        assert_non_null(f);
        assert_int_equal(fwrite(d + 1, 1, len - 1, f), len - 1);
        fclose(f);
        free(d);
        obs_scene s;
        obs_bake_scene b;
        obs__bake_world w;
        char err[OBS_ERR_LEN] = "";
        if (obs_scene_load(path, &s, err) != OBS_OK)
            fail_msg("%s: %s", good[i], err);
        assert_true(s.triangle_count >= 3);
        obs_scene_free(&s);
        if (obs_bake_load(path, 0, &b, err) != OBS_OK || obs__bake_flatten(&b, &w, err) != OBS_OK)
            fail_msg("%s: %s", good[i], err);
        obs__bake_world_free(&w);
        obs_bake_scene_free(&b);
        unlink(path);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_face_without_indices), cmocka_unit_test(test_face_no_vertices),
        cmocka_unit_test(test_ply_without_end_header), cmocka_unit_test(test_glb_chunk_past_end),
        cmocka_unit_test(test_node_dag),             cmocka_unit_test(test_node_index_not_integer),
        cmocka_unit_test(test_nan_vertex),
        cmocka_unit_test(test_transform_overflow),   cmocka_unit_test(test_mesh_under_no_node),
        cmocka_unit_test(test_coordinates_beyond_bound), cmocka_unit_test(test_all_degenerate),
        cmocka_unit_test(test_occluders_bounded),    cmocka_unit_test(test_all_at_one_point),     cmocka_unit_test(test_huge_declared_count),
        cmocka_unit_test(test_ac3d_strip_without_refs), cmocka_unit_test(test_ac3d_counts),
        cmocka_unit_test(test_gltf_not_gltf),          cmocka_unit_test(test_off_counts),
        cmocka_unit_test(test_deep_hierarchy),         cmocka_unit_test(test_ac3d_subdiv),
        cmocka_unit_test(test_valid_seeds_load),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
