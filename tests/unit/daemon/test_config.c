/* obscurad's option table: defaults, ranges, sizes, enums, config files,
 * flags over the file, and the generated --help. */
#include "testutil.h"

#include "config.h"

static void test_defaults(void **state)
{
    (void)state;
    obsd_config c;
    obsd_config_defaults(&c);
    assert_string_equal(c.http, "127.0.0.1:8420");
    assert_int_equal(c.queue, 8);
    assert_int_equal(c.max_body, (int64_t)1 << 30);
    assert_int_equal(c.log_level, OBSD_LOG_INFO);
    assert_string_equal(c.token_file, "");
    for (int i = 0; i < obsd_opt_count(); i++)
        assert_int_equal(c.set[i], 0);
}

static void test_set(void **state)
{
    (void)state;
    obsd_config c;
    char err[OBS_ERR_LEN] = "", buf[64];
    obsd_config_defaults(&c);
    assert_int_equal(obsd_config_set(&c, "queue", "3", err), OBS_OK);
    assert_int_equal(c.queue, 3);
    assert_int_equal(obsd_config_set(&c, "max-body", "16m", err), OBS_OK); /* '-' or '_' */
    assert_int_equal(c.max_body, 16 << 20);
    assert_int_equal(obsd_config_set(&c, "max_pixels", "2K", err), OBS_OK);
    assert_int_equal(c.max_pixels, 2048);
    assert_int_equal(obsd_config_set(&c, "log_level", "debug", err), OBS_OK);
    assert_int_equal(c.log_level, OBSD_LOG_DEBUG);
    obsd_config_format(&c, obsd_opt_find("log_level"), buf, sizeof buf);
    assert_string_equal(buf, "debug");
    assert_int_equal(obsd_config_set(&c, "backend", "osmesa", err), OBS_OK);
    obsd_config_format(&c, obsd_opt_find("backend"), buf, sizeof buf);
    assert_string_equal(buf, "osmesa");
    assert_int_equal(c.set[obsd_opt_find("backend") - obsd_opt_at(0)], 1);
    assert_int_equal(obsd_config_set(&c, "http", "0.0.0.0:9000", err), OBS_OK);
    assert_string_equal(c.http, "0.0.0.0:9000");
}

