/* The comparison methods (parameter method: hemisphere, angle, hbao, gtao; vao
 * is VAO++ with its extensions off): each estimator's CPU twin on
 * analytic scenes (open plane -> 1, corner -> the value derived below),
 * the angle-based method's arc cosine approximations against the errors
 * the article states, the GL passes against the CPU twin on the real
 * G-buffers, and the parameter rules of the methods. */
#include <math.h>

#include "gl_testutil.h"
#include "synth_planes.h"

#include "methods/angle.h"
#include "methods/gtao.h"
#include "methods/hbao.h"
#include "methods/hemisphere.h"
#include "methods/methods.h"

/* Odd sizes: with an orthographic camera of pixel size PX the centre of
 * pixel (CX, CY) is the view axis, x = y = 0. */
#define W 97
#define H 73
#define PX 0.02f
#define CX 48
#define CY 36

typedef struct scene {
    float depth[W * H];
    float normal[W * H * 3];
    obs_gbuffer gb;
} scene;

static void ortho(float P[16]) { sp_ortho(P, 0.5f * W * PX, 0.5f * H * PX); }

static void perspective(float P[16], float fov_y_deg) { sp_perspective(P, fov_y_deg, W, H); }

typedef sp_plane plane;

static void render(scene *s, const float P[16], const plane *pl, int count)
{
    sp_render(s->depth, s->normal, &s->gb, W, H, 0, P, pl, count);
}

/* Parameters of one method on camera-space normals, without the blur
 * (the estimator itself). */
static obs_params method_params(const char *method)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_param_set(&p, "method", method, err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "normal_space", "camera", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "blur", "off", err), OBS_OK);
    return p;
}

/* The frame and the prep pass's planes of a scene. */
static void setup(const scene *s, const obs_params *p, obs__frame *f, float **pos, float **nrm)
{
    obs_params rp;
    char err[OBS_ERR_LEN] = "";
    obs_params_resolve(p, &rp);
    if (obs__frame_setup(NULL, &s->gb, &rp, f, err) != OBS_OK)
        fail_msg("frame setup: %s", err);
    *pos = malloc(sizeof(float) * 4 * W * H);
    *nrm = malloc(sizeof(float) * 3 * W * H);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            obs__prep_position(f, s->depth[y * W + x], x, y, *pos + 4 * (y * W + x));
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            obs__prep_normal(f, *pos, s->normal + 3 * (y * W + x), x, y, *nrm + 3 * (y * W + x));
}

static const char *const methods[] = {"hemisphere", "angle", "hbao"};

/* ---- open plane -> 1 ------------------------------------------------------ */

/* An open plane occludes nothing.  hemisphere: every kernel point lies
 * above the plane, so the surface at its pixel is behind it (up to half a
 * pixel of slope, far inside the bias).  angle: both points of a pair lie
 * in the plane, perpendicular to n: theta_l + theta_r = pi, AO 1.  hbao:
 * every sample lies in the tangent plane, below t(theta) + bias.  Checked
 * on a plane tilted 31 degrees (orthographic) and one facing a perspective
 * camera, through the whole CPU chain. */
static void test_open_plane(void **state)
{
    (void)state;
    scene *s = malloc(sizeof *s);
    float P[16];
    for (int cam = 0; cam < 2; cam++) {
        plane pl;
        if (cam == 0) {
            float l = sqrtf(1 + 0.36f);
            pl = (plane){{0, 0.6f / l, 1 / l}, -5.0f / l};
            ortho(P);
        } else {
            pl = (plane){{0, 0, 1}, -5.0f};
            perspective(P, 60.0f);
        }
        render(s, P, &pl, 1);
        for (size_t m = 0; m < sizeof methods / sizeof methods[0]; m++) {
            obs_params p = method_params(methods[m]);
            p.radius = 0.4f;
            obs_result r;
            char err[OBS_ERR_LEN] = "";
            assert_int_equal(obs_run_cpu(&s->gb, &p, OBS_OUTPUT_AO, &r, err), OBS_OK);
            float mn = 1;
            for (int i = 0; i < W * H; i++) {
                assert_true(r.ao.data[i] <= 1.0f + 1e-6f);
                mn = fminf(mn, r.ao.data[i]);
            }
            print_message("open plane (%s), %-10s: min AO %.6f\n", cam ? "perspective" : "ortho",
                          methods[m], mn);
            assert_true(mn > 1.0f - 1e-5f);
            obs_result_free(&r);
        }
    }
    free(s);
}

/* ---- hemisphere: floor meets wall ----------------------------------------- */

/* The inner corner of test_vao_math.c: P on the floor (normal +Y) where it
 * meets a wall facing the orthographic camera.  The tangent frame of +Y
 * (Duff et al.) is t1 = +X, t2 = -Z, so kernel point k (rotated by the
 * tile's (c, s): k'y = s kx + c ky) lies at view depth z_P + R k'y; the
 * wall, at P's depth, is in front of it by R k'y, and the range check
 * gives 1 (|z_P - z_wall| = 0).  So
 *   AO = 1 - #{i : R k'y_i >= bias} / n,
 * the samples behind the wall's plane; over a kernel symmetric about the
 * wall plane that is 1/2 (the floor-wall corner's cosine-weighted value). */
