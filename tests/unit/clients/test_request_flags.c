/* The request options parsed by both paths the same way: every row of
 * obs_http_options (protocol/http.c) set as a query parameter
 * (obs_http_request_set) and as a flag of obscura ao (clients/flags.c's
 * cli_request_flag) gives the same request, or is refused by both.  The
 * only differences allowed are the ones a row declares: choices taken
 * from the CLI only, and a comma list where `list` has OBS_HTTP_CLI. */
#include "testutil.h"

#include "flags.h"

/* A copy of r with the pointers the NAMES rows set (the channel map's,
 * the layer's) made offsets into r, so two requests compare with memcmp. */
static void normalise(const obs_http_request *r, obs_http_request *out)
{
    memcpy(out, r, sizeof *r);
    for (const obs_http_option *op = obs_http_options; op->name; op++) {
        if (op->kind != OBS_HTTP_OPT_NAMES)
            continue;
        const char **m = (const char **)(void *)((char *)out + op->map);
        for (int i = 0; i < op->max; i++) {
            if (!m[i])
                continue;
            assert_true(m[i] >= (const char *)r && m[i] < (const char *)(r + 1));
            m[i] = (const char *)(uintptr_t)(m[i] - (const char *)r + 1);
        }
    }
}

static void assert_same_request(const obs_http_request *a, const obs_http_request *b, const char *what)
{
    obs_http_request na, nb;
    normalise(a, &na);
    normalise(b, &nb);
    if (memcmp(&na, &nb, sizeof na) != 0)
        fail_msg("%s: the query and the flag give different requests", what);
}

static obs_http_request fresh(void)
{
    obs_http_request r;
    obs_http_request_init(&r);
    return r;
}

static void flag_of(const obs_http_option *op, char *buf, size_t len)
{
    snprintf(buf, len, "%s", op->name);
    for (char *c = buf; *c; c++)
        if (*c == '_')
            *c = '-';
}

/* The choice named s[0..len) taken from `from`, or NULL. */
static const obs_http_choice *choice(const obs_http_option *op, const char *s, size_t len, unsigned from)
{
    for (const obs_http_choice *c = op->choices; c && c->name; c++)
        if ((c->from & from) && strlen(c->name) == len && !strncmp(c->name, s, len))
            return c;
    return NULL;
}

/* What the row says the CLI takes beyond the query: a value of choices
 * from the CLI (a comma list where the row has one, empty items skipped).
 * Returns 1 and the int it stores, or 0. */
static int cli_only_value(const obs_http_option *op, const char *v, int *value)
{
    int n = 0;
    *value = 0;
    if (op->kind != OBS_HTTP_OPT_CHOICE)
        return 0;
    if (!(op->list & OBS_HTTP_CLI)) {
        const obs_http_choice *c = choice(op, v, strlen(v), OBS_HTTP_CLI);
        return c ? (*value = c->value, 1) : 0;
    }
    for (const char *s = v;; s++) {
        size_t len = strcspn(s, ",");
        const obs_http_choice *c = choice(op, s, len, OBS_HTTP_CLI);
        if (len && !c)
            return 0;
        if (c) {
            *value |= c->value;
            n++;
        }
        s += len;
        if (!*s)
            break;
    }
    return n > 0;
}

/* Sets op to v both ways and compares; `argv_form` 0: --flag v, 1:
 * --flag=v, 2: -flag v. */
