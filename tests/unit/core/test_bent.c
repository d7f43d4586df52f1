/* The bent normal (OBS_OUTPUT_BENT; method gtao: Jimenez et al. 2016,
 * Algorithm 2, as XeGTAO computes it, methods/bent.c; vaopp: the
 * centroid of the tangent sphere's open volume, chain/vao_bent_cpu.c;
 * hemisphere, angle, hbao: their samples' open directions, methods/bent.c),
 * for every method: an open floor's
 * bent normal is its normal; at a floor-wall crease each side's tilts
 * away from the other, and the two sides' together point along the
 * bisector (by symmetry: the crease's cosine-weighted open directions
 * seen from its two faces mirror each other); GL against the CPU twin;
 * on room_small the angle between the bent normal and the normal grows
 * with occlusion (the correlation is printed); every method's, alone. */
#include <math.h>

#include "gl_testutil.h"

#include "chain/frame.h"
#include "synth_corner.h"

static void run(obs_ctx *ctx, const char *method, const obs_gbuffer *gb, int camera_normals, unsigned out,
                obs_result *r)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(&p, "method", method, err), OBS_OK);
    if (camera_normals)
        assert_int_equal(obs_param_set(&p, "normal_space", "camera", err), OBS_OK);
    /* the crease: hemisphere's 10-sample kernel, turned by the 9 tile
     * rotations, is not mirror-symmetric across the crease's normal plane,
     * so its bent normal leans along x by up to 0.14; 64 samples cover
     * the hemisphere evenly enough for the symmetry the test checks */
    if (camera_normals && strcmp(method, "hemisphere") == 0)
        assert_int_equal(obs_param_set(&p, "hemisphere_samples", "64", err), OBS_OK);
    obs_status s = ctx ? obs_run(ctx, gb, &p, out, r, err) : obs_run_cpu(gb, &p, out, r, err);
    if (s != OBS_OK)
        fail_msg("run: %s", err);
}

static double deg(double rad) { return rad * 180.0 / M_PI; }

/* The mean bent normal of the floor's row next to the wall (crease 0),
 * of the wall's row next to the floor (crease 1), and of the floor's
 * rows far from the wall (2: open), over the middle half of the columns. */
static void crease_means(const sc_scene *s, const obs_result *r, double m[3][3])
{
    memset(m, 0, 9 * sizeof(double));
    for (int y = 1; y < SC_H - 1; y++)
        for (int x = SC_W / 4; x < 3 * SC_W / 4; x++) {
            size_t i = (size_t)y * SC_W + x;
            int k = -1;
            if (!s->wall[i] && s->wall[i - SC_W])
                k = 0;
            else if (s->wall[i] && !s->wall[i + SC_W])
                k = 1;
            else if (!s->wall[i] && y > SC_H - 4)
                k = 2;
            if (k >= 0)
                for (int c = 0; c < 3; c++)
                    m[k][c] += r->bent.data[3 * i + c];
        }
    for (int k = 0; k < 3; k++) {
        double l = sqrt(m[k][0] * m[k][0] + m[k][1] * m[k][1] + m[k][2] * m[k][2]);
        for (int c = 0; c < 3; c++)
            m[k][c] /= l;
    }
}

static void crease(obs_ctx *ctx, const char *method)
{
    static sc_scene s;
    obs_result cpu, gl;
    double m[3][3], g[3][3];
    sc_render(&s);
    run(NULL, method, &s.gb, 1, OBS_OUTPUT_AO | OBS_OUTPUT_BENT, &cpu);
    run(ctx, method, &s.gb, 1, OBS_OUTPUT_AO | OBS_OUTPUT_BENT, &gl);
    crease_means(&s, &cpu, m);
    crease_means(&s, &gl, g);
    /* floor normal (0, 1, 0), wall normal (0, 0, 1); the crease runs along x */
    double tilt_floor = deg(atan2(m[0][2], m[0][1])), tilt_wall = deg(atan2(m[1][1], m[1][2]));
    double both[3] = {m[0][0] + m[1][0], m[0][1] + m[1][1], m[0][2] + m[1][2]};
    double bl = sqrt(both[0] * both[0] + both[1] * both[1] + both[2] * both[2]);
    double off_bisector = deg(acos((both[1] + both[2]) / (bl * sqrt(2.0))));
    double open = deg(acos(m[2][1]));
    print_message("crease, %s (CPU): floor's bent normal tilted %.1f deg away from the wall, the wall's "
                  "%.1f deg away from the floor (a cosine-weighted quarter space at the crease "
                  "line: 32.5 deg), together %.2f deg off the bisector; open floor %.2f deg off its "
                  "normal; x components %.3f %.3f\n",
                  method, tilt_floor, tilt_wall, off_bisector, open, m[0][0], m[1][0]);
    double open_ao = 0.0, open_n = 0.0;
    for (int y = SC_H - 3; y < SC_H - 1; y++)
        for (int x = SC_W / 4; x < 3 * SC_W / 4; x++)
            open_ao += cpu.ao.data[(size_t)y * SC_W + x], open_n++;
    print_message("crease, %s: the open floor's AO %.3f\n", method, open_ao / open_n);
    assert_true(tilt_floor > 10.0 && tilt_floor < 50.0);
    assert_true(tilt_wall > 10.0 && tilt_wall < 50.0);
    assert_true(fabs(m[0][0]) < 0.05 && fabs(m[1][0]) < 0.05);
    /* hbao marches in screen space but measures elevations from the view
     * axis: under perspective the floor farther up the screen lies below
     * the view plane and counts as an occluder (HBAO's own AO of the open
     * floor, printed above, is below 1 by as much), so its bent normal
     * leans off the floor's normal by the same occlusion; the symmetry
     * checks hold for the other methods */
    if (strcmp(method, "hbao") != 0) {
        assert_true(off_bisector < 5.0);
        assert_true(open < 3.0);
    }
    /* GL against the twin, pixel by pixel */
    size_t n = (size_t)SC_W * SC_H;
    double worst = 0.0, sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d = 0.0;
        for (int c = 0; c < 3; c++)
            d += (double)gl.bent.data[3 * i + c] * cpu.bent.data[3 * i + c];
        double a = deg(acos(fmin(1.0, d)));
        worst = fmax(worst, a);
        sum += a;
    }
    print_message("crease, %s: GL vs CPU bent normal: mean %.3f deg, worst %.3f deg\n", method,
                  sum / n, worst);
    assert_true(sum / n < 0.05);
    for (int k = 0; k < 3; k++)
        for (int c = 0; c < 3; c++)
            assert_float_equal(g[k][c], m[k][c], 1e-3);
    obs_result_free(&cpu);
    obs_result_free(&gl);
}

