/* The flags obscura bake and bake-dynamic share (clients/bake_common.c):
 * the level, --merge's parts up to the next option, -o, --shard, a
 * command's own options and the table's rows, in both tables. */
#include "testutil.h"

#include "bake_common.h"
#include "obscura/dynamic.h"

static int option_calls;
static int count_option(void *user, const char *key, const char *val)
{
    (void)user;
    (void)val;
    option_calls += !strcmp(key, "mine");
    return !strcmp(key, "mine");
}

static void test_bake_flags(void **state)
{
    (void)state;
    obs_bake_params params = {0};
    const char *ply = NULL;
    int color = 0;
    static const char *const flags[] = {"color", NULL};
    const cli_bake_str strs[] = {{"ply", &ply}, {NULL, NULL}};
    const cli_bake_cmd cmd = {.name = "bake", .out_hint = "OUT.glb", .table = &cli_bake_table,
                              .params = &params, .flags = flags, .flag_vals = &color,
                              .strs = strs, .option = count_option};
    char *argv[] = {"level.glb", "--merge", "p0", "p1", "-o", "out.glb", "--color",
                    "--ply=x.ply", "--rays", "16", "--mine", "1", "-q", "--merge=p2"};
    cli_bake_args a;
    option_calls = 0;
    assert_int_equal(cli_bake_parse(&cmd, 14, argv, &a), 1);
    assert_string_equal(a.in, "level.glb");
    assert_string_equal(a.out, "out.glb");
    assert_int_equal(a.nparts, 3);
    assert_string_equal(a.parts[0], "p0");
    assert_string_equal(a.parts[1], "p1");
    assert_string_equal(a.parts[2], "p2");
    assert_int_equal(a.merge, 1);
    assert_int_equal(a.quiet, 1);
    assert_int_equal(a.shards, 0);
    assert_int_equal(color, 1);
    assert_string_equal(ply, "x.ply");
    assert_int_equal(option_calls, 1);
    obs_bake_params p;
    obs_bake_params_resolve(&params, &p);
    assert_int_equal(p.rays, 16);
    cli_bake_args_free(&a);
}

static void test_dyn_flags(void **state)
{
    (void)state;
    obs_dyn_params params = {0};
    const cli_bake_cmd cmd = {.name = "bake-dynamic", .out_hint = "MODEL.json",
                              .table = &cli_dyn_table, .params = &params};
    char *argv[] = {"level.acc", "--shard", "1/4", "--output", "part", "--grid=4",
                    "--report", "r.json"};
    cli_bake_args a;
    assert_int_equal(cli_bake_parse(&cmd, 8, argv, &a), 1);
    assert_int_equal(a.shard, 1);
    assert_int_equal(a.shards, 4);
    assert_string_equal(a.out, "part");
    assert_string_equal(a.report, "r.json");
    assert_int_equal(a.nparts, 0);
    obs_dyn_params p;
    obs_dyn_params_resolve(&params, &p);
    assert_int_equal(p.grid, 4);
    cli_bake_args_free(&a);
}

static void test_progress_pace(void **state)
{
    (void)state;
    cli_progress p = {0.0, 1e300}; /* a line just drawn */
    double t;
    assert_int_equal(cli_progress_due(&p, 1, 10, &t), 0);
    assert_int_equal(cli_progress_due(&p, 10, 10, &t), 1); /* the end always */
    p.last = t - 1.0;
    assert_int_equal(cli_progress_due(&p, 2, 10, &t), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bake_flags),
        cmocka_unit_test(test_dyn_flags),
        cmocka_unit_test(test_progress_pace),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
