/* The flags obscura bake and bake-dynamic share (clients/bake_common.c):
 * the level, --merge's parts up to the next option, -o, --shard, a
 * command's own options and the table's rows, in both tables. */
#include "testutil.h"

#include <sys/wait.h>
#include <unistd.h>

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

/* The usage error of an unknown option, read from a child's stderr. */
static int unknown_message(const cli_bake_cmd *cmd, char *word, char *out, size_t len)
{
    int fd[2], status = 0;
    assert_int_equal(pipe(fd), 0);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        dup2(fd[1], 2);
        char *argv[] = {"level.glb", word, "1"};
        cli_bake_args a;
        cli_bake_parse(cmd, 3, argv, &a);
        _exit(0); /* not reached: the word is unknown */
    }
    close(fd[1]);
    size_t got = 0;
    ssize_t n;
    while (got < len - 1 && (n = read(fd[0], out + got, len - 1 - got)) > 0)
        got += (size_t)n; /* stderr is unbuffered: the message comes in pieces */
    out[got] = '\0';
    close(fd[0]);
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* "did you mean" on a near miss, as obscura ao says it: a table row, a
 * command's own option, a shared one; nothing for a word far from all. */
static void test_did_you_mean(void **state)
{
    (void)state;
    obs_bake_params params = {0};
    obs_dyn_params dparams = {0};
    const char *ply = NULL, *regions = NULL;
    int color = 0;
    static const char *const flags[] = {"color", NULL};
    const cli_bake_str strs[] = {{"ply", &ply}, {NULL, NULL}};
    const cli_bake_str dstrs[] = {{"regions", &regions}, {NULL, NULL}};
    const cli_bake_cmd bake = {.name = "bake", .out_hint = "OUT.glb", .table = &cli_bake_table,
                               .params = &params, .flags = flags, .flag_vals = &color, .strs = strs};
    const cli_bake_cmd dyn = {.name = "bake-dynamic", .out_hint = "MODEL.json", .table = &cli_dyn_table,
                              .params = &dparams, .strs = dstrs};
    char msg[1024];
    assert_int_equal(unknown_message(&bake, "--rayz", msg, sizeof msg), 2);
    assert_non_null(strstr(msg, "unknown option '--rayz'; did you mean --rays?"));
    assert_int_equal(unknown_message(&bake, "--distance-shrt", msg, sizeof msg), 2);
    assert_non_null(strstr(msg, "did you mean --distance-short?"));
    assert_int_equal(unknown_message(&bake, "--colr", msg, sizeof msg), 2);
    assert_non_null(strstr(msg, "did you mean --color?"));
    assert_int_equal(unknown_message(&dyn, "--regoins", msg, sizeof msg), 2);
    assert_non_null(strstr(msg, "bake-dynamic: unknown option '--regoins'; did you mean --regions?"));
    assert_int_equal(unknown_message(&dyn, "--decortors", msg, sizeof msg), 2);
    assert_non_null(strstr(msg, "did you mean --decorators?"));
    assert_int_equal(unknown_message(&bake, "--zzzzzz", msg, sizeof msg), 2);
    assert_null(strstr(msg, "did you mean"));
    assert_non_null(strstr(msg, "'obscura bake --params' lists the parameters"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bake_flags),
        cmocka_unit_test(test_dyn_flags),
        cmocka_unit_test(test_progress_pace),
        cmocka_unit_test(test_did_you_mean),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