static void test_hemisphere_corner(void **state)
{
    (void)state;
    scene *s = malloc(sizeof *s);
    float P[16];
    ortho(P);
    plane wall = {{0, 0, 1}, -5.0f};
    render(s, P, &wall, 1);
    const int counts[] = {3, 6, 10, 16, 64};
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++) {
        obs_params p = method_params("hemisphere");
        p.hemisphere_samples = counts[c];
        obs__frame f;
        float *pos, *nrm;
        setup(s, &p, &f, &pos, &nrm);
        const obs__hemisphere_state *hs = obs__hemisphere_of(&f);
        const float floor_n[3] = {0, 1, 0}, pt[3] = {0.0f, -0.3f, -5.0f};
        double mean = 0;
        for (int k = 0; k < 9; k++) { /* every rotation of the 3x3 tile */
            int x = CX + k / 3, y = CY + k % 3;
            const float *rot = f.rot[3 * (x % 3) + (y % 3)];
            int behind = 0;
            for (int i = 0; i < hs->count; i++) {
                float ky = rot[1] * hs->kernel[i][0] + rot[0] * hs->kernel[i][1];
                behind += f.radius * ky >= hs->bias;
            }
            float ao = obs__hemisphere_pixel(&f, pos, x, y, pt, floor_n);
            assert_float_equal(ao, 1.0f - (float)behind / (float)hs->count, 1e-6f);
            mean += ao / 9;
        }
        print_message("hemisphere corner, %2d samples: mean AO over the tile %.4f\n", counts[c],
                      mean);
        assert_true(mean > 0.3 && mean < 0.7);
        free(pos);
        free(nrm);
    }
    free(s);
}

/* ---- angle and hbao: a 90-degree valley ------------------------------------ */

/* Two planes meeting at 90 degrees along the view y axis, rising towards
 * the orthographic camera on both sides: z = -5 + |x|; plane B (x > 0)
 * has the normal nB = (-1, 0, 1)/sqrt 2, plane A (x < 0) nA = (1, 0, 1)/sqrt 2.
 * P is the crease point on the view axis, pixel (CX, CY), with nB (B is
 * listed first and wins the tie).  The true AO there is 1/2, as at the
 * floor-wall corner. */
static void valley(scene *s)
{
    float P[16];
    const float r2 = sqrtf(0.5f);
    ortho(P);
    plane pl[2] = {{{-r2, 0, r2}, -5.0f * r2}, {{r2, 0, r2}, -5.0f * r2}};
    render(s, P, pl, 2);
}

/* angle.  A pair point at offset v = x - P from P: on plane B, v is in
 * P's tangent plane, theta = pi/2; on plane A, v = (vx, vy, -vx) and
 *   cos theta = nB . v / |v| = sqrt 2 |vx| / sqrt(2 vx^2 + vy^2).
 * A pair (o, -o) puts one point on each side (or both on the crease
 * column, theta = pi/2 twice), so its AO is
 *   min((pi/2 + theta_A) / pi, 1) = 1/2 + theta_A / pi,
 * 1/2 for a pair across the crease, 1 for one along it.  No point is far:
 * |depth difference| = |vx| <= R.  The points are the pixel centres the
 * samples P +- o fall in.  Over all pair directions this averages
 * 1/2 + (1/pi^2) Int acos(sqrt 2 |cos a| / sqrt(1 + cos^2 a)) da. */
static void test_angle_valley(void **state)
{
    (void)state;
    scene *s = malloc(sizeof *s);
    valley(s);
    const char *const modes[] = {"quadratic", "linear", "exact"};
    const float nB[3] = {-sqrtf(0.5f), 0, sqrtf(0.5f)};
    for (int md = 0; md < 3; md++)
        for (int pairs = 2; pairs <= 16; pairs *= 2) {
            obs_params p = method_params("angle");
            char err[OBS_ERR_LEN];
            assert_int_equal(obs_param_set(&p, "angle_acos", modes[md], err), OBS_OK);
            p.angle_pairs = pairs;
            p.radius = 0.4f; /* 20 pixels */
            obs__frame f;
            float *pos, *nrm;
            setup(s, &p, &f, &pos, &nrm);
            const obs__angle_state *as = obs__angle_of(&f);
            const float *pt = pos + 4 * (CY * W + CX);
            assert_float_equal(pt[0], 0.0f, 1e-6f);
            double expect = 0;
            for (int i = 0; i < as->pairs; i++) {
                /* tile rotation of (CX, CY) is 0: offset R * pattern */
                float ox = f.radius * as->xy[i][0], oy = f.radius * as->xy[i][1];
                double th = M_PI / 2;
                for (int sg = -1; sg <= 1; sg += 2) {
                    int qx = (int)floorf((sg * ox) / PX + 0.5f * W);
                    int qy = (int)floorf(0.5f * H - (sg * oy) / PX);
                    float vx = (qx + 0.5f - 0.5f * W) * PX, vy = (0.5f * H - qy - 0.5f) * PX;
                    if (vx < 0)
                        th = obs__acos_mode(as->acos,
                                            sqrtf(2.0f) * fabsf(vx) / sqrtf(2 * vx * vx + vy * vy));
                }
                expect += fmin(0.5 + th / M_PI, 1.0) / as->pairs;
            }
            float ao = obs__angle_pixel(&f, pos, CX, CY, pt, nB);
            if (pairs == 16)
                print_message("angle valley (%s acos), %2d pairs: AO %.4f, derived %.4f\n",
                              modes[md], pairs, ao, expect);
            /* exact acos is steep near 1: the float rounding of cos shows */
            assert_float_equal(ao, (float)expect, md == 2 ? 1e-4f : 1e-5f);
            free(pos);
            free(nrm);
        }
    free(s);
}

