/* Loading levels with the node graph (core/bake/load.c), the bake
 * parameter table (params.c) and the output files (glb.c, ply.c), read
 * back through assimp. */
#include <cjson/cJSON.h>

#include "level/bake_testutil.h"

#define LEVELS TESTDATA "/levels"

static void test_params(void **state)
{
    (void)state;
    obs_bake_params p = {0}, r;
    char err[OBS_ERR_LEN] = "";
    obs_bake_params_resolve(&p, &r);
    assert_true(r.distance_short == 2.0f && r.distance_long == 300.0f);
    assert_true(fabsf(r.blend - 0.03f) < 1e-7f);
    assert_int_equal(r.rays, 256);
    assert_int_equal(r.mass, OBS_BAKE_MASS_SAMPLES);
    /* a given 0 stays 0 */
    bt_set(&p, "blend", "0");
    bt_set(&p, "max-samples-per-face", "8");
    bt_set(&p, "mass", "analytic");
    obs_bake_params_resolve(&p, &r);
    assert_true(r.blend == 0.0f);
    assert_int_equal(r.max_samples_per_face, 8);
    assert_int_equal(r.mass, OBS_BAKE_MASS_ANALYTIC);
    char buf[64];
    obs_bake_param_format(&r, obs_bake_param_find("mass"), buf, sizeof buf);
    assert_string_equal(buf, "analytic");
    assert_int_equal(obs_bake_param_set(&p, "blend", "1.5", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "blend"));
    assert_int_equal(obs_bake_param_set(&p, "rays", "2.5", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_bake_param_set(&p, "mass", "lumped", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "samples|analytic"));
    assert_int_equal(obs_bake_param_set(&p, "nonsense", "1", err), OBS_INVALID_ARGUMENT);
    /* every row has a doc and a default its own range takes */
    for (int i = 0; i < obs_bake_param_count(); i++) {
        const obs_bake_param_info *pi = obs_bake_param_at(i);
        obs_bake_params q = {0};
        assert_true(pi->doc && *pi->doc);
        assert_int_equal(obs_bake_param_set(&q, pi->name, pi->def, err), OBS_OK);
    }
}

static void expect_bad(const char *file, obs_status want, const char *words)
{
    char path[256], err[OBS_ERR_LEN] = "";
    obs_bake_scene sc;
    snprintf(path, sizeof path, LEVELS "/bad/%s", file);
    assert_int_equal(obs_bake_load(path, 0, &sc, err), want);
    print_message("%s: %s\n", file, err);
    assert_non_null(strstr(err, words));
    assert_null(sc.nodes);
}

static void test_bad_input(void **state)
{
    (void)state;
    expect_bad("no_triangles.obj", OBS_BAD_FILE, "no triangles");
    expect_bad("nan_vertex.obj", OBS_BAD_FILE, "not finite");
    expect_bad("huge_index_count.glb", OBS_BAD_FILE, "out of range");
    expect_bad("missing.glb", OBS_IO, "cannot open");
    /* all faces degenerate: the loader keeps them, the bake refuses */
    obs_bake_scene sc;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bake_load(LEVELS "/bad/degenerate.obj", 0, &sc, err), OBS_OK);
    obs_bake_result r;
    assert_int_equal(obs_bake_run(&sc, NULL, &r, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "degenerate"));
    obs_bake_scene_free(&sc);
    /* the flattened-size limit */
    assert_int_equal(obs_bake_load(LEVELS "/aalborg_cut.acc", 100, &sc, err), OBS_TOO_LARGE);
    assert_non_null(strstr(err, "max_triangles"));
}

