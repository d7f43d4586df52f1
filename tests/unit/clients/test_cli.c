/* What the CLI's commands share (clients/cli.c): control bytes escaped
 * in messages, the edit distance of "did you mean", and the
 * "Progress: N%" lines a farm's parser reads. */
#include "testutil.h"

#include <unistd.h>

#include "cli.h"

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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_escape),
        cmocka_unit_test(test_edit_distance),
        cmocka_unit_test(test_progress_percent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
