/* A bake spread over shards (core/bake/shard.c): the split, merged ==
 * unsharded for N = 1, 3, 4, the parts refused (missing, twice, another
 * level, another split, truncated, damaged, other trace parameters), and
 * the cancel through the progress callback. */
#include <stdio.h>
#include <unistd.h>

#include "level/bake_testutil.h"
#include "bake/shard.h"

static char dir[64];

static void path_of(char *buf, size_t len, const char *name, int i)
{
    snprintf(buf, len, "%s/%s%d.bin", dir, name, i);
}

/* A floor and a wall meeting at a crease: values that vary. */
static void level(obs_bake_scene *sc, float shift)
{
    obs_bake_mesh m[2];
    const float o[3] = {-2, 0, -2}, u[3] = {0, 0, 4}, v[3] = {4, 0, 0};
    const float o2[3] = {-2 + shift, 0, -2}, u2[3] = {0, 2, 0}, v2[3] = {0, 0, 4};
    bt_grid(&m[0], "floor", o, u, v, 6, 6);
    bt_grid(&m[1], "wall", o2, u2, v2, 3, 6);
    bt_scene(sc, m, 2);
}

static void params(obs_bake_desc *d, const char *rays, const char *threads)
{
    memset(d, 0, sizeof *d);
    bt_set(&d->params, "rays", rays);
    bt_set(&d->params, "distance_short", "0.5");
    bt_set(&d->params, "distance_long", "3");
    bt_set(&d->params, "threads", threads);
}

static void shard_all(const obs_bake_scene *sc, const char *name, int n, const char *rays)
{
    char err[OBS_ERR_LEN] = "", p[128];
    for (int i = 0; i < n; i++) {
        obs_bake_desc d;
        params(&d, rays, "2");
        obs_bake_stats st;
        path_of(p, sizeof p, name, i);
        assert_int_equal(obs_bake_shard(sc, &d, i, n, p, &st, err), OBS_OK);
        assert_true(st.rays == (uint64_t)st.samples * (uint64_t)atoi(rays));
    }
}

static obs_status merge(const obs_bake_scene *sc, const char *const *paths, size_t n,
                        obs_bake_result *r, char err[OBS_ERR_LEN])
{
    obs_bake_desc d;
    params(&d, "16", "1");
    d.params.set &= ~((uint64_t)1 << (obs_bake_param_find("rays") - obs_bake_param_at(0)));
    d.params.rays = 0; /* taken from the parts */
    return obs_bake_merge(sc, &d, paths, n, r, err);
}

static void test_split(void **state)
{
    (void)state;
    for (size_t total = 0; total < 60; total++)
        for (int n = 1; n < 9; n++) {
            assert_int_equal(obs__bake_shard_first(total, 0, n), 0);
            assert_int_equal(obs__bake_shard_first(total, n, n), total);
            for (int i = 0; i < n; i++) {
                size_t a = obs__bake_shard_first(total, i, n), b = obs__bake_shard_first(total, i + 1, n);
                assert_true(a <= b);
                assert_true(b - a <= total / (size_t)n + 1); /* balanced */
            }
        }
    /* no overflow for a large total */
    assert_int_equal(obs__bake_shard_first((size_t)1 << 62, 3, 4), ((size_t)1 << 62) / 4 * 3);
}

static void test_merged_is_unsharded(void **state)
{
    (void)state;
    obs_bake_scene sc;
    level(&sc, 0.0f);
    obs_bake_desc d;
    params(&d, "16", "1");
    obs_bake_result full;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_bake_run(&sc, &d, &full, err), OBS_OK);
    const int counts[] = {1, 3, 4};
    for (int c = 0; c < 3; c++) {
        int n = counts[c];
        shard_all(&sc, "m", n, "16");
        char names[4][128];
        const char *paths[4];
        for (int i = 0; i < n; i++) { /* given backwards: any order */
            path_of(names[i], sizeof names[i], "m", n - 1 - i);
            paths[i] = names[i];
        }
        obs_bake_result r;
        assert_int_equal(merge(&sc, paths, (size_t)n, &r, err), OBS_OK);
        assert_int_equal(r.instance_count, full.instance_count);
        assert_int_equal(r.stats.samples, full.stats.samples);
        assert_true(r.stats.rays == full.stats.rays);
        assert_int_equal(r.stats.samples_dropped_backface, full.stats.samples_dropped_backface);
        double worst = 0.0, spread = 0.0;
        for (size_t k = 0; k < r.instance_count; k++) {
            size_t nv = sc.meshes[r.instances[k].mesh].vertex_count;
            for (size_t v = 0; v < nv; v++) {
                worst = fmax(worst, fabs(r.instances[k].ao_short[v] - full.instances[k].ao_short[v]));
                worst = fmax(worst, fabs(r.instances[k].ao_long[v] - full.instances[k].ao_long[v]));
                worst = fmax(worst, fabs(r.instances[k].ao[v] - full.instances[k].ao[v]));
                spread = fmax(spread, fabs(full.instances[k].ao_short[v] - full.instances[0].ao_short[0]));
            }
        }
        assert_true(worst <= 1e-6);
        assert_true(spread > 0.05); /* the values do vary: a real comparison */
        assert_true(fabs(r.stats.residual_fit[0] - full.stats.residual_fit[0]) <= 1e-9);
        obs_bake_result_free(&r);
    }
    obs_bake_result_free(&full);
    obs_bake_scene_free(&sc);
}

