/* The CPU device's output does not depend on its thread count: every
 * method, the chain's variants (half resolution, culling off and greedy,
 * ao_definition volume, luminance and bleeding with colour, every
 * output) and the deep chain, on room_small and deep_small, the same
 * bytes with 1 thread and with several (bands_cpu.h). */
#include "testutil.h"
#include "chain/bands_cpu.h"
#include "methods/methods.h"
#include "obscura/deep.h"
#include "obscura/io.h"
#include "obscura/obscura.h"
#include "room_fixture.h"


static const unsigned all_outputs = OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE |
                                    OBS_OUTPUT_SAMPLE_COUNT | OBS_OUTPUT_CULL_MASK |
                                    OBS_OUTPUT_BLEED | OBS_OUTPUT_LUMINANCE;

static void same_image(const obs_image *a, const obs_image *b, const char *what)
{
    assert_int_equal(a->data != NULL, b->data != NULL);
    if (!a->data)
        return;
    size_t n = (size_t)a->width * (size_t)a->height * (size_t)a->channels * sizeof(float);
    if (memcmp(a->data, b->data, n) != 0)
        fail_msg("%s: the output differs between thread counts", what);
}

/* The frame with the parameters "name=value,..." (NULL: defaults) and
 * `outputs` on 1 thread and on 2, 3 and 7, compared byte for byte. */
static void check(const char *method, const char *const *set, unsigned outputs)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(&p, "method", method, err), OBS_OK);
    for (int k = 0; set && set[k]; k += 2)
        if (obs_param_set(&p, set[k], set[k + 1], err) != OBS_OK)
            fail_msg("%s=%s: %s", set[k], set[k + 1], err);
    obs_result one, many;
    int before = obs__cpu_set_threads(1);
    if (obs_run_cpu(&room.gb, &p, outputs, &one, err) != OBS_OK)
        fail_msg("%s: %s", method, err);
    static const int counts[] = {2, 3, 7};
    for (int t = 0; t < 3; t++) {
        obs__cpu_set_threads(counts[t]);
        assert_true(obs__cpu_threads() >= 1); /* the process's limit may cap it */
        if (obs_run_cpu(&room.gb, &p, outputs, &many, err) != OBS_OK)
            fail_msg("%s: %s", method, err);
        same_image(&one.ao, &many.ao, method);
        same_image(&one.composite, &many.composite, method);
        same_image(&one.sample_count, &many.sample_count, method);
        same_image(&one.cull_mask, &many.cull_mask, method);
        same_image(&one.bleed, &many.bleed, method);
        same_image(&one.luminance, &many.luminance, method);
        obs_result_free(&many);
    }
    obs__cpu_set_threads(before);
    obs_result_free(&one);
}

static void test_every_method(void **state)
{
    (void)state;
    for (int m = 0; m < obs__method_count(); m++)
        check(obs__method_at(m)->name, NULL, OBS_OUTPUT_AO | OBS_OUTPUT_SAMPLE_COUNT);
}

static void test_chain_variants(void **state)
{
    static const char *const half[] = {"ao_resolution", "half", NULL};
    static const char *const greedy[] = {"culling", "greedy", "ao_definition", "volume", NULL};
    static const char *const off[] = {"culling", "off", "adaptive", "off", "blur", "off", NULL};
    static const char *const colour[] = {"luminance", "lum", "bleeding", "half", NULL};
    static const char *const value[] = {"luminance", "value", NULL};
    (void)state;
    check("vaopp", half, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE);
    check("vaopp", greedy, all_outputs);
    check("vaopp", off, all_outputs);
    check("vaopp", colour, all_outputs);
    check("hbao", value, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE | OBS_OUTPUT_LUMINANCE);
}

static int cancel_after(void *user)
{
    int *calls = user; /* calls[0]: calls so far, calls[1]: the call that says stop */
    return __atomic_add_fetch(&calls[0], 1, __ATOMIC_RELAXED) >= calls[1];
}

