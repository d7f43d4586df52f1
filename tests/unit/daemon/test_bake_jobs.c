/* The bake job store (daemon/bake_jobs.c): a job runs to done with its
 * .glb kept, a bad level fails with the loader's message, a queued job
 * is cancelled at once, the active limit, finished jobs beyond `keep`
 * dropped oldest first, unknown ids, and an event stream's first and
 * last events. */
#include <stdio.h>
#include <unistd.h>

#include "bake_jobs.h"
#include "testutil.h"

static const char quad[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 5 2\n";

static unsigned char *copy(const char *s)
{
    unsigned char *p = malloc(strlen(s));
    assert_non_null(p);
    memcpy(p, s, strlen(s));
    return p;
}

static obsd_bake_state state_of(obsd_bakes *b, const char *id)
{
    char *j = obsd_bakes_json(b, id);
    assert_non_null(j);
    obsd_bake_state st = strstr(j, "\"state\":\"done\"")        ? OBSD_BAKE_DONE
                         : strstr(j, "\"state\":\"failed\"")    ? OBSD_BAKE_FAILED
                         : strstr(j, "\"state\":\"cancelled\"") ? OBSD_BAKE_CANCELLED
                         : strstr(j, "\"state\":\"running\"")   ? OBSD_BAKE_RUNNING
                                                                : OBSD_BAKE_QUEUED;
    free(j);
    return st;
}

static obsd_bake_state wait_end(obsd_bakes *b, const char *id)
{
    for (int i = 0; i < 3000; i++) {
        obsd_bake_state st = state_of(b, id);
        if (st >= OBSD_BAKE_DONE)
            return st;
        usleep(10000);
    }
    fail_msg("bake %s did not end", id);
    return OBSD_BAKE_QUEUED;
}

static obs_bake_params rays(const char *n)
{
    obs_bake_params p = {0};
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_bake_param_set(&p, "rays", n, err), OBS_OK);
    return p;
}

