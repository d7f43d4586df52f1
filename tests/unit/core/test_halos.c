/* Halos behind thin objects (VAO++ range check, eq 4, bounded by the
 * occluder's thickness: occluder_thickness() in vao.glsl, its twin
 * obs__occluder_thickness in chain/vao_cpu.c), through the CPU device and
 * the GL passes, on an orthographic camera looking at a wall (depth 5):
 *  - a rod (a cylinder of radius 0.1 along view y, axis at depth 4.3) in
 *    front of the wall: the rod's thickness along view Z is the chord
 *    2 rho n.z of its circle, which the estimate recovers from the turn of
 *    its normals; the wall's tangent spheres (R = 0.4, pipes from depth
 *    4.6 on) lie wholly behind the rod (its back at 4.4), so every wall
 *    pixel, beside the rod or far from it (an open plane), has AO 1;
 *  - a flat slab (a plate of the same width, face-on, at depth 4.3): its
 *    normals do not turn, one depth layer shows nothing of its thickness,
 *    and eq 4 alone applies, here with u = 1 (occluders taken as solid up
 *    to R behind them): the halo stays, the wall beside the slab darker
 *    than 0.9 (the estimate adds no thickness where it has none to see);
 *  - GL and the CPU device agree (test_gl_twin.c's tolerance).
 * The rows within R of the top and bottom edges are left out: their
 * samples off the image read the rod continued past the border
 * (border_cpu.c), whose thickness is not estimated (eq 4 alone). */
#include <math.h>

#include "gl_testutil.h"

#include "chain/frame.h"

#define W 121
#define H 91
#define PX 0.02f  /* orthographic pixel size */
#define RHO 0.1f  /* the rod's radius and the slab's half width */
#define AXIS 4.3f /* depth of the rod's axis and of the slab */
#define WALL 5.0f
#define EDGE 20 /* R in pixels: rows nearer the top or bottom edge have samples off the image */

typedef struct scene {
    float depth[W * H];
    float normal[W * H * 3];
    obs_gbuffer gb;
} scene;

static void render(scene *s, int rod)
{
    float P[16];
    const float n = 0.1f, f = 100.0f;
    memset(P, 0, sizeof P);
    P[0] = 1.0f / (0.5f * W * PX);
    P[5] = 1.0f / (0.5f * H * PX);
    P[10] = -2.0f / (f - n);
    P[11] = -(f + n) / (f - n);
    P[15] = 1.0f;
    memset(s, 0, sizeof *s);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float ox = (x + 0.5f - 0.5f * W) * PX; /* the rod's axis at view x = 0 */
            float *nv = &s->normal[3 * (y * W + x)];
            s->depth[y * W + x] = WALL;
            nv[2] = 1.0f;
            if (fabsf(ox) < RHO) {
                float c = rod ? sqrtf(RHO * RHO - ox * ox) : RHO;
                s->depth[y * W + x] = AXIS - (rod ? c : 0.0f);
                nv[0] = rod ? ox / RHO : 0.0f;
                nv[2] = c / RHO;
            }
        }
    s->gb.width = W;
    s->gb.height = H;
    s->gb.display_width = W;
    s->gb.display_height = H;
    s->gb.depth = (obs_plane){s->depth, 1, 0};
    s->gb.normal = (obs_plane){s->normal, 3, 0};
    memcpy(s->gb.camera.projection, P, sizeof P);
    obs__mat4_identity(s->gb.camera.world_to_camera);
    s->gb.camera.has_projection = 1;
    s->gb.camera.has_world_to_camera = 1;
}

static obs_params params(void)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_param_set(&p, "normal_space", "camera", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "blur", "off", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "ao_definition", "volume", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "culling", "off", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "adaptive", "off", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "range_u", "1", err), OBS_OK);
    p.radius = 0.4f; /* 20 pixels */
    p.samples = 32;
    return p;
}

/* The wall pixels' lowest AO, by the CPU device and by GL (which must
 * agree); *beside: the lowest within 20 pixels (R) of the occluder. */
static void wall_ao(obs_ctx *ctx, const scene *s, float lo[2])
{
    obs_params p = params();
    obs_result r[2];
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_run_cpu(&s->gb, &p, OBS_OUTPUT_AO, &r[0], err), OBS_OK);
    assert_int_equal(obs_run(ctx, &s->gb, &p, OBS_OUTPUT_AO, &r[1], err), OBS_OK);
    double sum = 0;
    int big = 0;
    for (int b = 0; b < 2; b++)
        lo[b] = 1.0f;
    for (int i = 0; i < W * H; i++) {
        double d = fabs((double)r[0].ao.data[i] - r[1].ao.data[i]);
        sum += d;
        big += d > 1e-3;
        if (s->depth[i] == WALL && i / W >= EDGE && i / W < H - EDGE)
            for (int b = 0; b < 2; b++)
                lo[b] = fminf(lo[b], r[b].ao.data[i]);
    }
    print_message("GL vs CPU: mean |diff| %.2e, %.2f %% > 1e-3\n", sum / (W * H),
                  100.0 * big / (W * H));
    assert_true(sum / (W * H) < 1e-3);
    assert_true(big < 0.02 * W * H);
    for (int b = 0; b < 2; b++)
        obs_result_free(&r[b]);
}

static void test_rod(void **state)
{
    (void)state;
    scene *s = malloc(sizeof *s);
    render(s, 1);
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    float lo[2];
    wall_ao(ctx, s, lo);
    print_message("rod: lowest wall AO %.5f (CPU), %.5f (GL)\n", lo[0], lo[1]);
    assert_true(lo[0] > 1.0f - 1e-4f);
    assert_true(lo[1] > 1.0f - 1e-4f);
    obs_ctx_destroy(ctx);
    free(s);
}

static void test_slab(void **state)
{
    (void)state;
    scene *s = malloc(sizeof *s);
    render(s, 0);
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    float lo[2];
    wall_ao(ctx, s, lo);
    print_message("slab: lowest wall AO %.5f (CPU), %.5f (GL)\n", lo[0], lo[1]);
    assert_true(lo[0] < 0.9f);
    assert_true(lo[1] < 0.9f);
    obs_ctx_destroy(ctx);
    free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rod),
        cmocka_unit_test(test_slab),
    };
    return cmocka_run_group_tests_name("halos", tests, NULL, NULL);
}
