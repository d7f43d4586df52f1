/* What the CLI's commands share (clients/cli.c, clients/flags.c): control bytes escaped
 * in messages, the edit distance of "did you mean", the
 * "Progress: N%" lines a farm's parser reads, and --threads and
 * --max-memory taken out of a command's argv. */
#include "testutil.h"

#include <unistd.h>

#include "cli.h"
#include "flags.h"
#include "obscura/obscura.h"

static void test_escape(void **state)
{
    (void)state;
    char buf[64];
    cli_escape("plain name.Z", buf, sizeof buf);
    assert_string_equal(buf, "plain name.Z");
    cli_escape("Dep\x1b[2J\x07\x7f", buf, sizeof buf);
    assert_string_equal(buf, "Dep\\x1b[2J\\x07\\x7f");
    cli_escape("caf\xc3\xa9", buf, sizeof buf); /* UTF-8 is text, kept */
    assert_string_equal(buf, "caf\xc3\xa9");
    cli_escape("ab\x1b", buf, 5); /* never past the buffer, never half an escape */
    assert_string_equal(buf, "ab");
    cli_escape("abcdef", buf, 4);
    assert_string_equal(buf, "abc");
}

static void test_edit_distance(void **state)
{
    (void)state;
    assert_int_equal(cli_edit_distance("radius", "radius"), 0);
    assert_int_equal(cli_edit_distance("radiu", "radius"), 1);
    assert_int_equal(cli_edit_distance("smaples", "samples"), 2);
    assert_int_equal(cli_edit_distance("", "abc"), 3);
    assert_int_equal(cli_edit_distance("kitten", "sitting"), 3);
    char longw[80];
    memset(longw, 'a', sizeof longw - 1);
    longw[sizeof longw - 1] = '\0';
    assert_true(cli_edit_distance(longw, "a") > 64);
}

static void test_progress_percent(void **state)
{
    (void)state;
    char path[] = "/tmp/obscura-test-progress-XXXXXX";
    int fd = mkstemp(path), saved = dup(1), last = -1;
    assert_true(fd >= 0 && saved >= 0);
    fflush(stdout);
    dup2(fd, 1);
    for (long done = 0; done <= 3; done++)
        cli_progress_percent(&last, done, 3);
    cli_progress_percent(&last, 3, 3); /* the same N: no line */
    fflush(stdout);
    dup2(saved, 1);
    close(saved);
    size_t len;
    char *text = (char *)obs_test_slurp(path, &len);
    text[len] = '\0';
    assert_string_equal(text, "Progress: 0%\nProgress: 33%\nProgress: 66%\nProgress: 100%\n");
    free(text);
    close(fd);
    remove(path);
}

/* --threads N is taken out of argv wherever it stands (either spelling)
 * and becomes the process's limit; a command without it keeps its argv. */
static void test_take_threads(void **state)
{
    (void)state;
    char a0[] = "in.exr", a1[] = "--threads", a2[] = "2", a3[] = "-o", a4[] = "out.exr", a5[] = "--threads=3";
    char *argv[] = {a0, a1, a2, a3, a4, a5};
    unsetenv("OBSCURA_THREADS");
    int n = cli_take_threads("ao", 6, argv);
    assert_int_equal(n, 3);
    assert_string_equal(argv[0], "in.exr");
    assert_string_equal(argv[1], "-o");
    assert_string_equal(argv[2], "out.exr");
    obs_threads_info ti;
    obs_threads_get(&ti);
    assert_int_equal(ti.limit, 3); /* the last one given */
    char *plain[] = {a0, a3, a4};
    setenv("OBSCURA_THREADS", "1", 1);
    assert_int_equal(cli_take_threads("ao", 3, plain), 3);
    obs_threads_get(&ti);
    assert_int_equal(ti.limit, 1); /* the environment's, when no flag */
    unsetenv("OBSCURA_THREADS");
    assert_true(cli_process_threads() >= 1);
}

/* --max-memory MIB is taken out of argv as --threads is (either
 * spelling, the last one given), over OBSCURA_MAX_MEMORY; neither: the
 * library's default, said as such. */
static void test_take_max_memory(void **state)
{
    (void)state;
    char a0[] = "in.exr", a1[] = "--max-memory", a2[] = "64", a3[] = "-o", a4[] = "out.exr",
         a5[] = "--max-memory=3";
    char *argv[] = {a0, a1, a2, a3, a4, a5};
    obs_cpu_options o = {0};
    setenv("OBSCURA_MAX_MEMORY", "7", 1);
    assert_int_equal(cli_take_max_memory("ao", 6, argv), 3);
    assert_string_equal(argv[0], "in.exr");
    assert_string_equal(argv[1], "-o");
    assert_string_equal(argv[2], "out.exr");
    cli_max_memory(&o);
    assert_true(o.max_memory == (size_t)3 << 20); /* the option's, the last one */
    assert_string_equal(o.max_memory_name, "--max-memory 3 MiB");
    assert_string_equal(cli_max_memory_text(), "3 MiB (--max-memory)");
    char *plain[] = {a0, a3, a4};
    assert_int_equal(cli_take_max_memory("ao", 3, plain), 3);
    cli_max_memory(&o);
    assert_true(o.max_memory == (size_t)7 << 20); /* the environment's, when no option */
    assert_string_equal(o.max_memory_name, "OBSCURA_MAX_MEMORY=7 MiB");
    unsetenv("OBSCURA_MAX_MEMORY");
    assert_int_equal(cli_take_max_memory("ao", 3, plain), 3);
    cli_max_memory(&o);
    assert_true(o.max_memory == 0); /* the default */
    assert_non_null(strstr(cli_max_memory_text(), "default: a quarter of"));
    assert_true(obs_cpu_memory_budget(&o) == obs_cpu_memory_usable() / 4);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_escape),
        cmocka_unit_test(test_edit_distance),
        cmocka_unit_test(test_progress_percent),
        cmocka_unit_test(test_take_threads),
        cmocka_unit_test(test_take_max_memory),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