/* The fixture cut from aalborg: baked, written, read back by assimp. */
static void test_fixture_round_trip(void **state)
{
    (void)state;
    obs_bake_scene sc, back;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bake_load(LEVELS "/aalborg_cut.acc", 0, &sc, err), OBS_OK);
    assert_int_equal(sc.mesh_count, 62);
    assert_int_equal(sc.instance_count, 62);
    assert_int_equal(sc.world_triangles, 811);
    /* AC3D's double-sided flag, read from the file (assimp drops it): 39
     * of the fixture's 62 poly objects have SURF 0x20 on their surfaces,
     * the tree cards among them (OBJ1559 is one) */
    size_t two = 0;
    for (size_t n = 0; n < sc.node_count; n++)
        for (uint32_t k = 0; k < sc.nodes[n].mesh_count; k++) {
            const obs_bake_mesh *m = &sc.meshes[sc.nodes[n].meshes[k]];
            two += m->two_sided && k == 0;
            if (!strcmp(sc.nodes[n].name, "OBJ1559"))
                assert_true(m->two_sided);
        }
    assert_int_equal(two, 39);
    obs_bake_desc d = {0};
    bt_set(&d.params, "rays", "32");
    bt_set(&d.params, "holdout", "1");
    obs_bake_result r;
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    assert_int_equal(r.instance_count, 62);
    /* held-out samples: traced apart, compared with all three */
    assert_true(r.stats.holdout_samples > 700);
    for (int c = 0; c < 2; c++)
        assert_true(r.stats.holdout_fit[c] > 0.0 && r.stats.holdout_fit[c] < 0.5 &&
                    r.stats.holdout_point[c] > 0.0 && r.stats.holdout_face_mean[c] > 0.0);
    assert_true(r.stats.ao_min >= 0.0 && r.stats.ao_max <= 1.0);
    assert_true(r.stats.ao_mean > 0.3 && r.stats.ao_mean < 1.0);
    /* With alpha 0 the fit is the least-squares fit of the samples: no
     * piecewise-linear signal, the two baselines included, comes closer
     * (up to the ridge's pull). */
    obs_bake_desc d0 = d;
    bt_set(&d0.params, "alpha", "0");
    obs_bake_result r0;
    assert_int_equal(obs_bake_run(&sc, &d0, &r0, err), OBS_OK);
    for (int c = 0; c < 2; c++) {
        assert_true(r0.stats.residual_fit[c] <= r0.stats.residual_face_mean[c] + 1e-4);
        assert_true(r0.stats.residual_fit[c] <= r0.stats.residual_point[c] + 1e-4);
        /* the regulariser costs some of the fit to the samples */
        assert_true(r.stats.residual_fit[c] >= r0.stats.residual_fit[c] - 1e-6);
    }
    obs_bake_result_free(&r0);
    const char *glb = obs_test_tmp_file("aalborg_cut.glb", NULL);
    assert_int_equal(obs_bake_write_glb(glb, &sc, &r, 1, err), OBS_OK);
    assert_int_equal(obs_bake_load(glb, 0, &back, err), OBS_OK);
    assert_int_equal(back.instance_count, sc.instance_count);
    assert_int_equal(back.world_triangles, sc.world_triangles);
    assert_int_equal(back.node_count, sc.node_count);
    for (size_t n = 0; n < sc.node_count; n++)
        assert_string_equal(back.nodes[n].name, sc.nodes[n].name);
    obs_bake_scene_free(&back);

    /* the JSON chunk: every primitive has the three attributes, one value
     * per vertex, within [0, 1] */
    size_t len;
    unsigned char *bytes = obs_test_slurp(glb, &len);
    uint32_t head[5];
    memcpy(head, bytes, sizeof head);
    assert_int_equal(head[0], 0x46546C67u);
    assert_int_equal(head[2], len);
    cJSON *js = cJSON_ParseWithLength((const char *)bytes + 20, head[3]);
    assert_non_null(js);
    cJSON *acc = cJSON_GetObjectItem(js, "accessors"), *mesh;
    int prims = 0;
    cJSON_ArrayForEach(mesh, cJSON_GetObjectItem(js, "meshes"))
    {
        cJSON *p;
        cJSON_ArrayForEach(p, cJSON_GetObjectItem(mesh, "primitives"))
        {
            cJSON *at = cJSON_GetObjectItem(p, "attributes");
            int pos = cJSON_GetObjectItem(at, "POSITION")->valueint;
            double count = cJSON_GetObjectItem(cJSON_GetArrayItem(acc, pos), "count")->valuedouble;
            const char *names[4] = {"_AO", "_AO_SHORT", "_AO_LONG", "COLOR_0"};
            for (int k = 0; k < 4; k++) {
                cJSON *ix = cJSON_GetObjectItem(at, names[k]);
                assert_non_null(ix);
                cJSON *a = cJSON_GetArrayItem(acc, ix->valueint);
                assert_true(cJSON_GetObjectItem(a, "count")->valuedouble == count);
                if (k < 3) {
                    assert_true(cJSON_GetArrayItem(cJSON_GetObjectItem(a, "min"), 0)->valuedouble >= 0.0);
                    assert_true(cJSON_GetArrayItem(cJSON_GetObjectItem(a, "max"), 0)->valuedouble <= 1.0);
                }
            }
            prims++;
        }
    }
    assert_int_equal(prims, 62);
    /* the materials: as many as loaded, each primitive's in range */
    cJSON *mats = cJSON_GetObjectItem(js, "materials");
    assert_int_equal(cJSON_GetArraySize(mats), (int)sc.material_count);
    assert_true(sc.material_count >= 1);
    cJSON_ArrayForEach(mesh, cJSON_GetObjectItem(js, "meshes"))
    {
        cJSON *p;
        cJSON_ArrayForEach(p, cJSON_GetObjectItem(mesh, "primitives"))
        {
            cJSON *mi = cJSON_GetObjectItem(p, "material");
            assert_non_null(mi);
            assert_true(mi->valueint >= 0 && mi->valueint < (int)sc.material_count);
        }
    }
    cJSON_Delete(js);
    free(bytes);

    const char *ply = obs_test_tmp_file("aalborg_cut.ply", NULL);
    assert_int_equal(obs_bake_write_ply(ply, &sc, &r, err), OBS_OK);
    assert_int_equal(obs_bake_load(ply, 0, &back, err), OBS_OK);
    assert_int_equal(back.world_triangles, sc.world_triangles);
    obs_bake_scene_free(&back);
    obs_bake_result_free(&r);
    obs_bake_scene_free(&sc);
}

