/* Decorator classification (core/bake/decor.c, section 2.2): from glTF
 * extras, node names, the --decorators file (its own rules and TORCS'
 * trees.json as it is), inheritance down the graph, and the errors. */
#include <cjson/cJSON.h>

#include "level/bake_testutil.h"
#include "level/decor.h"

#define LEVELS TESTDATA "/levels"

/* A graph of named nodes, no meshes: enough for the classification. */
static void graph(obs_bake_scene *s, const char *const *names, const char *const *extras,
                  const int *parent, size_t n)
{
    memset(s, 0, sizeof *s);
    s->nodes = calloc(n, sizeof *s->nodes);
    assert_non_null(s->nodes);
    s->node_count = n;
    for (size_t i = 0; i < n; i++) {
        s->nodes[i].name = strdup(names[i]);
        s->nodes[i].extras = extras[i] ? strdup(extras[i]) : NULL;
        s->nodes[i].parent = parent[i];
        s->nodes[i].meshes = malloc(sizeof(uint32_t));
        for (int k = 0; k < 16; k++)
            s->nodes[i].local[k] = s->nodes[i].world[k] = k % 5 == 0 ? 1.0f : 0.0f;
    }
}

static const char *const names[] = {
    "level",                                   /* 0 */
    "terrain",                                 /* 1 extras class terrain */
    "actor|flora/trees/palm_tropical_tall.xml", /* 2 extras class tree */
    "crown",                                   /* 3 child of 2: inherits tree */
    "actor|props/flora/bush_medit_me_lush.xml", /* 4 extras class bush */
    "gaia/grass_field",                        /* 5 extras kind grass: small */
    "pine_tree.003",                           /* 6 name: tree */
    "Hedge-row",                               /* 7 name: shrub */
    "street_lamp",                             /* 8 'street' is no tree */
    "OBJ1479",                                 /* 9 only the file says */
    "rock",                                    /* 10 extras class rock, name says nothing */
    "tree_stump",                              /* 11 extras decorator none beats the name */
    "bush_dense",                              /* 12 extras density 3 */
};
static const char *const extras[] = {
    NULL,
    "{\"class\":\"terrain\",\"template\":null}",
    "{\"template\":\"actor|flora/trees/palm_tropical_tall.xml\",\"class\":\"tree\",\"kind\":"
    "\"tree\"}",
    NULL,
    "{\"class\":\"bush\",\"kind\":\"bush\"}",
    "{\"class\":\"other\",\"kind\":\"grass\"}",
    NULL,
    NULL,
    NULL,
    NULL,
    "{\"class\":\"rock\",\"kind\":\"rock\"}",
    "{\"decorator\":\"none\"}",
    "{\"class\":\"bush\",\"density\":3}",
};
static const int parents[] = {-1, 0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0};
#define N (sizeof names / sizeof names[0])

static void classify(const obs_bake_scene *s, const char *mode, const char *json,
                     obs__bake_decor *d, obs_status want, char err[OBS_ERR_LEN])
{
    obs_bake_params p = {0};
    if (mode)
        bt_set(&p, "decorator-source", mode);
    bt_set(&p, "shrub-density", "0.75");
    obs_status st = obs__bake_decor_classify(s, &p, json, d, err);
    if (err[0])
        print_message("%s\n", err);
    assert_int_equal(st, want);
}

