/* obscurad's log (daemon/log.c): a line's text with a newline, a
 * carriage return or another control character in it (from a client's
 * query or a binary parameter) stays one line. */
#include "testutil.h"

#include "../../../daemon/log.h" /* core/log.h shadows it: -Icore comes first */

static void test_escape(void **state)
{
    (void)state;
    char out[64];
    const char in[] = "Z\n2030-01-01 obscurad info: FORGED\r\x01\x7f ok \xc3\xa9";
    size_t n = obsd_log_escape(in, sizeof in - 1, out, sizeof out);
    assert_int_equal(n, strlen(out));
    assert_null(strchr(out, '\n'));
    assert_null(strchr(out, '\r'));
    assert_string_equal(out, "Z\\x0a2030-01-01 obscurad info: FORGED\\x0d\\x01\\x7f ok \xc3\xa9");
    /* never past the buffer, never half an escape */
    char small[8];
    n = obsd_log_escape("ab\ncdef", 7, small, sizeof small);
    assert_string_equal(small, "ab\\x0ac");
    n = obsd_log_escape("abcde\n", 6, small, sizeof small);
    assert_string_equal(small, "abcde");
    assert_int_equal(n, 5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_escape)};
    return cmocka_run_group_tests_name("daemon_log", tests, NULL, NULL);
}
