/* bake-dynamic spread over shards (core/bake/dyn_shard.c,
 * dyn_shard_run.c): merged == unsharded byte for byte for N = 1, 3, 4
 * (the model file too), the parts' layout, and the parts refused
 * (missing, twice, another split, another level, other regions, other
 * parameters, truncated, damaged, not a part, traced with other
 * decorators). */
#include <stdio.h>
#include <unistd.h>

#include "level/bake_testutil.h"
#include "dynamic/dyn_internal.h"

static char dir[64];

static void path_of(char *buf, size_t len, const char *name, int i)
{
    snprintf(buf, len, "%s/%s%d.bin", dir, name, i);
}

/* A floor and a wall meeting at a crease. */
static void level(obs_bake_scene *sc, float shift)
{
    obs_bake_mesh m[2];
    const float o[3] = {-2, 0, -2}, u[3] = {0, 0, 4}, v[3] = {4, 0, 0};
    const float o2[3] = {-2 + shift, 0, -2}, u2[3] = {0, 2, 0}, v2[3] = {0, 0, 4};
    bt_grid(&m[0], "floor", o, u, v, 4, 4);
    bt_grid(&m[1], "wall", o2, u2, v2, 2, 4);
    bt_scene(sc, m, 2);
}

static void dset(obs_dyn_params *p, const char *name, const char *value)
{
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_dyn_param_set(p, name, value, err), OBS_OK);
}

static void params(obs_dyn_desc *d, const char *rays, const char *threads)
{
    memset(d, 0, sizeof *d);
    dset(&d->params, "rays", rays);
    dset(&d->params, "grid", "4");
    dset(&d->params, "max_regions", "4");
    dset(&d->params, "min_region_size", "0.5");
    dset(&d->params, "distance_short", "0.5");
    dset(&d->params, "distance_long", "3");
    dset(&d->params, "threads", threads);
}

static void shard_all(const obs_bake_scene *sc, const char *name, int n, const char *rays,
                      size_t *points)
{
    char err[OBS_ERR_LEN] = "", p[128];
    size_t sum = 0;
    for (int i = 0; i < n; i++) {
        obs_dyn_desc d;
        params(&d, rays, "2");
        obs_dyn_stats st;
        path_of(p, sizeof p, name, i);
        assert_int_equal(obs_dyn_bake_shard(sc, &d, i, n, p, &st, err), OBS_OK);
        size_t np = st.points_valid + st.points_backface;
        assert_true(st.rays == (uint64_t)np * (uint64_t)atoi(rays));
        /* the layout: a 128-byte header, 145 bytes a point */
        FILE *f = fopen(p, "rb");
        assert_non_null(f);
        char magic[8];
        assert_int_equal(fread(magic, 1, 8, f), 8);
        assert_memory_equal(magic, "OBSDYNPT", 8);
        fseek(f, 0, SEEK_END);
        assert_int_equal(ftell(f), 128 + 145 * (long)np);
        fclose(f);
        obs__dyn_part h;
        assert_int_equal(obs__part_header_read(p, &obs__dyn_part_format, &h, err), OBS_OK);
        assert_int_equal(h.r.index, i);
        assert_int_equal(h.r.count, n);
        assert_int_equal(h.r.first, sum);
        assert_int_equal(h.rays, atoi(rays));
        sum += np;
    }
    if (points)
        *points = sum;
}

static obs_status merge(const obs_bake_scene *sc, const char *const *paths, size_t n,
                        obs_dyn_result *r, char err[OBS_ERR_LEN])
{
    obs_dyn_desc d;
    params(&d, "16", "1");
    d.params.set &= ~((uint64_t)1 << (obs_dyn_param_find("rays") - obs_dyn_param_at(0)));
    d.params.rays = 0; /* taken from the parts */
    return obs_dyn_bake_merge(sc, &d, paths, n, r, err);
}

