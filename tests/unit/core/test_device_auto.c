/* --backend auto's kept choice (core/device_auto.c): without a
 * measurement asked for, nothing kept means a GPU, else the CPU device; a kept line of
 * this machine, version, method and thread count is read (the last one
 * of its key wins), another method's is not.  The measurement itself
 * (a GL context and the CPU device on a synthetic frame) runs in
 * tests/e2e/cpu_backend.sh. */
#include "testutil.h"

#include <unistd.h>

#include "internal.h"
#include "obscura/obscura.h"

static void write_lines(const char *path, const char *lines)
{
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs(lines, fp);
    fclose(fp);
}

static void test_kept_choice(void **state)
{
    char dir[] = "/tmp/obs_device_auto_XXXXXX", path[128], k[256], k2[256], lines[1024];
    char err[OBS_ERR_LEN] = "";
    obs_device_choice ch;
    obs_params p = {0};
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/devices.txt", dir);
    /* nothing kept: a GPU, else the CPU device (never the software GL
     * context), nothing measured */
    assert_int_equal(obs_device_choose(dir, NULL, 0, &ch, err), OBS_OK);
    assert_true(ch.cpu ? ch.backend == OBS_BACKEND_AUTO : ch.backend == OBS_BACKEND_EGL_DEVICE);
    assert_false(ch.cached || ch.measured);
    /* the default method's line: the CPU device */
    obs__device_key("vaopp", k, sizeof k);
    obs__device_key("gtao", k2, sizeof k2);
    snprintf(lines, sizeof lines, "%s cpu 10.0 20.0\n%s gl 30.0 20.0\n", k, k2);
    write_lines(path, lines);
    assert_int_equal(obs_device_choose(dir, NULL, 0, &ch, err), OBS_OK);
    assert_int_equal(ch.cpu, 1);
    assert_true(ch.cached);
    assert_true(ch.cpu_ms == 10.0 && ch.gl_ms == 20.0);
    /* another method's line is its own */
    assert_int_equal(obs_param_set(&p, "method", "gtao", err), OBS_OK);
    assert_int_equal(obs_device_choose(dir, &p, 0, &ch, err), OBS_OK);
    assert_int_equal(ch.cpu, 0);
    assert_true(ch.cached);
    /* a later line of the same key wins; a damaged line is ignored */
    snprintf(lines, sizeof lines, "%s cpu 10.0 20.0\n%s gl 30.0\n%s gl 25.0 20.0\n", k, k, k);
    write_lines(path, lines);
    assert_int_equal(obs_device_choose(dir, NULL, 0, &ch, err), OBS_OK);
    assert_int_equal(ch.cpu, 0);
    assert_true(ch.gl_ms == 20.0);
    unlink(path);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_kept_choice),
    };
    return cmocka_run_group_tests_name("device_auto", tests, NULL, NULL);
}