static void check_value(const obs_http_option *op, const char *v, int argv_form)
{
    char flag[64], arg[512], err[OBS_ERR_LEN] = "", what[700];
    obs_http_request h = fresh(), c = fresh(), def = fresh();
    const obs_http_option *which = NULL;
    int i = 0, k, cli_value;
    flag_of(op, flag, sizeof flag);
    char *argv[3] = {arg, (char *)v, NULL};
    int argc = 2;
    if (argv_form == 1) {
        snprintf(arg, sizeof arg, "--%s=%s", flag, v);
        argc = 1;
    } else {
        snprintf(arg, sizeof arg, "%s%s", argv_form == 2 ? "-" : "--", flag);
    }
    snprintf(what, sizeof what, "%s '%.300s' (form %d)", op->name, v, argv_form);

    obs_status sh = obs_http_request_set(&h, op->name, v, NULL);
    k = cli_request_flag(argc, argv, &i, &c, &which, err);
    if (k == 0)
        fail_msg("%s: the CLI does not take the flag", what);
    assert_ptr_equal(which, op);
    if (sh == OBS_OK) {
        if (k != 1)
            fail_msg("%s: the query takes it, the flag refuses it: %s", what, err);
        assert_int_equal(i, argc - 1); /* the value was consumed */
        assert_same_request(&h, &c, what);
        return;
    }
    assert_same_request(&h, &def, what); /* a refused query sets nothing */
    if (k == -1) {
        assert_non_null(strstr(err, op->name)); /* the message names it */
        assert_same_request(&c, &def, what);
        return;
    }
    /* the flag took what the query refused: only as the row declares */
    if (!cli_only_value(op, v, &cli_value))
        fail_msg("%s: the flag takes it, the query refuses it, and the row does not say so", what);
    memcpy((char *)&def + op->field, &cli_value, sizeof cli_value);
    assert_same_request(&c, &def, what);
}

/* Values for a row: its own choices and names, lists built from them,
 * and the usual bad ones. */
static int row_values(const obs_http_option *op, char vals[][300], int cap)
{
    static const char *const common[] = {"", ",", "x", "0", "1", "true", "false", "yes", "08", "8x",
                                         "16", "12", "a,b", "a,b,c", "a,b,c,d", "a,b,c,d,e", "a,,b,c",
                                         ",a,b,c", "a,b,c,", "Z", "N.X,N.Y,N.Z", "R,G,B,A", NULL};
    int n = 0;
    for (int i = 0; common[i] && n < cap; i++)
        snprintf(vals[n++], 300, "%s", common[i]);
    for (const obs_http_option *o = obs_http_options; o->name; o++) {
        for (const obs_http_choice *c = o->choices; c && c->name && n + 3 <= cap; c++) {
            snprintf(vals[n++], 300, "%s", c->name);
            snprintf(vals[n++], 300, "ao,%s", c->name);
            snprintf(vals[n++], 300, "%s,,", c->name);
        }
        for (const char *const *p = o->names; p && *p && n < cap; p++)
            snprintf(vals[n++], 300, "%s", *p);
    }
    if (op->kind == OBS_HTTP_OPT_NAMES) { /* min-1 .. max+1 names; names of slot-1 and slot bytes */
        for (int count = op->min > 1 ? op->min - 1 : 1; count <= op->max + 1 && n < cap; count++) {
            size_t o = 0;
            for (int j = 0; j < count; j++)
                o += (size_t)snprintf(vals[n] + o, 300 - o, "%sCh%d.V", j ? "," : "", j);
            n++;
        }
        for (size_t len = op->slot - 1; len <= op->slot && n < cap; len++) {
            memset(vals[n], 'y', len);
            vals[n++][len] = '\0';
        }
    }
    return n;
}

static void test_rows_same_both_ways(void **state)
{
    (void)state;
    static char vals[256][300];
    int rows = 0;
    for (const obs_http_option *op = obs_http_options; op->name; op++, rows++) {
        if (op->kind == OBS_HTTP_OPT_BOOL)
            continue; /* a switch: test_switches */
        int n = row_values(op, vals, 256);
        for (int j = 0; j < n; j++)
            for (int form = 0; form < 3; form++)
                check_value(op, vals[j], form);
    }
    assert_true(rows >= 8);
}

/* A BOOL row is a switch in the CLI: --float is float=1 (and float=,
 * which a query takes as 1); --float=0 and --float=1 set it to the value
 * (solve_camera, on by default, is turned off so). */