static void expect_refused(const obs_bake_scene *sc, const char *const *paths, size_t n, obs_status want,
                           const char *says)
{
    obs_bake_result r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(merge(sc, paths, n, &r, err), want);
    if (!strstr(err, says))
        fail_msg("'%s' does not say '%s'", err, says);
    assert_int_equal(r.instance_count, 0);
}

static void test_bad_parts(void **state)
{
    (void)state;
    obs_bake_scene sc, other;
    level(&sc, 0.0f);
    level(&other, 0.5f);
    shard_all(&sc, "b", 3, "8");
    shard_all(&sc, "q", 4, "8");
    shard_all(&other, "o", 3, "8");
    char p[12][128];
    for (int i = 0; i < 3; i++) {
        path_of(p[i], sizeof p[i], "b", i);
        path_of(p[3 + i], sizeof p[3 + i], "o", i);
    }
    path_of(p[6], sizeof p[6], "q", 0);
    path_of(p[7], sizeof p[7], "cut", 1);
    path_of(p[8], sizeof p[8], "flip", 1);
    path_of(p[9], sizeof p[9], "none", 0);
    bt_copy_cut(p[1], p[7], 200, -1);
    bt_copy_cut(p[1], p[8], -1, 140);
    const char *ok[] = {p[0], p[1], p[2]};
    obs_bake_result r;
    char err[OBS_ERR_LEN];
    assert_int_equal(merge(&sc, ok, 3, &r, err), OBS_OK);
    obs_bake_result_free(&r);

    const char *missing[] = {p[0], p[2]};
    expect_refused(&sc, missing, 2, OBS_INVALID_ARGUMENT, "1 of 3 shards missing (1)");
    const char *twice[] = {p[0], p[1], p[1]};
    expect_refused(&sc, twice, 3, OBS_INVALID_ARGUMENT, "given twice");
    const char *four[] = {p[0], p[1], p[2], p[1]};
    expect_refused(&sc, four, 4, OBS_INVALID_ARGUMENT, "given for a split into 3");
    const char *mixed[] = {p[0], p[6], p[2]};
    expect_refused(&sc, mixed, 3, OBS_INVALID_ARGUMENT, "different splits");
    const char *others[] = {p[3], p[4], p[5]};
    expect_refused(&sc, others, 3, OBS_INVALID_ARGUMENT, "another level");
    const char *mixed_level[] = {p[0], p[4], p[2]};
    expect_refused(&sc, mixed_level, 3, OBS_INVALID_ARGUMENT, "different levels");
    const char *cut[] = {p[0], p[7], p[2]};
    expect_refused(&sc, cut, 3, OBS_BAD_FILE, "truncated");
    const char *flipped[] = {p[0], p[8], p[2]};
    expect_refused(&sc, flipped, 3, OBS_BAD_FILE, "checksum");
    const char *absent[] = {p[0], p[9], p[2]};
    expect_refused(&sc, absent, 3, OBS_IO, "cannot open");
    const char *none[] = {NULL};
    expect_refused(&sc, none, 0, OBS_INVALID_ARGUMENT, "no parts");

    /* trace parameters: given ones must agree with the parts' */
    obs_bake_desc d;
    params(&d, "16", "1");
    assert_int_equal(obs_bake_merge(&sc, &d, ok, 3, &r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "traced with rays 8; this merge asks for 16"));
    params(&d, "8", "1");
    bt_set(&d.params, "alpha", "0.5"); /* a fit parameter: the merge's own */
    assert_int_equal(obs_bake_merge(&sc, &d, ok, 3, &r, err), OBS_OK);
    obs_bake_result_free(&r);
    /* a bad shard index */
    assert_int_equal(obs_bake_shard(&sc, &d, 3, 3, p[9], NULL, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_bake_shard(&sc, &d, 0, 0, p[9], NULL, err), OBS_INVALID_ARGUMENT);
    assert_int_equal(access(p[9], F_OK), -1);
    obs_bake_scene_free(&sc);
    obs_bake_scene_free(&other);
}

/* A copy of the part at from in to, its first keep bytes (-1: all) with
 * the 4 bytes at `at` set to v (little-endian). */
static void patch32(const char *from, const char *to, long keep, uint32_t at, uint32_t v)
{
    unsigned char b[4096];
    FILE *f = fopen(from, "rb");
    assert_non_null(f);
    size_t len = fread(b, 1, sizeof b, f);
    fclose(f);
    assert_true(len > at + 4 && len < sizeof b);
    obs__le_put32(b + at, v);
    FILE *g = fopen(to, "wb");
    assert_non_null(g);
    assert_int_equal(fwrite(b, 1, keep < 0 ? len : (size_t)keep, g), keep < 0 ? len : (size_t)keep);
    fclose(g);
}

/* Damaged headers (tests/fuzz/fuzz_files.c fuzzes the part reader): a
 * shard count near 2^31 with a level of as many samples (so the range
 * checks hold) is a missing shard, not an allocation of count parts;
 * trace parameters out of their rows' ranges (the header carries no
 * checksum) are refused, naming the parameter, not taken by the merge. */
static void test_damaged_headers(void **state)
{
    (void)state;
    obs_bake_scene sc;
    level(&sc, 0.0f);
    shard_all(&sc, "h", 1, "8");
    char p[128], bad[128];
    path_of(p, sizeof p, "h", 0);
    path_of(bad, sizeof bad, "hbad", 0);
    /* shard 0 of 2^31 - 1 over 2^31 - 1 samples: one sample, 128 + 9 bytes */
    patch32(p, bad, -1, 28, 0x7fffffffu);
    unsigned char b[4096];
    FILE *f = fopen(bad, "rb");
    size_t len = fread(b, 1, sizeof b, f);
    fclose(f);
    obs__le_put64(b + 32, 0x7fffffffu);
    obs__le_put64(b + 48, 1);
    f = fopen(bad, "wb");
    assert_int_equal(fwrite(b, 1, 128 + 9, f), 128 + 9);
    fclose(f);
    assert_true(len > 128 + 9);
    const char *one[] = {bad};
    expect_refused(&sc, one, 1, OBS_INVALID_ARGUMENT, "2147483646 of 2147483647 shards missing");
    /* parameters the merge takes from the parts: rays -5, a sample
     * budget that is NaN, a back-face limit of 2 */
    const struct {
        uint32_t at, v;
        const char *says;
    } fields[] = {{72, (uint32_t)-5, "rays"},
                  {84, 0x7fc00000u, "samples_per_face"},
                  {96, 0x40000000u, "backface_limit"}};
    for (size_t k = 0; k < sizeof fields / sizeof fields[0]; k++) {
        patch32(p, bad, -1, fields[k].at, fields[k].v);
        expect_refused(&sc, one, 1, OBS_BAD_FILE, fields[k].says);
    }
    obs_bake_scene_free(&sc);
}

static int stop_at;
static int cancel_cb(void *user, size_t done, size_t total)
{
    (void)user;
    (void)total;
    return done >= (size_t)stop_at;
}

static void test_cancel(void **state)
{
    (void)state;
    obs_bake_scene sc;
    level(&sc, 0.0f);
    obs_bake_desc d;
    params(&d, "8", "1");
    d.progress = cancel_cb;
    obs_bake_result r;
    char err[OBS_ERR_LEN] = "";
    stop_at = 1;
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_CANCELLED);
    assert_non_null(strstr(err, "cancelled after 64 of"));
    assert_int_equal(r.instance_count, 0);
    stop_at = 1 << 30; /* never */
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    obs_bake_result_free(&r);
    obs_bake_scene_free(&sc);
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/obs_shard_XXXXXX");
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
        cmocka_unit_test(test_split),
        cmocka_unit_test(test_merged_is_unsharded),
        cmocka_unit_test(test_bad_parts),
        cmocka_unit_test(test_damaged_headers),
        cmocka_unit_test(test_cancel),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
