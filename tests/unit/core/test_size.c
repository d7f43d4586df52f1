/* Size checks: overflow-checked products and the configured limits. */
#include "testutil.h"

#include "internal.h"

static void test_mul_overflow(void **state)
{
    (void)state;
    size_t n = 0;
    assert_int_equal(obs__size_mul(1000, 1000, &n), 0);
    assert_int_equal(n, 1000000);
    assert_int_equal(obs__size_mul(SIZE_MAX / 2, 3, &n), -1);
    assert_int_equal(n, 1000000); /* untouched on failure */
    assert_int_equal(obs__size_mul(0, SIZE_MAX, &n), 0);
    assert_int_equal(n, 0);
    assert_int_equal(obs__size_mul3(65536, 65536, 16, &n), 0);
    assert_int_equal(obs__size_mul3((size_t)1 << 32, (size_t)1 << 31, 4, &n), -1);
    assert_int_equal(obs__size_mul3(SIZE_MAX, 1, 2, &n), -1);
}

static void test_limits(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_check_size(NULL, 640, 480, err), OBS_OK);
    assert_int_equal(obs_check_size(NULL, 16384, 16384, err), OBS_OK);
    assert_int_equal(obs_check_size(NULL, 16385, 1, err), OBS_TOO_LARGE);
    assert_non_null(strstr(err, "16385"));
    assert_int_equal(obs_check_size(NULL, 0, 10, err), OBS_BAD_FILE);
    assert_int_equal(obs_check_size(NULL, 10, -5, err), OBS_BAD_FILE);
    assert_int_equal(obs_check_size(NULL, INT64_MAX, INT64_MAX, err), OBS_TOO_LARGE);

    obs_limits lim = {.max_width = 100, .max_height = 50};
    assert_int_equal(obs_check_size(&lim, 100, 50, err), OBS_OK);
    assert_int_equal(obs_check_size(&lim, 101, 50, err), OBS_TOO_LARGE);
    assert_int_equal(obs_check_size(&lim, 100, 51, err), OBS_TOO_LARGE);
    lim.max_pixels = 1000;
    assert_int_equal(obs_check_size(&lim, 40, 25, err), OBS_OK);
    assert_int_equal(obs_check_size(&lim, 41, 25, err), OBS_TOO_LARGE);
    assert_non_null(strstr(err, "1000 pixels"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mul_overflow),
        cmocka_unit_test(test_limits),
    };
    return cmocka_run_group_tests_name("size", tests, NULL, NULL);
}