static void test_switches(void **state)
{
    (void)state;
    for (const obs_http_option *op = obs_http_options; op->name; op++) {
        if (op->kind != OBS_HTTP_OPT_BOOL)
            continue;
        char flag[64], arg[80], err[OBS_ERR_LEN] = "";
        obs_http_request h1 = fresh(), h0 = fresh(), c = fresh(), def = fresh();
        const obs_http_option *which = NULL;
        int i = 0;
        flag_of(op, flag, sizeof flag);
        snprintf(arg, sizeof arg, "--%s", flag);
        char *argv[] = {arg, "next", NULL};
        assert_int_equal(obs_http_request_set(&h1, op->name, "1", NULL), OBS_OK);
        assert_int_equal(obs_http_request_set(&h0, op->name, "", NULL), OBS_OK);
        assert_int_equal(cli_request_flag(2, argv, &i, &c, &which, err), 1);
        assert_ptr_equal(which, op);
        assert_int_equal(i, 0); /* a switch takes no value */
        assert_same_request(&h1, &c, op->name);
        assert_same_request(&h0, &c, op->name);
        obs_http_request off = fresh(), c0 = fresh();
        assert_int_equal(obs_http_request_set(&off, op->name, "0", NULL), OBS_OK);
        if (memcmp(&c, &def, sizeof c) == 0 && memcmp(&off, &def, sizeof off) == 0)
            fail_msg("%s: neither value changes anything", op->name);
        snprintf(arg, sizeof arg, "--%s=0", flag);
        assert_int_equal(cli_request_flag(2, argv, &i, &c0, &which, err), 1);
        assert_int_equal(i, 0);
        assert_same_request(&off, &c0, op->name);
        snprintf(arg, sizeof arg, "--%s=maybe", flag);
        assert_int_equal(cli_request_flag(2, argv, &i, &c0, &which, err), -1);
        assert_non_null(strstr(err, op->name));
    }
}

/* Every row reaches its field from the CLI: some value of it changes the
 * request. */
static void test_every_row_sets_something(void **state)
{
    (void)state;
    static char vals[256][300];
    for (const obs_http_option *op = obs_http_options; op->name; op++) {
        if (op->kind == OBS_HTTP_OPT_BOOL)
            continue;
        int n = row_values(op, vals, 256), changed = 0;
        for (int j = 0; j < n && !changed; j++) {
            obs_http_request c = fresh(), def = fresh();
            char flag[64], arg[80], err[OBS_ERR_LEN];
            int i = 0;
            flag_of(op, flag, sizeof flag);
            snprintf(arg, sizeof arg, "--%s", flag);
            char *argv[] = {arg, vals[j], NULL};
            if (cli_request_flag(2, argv, &i, &c, NULL, err) == 1) {
                obs_http_request nc, nd;
                normalise(&c, &nc);
                normalise(&def, &nd);
                changed = memcmp(&nc, &nd, sizeof nc) != 0;
            }
        }
        if (!changed)
            fail_msg("%s: no value of the flag changes the request", op->name);
    }
}

/* Words that are not request options are left to the caller; a value
 * missing at the end is an error naming the flag. */
static void test_other_words(void **state)
{
    (void)state;
    static const char *const others[] = {"--radius", "--output-file", "--depth-mode", "-o", "--floats",
                                         "--png-bits-x", "in.exr", "--", NULL};
    obs_http_request c = fresh(), def = fresh();
    char err[OBS_ERR_LEN] = "";
    for (int j = 0; others[j]; j++) {
        char *argv[] = {(char *)others[j], "1", NULL};
        int i = 0;
        assert_int_equal(cli_request_flag(2, argv, &i, &c, NULL, err), 0);
        assert_int_equal(i, 0);
    }
    assert_same_request(&c, &def, "other words");
    char *last[] = {"--png-bits", NULL};
    int i = 0;
    assert_int_equal(cli_request_flag(1, last, &i, &c, NULL, err), -1);
    assert_string_equal(err, "option --png-bits needs a value");
}

/* The "did you mean" of an unknown option (obscura ao, the bakes): the
 * nearest name within two edits, '_' read as '-', "-" before one letter. */
static void test_suggest(void **state)
{
    (void)state;
    cli_suggest s;
    cli_suggest_start(&s, "--radiu=3");
    cli_suggest_try(&s, "rays");
    cli_suggest_try(&s, "radius");
    assert_string_equal(s.best, "--radius");
    cli_suggest_start(&s, "--png_bts");
    cli_suggest_try(&s, "png_bits");
    assert_string_equal(s.best, "--png-bits");
    cli_suggest_start(&s, "--qq");
    cli_suggest_try(&s, "q");
    assert_string_equal(s.best, "-q");
    cli_suggest_start(&s, "--zzzzzz");
    cli_suggest_try(&s, "radius");
    assert_string_equal(s.best, "");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rows_same_both_ways),
        cmocka_unit_test(test_switches),
        cmocka_unit_test(test_every_row_sets_something),
        cmocka_unit_test(test_other_words),
        cmocka_unit_test(test_suggest),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
