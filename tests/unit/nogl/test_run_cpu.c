/* The CPU twin of the chain (obs_run_cpu) links and runs without the GL
 * libraries: this binary is linked with libobscura.a, libm and cmocka
 * only (the Makefile's rule for tests/unit/nogl; `make unit` also checks
 * that it needs no libEGL, libOSMesa or libGL).  On a synthetic floor
 * meeting a wall, the crease is darker than the open floor, by the
 * default chain and by a comparison method from the method table. */
#include "testutil.h"
#include "core/synth_corner.h"
#include "chain/passes_cpu.h"

/* Mean AO over the floor pixels of rows [y0, y1). */
static double floor_mean(const sc_scene *s, const float *ao, int y0, int y1)
{
    double sum = 0.0;
    int n = 0;
    for (int y = y0; y < y1; y++)
        for (int x = SC_W / 4; x < 3 * SC_W / 4; x++)
            if (!s->wall[y * SC_W + x]) {
                sum += ao[y * SC_W + x];
                n++;
            }
    return n ? sum / n : -1.0;
}

/* The first row (from the top) whose middle pixel sees the floor. */
static int crease_row(const sc_scene *s)
{
    for (int y = 0; y < SC_H; y++)
        if (!s->wall[y * SC_W + SC_W / 2])
            return y;
    return -1;
}

static void run(const char *method)
{
    static sc_scene s;
    sc_render(&s);
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    if (method)
        assert_int_equal(obs_param_set(&p, "method", method, err), OBS_OK);
    obs_result r;
    obs_status st = obs_run_cpu(&s.gb, &p, OBS_OUTPUT_AO, &r, err);
    if (st != OBS_OK)
        fail_msg("obs_run_cpu: %s", err);
    for (int i = 0; i < SC_W * SC_H; i++)
        assert_true(r.ao.data[i] >= 0.0f && r.ao.data[i] <= 1.0f);
    int yc = crease_row(&s);
    assert_true(yc > 0 && yc < SC_H - 8);
    double crease = floor_mean(&s, r.ao.data, yc, yc + 3);
    double open = floor_mean(&s, r.ao.data, SC_H - 4, SC_H);
    print_message("method %s: floor at the crease %.3f, open floor %.3f\n",
                  method ? method : "default", crease, open);
    assert_true(crease >= 0.0 && open >= 0.0);
    assert_true(crease < open - 0.1);
    obs_result_free(&r);
}

static void test_default_chain(void **state)
{
    (void)state;
    run(NULL);
}

static void test_method_from_table(void **state)
{
    (void)state;
    run("hemisphere");
}

/* The pass table is in the order of obs_pass, every row has its test,
 * and the CPU column has a kernel for every row. */
static void test_pass_table(void **state)
{
    (void)state;
    for (int i = 0; i < OBS_PASS_COUNT; i++) {
        assert_int_equal(obs__passes[i].id, i);
        assert_non_null(obs__passes[i].when);
        assert_non_null(obs__cpu_kernels[i]);
        assert_string_equal(obs_pass_name((obs_pass)i), obs__passes[i].name);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_default_chain),
        cmocka_unit_test(test_method_from_table),
        cmocka_unit_test(test_pass_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