static void same_file(const char *a, const char *b)
{
    FILE *f = fopen(a, "rb"), *g = fopen(b, "rb");
    assert_non_null(f);
    assert_non_null(g);
    int x, y;
    long k = 0;
    do {
        x = fgetc(f), y = fgetc(g);
        if (x != y)
            fail_msg("%s and %s differ at byte %ld", a, b, k);
        k++;
    } while (x != EOF);
    fclose(f);
    fclose(g);
}

static void test_merged_is_unsharded(void **state)
{
    (void)state;
    obs_bake_scene sc;
    level(&sc, 0.0f);
    obs_dyn_desc d;
    params(&d, "32", "1");
    obs_dyn_result full;
    char err[OBS_ERR_LEN] = "", whole[128], merged[128];
    assert_int_equal(obs_dyn_bake(&sc, &d, &full, err), OBS_OK);
    assert_true(full.stats.points_valid > 50);
    assert_true(full.model.model_count >= 2);
    snprintf(whole, sizeof whole, "%s/whole.json", dir);
    assert_int_equal(obs_dyn_model_write(whole, &full.model, err), OBS_OK);
    assert_int_equal(full.model.level.triangles, 48); /* 32 floor + 16 wall */
    const int counts[] = {1, 3, 4};
    for (int c = 0; c < 3; c++) {
        int n = counts[c];
        size_t points;
        shard_all(&sc, "m", n, "32", &points);
        assert_int_equal(points, full.stats.points_valid + full.stats.points_backface);
        char names[4][128];
        const char *paths[4];
        for (int i = 0; i < n; i++) { /* given backwards: any order */
            path_of(names[i], sizeof names[i], "m", n - 1 - i);
            paths[i] = names[i];
        }
        obs_dyn_result r;
        assert_int_equal(merge(&sc, paths, (size_t)n, &r, err), OBS_OK);
        assert_int_equal(r.stats.points_valid, full.stats.points_valid);
        assert_true(r.stats.rays == full.stats.rays);
        assert_int_equal(r.model.region_count, full.model.region_count);
        assert_int_equal(r.model.model_count, full.model.model_count);
        assert_memory_equal(r.model.regions, full.model.regions,
                            full.model.region_count * sizeof *full.model.regions);
        assert_memory_equal(r.model.models, full.model.models,
                            full.model.model_count * sizeof *full.model.models);
        assert_memory_equal(r.original.models, full.original.models,
                            full.original.model_count * sizeof *full.original.models);
        assert_memory_equal(&r.model.level, &full.model.level, sizeof r.model.level);
        snprintf(merged, sizeof merged, "%s/merged%d.json", dir, n);
        assert_int_equal(obs_dyn_model_write(merged, &r.model, err), OBS_OK);
        same_file(whole, merged);
        obs_dyn_result_free(&r);
    }
    /* the model does vary (facing the floor, near it and higher): a real
     * comparison */
    float lo[3] = {0.1f, 0.1f, 0.1f}, hi[3] = {1.8f, 1.5f, 1.8f}, up[3] = {0, -1, 0}, a[3], b[3];
    obs_dyn_eval(&full.model, lo, up, OBS_DYN_QUADRATIC, a);
    obs_dyn_eval(&full.model, hi, up, OBS_DYN_QUADRATIC, b);
    assert_true(fabsf(a[2] - b[2]) > 0.02f);
    obs_dyn_result_free(&full);
    obs_bake_scene_free(&sc);
}

static void expect_refused(const obs_bake_scene *sc, const char *const *paths, size_t n,
                           obs_status want, const char *says)
{
    obs_dyn_result r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(merge(sc, paths, n, &r, err), want);
    if (!strstr(err, says))
        fail_msg("'%s' does not say '%s'", err, says);
    assert_int_equal(r.model.region_count, 0);
}