static void test_errors(void **state)
{
    (void)state;
    obsd_config c;
    char err[OBS_ERR_LEN] = "";
    obsd_config_defaults(&c);
    assert_int_equal(obsd_config_set(&c, "queue", "0", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "queue"));
    assert_non_null(strstr(err, "[1, 1024]"));
    assert_int_equal(obsd_config_set(&c, "queue", "8x", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obsd_config_set(&c, "queue", "", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obsd_config_set(&c, "queue", "99999999999999999999", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obsd_config_set(&c, "max_body", "1t", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obsd_config_set(&c, "max_body", "1mb", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obsd_config_set(&c, "max_body", "100", err), OBS_INVALID_ARGUMENT); /* < 1024 */
    assert_int_equal(obsd_config_set(&c, "max_body", "99999999999g", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obsd_config_set(&c, "log_level", "loud", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "error|warn|info|debug"));
    assert_int_equal(obsd_config_set(&c, "nope", "1", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "nope"));
    char longv[400];
    memset(longv, 'a', sizeof longv - 1);
    longv[sizeof longv - 1] = '\0';
    assert_int_equal(obsd_config_set(&c, "token_file", longv, err), OBS_INVALID_ARGUMENT);
    /* failures change nothing */
    assert_int_equal(c.queue, 8);
    assert_int_equal(c.log_level, OBSD_LOG_INFO);
}

static const char *write_file(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", obs_test_tmp(), name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

static void test_file_and_flags(void **state)
{
    (void)state;
    obsd_config c;
    char err[OBS_ERR_LEN] = "";
    int help = 1;
    const char *path = write_file("obscurad.conf",
                                  "# obscurad test config\n"
                                  "\n"
                                  "queue 4   # trailing comment\n"
                                  "  max-pixels 1m\n"
                                  "log_level warn\n"
                                  "http \"127.0.0.1:0\"\n");
    obsd_config_defaults(&c);
    char *argv[] = {"obscurad", "--queue=2", "--config", (char *)path, "--threads", "3", NULL};
    assert_int_equal(obsd_config_args(&c, 6, argv, &help, err), OBS_OK);
    assert_int_equal(help, 0);
    assert_int_equal(c.queue, 2); /* the flag wins, wherever it stands */
    assert_int_equal(c.max_pixels, 1 << 20);
    assert_int_equal(c.log_level, OBSD_LOG_WARN);
    assert_int_equal(c.threads, 3);
    assert_string_equal(c.http, "127.0.0.1:0");

    path = write_file("bad.conf", "queue 4\nqueue many\n");
    obsd_config_defaults(&c);
    assert_int_equal(obsd_config_load(&c, path, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "bad.conf:2"));
    assert_non_null(strstr(err, "queue"));
    assert_int_equal(obsd_config_load(&c, "/nonexistent/obscurad.conf", err), OBS_IO);

    char *a2[] = {"obscurad", "--queue", NULL};
    assert_int_equal(obsd_config_args(&c, 2, a2, &help, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "needs a value"));
    char *a3[] = {"obscurad", "--frob", "1", NULL};
    assert_int_equal(obsd_config_args(&c, 3, a3, &help, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "--frob"));
    char *a4[] = {"obscurad", "stray", NULL};
    assert_int_equal(obsd_config_args(&c, 2, a4, &help, err), OBS_INVALID_ARGUMENT);
    char *a5[] = {"obscurad", "-h", NULL};
    assert_int_equal(obsd_config_args(&c, 2, a5, &help, err), OBS_OK);
    assert_int_equal(help, 1);
}

static void test_help(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/help.txt", obs_test_tmp());
    FILE *f = fopen(path, "w+");
    assert_non_null(f);
    obsd_config_help(f);
    long n = ftell(f);
    rewind(f);
    char *text = calloc(1, (size_t)n + 1);
    assert_int_equal(fread(text, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    /* every option of the table, as a flag with '-' */
    for (int i = 0; i < obsd_opt_count(); i++) {
        char flag[64];
        snprintf(flag, sizeof flag, "--%s ", obsd_opt_at(i)->name);
        for (char *p = flag; *p; p++)
            if (*p == '_')
                *p = '-';
        if (!strstr(text, flag))
            fail_msg("--help lacks %s", flag);
    }
    free(text);
}

/* --render-threads bounds the work's threads (obscura's --threads);
 * --threads keeps its meaning, the HTTP pool. */
static void test_render_threads(void **state)
{
    (void)state;
    obsd_config c;
    char err[OBS_ERR_LEN];
    int help;
    obsd_config_defaults(&c);
    assert_int_equal(c.render_threads, 0); /* OBSCURA_THREADS, else every core */
    assert_int_equal(c.threads, 4);
    char *argv[] = {"obscurad", "--render-threads", "2", "--threads=8", NULL};
    assert_int_equal(obsd_config_args(&c, 4, argv, &help, err), OBS_OK);
    assert_int_equal(c.render_threads, 2);
    assert_int_equal(c.threads, 8);
    assert_int_equal(obsd_config_set(&c, "render_threads", "65", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "render_threads"));
    assert_int_equal(obsd_config_set(&c, "render-threads", "abc", err), OBS_INVALID_ARGUMENT);
}

/* --max-memory: MiB of the CPU device's budget (obscura's --max-memory),
 * 0 by default (OBSCURA_MAX_MEMORY, else the library's default); a flag
 * or a config line sets it and marks it given; not a number or negative
 * refused, naming it. */
static void test_max_memory(void **state)
{
    (void)state;
    obsd_config c;
    char err[OBS_ERR_LEN];
    int help;
    obsd_config_defaults(&c);
    assert_int_equal(c.max_memory, 0);
    char *argv[] = {"obscurad", "--max-memory", "256", NULL};
    assert_int_equal(obsd_config_args(&c, 3, argv, &help, err), OBS_OK);
    assert_int_equal(c.max_memory, 256);
    assert_true(c.set[obsd_opt_find("max-memory") - obsd_opt_at(0)]);
    assert_int_equal(obsd_config_set(&c, "max_memory", "-1", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "max_memory"));
    assert_int_equal(obsd_config_set(&c, "max-memory", "1g", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "max_memory"));
    assert_int_equal(c.max_memory, 256);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults), cmocka_unit_test(test_set),
        cmocka_unit_test(test_errors),   cmocka_unit_test(test_file_and_flags),
        cmocka_unit_test(test_help),     cmocka_unit_test(test_render_threads),
        cmocka_unit_test(test_max_memory),
    };
    return cmocka_run_group_tests_name("daemon_config", tests, NULL, NULL);
}