static void test_done_failed_unknown(void **state)
{
    (void)state;
    obsd_bakes *b = obsd_bakes_new(4, 1, 8, 1000);
    assert_non_null(b);
    char id[OBSD_BAKE_ID_LEN + 1], bad[OBSD_BAKE_ID_LEN + 1];
    obs_bake_params p = rays("8");
    assert_int_equal(obsd_bakes_submit(b, copy(quad), strlen(quad), "obj", NULL, 0, &p, id), 0);
    assert_int_equal(strlen(id), 16);
    static const char lines[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n";
    assert_int_equal(obsd_bakes_submit(b, copy(lines), strlen(lines), "obj", NULL, 0, &p, bad), 0);
    assert_string_not_equal(id, bad);
    assert_int_equal(wait_end(b, id), OBSD_BAKE_DONE);
    unsigned char *glb = NULL;
    size_t len = 0;
    obsd_bake_state st;
    assert_int_equal(obsd_bakes_result(b, id, &glb, &len, &st), 0);
    assert_true(len > 20 && !memcmp(glb, "glTF", 4));
    free(glb);
    char *j = obsd_bakes_json(b, id);
    assert_non_null(strstr(j, "\"triangles\":3"));
    assert_non_null(strstr(j, "\"max_triangles\":1000")); /* the store's cap */
    free(j);
    /* a decorators file goes to the bake: its rule matches no node of
     * the quad, which the job's JSON says, with the rule count */
    char dec[OBSD_BAKE_ID_LEN + 1];
    char *rules = strdup("{\"decorators\": [{\"name\": \"no_such_node\", \"class\": \"tree\"}]}");
    assert_non_null(rules);
    assert_int_equal(obsd_bakes_submit(b, copy(quad), strlen(quad), "obj", rules, 1, &p, dec), 0);
    assert_int_equal(wait_end(b, dec), OBSD_BAKE_DONE);
    j = obsd_bakes_json(b, dec);
    assert_non_null(strstr(j, "\"decorator_rules\":1"));
    assert_non_null(strstr(j, "no_such_node"));
    free(j);
    j = obsd_bakes_json(b, id); /* a job without a file has no rule count */
    assert_null(strstr(j, "decorator_rules"));
    free(j);
    assert_int_equal(wait_end(b, bad), OBSD_BAKE_FAILED);
    j = obsd_bakes_json(b, bad);
    assert_non_null(strstr(j, "no triangles"));
    free(j);
    assert_int_equal(obsd_bakes_result(b, bad, &glb, &len, &st), 1);
    assert_int_equal(st, OBSD_BAKE_FAILED);
    assert_null(obsd_bakes_json(b, "0123456789abcdef"));
    assert_int_equal(obsd_bakes_result(b, "0123456789abcdef", &glb, &len, &st), -1);
    int removed;
    assert_int_equal(obsd_bakes_delete(b, "0123456789abcdef", &st, &removed), -1);
    /* a finished job is dropped by DELETE */
    assert_int_equal(obsd_bakes_delete(b, id, &st, &removed), 0);
    assert_true(removed);
    assert_null(obsd_bakes_json(b, id));
    obsd_bakes_free(b);
}

static void nop(void *arg) { (void)arg; }

static void test_limits_cancel_keep(void **state)
{
    (void)state;
    /* one worker, 2 jobs active at most; the first would run for half a
     * minute (12288 samples of 16384 rays): it is cancelled, queued or
     * running */
    obsd_bakes *b = obsd_bakes_new(2, 1, 2, 1000);
    assert_non_null(b);
    char a[OBSD_BAKE_ID_LEN + 1], c[OBSD_BAKE_ID_LEN + 1], d[OBSD_BAKE_ID_LEN + 1], err[OBS_ERR_LEN];
    obs_bake_params slow = rays("16384"), fast = rays("4");
    assert_int_equal(obs_bake_param_set(&slow, "samples_per_face", "4096", err), OBS_OK);
    assert_int_equal(obs_bake_param_set(&slow, "max_samples_per_face", "4096", err), OBS_OK);
    assert_int_equal(obsd_bakes_submit(b, copy(quad), strlen(quad), "obj", NULL, 0, &slow, a), 0);
    assert_int_equal(obsd_bakes_submit(b, copy(quad), strlen(quad), "obj", NULL, 0, &fast, c), 0);
    /* refused (the store is full): the level and the decorators freed */
    assert_int_equal(obsd_bakes_submit(b, copy(quad), strlen(quad), "obj",
                                       strdup("{\"decorators\": []}"), 0, &fast, d),
                     -1);
    /* the second waits behind the first: cancelled at once */
    obsd_bake_state st;
    int removed;
    assert_int_equal(obsd_bakes_delete(b, c, &st, &removed), 0);
    assert_int_equal(st, OBSD_BAKE_CANCELLED);
    assert_false(removed);
    /* an event stream on the first: its state at once */
    obsd_bake_sub sub = {.park = nop, .wake = nop};
    char ev[512];
    assert_int_equal(obsd_bakes_subscribe(b, a, &sub), 0);
    assert_true(obsd_bakes_next_event(b, &sub, ev, sizeof ev) > 0);
    assert_non_null(strstr(ev, "event: progress"));
    assert_int_equal(obsd_bakes_delete(b, a, &st, &removed), 0);
    assert_int_equal(wait_end(b, a), OBSD_BAKE_CANCELLED);
    int n;
    while ((n = obsd_bakes_next_event(b, &sub, ev, sizeof ev)) > 0 && !strstr(ev, "event: cancelled"))
        ;
    assert_non_null(strstr(ev, "event: cancelled"));
    assert_int_equal(obsd_bakes_next_event(b, &sub, ev, sizeof ev), -1);
    obsd_bakes_unsubscribe(b, &sub);
    /* keep 2: a third finished job drops the oldest finished (a) */
    assert_int_equal(obsd_bakes_submit(b, copy(quad), strlen(quad), "obj", NULL, 0, &fast, d), 0);
    assert_int_equal(wait_end(b, d), OBSD_BAKE_DONE);
    assert_null(obsd_bakes_json(b, a));
    char *j = obsd_bakes_json(b, c);
    assert_non_null(j);
    free(j);
    int counts[5];
    obsd_bakes_counts(b, counts);
    assert_int_equal(counts[OBSD_BAKE_DONE], 1);
    assert_int_equal(counts[OBSD_BAKE_CANCELLED], 1);
    /* after the drain's cancel, nothing is taken */
    obsd_bakes_cancel_all(b);
    assert_int_equal(obsd_bakes_submit(b, copy(quad), strlen(quad), "obj", NULL, 0, &fast, d), -2);
    obsd_bakes_free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_done_failed_unknown),
        cmocka_unit_test(test_limits_cancel_keep),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