static void test_bad_parts(void **state)
{
    (void)state;
    obs_bake_scene sc, other;
    level(&sc, 0.0f);
    level(&other, 0.5f);
    shard_all(&sc, "b", 3, "8", NULL);
    shard_all(&sc, "q", 4, "8", NULL);
    shard_all(&other, "o", 3, "8", NULL);
    shard_all(&sc, "r", 3, "12", NULL);
    char p[14][128];
    for (int i = 0; i < 3; i++) {
        path_of(p[i], sizeof p[i], "b", i);
        path_of(p[3 + i], sizeof p[3 + i], "o", i);
    }
    path_of(p[6], sizeof p[6], "q", 0);
    path_of(p[7], sizeof p[7], "cut", 1);
    path_of(p[8], sizeof p[8], "flip", 1);
    path_of(p[9], sizeof p[9], "none", 0);
    path_of(p[10], sizeof p[10], "r", 1);
    path_of(p[11], sizeof p[11], "static", 0);
    bt_copy_cut(p[1], p[7], 1000, -1);
    bt_copy_cut(p[1], p[8], -1, 700);
    const char *ok[] = {p[0], p[1], p[2]};
    obs_dyn_result r;
    char err[OBS_ERR_LEN];
    assert_int_equal(merge(&sc, ok, 3, &r, err), OBS_OK);
    obs_dyn_result_free(&r);

    const char *missing[] = {p[0], p[2]};
    expect_refused(&sc, missing, 2, OBS_INVALID_ARGUMENT, "1 of 3 shards missing (1)");
    const char *twice[] = {p[0], p[1], p[1]};
    expect_refused(&sc, twice, 3, OBS_INVALID_ARGUMENT, "shard 1/3 given twice");
    const char *four[] = {p[0], p[1], p[2], p[1]};
    expect_refused(&sc, four, 4, OBS_INVALID_ARGUMENT, "given for a split into 3");
    const char *mixed[] = {p[0], p[6], p[2]};
    expect_refused(&sc, mixed, 3, OBS_INVALID_ARGUMENT, "different splits");
    const char *others[] = {p[3], p[4], p[5]};
    expect_refused(&sc, others, 3, OBS_INVALID_ARGUMENT, "another level");
    const char *mixed_level[] = {p[0], p[4], p[2]};
    expect_refused(&sc, mixed_level, 3, OBS_INVALID_ARGUMENT, "different levels");
    const char *mixed_rays[] = {p[0], p[10], p[2]};
    expect_refused(&sc, mixed_rays, 3, OBS_INVALID_ARGUMENT, "different rays (8 and 12)");
    const char *cut[] = {p[0], p[7], p[2]};
    expect_refused(&sc, cut, 3, OBS_BAD_FILE, "truncated: 1000 bytes");
    const char *flipped[] = {p[0], p[8], p[2]};
    expect_refused(&sc, flipped, 3, OBS_BAD_FILE, "checksum");
    const char *absent[] = {p[0], p[9], p[2]};
    expect_refused(&sc, absent, 3, OBS_IO, "cannot open");
    const char *none[] = {NULL};
    expect_refused(&sc, none, 0, OBS_INVALID_ARGUMENT, "no parts");
    /* a part of the static bake is not one of these */
    obs_bake_desc bd = {0};
    bt_set(&bd.params, "rays", "4");
    assert_int_equal(obs_bake_shard(&sc, &bd, 0, 1, p[11], NULL, err), OBS_OK);
    const char *stat_part[] = {p[11]};
    expect_refused(&sc, stat_part, 1, OBS_BAD_FILE, "not a bake-dynamic part");

    /* parameters the parts carry: given ones must agree */
    obs_dyn_desc d;
    params(&d, "16", "1");
    assert_int_equal(obs_dyn_bake_merge(&sc, &d, ok, 3, &r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "traced with rays 8; this merge asks for 16"));
    params(&d, "8", "1");
    dset(&d.params, "grid", "5");
    assert_int_equal(obs_dyn_bake_merge(&sc, &d, ok, 3, &r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "traced with grid 4; this merge asks for 5"));
    /* other regions than the shards' */
    params(&d, "8", "1");
    obs_dyn_regions rg = {0};
    assert_int_equal(obs_dyn_regions_parse("{\"regions\": [{\"min\": [-2, 0, -2], \"max\": [2, 2, 2]}]}",
                                           &rg, err), OBS_OK);
    d.regions = &rg;
    assert_int_equal(obs_dyn_bake_merge(&sc, &d, ok, 3, &r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "--regions"));
    obs_dyn_regions_free(&rg);
    /* a fit parameter is the merge's own */
    params(&d, "8", "1");
    dset(&d.params, "beta", "0");
    assert_int_equal(obs_dyn_bake_merge(&sc, &d, ok, 3, &r, err), OBS_OK);
    obs_dyn_result_free(&r);
    /* a bad shard index writes nothing */
    assert_int_equal(obs_dyn_bake_shard(&sc, &d, 3, 3, p[9], NULL, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_dyn_bake_shard(&sc, &d, 0, 0, p[9], NULL, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(access(p[9], F_OK), -1);
    obs_bake_scene_free(&sc);
    obs_bake_scene_free(&other);
}

/* The decorators are folded into the parts' level fingerprint: the wall
 * as a node named tree (semi-transparent), a part traced so is refused by
 * a merge without decorators or with another tree attenuation, and
 * merged with the same ones it is the unsharded model; a part traced all
 * opaque is refused by a merge with the tree. */
static obs_status merge_as(const obs_bake_scene *sc, const char *path, const char *source,
                           const char *attenuation, obs_dyn_result *r, char err[OBS_ERR_LEN])
{
    obs_dyn_desc d;
    params(&d, "16", "1");
    dset(&d.params, "decorator_source", source);
    if (attenuation)
        dset(&d.params, "tree_attenuation", attenuation);
    return obs_dyn_bake_merge(sc, &d, &path, 1, r, err);
}

static void test_decorators_in_fingerprint(void **state)
{
    (void)state;
    obs_bake_scene sc;
    level(&sc, 0.0f);
    const char *names[2] = {"level", "tree"};
    const uint32_t counts[2] = {1, 1};
    bt_split(&sc, names, counts, 2);
    char err[OBS_ERR_LEN] = "", tree[128], opaque[128], whole[128], merged[128];
    path_of(tree, sizeof tree, "dtree", 0);
    path_of(opaque, sizeof opaque, "dopaque", 0);
    path_of(whole, sizeof whole, "dwhole", 0);
    path_of(merged, sizeof merged, "dmerged", 0);
    obs_dyn_desc d;
    params(&d, "16", "2");
    obs_dyn_stats st;
    assert_int_equal(obs_dyn_bake_shard(&sc, &d, 0, 1, tree, &st, err), OBS_OK);
    assert_int_equal(st.decorator_nodes[2], 1); /* the node named tree */
    dset(&d.params, "decorator_source", "off");
    assert_int_equal(obs_dyn_bake_shard(&sc, &d, 0, 1, opaque, &st, err), OBS_OK);
    assert_int_equal(st.decorator_nodes[2], 0);
    obs_dyn_result r;
    assert_int_equal(merge_as(&sc, tree, "off", NULL, &r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "other decorators"));
    assert_int_equal(merge_as(&sc, tree, "auto", "0.25", &r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "other decorators"));
    assert_int_equal(merge_as(&sc, opaque, "auto", NULL, &r, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(merge_as(&sc, opaque, "off", NULL, &r, err), OBS_OK);
    obs_dyn_result_free(&r);
    assert_int_equal(merge_as(&sc, tree, "auto", NULL, &r, err), OBS_OK);
    assert_int_equal(obs_dyn_model_write(merged, &r.model, err), OBS_OK);
    obs_dyn_result_free(&r);
    params(&d, "16", "1");
    assert_int_equal(obs_dyn_bake(&sc, &d, &r, err), OBS_OK);
    assert_int_equal(obs_dyn_model_write(whole, &r.model, err), OBS_OK);
    obs_dyn_result_free(&r);
    same_file(merged, whole);
    const char *made[4] = {tree, opaque, whole, merged};
    for (int i = 0; i < 4; i++)
        unlink(made[i]);
    obs_bake_scene_free(&sc);
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/obs_dynshard_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_merged_is_unsharded),
        cmocka_unit_test(test_bad_parts),
        cmocka_unit_test(test_decorators_in_fingerprint),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