static void test_deep_chain(void **state)
{
    obs_deep_image d;
    obs_deep_result one, many;
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    (void)state;
    if (obs_deep_read_exr(TESTDATA "/deep_small.exr", NULL, &d, err) != OBS_OK)
        fail_msg("deep_small: %s", err);
    int before = obs__cpu_set_threads(1);
    assert_int_equal(obs_deep_run_cpu(&d, &p, &one, err), OBS_OK);
    obs__cpu_set_threads(3);
    assert_int_equal(obs_deep_run_cpu(&d, &p, &many, err), OBS_OK);
    obs__cpu_set_threads(before);
    same_image(&one.ao_blend, &many.ao_blend, "deep ao");
    same_image(&one.ao_front, &many.ao_front, "deep front ao");
    same_image(&one.composite, &many.composite, "deep composite");
    obs_deep_result_free(&many);
    /* the deadline and the cancel, read between the AO's rows: a cancel
     * that never fires gives the same bytes; one that fires midway and a
     * deadline already past give no result */
    int never[2] = {0, 1 << 30};
    obs_cpu_options polled = {.cancel = cancel_after, .cancel_user = never};
    assert_int_equal(obs_deep_run_cpu_opts(&d, &p, &polled, &many, err), OBS_OK);
    same_image(&one.ao_blend, &many.ao_blend, "deep ao, cancel polled");
    obs_deep_result_free(&many);
    assert_true(never[0] >= d.height); /* once a row at least */
    int mid[2] = {0, never[0] / 2};
    obs_cpu_options midway = {.cancel = cancel_after, .cancel_user = mid};
    assert_int_equal(obs_deep_run_cpu_opts(&d, &p, &midway, &many, err), OBS_CANCELLED);
    assert_non_null(strstr(err, "cancelled (in the ao pass)"));
    assert_null(many.ao_blend.data);
    obs_cpu_options past = {.deadline = 1e-9};
    assert_int_equal(obs_deep_run_cpu_opts(&d, &p, &past, &many, err), OBS_DEADLINE);
    assert_non_null(strstr(err, "past its deadline"));
    assert_null(many.ao_blend.data);
    obs_deep_result_free(&one);
    obs_deep_free(&d);
}

/* A deadline already past stops the run with OBS_DEADLINE and nothing
 * allocated; none (0) runs it whole; the log gets the frame's notes. */
static void note(void *user, obs_log_level level, const char *msg)
{
    (void)level;
    (void)msg;
    (*(int *)user)++;
}

static void test_deadline_and_log(void **state)
{
    obs_result r;
    char err[OBS_ERR_LEN] = "";
    int lines = 0;
    (void)state;
    obs_cpu_options past = {.deadline = 1e-9};
    assert_int_equal(obs_run_cpu_opts(&room.gb, NULL, OBS_OUTPUT_AO, &r, &past, err), OBS_DEADLINE);
    assert_non_null(strstr(err, "deadline"));
    assert_null(r.ao.data);
    obs_gbuffer no_normals = room.gb; /* normals derived from depth: a note */
    no_normals.normal = (obs_plane){NULL, 0, 0};
    obs_cpu_options none = {.log = note, .log_user = &lines};
    assert_int_equal(obs_run_cpu_opts(&no_normals, NULL, OBS_OUTPUT_AO, &r, &none, err), OBS_OK);
    assert_non_null(r.ao.data);
    assert_true(lines > 0);
    obs_result_free(&r);
}

/* obs_cpu_options.cancel: polled while the frame runs (between passes
 * and tiles, from the pool's threads); a nonzero return stops the run
 * with OBS_CANCELLED and nothing allocated, and the cancel is not asked
 * again; one that never says stop leaves the frame's bytes as they are. */

static void test_cancel(void **state)
{
    obs_result r, plain;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    int calls[2] = {0, 1};
    obs_cpu_options now = {.cancel = cancel_after, .cancel_user = calls};
    assert_int_equal(obs_run_cpu_opts(&room.gb, NULL, OBS_OUTPUT_AO, &r, &now, err), OBS_CANCELLED);
    assert_non_null(strstr(err, "cancelled (before the"));
    assert_null(r.ao.data);
    assert_int_equal(calls[0], 1);
    int never[2] = {0, 1 << 30};
    obs_cpu_options polled = {.cancel = cancel_after, .cancel_user = never};
    assert_int_equal(obs_run_cpu(&room.gb, NULL, OBS_OUTPUT_AO, &plain, err), OBS_OK);
    assert_int_equal(obs_run_cpu_opts(&room.gb, NULL, OBS_OUTPUT_AO, &r, &polled, err), OBS_OK);
    assert_memory_equal(r.ao.data, plain.ao.data, (size_t)r.ao.width * r.ao.height * sizeof(float));
    obs_result_free(&r);
    /* asked before each pass (OBS_PASS_COUNT at most) and between the AO
     * pass's tiles: halfway through the calls is inside the AO pass */
    assert_true(never[0] > OBS_PASS_COUNT);
    int mid[2] = {0, never[0] / 2};
    obs_cpu_options midway = {.cancel = cancel_after, .cancel_user = mid};
    assert_int_equal(obs_run_cpu_opts(&room.gb, NULL, OBS_OUTPUT_AO, &r, &midway, err), OBS_CANCELLED);
    assert_non_null(strstr(err, "cancelled"));
    assert_null(r.ao.data);
    /* each thread that was in a tile asks at most once more */
    assert_true(mid[0] <= mid[1] + 64);
    /* a frame in bands of rows (bands_run.c) asks too */
    int banded[2] = {0, never[0] / 2};
    obs_cpu_options bands = {.cancel = cancel_after, .cancel_user = banded, .band_rows = 32};
    assert_int_equal(obs_run_cpu_opts(&room.gb, NULL, OBS_OUTPUT_AO, &r, &bands, err), OBS_CANCELLED);
    assert_non_null(strstr(err, "cancelled"));
    assert_null(r.ao.data);
    obs_result_free(&plain);
}