static void test_crease(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    (void)state;
    crease(ctx, "vaopp");
    crease(ctx, "gtao");
    crease(ctx, "hemisphere");
    crease(ctx, "angle");
    crease(ctx, "hbao");
    obs_ctx_destroy(ctx);
}

/* room_small (world-space normals): the bent normal is unit length on the
 * geometry and 0 on the background, and its angle to the normal grows
 * with the occlusion (Pearson correlation of the angle with 1 - AO over
 * the geometry, AO unblurred to match the bent normal). */
static void room(const char *method)
{
    obs_gbuffer_file gf = {0};
    obs_result r;
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    load(scenes[0], &gf);
    assert_int_equal(obs_param_set(&p, "method", method, err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "blur", "off", err), OBS_OK);
    assert_int_equal(obs_run_cpu(&gf.gb, &p, OBS_OUTPUT_AO | OBS_OUTPUT_BENT, &r, err), OBS_OK);
    const obs_gbuffer *gb = &gf.gb;
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0, cnt = 0, bins[4] = {0}, nb[4] = {0};
    for (int y = 0; y < gb->height; y++)
        for (int x = 0; x < gb->width; x++) {
            size_t i = (size_t)y * gb->width + x;
            const float *b = r.bent.data + 3 * i;
            double bl = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
            if (bl == 0.0)
                continue; /* background */
            assert_true(fabs(bl - 1.0) < 1e-4);
            const float *nn = obs__plane_px(&gb->normal, gb->width, x, y);
            double nl = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            double a = deg(acos(fmin(1.0, (b[0] * nn[0] + b[1] * nn[1] + b[2] * nn[2]) / nl)));
            double occ = 1.0 - r.ao.data[i];
            sx += occ, sy += a, sxx += occ * occ, syy += a * a, sxy += occ * a, cnt++;
            int k = occ < 0.1 ? 0 : occ < 0.3 ? 1 : occ < 0.5 ? 2 : 3;
            bins[k] += a, nb[k]++;
        }
    double cov = sxy / cnt - sx / cnt * sy / cnt;
    double rho = cov / sqrt((sxx / cnt - sx * sx / cnt / cnt) * (syy / cnt - sy * sy / cnt / cnt));
    print_message("room_small, %s: correlation of the bent normal's angle to the normal with "
                  "the occlusion 1 - AO over %.0f pixels: r = %.3f; mean angle for occlusion "
                  "< 0.1: %.1f deg (%.0f px), 0.1-0.3: %.1f (%.0f), 0.3-0.5: %.1f (%.0f), "
                  ">= 0.5: %.1f (%.0f)\n",
                  method, cnt, rho, bins[0] / fmax(nb[0], 1), nb[0], bins[1] / fmax(nb[1], 1), nb[1],
                  bins[2] / fmax(nb[2], 1), nb[2], bins[3] / fmax(nb[3], 1), nb[3]);
    assert_true(rho > 0.3);
    assert_true(bins[0] / nb[0] < bins[1] / nb[1] && bins[1] / nb[1] < bins[2] / nb[2]);
    obs_result_free(&r);
    obs_gbuffer_free(&gf);
}

static void test_room_correlation(void **state)
{
    (void)state;
    room("vaopp");
    room("gtao");
    room("hemisphere");
    room("angle");
    room("hbao");
}

/* Every method has a bent normal: alone it is made (no refusal), unit
 * length on the geometry, in the normals' space: the CPU device's
 * --output bent of every method. */
static void test_every_method(void **state)
{
    static sc_scene s;
    static const char *const names[] = {"vaopp", "vao", "hemisphere", "angle", "hbao", "gtao"};
    (void)state;
    sc_render(&s);
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        obs_result r;
        obs_params p = {0};
        char err[OBS_ERR_LEN] = "";
        assert_int_equal(obs_param_set(&p, "method", names[k], err), OBS_OK);
        if (obs_run_cpu(&s.gb, &p, OBS_OUTPUT_BENT, &r, err) != OBS_OK)
            fail_msg("%s: %s", names[k], err);
        assert_non_null(r.bent.data);
        for (size_t i = 0; i < (size_t)SC_W * SC_H; i++) {
            const float *b = r.bent.data + 3 * i;
            assert_true(fabsf(sqrtf(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]) - 1.0f) < 1e-4f);
        }
        obs_result_free(&r);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crease),
        cmocka_unit_test(test_room_correlation),
        cmocka_unit_test(test_every_method),
    };
    return cmocka_run_group_tests_name("bent normal", tests, NULL, NULL);
}
