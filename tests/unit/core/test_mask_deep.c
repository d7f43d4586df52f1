/* Object masks on deep input (core/mask.c, core/deep): a plate in front
 * of a wall, as deep
 * samples with an object ID each: leaving the plate out of the occluders
 * gives the wall's nodes exactly the AO of the wall alone, and self_only
 * gives each object's nodes the AO of that object alone, every method of
 * the deep chain; GL against the CPU twin with masks; the occluders and
 * the objects of the Arnold sample's deep id channel read at every
 * sample (the front sample's the same as the flat reader's), a channel
 * the deep part lacks named in the error; at half resolution the masked
 * AO equals the unmasked one away from what is excluded and rises near
 * it, GL against the CPU twin. */
#include "testutil.h"

#include <math.h>

#include <stdlib.h>
#include <string.h>

#include "obscura/deep.h"
#include "obscura/mask.h"

#define ARNOLD TESTDATA "/arnold_sample2.exr"

enum { N = 32, PLATE_LO = 10, PLATE_HI = 22 };
enum { WALL = 1, PLATE = 2 };

static void set(obs_params *p, const char *name, const char *value)
{
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_param_set(p, name, value, err), OBS_OK);
}

static int on_plate(int x, int y)
{
    return x >= PLATE_LO && x < PLATE_HI && y >= PLATE_LO && y < PLATE_HI;
}

/* The wall (depth 10, object 1) everywhere and the plate (depth 9.5,
 * object 2) over a square in front of it, as asked (`objects`: bits
 * WALL, PLATE); normals given (facing the camera), so that a node's
 * normal does not depend on the other nodes of its plane.  Every sample
 * has its object ID and an occluders weight of 1 except those of object
 * `excluded` (0: none). */
static void plate_wall(obs_deep_image *d, int objects, int excluded)
{
    memset(d, 0, sizeof *d);
    d->width = d->height = N;
    d->offset = calloc((size_t)N * N + 1, sizeof *d->offset);
    d->samples = calloc((size_t)N * N * 2, OBS_DEEP_CH * sizeof(float));
    d->occluders = calloc((size_t)N * N * 2, sizeof(float));
    d->object_id = calloc((size_t)N * N * 2, sizeof(float));
    assert_non_null(d->offset);
    assert_non_null(d->samples);
    assert_non_null(d->occluders);
    assert_non_null(d->object_id);
    d->has_alpha = d->has_normal = 1;
    uint64_t n = 0;
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            for (int obj = PLATE; obj >= WALL; obj--) { /* front to back */
                if (!(objects & obj) || (obj == PLATE && !on_plate(x, y)))
                    continue;
                float *s = d->samples + n * OBS_DEEP_CH;
                s[OBS_DEEP_Z] = s[OBS_DEEP_ZBACK] = obj == PLATE ? 9.5f : 10.0f;
                s[OBS_DEEP_A] = 1.0f;
                s[OBS_DEEP_NZ] = 1.0f;
                d->occluders[n] = obj == excluded ? 0.0f : 1.0f;
                d->object_id[n] = (float)obj;
                n++;
            }
            d->offset[(size_t)y * N + x + 1] = n;
        }
}

static obs_params deep_params(const char *method)
{
    obs_params p = {0};
    set(&p, "fov_y", "40");
    set(&p, "radius", "1");
    set(&p, "blur", "off");
    set(&p, "method", method);
    return p;
}

/* The AO of the node of object `obj` at every pixel (1 where it has
 * none): the deep AO out's per-node AO. */
static void node_ao(const obs_deep_image *d, const obs_params *p, int obj, float *out)
{
    obs_deep_ao a;
    char err[OBS_ERR_LEN] = "";
    if (obs_deep_ao_nodes(d, p, &a, err) != OBS_OK)
        fail_msg("%s", err);
    for (int i = 0; i < N * N; i++) {
        out[i] = 1.0f;
        for (uint64_t k = a.offset[i]; k < a.offset[i + 1]; k++) {
            float z = a.node[k * OBS_DEEP_AO_CH + OBS_DEEP_AO_Z];
            if ((obj == PLATE) == (z < 9.75f))
                out[i] = a.node[k * OBS_DEEP_AO_CH + OBS_DEEP_AO_AO];
        }
    }
    obs_deep_ao_free(&a);
}

static const char *const methods[] = {"vaopp", "hemisphere", "gtao", "hbao"};

/* Leaving the plate out of the occluders: the wall's nodes get the AO
 * of the wall alone, where without the mask the plate darkens them. */