/* hbao.  Directions 0, 45, ..., 315 degrees (tile rotation 0 at P's
 * pixel), steps of R_px / (Ns + 1) pixels rounded to the nearest pixel,
 * so the 180-degree ray visits (-k, 0), the 135- and 225-degree rays
 * (-k', -+k') with k = round(step), k' = round(step / sqrt 2).
 * Towards B (0, 45, 315 degrees) and along the crease (90, 270) every
 * sample lies in P's tangent plane: elevation = t(theta) < t + bias, no
 * AO.  Towards A every sample has the same elevation h (a plane through
 * P): 180: v = k PX (-1, 0, 1), sin h = 1/sqrt 2, r1^2 = 2 k^2 PX^2;
 * 135/225: v = k' PX (-1, +-1, 1), sin h = 1/sqrt 3, r1^2 = 3 k'^2 PX^2,
 * and only the first sample raises the horizon above t + bias:
 *   AO = 1 - 1/8 sum_{180, 135, 225} W(r1) (sin h - sin(t + bias)),
 * W(r) = 1 - r^2/R^2, t = atan(-(nB . D) / nB.z): -45 degrees at 180,
 * -35.26 at 135 and 225.  (Without bias and attenuation, with directions
 * dense, the integral gives exactly 1/2.) */
static void test_hbao_valley(void **state)
{
    (void)state;
    scene *s = malloc(sizeof *s);
    valley(s);
    const float nB[3] = {-sqrtf(0.5f), 0, sqrtf(0.5f)};
    const char *const biases[] = {"30", "0.001", "10"};
    for (int b = 0; b < 3; b++) {
        obs_params p = method_params("hbao");
        char err[OBS_ERR_LEN];
        assert_int_equal(obs_param_set(&p, "hbao_angle_bias", biases[b], err), OBS_OK);
        p.radius = 0.5f; /* R_px = 25 */
        obs__frame f;
        float *pos, *nrm;
        setup(s, &p, &f, &pos, &nrm);
        const float *pt = pos + 4 * (CY * W + CX);
        const double R = f.radius, bias = atof(biases[b]) * M_PI / 180;
        const double step = (R / PX) / (obs__hbao_of(&f)->steps + 1);
        const double k = floor(step + 0.5), k2 = floor(step * sqrt(0.5) + 0.5);
        const double W180 = 1 - 2 * k * k * PX * PX / (R * R);
        const double W135 = 1 - 3 * k2 * k2 * PX * PX / (R * R);
        const double t180 = -M_PI / 4, t135 = -atan(sqrt(0.5));
        double sum = W180 * (sqrt(0.5) - sin(t180 + bias)) +
                     2 * W135 * (sqrt(1.0 / 3) - sin(t135 + bias));
        double expect = 1 - sum / 8;
        int count;
        float ao = obs__hbao_pixel(&f, pos, CX, CY, pt, nB, &count);
        print_message("hbao valley, bias %s degrees: AO %.5f, derived %.5f (%d samples)\n",
                      biases[b], ao, expect, count);
        assert_float_equal(ao, (float)expect, 1e-5f);
        assert_int_equal(count, 8 * 6);
        free(pos);
        free(nrm);
    }
    free(s);
}

/* ---- gtao: open plane, crease, radius and falloff ------------------------- */

/* Parameters of gtao as Jimenez et al.'s slice integral with a hard cut
 * at the radius: no XeGTAO heuristics, power 1, falloff ~0, multiplier 1. */
static obs_params gtao_exact(int slices, int steps)
{
    obs_params p = method_params("gtao");
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_param_set(&p, "gtao_heuristics", "off", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "gtao_power", "1", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "gtao_falloff", "1e-5", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "gtao_radius_multiplier", "1", err), OBS_OK);
    p.gtao_slices = slices;
    p.gtao_steps = steps;
    return p;
}

/* The smallest AO of the CPU chain on scene s. */
static float min_ao(const scene *s, const obs_params *p)
{
    obs_result r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_run_cpu(&s->gb, p, OBS_OUTPUT_AO, &r, err), OBS_OK);
    float mn = 1;
    for (int i = 0; i < W * H; i++)
        mn = fminf(mn, r.ao.data[i]);
    obs_result_free(&r);
    return mn;
}

/* The slice of angle phi (screen direction (cos phi, sin phi) in view
 * xy) for the orthographic view vector v = +z and the normal n: the
 * projected normal's length L and its angle gamma to v (signed: positive
 * towards +(cos phi, sin phi)).  With t = (cos phi, sin phi, 0) and the
 * slice plane spanned by v and t, n_p = (n.t) t + n.z v. */
static void ortho_slice(const float n[3], double phi, double *L, double *gamma)
{
    double nt = n[0] * cos(phi) + n[1] * sin(phi);
    *L = sqrt(nt * nt + (double)n[2] * n[2]);
    *gamma = atan2(nt, n[2]);
}

/* The slice integral's closed form: L (a(h0) + a(h1)),
 * a(h) = (cos gamma + 2 h sin gamma - cos(2 h - gamma)) / 4. */
