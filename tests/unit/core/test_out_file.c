/* Outputs written whole or not at all (core/io/out_file.c): the temporary
 * sibling's name, the rename on success, the removal on failure with an
 * older file under the final name kept, devices written directly; and
 * through a real writer, a failed PNG leaves the older file alone. */
#include "testutil.h"

#include <png.h>
#include <unistd.h>

#include "io/out_file.h"
#include "obscura/io.h"

static char *slurp_text(const char *path)
{
    size_t n;
    char *t = (char *)obs_test_slurp(path, &n);
    assert_non_null(t);
    t[n] = '\0';
    return t;
}

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void test_sibling_name(void **state)
{
    (void)state;
    obs__out_file o;
    char want[600];
    snprintf(want, sizeof want, "/some/dir/.ao.0001.exr.%ld.tmp", (long)getpid());
    assert_string_equal(obs__out_begin(&o, "/some/dir/ao.0001.exr"), want);
    assert_int_equal(o.direct, 0);
    snprintf(want, sizeof want, ".ao.png.%ld.tmp", (long)getpid());
    assert_string_equal(obs__out_begin(&o, "ao.png"), want);
    /* a device is written in place, never renamed over */
    assert_string_equal(obs__out_begin(&o, "/dev/null"), "/dev/null");
    assert_int_equal(o.direct, 1);
    assert_int_equal(obs__out_end(&o, OBS_IO, NULL), OBS_IO);
    assert_true(obs_test_exists("/dev/null"));
}

static void test_rename_or_remove(void **state)
{
    (void)state;
    char final[512], tmp[4096];
    snprintf(final, sizeof final, "%s", obs_test_tmp_file("out_file.txt", "old"));
    obs__out_file o;
    char err[OBS_ERR_LEN] = "";

    /* a failed write: the temporary file goes, the older output stays */
    snprintf(tmp, sizeof tmp, "%s", obs__out_begin(&o, final));
    put(tmp, "half");
    assert_int_equal(obs__out_end(&o, OBS_IO, err), OBS_IO);
    assert_false(obs_test_exists(tmp));
    char *t = slurp_text(final);
    assert_string_equal(t, "old");
    free(t);

    /* a finished one replaces it, under the final name only */
    snprintf(tmp, sizeof tmp, "%s", obs__out_begin(&o, final));
    put(tmp, "new");
    assert_int_equal(obs__out_end(&o, OBS_OK, err), OBS_OK);
    assert_false(obs_test_exists(tmp));
    t = slurp_text(final);
    assert_string_equal(t, "new");
    free(t);
    remove(final);
}

/* libpng fails (its width limit) after the file was opened: the older PNG
 * under that name is untouched and no temporary file is left. */
static void test_png_failure_keeps_old(void **state)
{
    (void)state;
    float px[1] = {0.5f};
    obs_image img = {PNG_USER_WIDTH_MAX + 1, 1, 1, px};
    char err[OBS_ERR_LEN] = "", path[512];
    snprintf(path, sizeof path, "%s", obs_test_tmp_file("out_file_old.png", "an older frame"));
    assert_int_equal(obs_png_write(path, &img, 8, 0, err), OBS_IO);
    char *t = slurp_text(path);
    assert_string_equal(t, "an older frame");
    free(t);
    obs__out_file o;
    assert_false(obs_test_exists(obs__out_begin(&o, path)));
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sibling_name),
        cmocka_unit_test(test_rename_or_remove),
        cmocka_unit_test(test_png_failure_keeps_old),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
