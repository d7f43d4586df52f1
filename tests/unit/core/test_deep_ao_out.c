/* The deep AO out (obs_deep_ao_nodes, obs_deep_ao_write_exr and its
 * in-memory twin, byte for byte the file; obscura ao
 * --output deep) on the deep fixture: every kept node's AO in [0, 1],
 * its flattening front to back by the nodes' alpha equal to
 * obs_deep_run_cpu's flat AO (blur off), and the file read back through
 * OpenEXR's C API (obs_deep_read_exr: the deep part's counts, Z, ZBack
 * and A; obs_exr_read_channel: the flat part's AOFront.Y); the work it
 * adds to the frame's cost (obs_deep_frame_cost), by the nodes
 * obs_deep_ao_nodes keeps; the GL pass's own per-node AO
 * (obs_deep_run_nodes) against that CPU twin. */
#include "testutil.h"

#include <math.h>
#include <openexr.h>
#include <stdio.h>
#include <unistd.h>

#include "gl_testutil.h"
#include "obscura/deep.h"

#define FIXTURE TESTDATA "/deep_small.exr"

static void params(obs_params *p)
{
    char err[OBS_ERR_LEN] = "";
    memset(p, 0, sizeof *p);
    assert_int_equal(obs_param_set(p, "blur", "off", err), OBS_OK);
    assert_int_equal(obs_param_set(p, "radius", "2", err), OBS_OK);
}