static double slice_value(double L, double gamma, double h0, double h1)
{
    double a0 = (cos(gamma) + 2 * h0 * sin(gamma) - cos(2 * h0 - gamma)) / 4;
    double a1 = (cos(gamma) + 2 * h1 * sin(gamma) - cos(2 * h1 - gamma)) / 4;
    return L * (a0 + a1);
}

/* The slice angles gtao takes at pixel (x, y): (i + noise) pi / S. */
static double gtao_phi(int x, int y, int i, int slices)
{
    float noise[2];
    obs__gtao_noise(3 * (x % 3) + (y % 3), noise); /* no display offset */
    return ((double)i + noise[0]) / slices * M_PI;
}

/* An open plane: in every slice both horizons stay at the tangent plane,
 * h = gamma -+ pi/2, and the slice gives L (cos gamma + gamma sin gamma);
 * over phi that averages to 1, the cosine-weighted visibility of the open
 * hemisphere (checked here by quadrature).  Facing an orthographic camera
 * (n = v: L = 1, gamma = 0) every slice is 1, so gtao gives 1 with its
 * defaults too (heuristics on, power 2.2; the radius is 20 pixels, over
 * the 10 below which XeGTAO fades towards open).  On the plane tilted 31
 * degrees, each pixel is the mean of the closed form over its slices up
 * to the samples XeGTAO's rounding to a pixel puts off the slice plane
 * (a point of the plane at another azimuth can lie above this slice's
 * tangent): within 0.01 of it and of 1 (measured 4e-3 with 3 slices,
 * 3e-3 with 8); with the defaults (3 slices, the heuristics' slope fudge
 * raising L, power 2.2) every pixel is within 0.03 of 1. */
static void test_gtao_open_plane(void **state)
{
    (void)state;
    scene *s = malloc(sizeof *s);
    float P[16];
    ortho(P);
    const float l = sqrtf(1 + 0.36f);
    const float tilt_n[3] = {0, 0.6f / l, 1 / l};
    double quad = 0;
    for (int i = 0; i < 4096; i++) {
        double L, g;
        ortho_slice(tilt_n, (i + 0.5) / 4096 * M_PI, &L, &g);
        quad += slice_value(L, g, g - M_PI / 2, g + M_PI / 2) / 4096;
    }
    print_message("gtao open plane: closed form's mean over phi %.7f\n", quad);
    assert_float_equal(quad, 1.0, 1e-6);

    plane facing = {{0, 0, 1}, -5.0f};
    render(s, P, &facing, 1);
    for (int variant = 0; variant < 2; variant++) {
        obs_params p = variant ? gtao_exact(3, 3) : method_params("gtao");
        p.radius = 0.4f;
        float mn = min_ao(s, &p);
        print_message("gtao open plane facing, %s: min AO %.7f\n",
                      variant ? "heuristics off, power 1" : "defaults", mn);
        assert_true(mn > 1.0f - 1e-5f);
    }

    plane tilted = {{tilt_n[0], tilt_n[1], tilt_n[2]}, -5.0f / l};
    render(s, P, &tilted, 1);
    const int slice_counts[] = {3, 8, 32};
    for (size_t k = 0; k < sizeof slice_counts / sizeof slice_counts[0]; k++) {
        obs_params p = gtao_exact(slice_counts[k], 3);
        p.radius = 0.4f;
        obs__frame f;
        float *pos, *nrm;
        setup(s, &p, &f, &pos, &nrm);
        const obs__gtao_state *gs = obs__gtao_of(&f);
        double worst = 0, worst1 = 0;
        for (int y = 2; y < H - 2; y++)
            for (int x = 2; x < W - 2; x++) {
                double expect = 0;
                for (int i = 0; i < gs->slices; i++) {
                    double L, g;
                    ortho_slice(tilt_n, gtao_phi(x, y, i, gs->slices), &L, &g);
                    expect += slice_value(L, g, g - M_PI / 2, g + M_PI / 2) / gs->slices;
                }
                size_t i = (size_t)y * W + x;
                float ao = obs__gtao_pixel(&f, pos, nrm, x, y, pos + 4 * i, nrm + 3 * i, NULL);
                worst = fmax(worst, fabs(ao - fmin(expect, 1.0)));
                worst1 = fmax(worst1, fabs(ao - 1.0));
            }
        print_message("gtao open plane tilted, %2d slices: max |AO - closed form| %.2e, "
                      "max |AO - 1| %.2e\n", gs->slices, worst, worst1);
        assert_true(worst < 0.01);
        assert_true(worst1 < 0.01);
        free(pos);
        free(nrm);
    }
    obs_params p = method_params("gtao");
    p.radius = 0.4f;
    float mn = min_ao(s, &p);
    print_message("gtao open plane tilted, defaults: min AO %.4f\n", mn);
    assert_true(mn > 0.97f);
    free(s);
}

