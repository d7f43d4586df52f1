/* Frame specs and path patterns of obscura batch (clients/batch.c). */
#include "testutil.h"

#include "batch.h"

#include <unistd.h>

static void expect_frames(const char *spec, const int *want, int n)
{
    int *f = NULL, count = -1;
    char err[256] = "";
    assert_int_equal(cli_batch_parse_frames(spec, &f, &count, err, sizeof err), 0);
    assert_int_equal(count, n);
    for (int i = 0; i < n; i++)
        assert_int_equal(f[i], want[i]);
    free(f);
}

static void expect_bad_spec(const char *spec)
{
    int *f = (int *)1, count = -1;
    char err[256] = "";
    assert_int_equal(cli_batch_parse_frames(spec, &f, &count, err, sizeof err), -1);
    assert_null(f);
    assert_int_equal(count, 0);
    assert_true(strstr(err, "--frames") != NULL);
}

static void test_frames(void **state)
{
    (void)state;
    static const int one[] = {7};
    expect_frames("7", one, 1);
    static const int range[] = {1, 2, 3, 4, 5};
    expect_frames("1-5", range, 5);
    static const int step[] = {1, 3, 5, 7, 9};
    expect_frames("1-10x2", step, 5);
    expect_frames("1-9:2", step, 5);
    static const int list[] = {1, 5, 9};
    expect_frames("1,5,9", list, 3);
    static const int combo[] = {1, 2, 3, 20};
    expect_frames("1-3,20", combo, 4);
    /* unordered and overlapping: ascending, each once */
    static const int merged[] = {0, 1, 2, 3, 4, 10};
    expect_frames("10, 2-4,0-3,1", merged, 6);
    static const int hundred_x2[] = {1, 3, 5};
    int *f, n;
    char err[256];
    assert_int_equal(cli_batch_parse_frames("1-100x2", &f, &n, err, sizeof err), 0);
    assert_int_equal(n, 50);
    for (int i = 0; i < 3; i++)
        assert_int_equal(f[i], hundred_x2[i]);
    assert_int_equal(f[49], 99);
    free(f);
}

static void test_bad_frames(void **state)
{
    (void)state;
    expect_bad_spec("");
    expect_bad_spec("a");
    expect_bad_spec("1-");
    expect_bad_spec("-3");
    expect_bad_spec("5-1");
    expect_bad_spec("1-10x0");
    expect_bad_spec("1-10x");
    expect_bad_spec("1,,2");
    expect_bad_spec("1,");
    expect_bad_spec("1-10y2");
    expect_bad_spec("9999999999");
    expect_bad_spec("0-999999999"); /* more than CLI_BATCH_MAX_FRAMES */
    expect_bad_spec("0-600000,700000-1300000");
}

static void test_patterns(void **state)
{
    (void)state;
    char buf[256], err[256];
    assert_int_equal(cli_batch_expand("shot/frame.####.exr", 7, buf, sizeof buf), 0);
    assert_string_equal(buf, "shot/frame.0007.exr");
    assert_int_equal(cli_batch_expand("f.#.exr", 123, buf, sizeof buf), 0);
    assert_string_equal(buf, "f.123.exr");
    assert_int_equal(cli_batch_expand("out/ao.%04d.exr", 42, buf, sizeof buf), 0);
    assert_string_equal(buf, "out/ao.0042.exr");
    assert_int_equal(cli_batch_expand("ao.%d.exr", 42, buf, sizeof buf), 0);
    assert_string_equal(buf, "ao.42.exr");
    assert_int_equal(cli_batch_expand("100%%/ao.%06d.exr", 5, buf, sizeof buf), 0);
    assert_string_equal(buf, "100%/ao.000005.exr");
    assert_int_equal(cli_batch_expand("ao.####.exr", 123456, buf, sizeof buf), 0);
    assert_string_equal(buf, "ao.123456.exr"); /* wider than the padding: all digits */

    assert_int_equal(cli_batch_check_pattern("a.exr", err, sizeof err), -1);
    assert_true(strstr(err, "no frame placeholder") != NULL);
    assert_int_equal(cli_batch_check_pattern("a.##.#.exr", err, sizeof err), -1);
    assert_true(strstr(err, "more than one") != NULL);
    assert_int_equal(cli_batch_check_pattern("a.%04d.####.exr", err, sizeof err), -1);
    assert_int_equal(cli_batch_check_pattern("a.%s.exr", err, sizeof err), -1);
    assert_int_equal(cli_batch_check_pattern("a.%4d.exr", err, sizeof err), -1);
    assert_int_equal(cli_batch_expand("a.exr", 1, buf, sizeof buf), -1);
    /* never past the buffer */
    assert_int_equal(cli_batch_expand("ao.####.exr", 1, buf, 11), -1);
    assert_int_equal(cli_batch_expand("ao.####.exr", 1, buf, 12), 0);
    assert_string_equal(buf, "ao.0001.exr");
}