static void test_deep_occluders_plate(void **state)
{
    (void)state;
    static float ref[N * N], masked[N * N], plain[N * N];
    for (int m = 0; m < 4; m++) {
        obs_params p = deep_params(methods[m]);
        obs_deep_image alone, both;
        plate_wall(&alone, WALL, 0);
        plate_wall(&both, WALL | PLATE, PLATE);
        free(both.object_id); /* occluders alone: no self_only */
        both.object_id = NULL;
        node_ao(&alone, &p, WALL, ref);
        node_ao(&both, &p, WALL, masked);
        free(both.occluders); /* the same file without the mask */
        both.occluders = NULL;
        node_ao(&both, &p, WALL, plain);
        double worst = 0.0;
        int darker = 0;
        for (int i = 0; i < N * N; i++) {
            worst = fmax(worst, fabs(masked[i] - ref[i]));
            darker += plain[i] < ref[i] - 0.02f;
        }
        print_message("%s: occluders without the plate: max |wall - wall alone| %.2e; the "
                      "plate darkens %d wall nodes without the mask\n",
                      methods[m], worst, darker);
        assert_true(worst <= 1e-6);
        assert_true(darker >= 20);
        obs_deep_free(&alone);
        obs_deep_free(&both);
    }
}

/* self_only: each object's nodes get the AO of that object alone. */
static void test_deep_self_only(void **state)
{
    (void)state;
    static float wall[N * N], plate[N * N], w_self[N * N], p_self[N * N];
    for (int m = 0; m < 4; m++) {
        obs_params p = deep_params(methods[m]);
        obs_deep_image w, pl, both;
        plate_wall(&w, WALL, 0);
        plate_wall(&pl, PLATE, 0);
        plate_wall(&both, WALL | PLATE, 0);
        free(both.occluders); /* self_only alone: no weights */
        both.occluders = NULL;
        node_ao(&w, &p, WALL, wall);
        node_ao(&pl, &p, PLATE, plate);
        node_ao(&both, &p, WALL, w_self);
        node_ao(&both, &p, PLATE, p_self);
        double worst = 0.0;
        for (int i = 0; i < N * N; i++)
            worst = fmax(worst, fmax(fabs(w_self[i] - wall[i]), fabs(p_self[i] - plate[i])));
        print_message("%s: self_only: max |node - its object alone| %.2e\n", methods[m], worst);
        assert_true(worst <= 1e-6);
        obs_deep_free(&w);
        obs_deep_free(&pl);
        obs_deep_free(&both);
    }
}

/* GL's deep pass against the CPU twin with occluders and with self_only,
 * the plate half transparent (the wall's nodes behind it show in the
 * blend): the unmasked deep twin's tolerance (test_deep.c), a sample
 * reading its weight at the pixel it reads its node at; the masks
 * themselves move the AO far more. */
static void test_deep_gl_twin(void **state)
{
    (void)state;
    obs_ctx *ctx = NULL;
    obs_ctx_desc desc = {0};
    char err[OBS_ERR_LEN] = "";
    if (obs_ctx_create(&desc, &ctx, err) != OBS_OK) {
        print_message("no GL context (%s): skipped\n", err);
        skip();
    }
    for (int m = 0; m < 4; m++)
        for (int self = 0; self < 2; self++) {
            obs_params p = deep_params(methods[m]);
            obs_deep_image d;
            obs_deep_result g, c, plain;
            plate_wall(&d, WALL | PLATE, self ? 0 : PLATE);
            for (uint64_t k = 0; k < d.offset[N * N]; k++)
                if (d.object_id[k] == (float)PLATE)
                    d.samples[k * OBS_DEEP_CH + OBS_DEEP_A] = 0.5f;
            if (self) { /* self_only alone */
                free(d.occluders);
                d.occluders = NULL;
            } else {
                free(d.object_id);
                d.object_id = NULL;
            }
            if (obs_deep_run(ctx, &d, &p, &g, err) != OBS_OK)
                fail_msg("GL: %s", err);
            assert_int_equal(obs_deep_run_cpu(&d, &p, &c, err), OBS_OK);
            float *keep[2] = {d.occluders, d.object_id};
            d.occluders = d.object_id = NULL;
            assert_int_equal(obs_deep_run_cpu(&d, &p, &plain, err), OBS_OK);
            d.occluders = keep[0];
            d.object_id = keep[1];
            double worst = 0.0, sum = 0.0, moved = 0.0;
            for (int i = 0; i < N * N; i++) {
                double e = fmax(fabs(g.ao_front.data[i] - c.ao_front.data[i]),
                                fabs(g.ao_blend.data[i] - c.ao_blend.data[i]));
                worst = fmax(worst, e);
                sum += e;
                moved = fmax(moved, fabs(plain.ao_blend.data[i] - c.ao_blend.data[i]));
            }
            print_message("%s, %s: GL vs CPU max |diff| %.2e, mean %.2e; the masks move the "
                          "blend by up to %.3f\n",
                          methods[m], self ? "self_only" : "occluders", worst, sum / (N * N),
                          moved);
            assert_true(worst < 2e-3);
            assert_true(sum / (N * N) < 1e-5);
            assert_true(moved > 0.02);
            obs_deep_result_free(&g);
            obs_deep_result_free(&c);
            obs_deep_result_free(&plain);
            obs_deep_free(&d);
        }
    obs_ctx_destroy(ctx);
}

