/* Shared bits of the cmocka unit tests.  Tests run from the repository
 * root (make unit does that), so data paths are relative to it. */
#ifndef OBS_TESTUTIL_H
#define OBS_TESTUTIL_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cmocka.h>

/* Small copies of real inputs, committed in the repository. */
#define TESTDATA "tests/data"

/* The larger shared data set; tests that use it skip when it is absent. */
static inline const char *obs_test_shared(void)
{
    const char *s = getenv("OBSCURA_SHARED_DATA");
    return s && *s ? s : "../shared/data";
}

/* The whole of a file, one byte more allocated (a NUL may follow);
 * *len its size.  Caller frees. */
static inline unsigned char *obs_test_slurp(const char *path, size_t *len)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    assert_int_equal(fseek(fp, 0, SEEK_END), 0);
    long n = ftell(fp);
    assert_true(n >= 0);
    rewind(fp);
    unsigned char *buf = malloc((size_t)n + 1);
    assert_non_null(buf);
    assert_int_equal(fread(buf, 1, (size_t)n, fp), (size_t)n);
    fclose(fp);
    *len = (size_t)n;
    return buf;
}

static inline int obs_test_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Where tests may write files (created by run_unit.sh). */
static inline const char *obs_test_tmp(void)
{
    const char *s = getenv("OBSCURA_TEST_TMP");
    return s && *s ? s : "/tmp";
}

/* A path under obs_test_tmp(); with text, the file is written with it.
 * The last four paths stay valid. */
static inline const char *obs_test_tmp_file(const char *name, const char *text)
{
    static char path[4][512];
    static int k;
    char *p = path[k++ & 3];
    snprintf(p, sizeof path[0], "%s/%s", obs_test_tmp(), name);
    if (text) {
        FILE *f = fopen(p, "wb");
        assert_non_null(f);
        fputs(text, f);
        fclose(f);
    }
    return p;
}

#endif