/* A server list rotated frame by frame: round robin over the daemons. */
static void test_rotate(void **state)
{
    (void)state;
    char buf[64];
    assert_int_equal(cli_batch_rotate("a,b,c", 0, buf, sizeof buf), 0);
    assert_string_equal(buf, "a,b,c");
    assert_int_equal(cli_batch_rotate("a,b,c", 1, buf, sizeof buf), 0);
    assert_string_equal(buf, "b,c,a");
    assert_int_equal(cli_batch_rotate("a,b,c", 5, buf, sizeof buf), 0);
    assert_string_equal(buf, "c,a,b");
    assert_int_equal(cli_batch_rotate("http://h:1,unix:/s", 3, buf, sizeof buf), 0);
    assert_string_equal(buf, "unix:/s,http://h:1");
    assert_int_equal(cli_batch_rotate("only", 7, buf, sizeof buf), 0);
    assert_string_equal(buf, "only");
    assert_int_equal(cli_batch_rotate("a,b,c", 1, buf, 5), -1); /* never past the buffer */
    assert_int_equal(cli_batch_rotate("a,b,c", 1, buf, 6), 0);
    assert_string_equal(buf, "b,c,a");
}

/* cli_batch's exit code with a stand-in for `obscura ao` (each frame
 * "written" with exit 0): the farm's view of gaps. */
static void fake_check(int argc, char **argv)
{
    (void)argc, (void)argv;
}

static int fake_ao(int argc, char **argv)
{
    (void)argc, (void)argv;
    return 0;
}

static int run_batch(const char *dir, const char *frames, const char *extra)
{
    static const cli_batch_ops ops = {fake_check, fake_ao, NULL};
    char in[512], out[512], fr[64], ex[64];
    snprintf(in, sizeof in, "%s/f.####.exr", dir);
    snprintf(out, sizeof out, "%s/o/ao.####.exr", dir);
    snprintf(fr, sizeof fr, "%s", frames);
    snprintf(ex, sizeof ex, "%s", extra ? extra : "-q");
    char *argv[] = {in, "--frames", fr, "-o", out, ex, NULL};
    return cli_batch(6, argv, &ops);
}

static void test_exit_codes(void **state)
{
    (void)state;
    char dir[] = "/tmp/obscura-test-batch-XXXXXX", p[512];
    assert_non_null(mkdtemp(dir));
    for (int f = 1; f <= 3; f += 2) {
        snprintf(p, sizeof p, "%s/f.%04d.exr", dir, f);
        FILE *fp = fopen(p, "w");
        assert_non_null(fp);
        fclose(fp);
    }
    assert_int_equal(run_batch(dir, "1,3", NULL), 0);                /* every frame written */
    assert_int_equal(run_batch(dir, "1-3", NULL), 3);                /* frame 2 missing */
    assert_int_equal(run_batch(dir, "1-3", "--allow-missing"), 0);   /* a gap accepted */
    assert_int_equal(run_batch(dir, "2,4", "--allow-missing"), 3);   /* nothing written */
    assert_int_equal(run_batch(dir, "1-3", "--progress=percent"), 3); /* progress changes no code */
    for (int f = 1; f <= 3; f += 2) {
        snprintf(p, sizeof p, "%s/f.%04d.exr", dir, f);
        remove(p);
    }
    snprintf(p, sizeof p, "%s/o", dir);
    rmdir(p);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frames),
        cmocka_unit_test(test_bad_frames),
        cmocka_unit_test(test_patterns),
        cmocka_unit_test(test_rotate),
        cmocka_unit_test(test_exit_codes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