/* The Arnold sample's deep id channel: the occluders weight and the
 * object of every sample, the front sample's equal to what the flat
 * reader takes at each pixel; excluding one object raises the AO; a
 * channel the deep part lacks is named. */
static void test_deep_arnold(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_deep_image d;
    obs_params p = {0};
    set(&p, "radius", "1");
    set(&p, "blur", "off");
    assert_int_equal(obs_deep_read_exr(ARNOLD, NULL, &d, err), OBS_OK);
    obs_deep_result all, sel;
    assert_int_equal(obs_deep_run_cpu(&d, &p, &all, err), OBS_OK);
    set(&p, "occluders", "!id:id=2");
    set(&p, "self_only", "on");
    if (obs_deep_read_masks(&d, ARNOLD, NULL, 0, &p, NULL, err) != OBS_OK)
        fail_msg("%s", err);
    assert_non_null(d.occluders);
    assert_non_null(d.object_id);
    obs_image w, ids;
    assert_int_equal(obs_mask_plane(ARNOLD, NULL, 0, "!id:id=2", NULL, &w, &ids, err), OBS_OK);
    const size_t npx = (size_t)d.width * d.height;
    size_t excluded = 0, deeper = 0;
    for (size_t i = 0; i < npx; i++) {
        if (d.offset[i + 1] == d.offset[i])
            continue;
        assert_true(d.occluders[d.offset[i]] == w.data[i]);
        assert_memory_equal(&d.object_id[d.offset[i]], &ids.data[i], sizeof(float));
        for (uint64_t s = d.offset[i]; s < d.offset[i + 1]; s++) {
            /* the weight is the selector's on the sample's own ID */
            assert_true(d.occluders[s] == (d.object_id[s] == 2.0f ? 0.0f : 1.0f));
            excluded += d.occluders[s] == 0.0f;
            deeper += s > d.offset[i] && d.object_id[s] != d.object_id[d.offset[i]];
        }
    }
    print_message("Arnold: %zu samples excluded, %zu deeper samples of another object than "
                  "the front one\n", excluded, deeper);
    assert_true(excluded > 1000 && deeper > 10);
    obs_image_free(&w);
    obs_image_free(&ids);
    /* occluders alone: the AO rises or stays (VAO's occlusion is the
     * largest over the nodes, each times its weight) */
    free(d.object_id);
    d.object_id = NULL;
    assert_int_equal(obs_deep_run_cpu(&d, &p, &sel, err), OBS_OK);
    int rose = 0;
    for (size_t i = 0; i < npx; i++) {
        assert_true(sel.ao_blend.data[i] >= all.ao_blend.data[i] - 1e-6f);
        rose += sel.ao_blend.data[i] > all.ao_blend.data[i] + 1e-3f;
    }
    assert_true(rose > 100);
    obs_deep_result_free(&all);
    obs_deep_result_free(&sel);
    /* a per-sample channel the deep part does not have */
    obs_params q = {0};
    set(&q, "occluders", "id:object=1");
    assert_int_equal(obs_deep_read_masks(&d, ARNOLD, NULL, 0, &q, NULL, err),
                     OBS_MISSING_CHANNEL);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "occluders on deep input"));
    assert_non_null(strstr(err, "no per-sample channel 'object'"));
    obs_deep_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_deep_occluders_plate), cmocka_unit_test(test_deep_self_only),
        cmocka_unit_test(test_deep_gl_twin),         cmocka_unit_test(test_deep_arnold),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
