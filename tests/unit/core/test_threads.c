/* The process's thread limit (obs_threads_set, core/context_threads.c)
 * and the one thread-count rule it feeds (obs__pool_threads, core/pool.c):
 * every pool stays within the limit, a caller's own count too; llvmpipe's
 * LP_NUM_THREADS is set from it unless the user set it first. */
#include "testutil.h"

#include <pthread.h>
#include <unistd.h>

#include "obscura/obscura.h"
#include "pool.h"

static int cores(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > OBS__POOL_MAX_THREADS ? OBS__POOL_MAX_THREADS : (int)n;
}

static int reset(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    obs_threads_set(0, err);
    unsetenv("LP_NUM_THREADS");
    return 0;
}

static void test_rule(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    assert_int_equal(obs__pool_threads(0), cores());
    assert_int_equal(obs__pool_threads(5), 5);
    assert_int_equal(obs__pool_threads(1000), OBS__POOL_MAX_THREADS);
    assert_int_equal(obs_threads_set(3, err), OBS_OK);
    assert_int_equal(obs__pool_threads(5), 3); /* a caller's own count is bounded too */
    assert_int_equal(obs__pool_threads(2), 2);
    assert_int_equal(obs__pool_threads(0), cores() < 3 ? cores() : 3);
    assert_int_equal(obs_threads_set(1, err), OBS_OK);
    assert_int_equal(obs__pool_threads(0), 1);
    assert_int_equal(obs__pool_threads(64), 1);
    obs_threads_info ti;
    obs_threads_get(&ti);
    assert_int_equal(ti.limit, 1);
    assert_int_equal(ti.pool, 1);
    assert_int_equal(obs_threads_set(0, err), OBS_OK); /* lifted */
    assert_int_equal(obs__pool_threads(0), cores());
}

static void test_bad_values(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_threads_set(-1, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "threads -1 is outside [1, 64]"));
    assert_int_equal(obs_threads_set(65, err), OBS_INVALID_ARGUMENT);
    obs_threads_info ti;
    obs_threads_get(&ti);
    assert_int_equal(ti.limit, 0); /* a refused value changes nothing */
}

static void test_llvmpipe_env(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    obs_threads_info ti;
    obs_threads_get(&ti);
    assert_int_equal(ti.llvmpipe, -1);
    assert_int_equal(obs_threads_set(2, err), OBS_OK);
    assert_string_equal(getenv("LP_NUM_THREADS"), "2");
    assert_int_equal(obs_threads_set(4, err), OBS_OK); /* ours: follows the limit */
    assert_string_equal(getenv("LP_NUM_THREADS"), "4");
    obs_threads_get(&ti);
    assert_int_equal(ti.llvmpipe, 4);
    assert_int_equal(ti.llvmpipe_from_user, 0);
    assert_int_equal(obs_threads_set(0, err), OBS_OK); /* lifted: ours removed */
    assert_null(getenv("LP_NUM_THREADS"));
    setenv("LP_NUM_THREADS", "7", 1); /* the user's: kept */
    assert_int_equal(obs_threads_set(1, err), OBS_OK);
    assert_string_equal(getenv("LP_NUM_THREADS"), "7");
    obs_threads_get(&ti);
    assert_int_equal(ti.llvmpipe, 7);
    assert_int_equal(ti.llvmpipe_from_user, 1);
    assert_int_equal(ti.limit, 1);
}

/* The threads a loop ran on: each begin hook counts one. */
typedef struct seen {
    int begun;
} seen;

static void begin(void *ctx, void *local)
{
    (void)local;
    __atomic_add_fetch(&((seen *)ctx)->begun, 1, __ATOMIC_SEQ_CST);
}

static int range(void *ctx, void *local, size_t i0, size_t i1)
{
    (void)ctx, (void)local, (void)i0, (void)i1;
    usleep(100);
    return 0;
}

static void test_pool_bounded(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN];
    seen s = {0};
    obs__pool_for f = {.end = 256, .chunk = 1, .threads = 8, .range = range, .ctx = &s, .begin = begin};
    assert_int_equal(obs_threads_set(2, err), OBS_OK);
    assert_int_equal(obs__pool_run(&f, NULL), 0);
    assert_true(s.begun >= 1 && s.begun <= 2); /* 8 asked, the limit 2 */
    s.begun = 0;
    assert_int_equal(obs_threads_set(1, err), OBS_OK);
    assert_int_equal(obs__pool_run(&f, NULL), 0);
    assert_int_equal(s.begun, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_rule, reset, reset),
        cmocka_unit_test_setup_teardown(test_bad_values, reset, reset),
        cmocka_unit_test_setup_teardown(test_llvmpipe_env, reset, reset),
        cmocka_unit_test_setup_teardown(test_pool_bounded, reset, reset),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
