/* The deep AO out (obs_deep_ao_nodes, obs_deep_ao_write_exr and its
 * in-memory twin, byte for byte the file; obscura ao
 * --output deep) on the deep fixture: every kept node's AO in [0, 1],
 * its flattening front to back by the nodes' alpha equal to
 * obs_deep_run_cpu's flat AO (blur off), and the file read back through
 * OpenEXR's C API (obs_deep_read_exr: the deep part's counts, Z, ZBack
 * and A; obs_exr_read_channel: the flat part's AOFront.Y); the work it
 * adds to the frame's cost (obs_deep_frame_cost), by the nodes
 * obs_deep_ao_nodes keeps. */
#include "testutil.h"

#include <math.h>
#include <openexr.h>
#include <stdio.h>
#include <unistd.h>

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

/* obs_deep_frame_cost: the pass's obs_frame_cost without output deep;
 * with it, more by the method's samples x deep_layers for every node
 * obs_deep_ao_nodes keeps (counted here from its output, at two node
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
            unsigned long long flat = obs_deep_frame_cost(&d, &p, OBS_OUTPUT_AO);
            unsigned long long deep = obs_deep_frame_cost(&d, &p, OBS_OUTPUT_AO | OBS_OUTPUT_DEEP);
            assert_true(flat == obs_frame_cost(&p, d.width, d.height, m));
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
    assert_true(obs_deep_frame_cost(NULL, NULL, OBS_OUTPUT_DEEP) == 0);
    obs_deep_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nodes_flatten_to_flat_ao),
        cmocka_unit_test(test_frame_cost_counts_nodes),
    };
    return cmocka_run_group_tests_name("deep AO out", tests, NULL, NULL);
}
