/* Baked and screen-space AO in one frame (obs_result_combine_baked):
 * product and min by hand, the composite scaled with the AO, the chain's
 * AO and the baked values kept, bad arguments. */
#include <math.h>

#include "testutil.h"

#include "obscura/obscura.h"
#include "obscura/params.h"

static obs_image img(int w, int h, int c, const float *v)
{
    obs_image m = {w, h, c, malloc((size_t)w * h * c * sizeof(float))};
    assert_non_null(m.data);
    memcpy(m.data, v, (size_t)w * h * c * sizeof(float));
    return m;
}

static void test_product_and_min(void **state)
{
    (void)state;
    const float ssao[4] = {1.0f, 0.5f, 0.8f, 0.0f}, bk[4] = {0.6f, 0.5f, NAN, 0.3f};
    const float rgba[16] = {1, 1, 1, 1, 0.5f, 0.2f, 0.1f, 1, 1, 0, 0, 0.5f, 0.3f, 0.3f, 0.3f, 1};
    for (int mode = 0; mode < 2; mode++) {
        obs_result r = {0};
        obs_image b = img(2, 2, 1, bk);
        r.ao = img(2, 2, 1, ssao);
        r.composite = img(2, 2, 4, rgba);
        obs_params p = {0};
        char err[OBS_ERR_LEN] = "";
        if (mode)
            assert_int_equal(obs_param_set(&p, "baked_combine", "min", err), OBS_OK);
        assert_int_equal(obs_result_combine_baked(&r, &b, &p, err), OBS_OK);
        for (int i = 0; i < 4; i++) {
            float bv = isfinite(bk[i]) ? bk[i] : 1.0f; /* NaN: no baked value */
            float want = mode ? fminf(ssao[i], bv) : ssao[i] * bv;
            assert_float_equal(r.ao.data[i], want, 1e-6f);
            assert_float_equal(r.ao_screen.data[i], ssao[i], 0.0f);
            assert_float_equal(r.ao_baked.data[i], bv, 0.0f);
            /* colour x combined AO: the composite's RGB scaled by
             * combined / screen-space (0 where the screen-space AO is 0) */
            float f = ssao[i] > 0.0f ? want / ssao[i] : 0.0f;
            for (int k = 0; k < 3; k++)
                assert_float_equal(r.composite.data[4 * i + k], rgba[4 * i + k] * f, 1e-6f);
            assert_float_equal(r.composite.data[4 * i + 3], rgba[4 * i + 3], 0.0f);
        }
        /* a second combination would multiply twice: refused */
        assert_int_equal(obs_result_combine_baked(&r, &b, &p, err), OBS_INVALID_ARGUMENT);
        assert_non_null(strstr(err, "already"));
        obs_image_free(&b);
        obs_result_free(&r);
        assert_null(r.ao_screen.data);
    }
}

static void test_errors(void **state)
{
    (void)state;
    const float v[6] = {1, 1, 1, 1, 1, 1};
    obs_result r = {0};
    obs_image b = img(3, 2, 1, v);
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_result_combine_baked(&r, &b, NULL, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "no AO"));
    r.ao = img(2, 3, 1, v);
    assert_int_equal(obs_result_combine_baked(&r, &b, NULL, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "3x2"));
    assert_non_null(r.ao.data); /* left as it was */
    assert_null(r.ao_screen.data);
    obs_image_free(&b);
    obs_result_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_product_and_min),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