/* The 90-degree valley of test_hbao_valley, P on the crease with the
 * normal nB = (-1, 0, 1)/sqrt 2, v = +z.  Slice phi, c = cos phi:
 * n_p = (-c^2, -s c, 1)/sqrt 2, so L = sqrt((1 + c^2)/2) and
 * gamma = -atan(c).  Plane A (x < 0) through P is the occluder: on the
 * side that crosses it, every point of A in the slice plane has
 * cos h = |c| / sqrt(1 + c^2), so h = -+(pi/2 - atan|c|); on the other
 * side the horizon is B's tangent, gamma +- pi/2.  The closed form's mean
 * over phi is 1/2 (a wall through P perpendicular to the surface hides
 * half the cosine-weighted hemisphere, as a ray tracer sees it; checked
 * by quadrature).
 *
 * The samples: XeGTAO rounds a step's offset to a pixel, so a sample
 * lies off the slice plane; the horizon it gives is the angle of the
 * actual point, cos h = dot(q - c, v) / |q - c|, q on the valley at the
 * rounded pixel, c = P moved 1e-5 of its depth towards the camera.  With
 * one step per side (offset ((noise)^2 + 1.3 / R_px) R_px (cos phi,
 * -sin phi) pixels), AO = mean over the slices of the closed form at
 * those horizons, each at least the tangent: checked to 1e-5 at every
 * pixel of the 3x3 tile (a sample farther than R is left out: weight 0
 * with the hard cut); and with 32 slices and 8 steps P's own pixel is
 * within 0.05 below 1/2: a sample rounded off the slice towards a
 * steeper azimuth of A raises the horizon, and the horizon is the largest
 * over 8 of them (measured 0.470). */
static void test_gtao_crease(void **state)
{
    (void)state;
    const float nB[3] = {-sqrtf(0.5f), 0, sqrtf(0.5f)};
    double quad = 0;
    for (int i = 0; i < 4096; i++) {
        double phi = (i + 0.5) / 4096 * M_PI, c = cos(phi), L, g;
        ortho_slice(nB, phi, &L, &g);
        assert_float_equal(L, sqrt((1 + c * c) / 2), 1e-6);
        assert_float_equal(g, -atan(c), 1e-6);
        double hA = M_PI / 2 - atan(fabs(c));
        double h0 = c > 0 ? -hA : g - M_PI / 2, h1 = c > 0 ? g + M_PI / 2 : hA;
        quad += slice_value(L, g, h0, h1) / 4096;
    }
    print_message("gtao crease: closed form's mean over phi %.7f\n", quad);
    assert_float_equal(quad, 0.5, 1e-6);

    scene *s = malloc(sizeof *s);
    valley(s);
    {
        obs_params p = gtao_exact(4, 1);
        p.radius = 0.5f; /* 25 pixels */
        obs__frame f;
        float *pos, *nrm;
        setup(s, &p, &f, &pos, &nrm);
        const obs__gtao_state *gs = obs__gtao_of(&f);
        const float *pt = pos + 4 * (CY * W + CX);
        const double cz = pt[2] * 0.99999f;
        for (int k = 0; k < 9; k++) {
            int x = CX + k / 3, y = CY + k % 3; /* P's own point at every rotation of the tile */
            float noise[2];
            obs__gtao_noise(3 * (x % 3) + (y % 3), noise); /* no display offset */
            double rpx = f.radius / PX, min_s = 1.3 / rpx, expect = 0;
            for (int i = 0; i < gs->slices; i++) {
                double phi = gtao_phi(x, y, i, gs->slices), L, g;
                ortho_slice(nB, phi, &L, &g);
                double sn = noise[1] + i * 0.6180339887498948482;
                sn -= floor(sn);
                double sd = sn * sn + min_s;
                int ox = (int)floor(sd * rpx * cos(phi) + 0.5);
                int oy = (int)floor(-sd * rpx * sin(phi) + 0.5);
                double h[2];
                for (int side = 0; side < 2; side++) {
                    int sg = side ? -1 : 1;
                    /* the view offset from P of the pixel read (the pixel
                     * of the tile is P's neighbour, P's point is passed) */
                    double vx = (x - CX + sg * ox) * PX, vy = -(y - CY + sg * oy) * PX;
                    double d[3] = {vx, vy, -5.0 + fabs(vx) - cz};   /* the valley there */
                    double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), ch = d[2] / r;
                    double low = cos(side ? g - M_PI / 2 : g + M_PI / 2);
                    if (r >= gs->radius)
                        ch = low; /* beyond the cut: weight 0 */
                    double hh = acos(fmax(ch, low));
                    h[side] = side ? fmax(-hh, g - M_PI / 2) : fmin(hh, g + M_PI / 2);
                }
                expect += slice_value(L, g, h[1], h[0]) / gs->slices;
            }
            int count;
            float ao = obs__gtao_pixel(&f, pos, nrm, x, y, pt, nB, &count);
            print_message("gtao crease, tile %d: AO %.6f, derived %.6f\n", k, ao, expect);
            assert_float_equal(ao, (float)expect, 1e-5f);
            assert_int_equal(count, 2 * gs->slices);
        }
        free(pos);
        free(nrm);
    }
    {
        obs_params p = gtao_exact(32, 8);
        p.radius = 0.5f;
        obs__frame f;
        float *pos, *nrm;
        setup(s, &p, &f, &pos, &nrm);
        const float *pt = pos + 4 * (CY * W + CX);
        float ao = obs__gtao_pixel(&f, pos, nrm, CX, CY, pt, nB, NULL);
        print_message("gtao crease, 32 slices x 8 steps: AO %.4f (1/2)\n", ao);
        assert_true(ao > 0.45f && ao < 0.505f);
        free(pos);
        free(nrm);
    }
    free(s);
}

