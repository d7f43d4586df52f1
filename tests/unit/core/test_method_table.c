/* The method table (core/methods/methods.c) against the parameter table:
 * a row per choice of `method`, in its order, named as it; a comparison
 * method has a shader, a CPU twin and uniforms its shader declares; the
 * lookups refuse what is not a method. */
#include "testutil.h"

#include "methods/methods.h"
#include "obs_shaders.h"

/* Choice k (0-based) of a '|' list into buf. */
static void nth_choice(const char *choices, int k, char *buf, size_t len)
{
    const char *p = choices;
    for (int i = 0; i < k && p; i++)
        if ((p = strchr(p, '|')))
            p++;
    assert_non_null(p);
    const char *end = strchr(p, '|');
    snprintf(buf, len, "%.*s", end ? (int)(end - p) : (int)strlen(p), p);
}

static void test_rows_are_the_choices(void **state)
{
    (void)state;
    const obs_param_info *pi = obs_param_find("method");
    int choices = 1;
    for (const char *c = pi->choices; *c; c++)
        choices += *c == '|';
    assert_int_equal(obs__method_count(), choices);
    assert_int_equal(obs__method_count(), OBS_METHOD_COUNT - 1);
    for (int i = 0; i < obs__method_count(); i++) {
        const obs__method *m = obs__method_at(i);
        char name[32], err[OBS_ERR_LEN] = "";
        nth_choice(pi->choices, i, name, sizeof name);
        assert_string_equal(m->name, name);
        assert_int_equal((int)m->id, OBS_METHOD_VAOPP + i);
        assert_ptr_equal(obs__method_get(m->id), m);
        obs_params p = {0};
        assert_int_equal(obs_param_set(&p, "method", name, err), OBS_OK);
        assert_int_equal(p.method, (int)m->id);
    }
    assert_null(obs__method_get(OBS_METHOD_DEFAULT));
    assert_null(obs__method_get(OBS_METHOD_COUNT));
    assert_null(obs__method_at(-1));
    assert_null(obs__method_at(obs__method_count()));
}

static void test_rows_are_whole(void **state)
{
    (void)state;
    for (int i = 0; i < obs__method_count(); i++) {
        const obs__method *m = obs__method_at(i);
        /* a shader of its own exactly when it has a CPU twin of it */
        assert_int_equal(m->glsl != NULL, m->pixel != NULL);
        if (!m->glsl) {
            assert_null(m->uniforms[0].name); /* the VAO pass sets its own */
            continue;
        }
        assert_non_null(strstr(m->glsl, "float method_ao("));
        for (const obs__uniform *u = m->uniforms; u->name; u++) {
            char decl[96];
            snprintf(decl, sizeof decl, " %s", u->name);
            if (!strstr(m->glsl, decl))
                fail_msg("method %s: uniform %s is not in its shader", m->name, u->name);
            assert_true(u->offset < sizeof(obs__frame));
            assert_true(u->count_of < sizeof(obs__frame));
        }
    }
    /* the deep chain runs the VAO methods, hemisphere (OITAO's GetAO) and
     * the horizon searches of hbao and gtao over the nodes; not angle */
    assert_true(obs__method_get(OBS_METHOD_VAOPP)->deep);
    assert_true(obs__method_get(OBS_METHOD_HEMISPHERE)->deep);
    assert_true(obs__method_get(OBS_METHOD_HBAO)->deep);
    assert_true(obs__method_get(OBS_METHOD_GTAO)->deep);
    assert_false(obs__method_get(OBS_METHOD_ANGLE)->deep);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rows_are_the_choices),
        cmocka_unit_test(test_rows_are_whole),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