static void test_nodes_flatten_to_flat_ao(void **state)
{
    obs_deep_image d;
    obs_deep_ao a;
    obs_deep_result r;
    obs_params p;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    params(&p);
    if (obs_deep_read_exr(FIXTURE, NULL, &d, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(obs_deep_ao_nodes(&d, &p, &a, err), OBS_OK);
    assert_int_equal(obs_deep_run_cpu(&d, &p, &r, err), OBS_OK);
    size_t npx = (size_t)d.width * d.height, occluded = 0;
    double worst = 0.0;
    for (size_t i = 0; i < npx; i++) {
        float T = 1.0f, acc = 0.0f, zprev = -INFINITY;
        assert_true(a.offset[i + 1] - a.offset[i] <= 4); /* deep_layers 4 */
        for (uint64_t s = a.offset[i]; s < a.offset[i + 1]; s++) {
            const float *v = a.node + s * OBS_DEEP_AO_CH;
            assert_true(v[OBS_DEEP_AO_AO] >= 0.0f && v[OBS_DEEP_AO_AO] <= 1.0f);
            assert_true(v[OBS_DEEP_AO_Z] >= zprev); /* front to back */
            zprev = v[OBS_DEEP_AO_Z];
            occluded += v[OBS_DEEP_AO_AO] < 0.9f;
            acc += T * v[OBS_DEEP_AO_A] * v[OBS_DEEP_AO_AO];
            T *= 1.0f - v[OBS_DEEP_AO_A];
        }
        if (a.offset[i + 1] > a.offset[i])
            assert_true(a.node[a.offset[i] * OBS_DEEP_AO_CH + OBS_DEEP_AO_AO] == r.ao_front.data[i]);
        worst = fmax(worst, fabs(acc + T - r.ao_blend.data[i]));
    }
    print_message("deep_small: %llu nodes, %zu with AO < 0.9; worst |flattened - flat AO| %.2e\n",
                  (unsigned long long)a.offset[npx], occluded, worst);
    assert_true(occluded > 50);
    assert_true(worst < 1e-6);

    /* written and read back */
    char path[] = "/tmp/obs_deep_ao_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    if (obs_deep_ao_write_exr(path, &a, &r.ao_blend, &r.ao_front, OBS_EXR_ZIP_DEFAULT, err) != OBS_OK)
        fail_msg("%s", err);
    obs_deep_image back;
    if (obs_deep_read_exr(path, NULL, &back, err) != OBS_OK)
        fail_msg("%s", err);
    assert_int_equal(back.width, d.width);
    assert_true(back.has_zback && back.has_alpha && !back.has_color);
    assert_true(back.camera.has_projection);
    for (size_t i = 0; i <= npx; i++)
        assert_true(back.offset[i] == a.offset[i]);
    for (uint64_t s = 0; s < a.offset[npx]; s++) {
        assert_true(back.samples[s * OBS_DEEP_CH + OBS_DEEP_Z] == a.node[s * OBS_DEEP_AO_CH + OBS_DEEP_AO_Z]);
        assert_true(back.samples[s * OBS_DEEP_CH + OBS_DEEP_A] == a.node[s * OBS_DEEP_AO_CH + OBS_DEEP_AO_A]);
    }
    obs_image front;
    if (obs_exr_read_channel(path, "AOFront.Y", NULL, &front, err) != OBS_OK)
        fail_msg("%s", err);
    assert_memory_equal(front.data, r.ao_front.data, npx * sizeof(float));
    obs_image_free(&front);
    obs_deep_free(&back);
    /* into memory (obscurad's answer): the file's bytes */
    obs_bytes mem;
    if (obs_deep_ao_write_exr_mem(&a, &r.ao_blend, &r.ao_front, OBS_EXR_ZIP_DEFAULT, &mem, err) != OBS_OK)
        fail_msg("%s", err);
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    unsigned char *file = malloc(mem.size + 1);
    assert_non_null(file);
    assert_int_equal(fread(file, 1, mem.size + 1, fp), mem.size);
    fclose(fp);
    assert_memory_equal(file, mem.data, mem.size);
    free(file);
    obs_bytes_free(&mem);
    assert_int_equal(obs_deep_ao_write_exr_mem(NULL, NULL, NULL, OBS_EXR_ZIP_DEFAULT, &mem, err), OBS_INVALID_ARGUMENT);
    /* a compression named: both parts' (zip: ZIPS in the deep part, as
     * the default), the AO the same; one deep data has no codec for
     * refused, naming it */
    static const obs_exr_compression named[] = {OBS_EXR_NONE, OBS_EXR_RLE, OBS_EXR_ZIPS, OBS_EXR_ZIP};
    for (size_t k = 0; k < sizeof named / sizeof named[0]; k++) {
        if (obs_deep_ao_write_exr(path, &a, &r.ao_blend, &r.ao_front, named[k], err) != OBS_OK)
            fail_msg("%s: %s", obs_exr_compression_name(named[k]), err);
        static const exr_compression_t want[][2] = {{EXR_COMPRESSION_NONE, EXR_COMPRESSION_NONE},
                                                    {EXR_COMPRESSION_RLE, EXR_COMPRESSION_RLE},
                                                    {EXR_COMPRESSION_ZIPS, EXR_COMPRESSION_ZIPS},
                                                    {EXR_COMPRESSION_ZIPS, EXR_COMPRESSION_ZIP}};
        exr_context_t ctx;
        exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
        assert_int_equal(exr_start_read(&ctx, path, &init), EXR_ERR_SUCCESS);
        for (int part = 0; part < 2; part++) { /* deep, flat */
            exr_compression_t c;
            assert_int_equal(exr_get_compression(ctx, part, &c), EXR_ERR_SUCCESS);
            assert_int_equal(c, want[k][part]);
        }
        exr_finish(&ctx);
        if (obs_exr_read_channel(path, "AOFront.Y", NULL, &front, err) != OBS_OK)
            fail_msg("%s", err);
        assert_memory_equal(front.data, r.ao_front.data, npx * sizeof(float));
        obs_image_free(&front);
    }
    assert_int_equal(obs_deep_ao_write_exr_mem(&a, &r.ao_blend, &r.ao_front, OBS_EXR_PIZ, &mem, err),
                     OBS_UNSUPPORTED);
    assert_non_null(strstr(err, "piz"));
    unlink(path);
    obs_deep_ao_free(&a);
    obs_deep_result_free(&r);
    obs_deep_free(&d);
}

/* obs_deep_frame_cost: the pass's obs_frame_cost without output deep and
 * on GL; with it on the CPU device, more by the method's samples x
 * deep_layers for every node obs_deep_ao_nodes keeps (counted here from its output, at two node
 * counts and two methods, so the extra follows the kept nodes). */
static void test_frame_cost_counts_nodes(void **state)
{
    obs_deep_image d;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    if (obs_deep_read_exr(FIXTURE, NULL, &d, err) != OBS_OK)
        fail_msg("%s", err);
    const size_t npx = (size_t)d.width * d.height;
    static const char *const method[] = {"vao", "gtao"};
    for (int mi = 0; mi < 2; mi++) {
        unsigned long long extra_of[2] = {0, 0}, kept_of[2] = {0, 0};
        for (int li = 0; li < 2; li++) {
            const int m = li ? 4 : 2;
            char v[8];
            obs_params p;
            params(&p);
            snprintf(v, sizeof v, "%d", m);
            assert_int_equal(obs_param_set(&p, "deep_layers", v, err), OBS_OK);
            assert_int_equal(obs_param_set(&p, "method", method[mi], err), OBS_OK);
            unsigned long long flat = obs_deep_frame_cost(&d, &p, OBS_OUTPUT_AO, 1);
            unsigned long long deep = obs_deep_frame_cost(&d, &p, OBS_OUTPUT_AO | OBS_OUTPUT_DEEP, 1);
            assert_true(flat == obs_frame_cost(&p, d.width, d.height, m));
            assert_true(obs_deep_frame_cost(&d, &p, OBS_OUTPUT_AO, 0) == flat);
            /* GL: the pass keeps the nodes (obs_deep_run_nodes), nothing apart */
            assert_true(obs_deep_frame_cost(&d, &p, OBS_OUTPUT_AO | OBS_OUTPUT_DEEP, 0) == flat);
            assert_true(deep > flat);
            obs_deep_ao a;
            if (obs_deep_ao_nodes(&d, &p, &a, err) != OBS_OK)
                fail_msg("%s", err);
            kept_of[li] = a.offset[npx];
            extra_of[li] = deep - flat;
            unsigned long long spp = obs_frame_cost(&p, 1, 1, 0);
            assert_true(spp > 0);
            assert_true(extra_of[li] == kept_of[li] * spp * (unsigned long long)m);
            obs_deep_ao_free(&a);
        }
        /* the fixture has pixels of more than 2 samples: more nodes kept at 4 */
        assert_true(kept_of[1] > kept_of[0]);
        assert_true(extra_of[1] * kept_of[0] * 2 == extra_of[0] * kept_of[1] * 4);
        print_message("deep_small %s: kept nodes %llu (m 2), %llu (m 4)\n", method[mi], kept_of[0],
                      kept_of[1]);
    }
    assert_true(obs_deep_frame_cost(NULL, NULL, OBS_OUTPUT_DEEP, 1) == 0);
    obs_deep_free(&d);
}

/* obs_deep_run_nodes against obs_deep_ao_nodes: the same nodes (offsets,
 * Z, ZBack, alpha exactly), each node's AO within the deep GL twin's
 * tolerance (test_deep.c's compare_gl: max 2e-3; its mean 1e-5 a pixel
 * on the front nodes, which are the run's front AO exactly), and the GL
 * nodes flattened front to back equal to the GL run's flat AO (blur off)
 * within 1e-3; the run's planes the same as obs_deep_run's. */
static void compare_nodes_gl(obs_ctx *ctx, const obs_deep_image *d, const obs_params *p, const char *what)
{
    obs_deep_result g, plain;
    obs_deep_ao gn, cn;
    char err[OBS_ERR_LEN] = "";
    if (obs_deep_run_nodes(ctx, d, p, &g, &gn, err) != OBS_OK)
        fail_msg("%s: GL: %s", what, err);
    if (obs_deep_run(ctx, d, p, &plain, err) != OBS_OK)
        fail_msg("%s: GL without nodes: %s", what, err);
    assert_int_equal(obs_deep_ao_nodes(d, p, &cn, err), OBS_OK);
    const size_t npx = (size_t)d->width * d->height;
    obs_deep_result c;
    assert_int_equal(obs_deep_run_cpu(d, p, &c, err), OBS_OK);
    double flat_worst = 0.0, flat_sum = 0.0;
    for (size_t i = 0; i < npx; i++) {
        double e = fabs(g.ao_blend.data[i] - c.ao_blend.data[i]);
        flat_worst = fmax(flat_worst, e);
        flat_sum += e;
    }
    print_message("%s: flat AO GL vs CPU max |diff| %.2e, mean %.2e\n", what, flat_worst, flat_sum / (double)npx);
    obs_deep_result_free(&c);
    assert_memory_equal(g.ao_blend.data, plain.ao_blend.data, npx * sizeof(float));
    assert_memory_equal(g.ao_front.data, plain.ao_front.data, npx * sizeof(float));
    assert_memory_equal(gn.offset, cn.offset, (npx + 1) * sizeof *gn.offset);
    double worst = 0.0, sum = 0.0, flat = 0.0, front_sum = 0.0;
    for (size_t i = 0; i < npx; i++) {
        float T = 1.0f, acc = 0.0f;
        if (gn.offset[i + 1] > gn.offset[i]) { /* the front node: the run's front AO (blur off) */
            const float *a = gn.node + gn.offset[i] * OBS_DEEP_AO_CH, *b = cn.node + cn.offset[i] * OBS_DEEP_AO_CH;
            assert_true(a[OBS_DEEP_AO_AO] == g.ao_front.data[i]);
            front_sum += fabs(a[OBS_DEEP_AO_AO] - b[OBS_DEEP_AO_AO]);
        }
        for (uint64_t s = gn.offset[i]; s < gn.offset[i + 1]; s++) {
            const float *a = gn.node + s * OBS_DEEP_AO_CH, *b = cn.node + s * OBS_DEEP_AO_CH;
            assert_true(a[OBS_DEEP_AO_Z] == b[OBS_DEEP_AO_Z] && a[OBS_DEEP_AO_ZBACK] == b[OBS_DEEP_AO_ZBACK] &&
                        a[OBS_DEEP_AO_A] == b[OBS_DEEP_AO_A]);
            assert_true(a[OBS_DEEP_AO_AO] >= 0.0f && a[OBS_DEEP_AO_AO] <= 1.0f);
            double e = fabs(a[OBS_DEEP_AO_AO] - b[OBS_DEEP_AO_AO]);
            worst = fmax(worst, e);
            sum += e;
            acc += T * a[OBS_DEEP_AO_A] * a[OBS_DEEP_AO_AO];
            T *= 1.0f - a[OBS_DEEP_AO_A];
        }
        flat = fmax(flat, fabs(acc + T - g.ao_blend.data[i]));
    }
    const uint64_t n = gn.offset[npx];
    print_message("%s: %llu nodes, GL vs CPU per node max |diff| %.2e, mean %.2e (front nodes: mean "
                  "%.2e a pixel); |flattened - flat AO| %.2e\n",
                  what, (unsigned long long)n, worst, sum / (double)n, front_sum / (double)npx, flat);
    assert_true(n > npx);
    /* test_deep.c's bounds: every node under its max, the front nodes
     * (its ao_front) under its mean a pixel; the nodes behind, more often
     * occluded, differ by the same rounding more often (a line sample's
     * test flipping, ~1e-4 each) */
    assert_true(worst < 2e-3);
    assert_true(front_sum / (double)npx < 1e-5);
    assert_true(flat < 1e-3);
    obs_deep_ao_free(&gn);
    obs_deep_ao_free(&cn);
    obs_deep_result_free(&g);
    obs_deep_result_free(&plain);
}

/* test_deep.c's fixture cases' parameters (radius 1), blur off */
static void gl_params(obs_params *p)
{
    char err[OBS_ERR_LEN] = "";
    params(p);
    assert_int_equal(obs_param_set(p, "radius", "1", err), OBS_OK);
}

static void test_nodes_gl_twin(void **state)
{
    (void)state;
    obs_ctx *ctx = NULL;
    char err[OBS_ERR_LEN] = "";
    CTX_OR_SKIP(ctx);
    obs_deep_image d;
    if (obs_deep_read_exr(FIXTURE, NULL, &d, err) != OBS_OK)
        fail_msg("%s", err);
    obs_params p;
    gl_params(&p);
    compare_nodes_gl(ctx, &d, &p, "fixture, vaopp, solid");
    assert_int_equal(obs_param_set(&p, "deep_hull", "thin", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "deep_layers", "2", err), OBS_OK);
    compare_nodes_gl(ctx, &d, &p, "fixture, thin, m = 2 (targets remade)");
    gl_params(&p);
    assert_int_equal(obs_param_set(&p, "method", "hemisphere", err), OBS_OK);
    compare_nodes_gl(ctx, &d, &p, "fixture, hemisphere");
    gl_params(&p);
    assert_int_equal(obs_param_set(&p, "method", "gtao", err), OBS_OK);
    compare_nodes_gl(ctx, &d, &p, "fixture, gtao");
    /* the blur does not reach the nodes (the CPU twin's are unblurred) */
    gl_params(&p);
    assert_int_equal(obs_param_set(&p, "blur", "on", err), OBS_OK);
    obs_deep_result g;
    obs_deep_ao gn, cn;
    if (obs_deep_run_nodes(ctx, &d, &p, &g, &gn, err) != OBS_OK)
        fail_msg("blur: %s", err);
    assert_int_equal(obs_deep_ao_nodes(&d, &p, &cn, err), OBS_OK);
    double worst = 0.0;
    for (uint64_t s = 0; s < cn.offset[(size_t)d.width * d.height]; s++)
        worst = fmax(worst, fabs(gn.node[s * OBS_DEEP_AO_CH + OBS_DEEP_AO_AO] - cn.node[s * OBS_DEEP_AO_CH + OBS_DEEP_AO_AO]));
    assert_true(worst < 2e-3);
    obs_deep_ao_free(&gn);
    obs_deep_ao_free(&cn);
    obs_deep_result_free(&g);
    assert_int_equal(obs_deep_run_nodes(ctx, &d, &p, &g, NULL, err), OBS_INVALID_ARGUMENT);
    obs_deep_free(&d);
    obs_ctx_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nodes_flatten_to_flat_ao),
        cmocka_unit_test(test_frame_cost_counts_nodes),
        cmocka_unit_test(test_nodes_gl_twin),
    };
    return cmocka_run_group_tests_name("deep AO out", tests, NULL, NULL);
}