/* Radius and falloff.  The valley against a steeper one: B (x > 0) the
 * same, A replaced by A2: z = -5 - 2x (x < 0).  Every point of A or A2
 * lies at least 3 x_P / sqrt 5 from a point P = (x_P, ., -5 + x_P) of B
 * (the distance to A2's plane, less than the sqrt 2 x_P to A's), so with
 * a hard cut at R gtao gives the same AO at every P of B with
 * 3 x_P / sqrt 5 > R in both scenes (the samples there are weighed 0),
 * and a lower one in the steeper valley where the crease is well inside
 * R.  The falloff only lowers a sample's weight as gtao_falloff grows, so
 * at every pixel AO does not fall as it grows, and near the crease it
 * rises. */
static void test_gtao_radius_falloff(void **state)
{
    (void)state;
    scene *s1 = malloc(sizeof *s1), *s2 = malloc(sizeof *s2);
    float P[16];
    const float r2 = sqrtf(0.5f), r5 = 1.0f / sqrtf(5.0f);
    ortho(P);
    plane pl1[2] = {{{-r2, 0, r2}, -5.0f * r2}, {{r2, 0, r2}, -5.0f * r2}};
    plane pl2[2] = {{{-r2, 0, r2}, -5.0f * r2}, {{2 * r5, 0, r5}, -5.0f * r5}};
    render(s1, P, pl1, 2);
    render(s2, P, pl2, 2);
    obs_params p = gtao_exact(3, 3);
    p.radius = 0.3f; /* 15 pixels */
    obs_result a, b;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_run_cpu(&s1->gb, &p, OBS_OUTPUT_AO, &a, err), OBS_OK);
    assert_int_equal(obs_run_cpu(&s2->gb, &p, OBS_OUTPUT_AO, &b, err), OBS_OK);
    int same = 0, inside = 0;
    double near1 = 0, near2 = 0;
    for (int y = 0; y < H; y++)
        for (int x = CX + 1; x < W; x++) {
            float xp = (x + 0.5f - 0.5f * W) * PX;
            size_t i = (size_t)y * W + x;
            if (3 * xp * r5 > p.radius * 1.001f) {
                assert_float_equal(a.ao.data[i], b.ao.data[i], 1e-7f);
                same++;
            } else if (sqrtf(2.0f) * xp < 0.5f * p.radius) {
                near1 += a.ao.data[i];
                near2 += b.ao.data[i];
                inside++;
            }
        }
    print_message("gtao radius: %d pixels beyond R equal; near the crease mean AO %.4f "
                  "(valley), %.4f (steeper)\n", same, near1 / inside, near2 / inside);
    assert_true(same > 1000 && inside > 100);
    assert_true(near2 / inside < near1 / inside - 0.02);
    obs_result_free(&a);
    obs_result_free(&b);

    const char *const falloffs[] = {"1e-5", "0.3", "0.615", "1"};
    float *prev = NULL;
    double prev_near = 0;
    for (size_t k = 0; k < sizeof falloffs / sizeof falloffs[0]; k++) {
        obs_params q = gtao_exact(3, 3);
        assert_int_equal(obs_param_set(&q, "gtao_falloff", falloffs[k], err), OBS_OK);
        q.radius = 0.3f;
        assert_int_equal(obs_run_cpu(&s1->gb, &q, OBS_OUTPUT_AO, &a, err), OBS_OK);
        double near = 0;
        int nn = 0;
        for (int y = 0; y < H; y++)
            for (int x = CX + 1; x < W; x++) {
                size_t i = (size_t)y * W + x;
                if (prev)
                    assert_true(a.ao.data[i] >= prev[i] - 1e-6f);
                if (x - CX < 8) {
                    near += a.ao.data[i];
                    nn++;
                }
            }
        near /= nn;
        print_message("gtao falloff %s: mean AO within 8 pixels of the crease %.4f\n", falloffs[k],
                      near);
        if (prev)
            assert_true(near > prev_near);
        free(prev);
        prev = malloc(sizeof(float) * W * H);
        memcpy(prev, a.ao.data, sizeof(float) * W * H);
        prev_near = near;
        obs_result_free(&a);
    }
    free(prev);
    free(s1);
    free(s2);
}

/* ---- the article's arc cosine approximations ------------------------------- */

/* "the maximum error between the two functions is around 18.946 degrees"
 * (linear) and "around 9.473 degrees" (quadratic). */
static void test_acos_errors(void **state)
{
    (void)state;
    double worst[4] = {0, 0, 0, 0};
    for (int i = 0; i <= 200000; i++) {
        float x = (float)(i / 100000.0 - 1.0);
        for (int m = OBS_ACOS_QUADRATIC; m <= OBS_ACOS_EXACT; m++)
            worst[m] = fmax(worst[m], fabs(obs__acos_mode(m, x) - acos((double)x)) * 180 / M_PI);
    }
    print_message("acos: max error linear %.3f, quadratic %.3f, exact %.5f degrees\n",
                  worst[OBS_ACOS_LINEAR], worst[OBS_ACOS_QUADRATIC], worst[OBS_ACOS_EXACT]);
    assert_float_equal(worst[OBS_ACOS_LINEAR], 18.946, 0.01);
    assert_float_equal(worst[OBS_ACOS_QUADRATIC], 9.473, 0.01);
    assert_true(worst[OBS_ACOS_EXACT] < 1e-3);
    /* out of range inputs are clamped, not NaN */
    assert_float_equal(obs__acos_mode(OBS_ACOS_EXACT, 1.5f), 0.0f, 0.0f);
    assert_float_equal(obs__acos_mode(OBS_ACOS_QUADRATIC, -2.0f), (float)M_PI, 1e-6f);
}

