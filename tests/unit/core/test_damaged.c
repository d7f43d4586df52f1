/* Damaged EXRs (from OpenEXR's fuzzing corpus) are rejected with a status
 * and a message, or read correctly: never a crash, hang or leak (run it
 * under ASan).  The copies in tests/data/damaged always run; the whole
 * set runs when ../shared is present.
 *
 * Most of these files hold no depth channel, so each is also read with
 * its first channel mapped as depth (and more as normal and colour) and
 * one channel on its own, to drive the decoder through the damage. */
#include "testutil.h"

#include <dirent.h>

#include "obscura/io.h"

typedef struct tally {
    int files, rejected, read;     /* the G-buffer with the auto map */
    int forced_rejected, forced_read; /* with the first channel as depth */
} tally;

/* OK, or a failure with a message. */
static void check(const char *path, const char *what, obs_status st, const char *err)
{
    if (st != OBS_OK && err[0] == '\0')
        fail_msg("%s: %s failed (%s) without a message", path, what, obs_status_name(st));
    if (st != OBS_OK && st != OBS_BAD_FILE && st != OBS_UNSUPPORTED && st != OBS_MISSING_CHANNEL &&
        st != OBS_TOO_LARGE && st != OBS_NO_MEMORY && st != OBS_IO && st != OBS_INVALID_ARGUMENT)
        fail_msg("%s: %s gave an unexpected status %s", path, what, obs_status_name(st));
}

static void check_gbuffer(const obs_gbuffer_file *f)
{
    assert_true(f->gb.width > 0 && f->gb.height > 0);
    assert_non_null(f->gb.depth.data);
}

static void run_file(const char *path, tally *t)
{
    obs_gbuffer_file f, m;
    char err[OBS_ERR_LEN] = "", merr[OBS_ERR_LEN] = "";
    size_t len;
    unsigned char *buf = obs_test_slurp(path, &len);

    obs_status st = obs_gbuffer_read_exr(path, NULL, NULL, &f, err);
    check(path, "obs_gbuffer_read_exr", st, err);
    obs_status mst = obs_gbuffer_read_exr_mem(buf, len, NULL, NULL, &m, merr);
    check(path, "obs_gbuffer_read_exr_mem", mst, merr);
    if (st != mst)
        fail_msg("%s: file reader says %s (%s), memory reader %s (%s)", path, obs_status_name(st), err,
                 obs_status_name(mst), merr);
    if (st == OBS_OK) {
        check_gbuffer(&f);
        assert_int_equal(f.gb.width, m.gb.width);
        assert_int_equal(f.gb.height, m.gb.height);
        t->read++;
    } else {
        t->rejected++;
    }
    obs_gbuffer_free(&f);
    obs_gbuffer_free(&m);
    free(buf);

    char **names = NULL;
    err[0] = '\0';
    st = obs_exr_list_channels(path, &names, err);
    check(path, "obs_exr_list_channels", st, err);
    if (st == OBS_OK) {
        int n = 0;
        while (names[n])
            n++;
        if (n > 0) {
            /* first channel as depth; then three as normal, three as colour */
            obs_channel_map map = {.preset = "generic", .depth = names[0]};
            if (n >= 4)
                for (int i = 0; i < 3; i++)
                    map.normal[i] = names[1 + i];
            if (n >= 7)
                for (int i = 0; i < 3; i++)
                    map.color[i] = names[4 + i];
            err[0] = '\0';
            st = obs_gbuffer_read_exr(path, &map, NULL, &f, err);
            check(path, "obs_gbuffer_read_exr (explicit map)", st, err);
            if (st == OBS_OK)
                check_gbuffer(&f);
            *(st == OBS_OK ? &t->forced_read : &t->forced_rejected) += 1;
            obs_gbuffer_free(&f);

            obs_image img;
            err[0] = '\0';
            st = obs_exr_read_channel(path, names[n - 1], NULL, &img, err);
            check(path, "obs_exr_read_channel", st, err);
            obs_image_free(&img);
        }
    }
    obs_strv_free(names);
    t->files++;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Runs every file in `dir` except README.rst, in name order. */
static void run_dir(const char *dir, tally *t)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    char **paths = NULL;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.' || strcmp(e->d_name, "README.rst") == 0)
            continue;
        paths = realloc(paths, sizeof *paths * (size_t)(n + 1));
        size_t len = strlen(dir) + strlen(e->d_name) + 2;
        paths[n] = malloc(len);
        snprintf(paths[n++], len, "%s/%s", dir, e->d_name);
    }
    closedir(d);
    qsort(paths, (size_t)n, sizeof *paths, by_name);
    for (int i = 0; i < n; i++) {
        run_file(paths[i], t);
        free(paths[i]);
    }
    free(paths);
}

static void print_tally(const char *dir, const tally *t)
{
    printf("damaged EXRs in %s: %d files, %d rejected, %d read (first channel as depth: %d "
           "rejected, %d read)\n", dir, t->files, t->rejected, t->read, t->forced_rejected,
           t->forced_read);
}

static void test_local_copies(void **state)
{
    (void)state;
    tally t = {0};
    run_dir(TESTDATA "/damaged", &t);
    assert_true(t.files >= 80);
    print_tally(TESTDATA "/damaged", &t);
}

static void test_shared_set(void **state)
{
    (void)state;
    char dir[512];
    snprintf(dir, sizeof dir, "%s/openexr-images/Damaged", obs_test_shared());
    if (!obs_test_exists(dir)) {
        printf("damaged EXRs (%s): absent, skipped\n", dir);
        skip();
    }
    tally t = {0};
    run_dir(dir, &t);
    print_tally(dir, &t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_local_copies),
        cmocka_unit_test(test_shared_set),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