static void test_extras_and_names(void **state)
{
    (void)state;
    obs_bake_scene s;
    graph(&s, names, extras, parents, N);
    obs__bake_decor d;
    char err[OBS_ERR_LEN];
    classify(&s, NULL, NULL, &d, OBS_OK, err);
    assert_string_equal(err, "");
    assert_int_equal(d.node_count, N);
    const uint8_t want[N] = {OBS__DECOR_NONE,  OBS__DECOR_NONE,  OBS__DECOR_TREE,
                             OBS__DECOR_TREE,  OBS__DECOR_SHRUB, OBS__DECOR_SMALL,
                             OBS__DECOR_TREE,  OBS__DECOR_SHRUB, OBS__DECOR_NONE,
                             OBS__DECOR_NONE,  OBS__DECOR_NONE,  OBS__DECOR_NONE,
                             OBS__DECOR_SHRUB};
    size_t counts[4] = {0};
    for (size_t i = 0; i < N; i++) {
        print_message("%-44s %s %g\n", names[i], obs__bake_decor_class_name(d.node_class[i]),
                      (double)d.density[i]);
        assert_int_equal(d.node_class[i], want[i]);
        counts[want[i]]++;
        /* density: shrubs only; the extras' own, else the parameter */
        float dw = want[i] != OBS__DECOR_SHRUB ? 0.0f : i == 12 ? 3.0f : 0.75f;
        assert_true(d.density[i] == dw);
    }
    for (int c = 0; c < 4; c++)
        assert_int_equal(d.counts[c], counts[c]);
    obs__bake_decor_free(&d);

    /* off: everything opaque; file without a file: nothing but NONE */
    classify(&s, "off", NULL, &d, OBS_OK, err);
    assert_int_equal(d.counts[OBS__DECOR_NONE], N);
    obs__bake_decor_free(&d);
    classify(&s, "file", NULL, &d, OBS_OK, err);
    assert_int_equal(d.counts[OBS__DECOR_NONE], N);
    obs__bake_decor_free(&d);
    obs_bake_scene_free(&s);
}

static void test_file(void **state)
{
    (void)state;
    obs_bake_scene s;
    graph(&s, names, extras, parents, N);
    obs__bake_decor d;
    char err[OBS_ERR_LEN];
    /* rules: a name, a pattern (later rules win), a density; the file
     * beats the extras (the palm becomes small, its crown follows) */
    const char *json = "{\"decorators\": ["
                       " {\"name\": \"OBJ1479\", \"class\": \"tree\"},"
                       " {\"match\": \"*bush*\", \"class\": \"shrub\", \"density\": 0.25},"
                       " {\"match\": \"actor|flora/trees/*\", \"class\": \"small\"},"
                       " {\"name\": \"street_lamp\", \"class\": \"hedge\"}]}";
    classify(&s, NULL, json, &d, OBS_OK, err);
    assert_string_equal(err, "");
    assert_int_equal(d.node_class[9], OBS__DECOR_TREE);
    assert_int_equal(d.node_class[4], OBS__DECOR_SHRUB);
    assert_true(d.density[4] == 0.25f && d.density[12] == 0.25f);
    assert_int_equal(d.node_class[2], OBS__DECOR_SMALL);
    assert_int_equal(d.node_class[3], OBS__DECOR_SMALL);
    assert_int_equal(d.node_class[8], OBS__DECOR_SHRUB);
    assert_true(d.density[8] == 0.75f);
    assert_int_equal(d.node_class[6], OBS__DECOR_TREE); /* its name still */
    obs__bake_decor_free(&d);

    /* file mode: the rules alone, no extras or names */
    classify(&s, "file", json, &d, OBS_OK, err);
    assert_int_equal(d.node_class[6], OBS__DECOR_NONE);
    assert_int_equal(d.node_class[5], OBS__DECOR_NONE);
    assert_int_equal(d.node_class[9], OBS__DECOR_TREE);
    obs__bake_decor_free(&d);

    /* trees.json's own layout: "trees", "kind" tree / tree_line / hedge,
     * unmatched names a warning, not an error */
    const char *trees = "{\"file\": \"x.acc\", \"counts\": {\"objects\": 3}, \"trees\": ["
                        " {\"name\": \"OBJ1479\", \"object_index\": 9, \"kind\": \"tree\"},"
                        " {\"name\": \"Hedge-row\", \"kind\": \"hedge\"},"
                        " {\"name\": \"street_lamp\", \"kind\": \"tree_line\"},"
                        " {\"name\": \"OBJ9999\", \"kind\": \"tree\"}]}";
    classify(&s, "file", trees, &d, OBS_OK, err);
    assert_non_null(strstr(err, "1 of 4 entries match no node"));
    assert_non_null(strstr(err, "OBJ9999"));
    assert_int_equal(d.node_class[9], OBS__DECOR_TREE);
    assert_int_equal(d.node_class[7], OBS__DECOR_SHRUB);
    assert_int_equal(d.node_class[8], OBS__DECOR_TREE);
    assert_int_equal(d.counts[OBS__DECOR_TREE], 2);
    obs__bake_decor_free(&d);
    obs_bake_scene_free(&s);
}