/* The planes kept for the next frame: counted, kept under a budget
 * above them, released under one below them or 0. */
static void test_kept_trim(void **state)
{
    obs_result r;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    assert_int_equal(obs_run_cpu(&room.gb, NULL, OBS_OUTPUT_AO, &r, err), OBS_OK);
    obs_result_free(&r);
    unsigned long long kept = obs_cpu_kept_bytes();
    size_t px = (size_t)room.gb.width * room.gb.height;
    assert_true(kept >= px * 9 * sizeof(float)); /* position, normal, AO, blur */
    obs_cpu_trim(kept);
    assert_int_equal(obs_cpu_kept_bytes(), kept);
    obs_cpu_trim(kept - 1);
    assert_int_equal(obs_cpu_kept_bytes(), 0);
    assert_int_equal(obs_run_cpu(&room.gb, NULL, OBS_OUTPUT_AO, &r, err), OBS_OK);
    obs_result_free(&r);
    assert_int_equal(obs_cpu_kept_bytes(), kept);
    obs_cpu_trim(0);
    assert_int_equal(obs_cpu_kept_bytes(), 0);
}

/* Every row in exactly one band, bands no taller than asked. */
static void count_rows(void *ctx, int y0, int y1)
{
    int *seen = ctx;
    assert_true(y0 < y1 && y1 - y0 <= 5);
    for (int y = y0; y < y1; y++)
        __atomic_add_fetch(&seen[y], 1, __ATOMIC_RELAXED);
}

static void test_bands(void **state)
{
    int seen[103] = {0};
    (void)state;
    int before = obs__cpu_set_threads(4);
    obs__cpu_rows(103, 5, count_rows, seen);
    obs__cpu_set_threads(before);
    for (int y = 0; y < 103; y++)
        assert_int_equal(seen[y], 1);
}

/* The planes kept from one frame for the next (planes_cpu.c) carry
 * nothing over: a frame after frames of other parameters and sizes is the
 * same bytes as the first. */
static void test_kept_planes(void **state)
{
    static const char *const half[] = {"ao_resolution", "half", "luminance", "lum", NULL};
    obs_params p = {0}, q = {0};
    obs_result first, other, again;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    for (int k = 0; half[k]; k += 2)
        assert_int_equal(obs_param_set(&q, half[k], half[k + 1], err), OBS_OK);
    assert_int_equal(obs_run_cpu(&room.gb, &p, all_outputs, &first, err), OBS_OK);
    assert_int_equal(obs_run_cpu(&room.gb, &q, OBS_OUTPUT_AO, &other, err), OBS_OK);
    obs_result_free(&other);
    obs_gbuffer small = room.gb;
    small.width /= 2; /* the left half, rows at their stride */
    small.depth.row_stride = (size_t)room.gb.width * sizeof(float);
    small.normal.row_stride = (size_t)room.gb.width * 3 * sizeof(float);
    small.color.row_stride = (size_t)room.gb.width * 4 * sizeof(float);
    assert_int_equal(obs_run_cpu(&small, &p, OBS_OUTPUT_AO, &other, err), OBS_OK);
    obs_result_free(&other);
    assert_int_equal(obs_run_cpu(&room.gb, &p, all_outputs, &again, err), OBS_OK);
    same_image(&first.ao, &again.ao, "ao");
    same_image(&first.composite, &again.composite, "composite");
    same_image(&first.bleed, &again.bleed, "bleed");
    same_image(&first.sample_count, &again.sample_count, "sample count");
    obs_result_free(&first);
    obs_result_free(&again);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bands),
        cmocka_unit_test(test_deadline_and_log),
        cmocka_unit_test(test_cancel),
        cmocka_unit_test(test_kept_trim),
        cmocka_unit_test(test_every_method),
        cmocka_unit_test(test_chain_variants),
        cmocka_unit_test(test_deep_chain),
        cmocka_unit_test(test_kept_planes),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