/* Instancing and extras: two nodes share one mesh at different places;
 * each is its own instance with its own values, and the written file
 * keeps the graph, the transforms and the extras. */
static void test_instances_and_extras(void **state)
{
    (void)state;
    obs_bake_mesh m[2];
    const float o[3] = {-20, 0, -20}, u[3] = {0, 0, 40}, v[3] = {40, 0, 0};
    const float bo[3] = {-1, 0, -1}, bu[3] = {0, 2, 0}, bv[3] = {0, 0, 2};
    bt_grid(&m[0], "ground", o, u, v, 8, 8);
    bt_grid(&m[1], "wall", bo, bu, bv, 2, 2); /* a 2 x 2 wall facing +x */
    obs_bake_scene sc;
    bt_scene(&sc, m, 1);
    /* two more nodes, children of the root, each holding mesh 1 */
    obs_bake_mesh *meshes = realloc(sc.meshes, 2 * sizeof *meshes);
    assert_non_null(meshes);
    sc.meshes = meshes;
    sc.meshes[1] = m[1];
    sc.mesh_count = 2;
    obs_bake_node *nodes = realloc(sc.nodes, 3 * sizeof *nodes);
    assert_non_null(nodes);
    sc.nodes = nodes;
    for (int k = 1; k <= 2; k++) {
        obs_bake_node *nd = &sc.nodes[k];
        memset(nd, 0, sizeof *nd);
        nd->name = strdup(k == 1 ? "wall_a" : "wall_b");
        nd->parent = 0;
        for (int i = 0; i < 16; i++)
            nd->local[i] = nd->world[i] = i % 5 == 0 ? 1.0f : 0.0f;
        nd->local[3] = nd->world[3] = k == 1 ? -5.0f : 5.0f; /* x */
        nd->meshes = malloc(sizeof *nd->meshes);
        nd->meshes[0] = 1;
        nd->mesh_count = 1;
        nd->extras = k == 1 ? strdup("{\"class\":\"building\",\"uid\":7}") : NULL;
    }
    sc.node_count = 3;
    sc.instance_count = 3;
    sc.world_triangles += 2 * m[1].triangle_count;
    obs_bake_desc d = {0};
    bt_set(&d.params, "rays", "64");
    bt_set(&d.params, "distance_long", "3");
    obs_bake_result r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    assert_int_equal(r.instance_count, 3);
    /* each wall stands on the ground: its bottom vertex (0) is darker
     * than its top one (the last) */
    const obs_bake_instance *a = &r.instances[1];
    assert_int_equal(a->node, 1);
    assert_true(a->ao_long[0] < a->ao_long[sc.meshes[1].vertex_count - 1] + 1e-6f);
    const char *glb = obs_test_tmp_file("instances.glb", NULL);
    assert_int_equal(obs_bake_write_glb(glb, &sc, &r, 0, err), OBS_OK);
    obs_bake_scene back;
    assert_int_equal(obs_bake_load(glb, 0, &back, err), OBS_OK);
    assert_int_equal(back.node_count, 3);
    assert_int_equal(back.instance_count, 3);
    int found = 0;
    for (size_t n = 0; n < back.node_count; n++) {
        if (strcmp(back.nodes[n].name, "wall_a"))
            continue;
        found = 1;
        assert_true(fabsf(back.nodes[n].world[3] + 5.0f) < 1e-6f);
        assert_non_null(back.nodes[n].extras);
        assert_non_null(strstr(back.nodes[n].extras, "\"class\":\"building\""));
    }
    assert_true(found);
    obs_bake_scene_free(&back);
    obs_bake_result_free(&r);
    obs_bake_scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_params),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_fixture_round_trip),
        cmocka_unit_test(test_instances_and_extras),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