static void expect_bad(const obs_bake_scene *s, const char *json, const char *words)
{
    obs__bake_decor d;
    char err[OBS_ERR_LEN];
    classify(s, NULL, json, &d, OBS_INVALID_ARGUMENT, err);
    assert_non_null(strstr(err, words));
    assert_null(d.node_class);
}

static void test_bad_file(void **state)
{
    (void)state;
    obs_bake_scene s;
    graph(&s, names, extras, parents, N);
    expect_bad(&s, "{\"decorators\": [ {\"name\": \"a\", \"class\": \"tree\"} ", "not JSON");
    expect_bad(&s, "{\n\"decorators\": [\n {\"name\": \"a\" \"class\": 1}]}", "line 3");
    expect_bad(&s, "[1, 2]", "expected an object");
    expect_bad(&s, "{\"other\": []}", "no \"decorators\" or \"trees\"");
    expect_bad(&s, "{\"decorators\": {}}", "\"decorators\" is not an array");
    expect_bad(&s, "{\"decorators\": [3]}", "decorators[0] is not an object");
    expect_bad(&s, "{\"decorators\": [{\"class\": \"tree\"}]}", "needs one of");
    expect_bad(&s, "{\"decorators\": [{\"name\": \"a\", \"match\": \"b\", \"class\": \"tree\"}]}",
               "needs one of");
    expect_bad(&s, "{\"decorators\": [{\"name\": \"a\"}]}", "no \"class\"");
    expect_bad(&s, "{\"decorators\": [{\"name\": \"a\", \"class\": \"palm\"}]}",
               "unknown class 'palm'");
    expect_bad(&s, "{\"trees\": [{\"name\": \"a\", \"kind\": \"fence\"}]}",
               "trees[0] ('a'): unknown class 'fence'");
    expect_bad(&s, "{\"decorators\": [{\"name\": \"a\", \"class\": \"shrub\", \"density\": -1}]}",
               "density");
    expect_bad(&s, "{\"decorators\": [{\"name\": \"a\", \"class\": \"shrub\", \"density\": \"x\"}]}",
               "density");
    obs_bake_scene_free(&s);
}

/* The fixture and its two tree cards (tests/data/levels/aalborg_cut.trees.json,
 * cut from TORCS' trees.json): the names assimp gives the AC3D objects are
 * the file's. */
static void test_fixture(void **state)
{
    (void)state;
    obs_bake_scene s;
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_bake_load(LEVELS "/aalborg_cut.acc", 0, &s, err), OBS_OK);
    FILE *f = fopen(LEVELS "/aalborg_cut.trees.json", "rb");
    assert_non_null(f);
    static char text[65536];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = 0;
    obs__bake_decor d;
    classify(&s, NULL, text, &d, OBS_OK, err);
    assert_string_equal(err, "");
    assert_int_equal(d.counts[OBS__DECOR_TREE], 2);
    assert_int_equal(d.counts[OBS__DECOR_SHRUB] + d.counts[OBS__DECOR_SMALL], 0);
    obs__bake_decor_free(&d);
    obs_bake_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_extras_and_names),
        cmocka_unit_test(test_file),
        cmocka_unit_test(test_bad_file),
        cmocka_unit_test(test_fixture),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