/* ---- parameters ------------------------------------------------------------ */

static void expect_refused(const char *method, const char *name, const char *value)
{
    obs_params p = {0}, r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(&p, "method", method, err), OBS_OK);
    assert_int_equal(obs_param_set(&p, name, value, err), OBS_OK);
    obs_params_resolve(&p, &r);
    assert_int_equal(obs_params_check(&r, err), OBS_INVALID_ARGUMENT);
    print_message("method %s, %s %s: %s\n", method, name, value, err);
    assert_non_null(strstr(err, name));
    assert_non_null(strstr(err, method));
}

static void expect_accepted(const char *method, const char *name, const char *value)
{
    obs_params p = {0}, r;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(&p, "method", method, err), OBS_OK);
    if (name)
        assert_int_equal(obs_param_set(&p, name, value, err), OBS_OK);
    obs_params_resolve(&p, &r);
    if (obs_params_check(&r, err) != OBS_OK)
        fail_msg("method %s, %s %s: %s", method, name ? name : "", value ? value : "", err);
}

static void test_method_params(void **state)
{
    (void)state;
    obs_params p = {0}, r;
    char err[OBS_ERR_LEN] = "";
    /* the default is VAO++ with its extensions */
    obs_params_resolve(&p, &r);
    assert_int_equal(r.method, OBS_METHOD_VAOPP);
    assert_int_equal(r.adaptive, OBS_ON);
    assert_int_equal(r.culling, OBS_CULLING_CAREFUL);
    assert_int_equal(r.range_check, OBS_ON);
    /* method vao fixes them off; the others also bleeding */
    assert_int_equal(obs_param_set(&p, "method", "vao", err), OBS_OK);
    obs_params_resolve(&p, &r);
    assert_int_equal(r.adaptive, OBS_OFF);
    assert_int_equal(r.culling, OBS_CULLING_OFF);
    assert_int_equal(r.range_check, OBS_OFF);
    assert_int_equal(obs_params_check(&r, err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "method", "hbao", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "bleeding", "off", err), OBS_OK);
    obs_params_resolve(&p, &r);
    assert_int_equal(r.bleeding, OBS_BLEEDING_OFF);
    assert_int_equal(r.hbao_directions, 8);
    assert_int_equal(r.hbao_steps, 6);
    assert_int_equal(r.hemisphere_samples, 10);
    assert_int_equal(r.angle_pairs, 6);
    assert_int_equal(r.angle_acos, OBS_ACOS_QUADRATIC);
    /* a resolved struct resolves again to itself, without conflicts */
    obs_params r2;
    obs_params_resolve(&r, &r2);
    assert_memory_equal(&r, &r2, sizeof r);
    assert_int_equal(obs_params_check(&r2, err), OBS_OK);

    /* a value that contradicts the method, or a parameter it does not use,
     * is refused by name */
    expect_refused("vao", "adaptive", "on");
    expect_refused("vao", "culling", "greedy");
    expect_refused("vao", "range_check", "on");
    expect_refused("vao", "range_u", "0.1");
    expect_refused("hemisphere", "samples", "16");
    expect_refused("angle", "bleeding", "full");
    expect_refused("hbao", "adaptive_diameter", "0.02");
    expect_refused("vaopp", "hbao_steps", "4");
    expect_refused("hbao", "hemisphere_samples", "6");
    expect_refused("hemisphere", "angle_acos", "exact");
    expect_refused("hbao", "ao_definition", "rays");
    expect_refused("angle", "ao_definition", "volume");
    expect_refused("gtao", "hbao_steps", "4");
    expect_refused("hbao", "gtao_slices", "4");
    expect_refused("vaopp", "gtao_power", "1");
    expect_refused("gtao", "samples", "8");
    /* agreeing values and the shared chain are fine */
    expect_accepted("vao", "adaptive", "off");
    expect_accepted("vao", "samples", "32");
    expect_accepted("vao", "bleeding", "full");
    expect_accepted("vao", "ao_definition", "volume");
    expect_accepted("hbao", "culling", "off");
    expect_accepted("hbao", "luminance", "lum");
    expect_accepted("angle", "blur_radius", "4");
    expect_accepted("hemisphere", "hemisphere_samples", "3");
    expect_accepted("angle", "angle_pairs", "16");
    expect_accepted("hbao", "hbao_directions", "32");
    expect_accepted("gtao", "gtao_slices", "9");
    expect_accepted("gtao", "gtao_heuristics", "off");
    expect_accepted("gtao", "blur", "off");
    /* ranges of the method parameters */
    assert_int_equal(obs_param_set(&p, "hbao_steps", "0", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "hbao_steps"));
    assert_int_equal(obs_param_set(&p, "angle_pairs", "17", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_param_set(&p, "hemisphere_samples", "65", err), OBS_INVALID_ARGUMENT);
    assert_int_equal(obs_param_set(&p, "method", "ssao", err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "vaopp|vao|hemisphere|angle|hbao|gtao"));
    /* and the run itself refuses, naming it */
    scene *s = malloc(sizeof *s);
    valley(s);
    obs_params q = {0};
    obs_result res;
    assert_int_equal(obs_param_set(&q, "method", "angle", err), OBS_OK);
    assert_int_equal(obs_param_set(&q, "samples", "8", err), OBS_OK);
    assert_int_equal(obs_run_cpu(&s->gb, &q, OBS_OUTPUT_AO, &res, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "samples"));
    free(s);
}

/* ---- GL against the CPU twin on real input --------------------------------- */

/* As in test_gl_twin.c: a sample within rounding of a pixel border may
 * read the neighbour on one side only, so the mean difference is tiny and
 * few pixels differ (mean < 1e-3, under 2 % of pixels > 1e-3); the sample
 * counts (hbao: the samples inside the image) match. */
static void test_gl_matches_cpu(void **state)
{
    (void)state;
    obs_ctx *ctx = make_ctx(OBS_BACKEND_EGL_SURFACELESS);
    static const char *const variants[][3][2] = {
        {{"method", "vao"}, {NULL, NULL}, {NULL, NULL}},
        {{"method", "hemisphere"}, {NULL, NULL}, {NULL, NULL}},
        {{"method", "hemisphere"}, {"hemisphere_samples", "3"}, {"blur", "off"}},
        {{"method", "hemisphere"}, {"hemisphere_samples", "16"}, {"luminance", "lum"}},
        {{"method", "angle"}, {NULL, NULL}, {NULL, NULL}},
        {{"method", "angle"}, {"angle_acos", "exact"}, {"blur", "off"}},
        {{"method", "angle"}, {"angle_acos", "linear"}, {"angle_pairs", "16"}},
        {{"method", "hbao"}, {NULL, NULL}, {NULL, NULL}},
        {{"method", "hbao"}, {"hbao_directions", "4"}, {"blur", "off"}},
        {{"method", "hbao"}, {"hbao_steps", "16"}, {"hbao_angle_bias", "10"}},
        {{"method", "gtao"}, {NULL, NULL}, {NULL, NULL}},
        {{"method", "gtao"}, {"gtao_slices", "9"}, {"blur", "off"}},
        {{"method", "gtao"}, {"gtao_heuristics", "off"}, {"gtao_thin", "0.5"}},
    };
    for (size_t sc = 0; sc < sizeof scenes / sizeof scenes[0]; sc++) {
        obs_gbuffer_file gf = {0};
        load(scenes[sc], &gf);
        for (size_t v = 0; v < sizeof variants / sizeof variants[0]; v++) {
            obs_params p = {0};
            obs_result gl, cpu;
            char err[OBS_ERR_LEN] = "";
            for (int k = 0; k < 3; k++)
                if (variants[v][k][0])
                    assert_int_equal(obs_param_set(&p, variants[v][k][0], variants[v][k][1], err),
                                     OBS_OK);
            unsigned out = OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE | OBS_OUTPUT_SAMPLE_COUNT |
                           OBS_OUTPUT_CULL_MASK | OBS_OUTPUT_BLEED;
            if (obs_run(ctx, &gf.gb, &p, out, &gl, err) != OBS_OK)
                fail_msg("GL: %s", err);
            assert_int_equal(obs_run_cpu(&gf.gb, &p, out, &cpu, err), OBS_OK);
            double mean, frac, cmean, cfrac, nmean, nfrac, mmean, mfrac;
            diff(&gl.ao, &cpu.ao, &mean, &frac);
            diff(&gl.composite, &cpu.composite, &cmean, &cfrac);
            diff(&gl.sample_count, &cpu.sample_count, &nmean, &nfrac);
            diff(&gl.cull_mask, &cpu.cull_mask, &mmean, &mfrac);
            double ao_mean = 0;
            for (int i = 0; i < gl.ao.width * gl.ao.height; i++)
                ao_mean += gl.ao.data[i] / (gl.ao.width * gl.ao.height);
            print_message("%s (%s %s %s): GL vs CPU AO mean |diff| %.2e, %.3f %% > 1e-3; mean AO "
                          "%.4f; counts differ at %.3f %%\n",
                          scenes[sc], variants[v][0][1], variants[v][1][0] ? variants[v][1][0] : "",
                          variants[v][1][1] ? variants[v][1][1] : "", mean, 100 * frac, ao_mean,
                          100 * nfrac);
            assert_true(mean < 1e-3);
            assert_true(frac < 0.02);
            assert_true(cmean < 1e-3);
            assert_true(nfrac < 1e-3);
            assert_true(mmean == 0.0);
            assert_true(ao_mean > 0.3 && ao_mean <= 1.0);
            obs_result_free(&gl);
            obs_result_free(&cpu);
        }
        obs_gbuffer_free(&gf);
    }
    obs_ctx_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_open_plane),
        cmocka_unit_test(test_hemisphere_corner),
        cmocka_unit_test(test_angle_valley),
        cmocka_unit_test(test_hbao_valley),
        cmocka_unit_test(test_gtao_open_plane),
        cmocka_unit_test(test_gtao_crease),
        cmocka_unit_test(test_gtao_radius_falloff),
        cmocka_unit_test(test_acos_errors),
        cmocka_unit_test(test_method_params),
        cmocka_unit_test(test_gl_matches_cpu),
    };
    return cmocka_run_group_tests_name("methods", tests, NULL, NULL);
}
