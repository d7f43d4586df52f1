/* The VAO math of the CPU twin on analytic scenes (VAO++ section 3):
 * an open plane is unoccluded, a point on the inner corner of two
 * perpendicular planes is half occluded.  These run the paper's
 * volumetric obscurance (ao_definition volume); the conversion of
 * ao_definition rays is checked in closed form and on the crease at the
 * end. */
#include <math.h>

#include "gl_testutil.h"
#include "synth_planes.h"

#include "methods/methods.h"

#define W 96
#define H 72

typedef struct scene {
    float depth[W * H];
    float normal[W * H * 3];
    obs_gbuffer gb;
} scene;

static void ortho(float P[16], float half_w, float half_h) { sp_ortho(P, half_w, half_h); }

static void perspective(float P[16], float fov_y_deg) { sp_perspective(P, fov_y_deg, W, H); }

/* Ray of pixel (x, y): origin o, direction d with d.z = -1. */
static void pixel_ray(const float P[16], int x, int y, float o[3], float d[3])
{
    float nx = (x + 0.5f) / W * 2 - 1, ny = 1 - (y + 0.5f) / H * 2;
    if (P[14] == 0.0f) { /* orthographic */
        o[0] = nx / P[0];
        o[1] = ny / P[5];
        o[2] = 0;
        d[0] = d[1] = 0;
    } else {
        o[0] = o[1] = o[2] = 0;
        d[0] = nx / P[0];
        d[1] = ny / P[5];
    }
    d[2] = -1;
}

typedef sp_plane plane;

/* A scene of planes; each pixel sees the nearest one. */
static void render(scene *s, const float P[16], const plane *pl, int count)
{
    sp_render(s->depth, s->normal, &s->gb, W, H, 0, P, pl, count);
}

static obs_params camera_normals(int samples)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN];
    obs_param_set(&p, "normal_space", "camera", err);
    /* the paper's volume fraction, R = radius (frame.h) */
    obs_param_set(&p, "ao_definition", "volume", err);
    /* the VAO estimate itself, not the low-pass filter (test_blur.c) */
    obs_param_set(&p, "blur", "off", err);
    /* every pixel with its own count, none culled (4.2: test_culling.c) */
    obs_param_set(&p, "culling", "off", err);
    p.samples = samples;
    return p;
}

static void run(const scene *s, const obs_params *p, obs_result *r)
{
    char err[OBS_ERR_LEN] = "";
    obs_status st = obs_run_cpu(&s->gb, p, OBS_OUTPUT_AO, r, err);
    if (st != OBS_OK)
        fail_msg("obs_run_cpu: %s", err);
}

/* An open plane, seen along orthographic rays (the pipes' direction):
 * the tangent sphere lies wholly in front of it, so AO is 1 up to the
 * depth buffer's discretisation: a sample reads the plane's depth at its
 * pixel's centre, up to half a pixel (in y, the plane's slope 0.6) away,
 * i.e. up to D = 0.5 * pixel * 0.6 nearer than under the sample.  Pipe i
 * ends gap_i in front of the plane (0 where the sphere touches it), so it
 * loses at most max(0, D - gap_i) of its length 2 h_i, and
 *   1 - sum_i max(0, D - gap_i) / F <= AO <= 1,  F = sum 2 h_i (eq 2),
 * per rotation of the 3x3 tile (a plane looks the same from every point,
 * so gap_i does not depend on the pixel).  The bound holds where every
 * sample lands on the image: samples off it are left out of the sum and
 * of F, so pixels within the sphere's radius of the border are only
 * checked for AO <= 1. */
static void test_open_plane_ortho(void **state)
{
    scene *s = malloc(sizeof *s);
    (void)state;
    float P[16];
    ortho(P, 2.0f, 1.5f);
    float l = sqrtf(1 + 0.36f);
    const float nrm[3] = {0, 0.6f / l, 1 / l};
    plane pl = {{nrm[0], nrm[1], nrm[2]}, -5.0f / l}; /* tilted 31 degrees about x */
    render(s, P, &pl, 1);
    const double D = 0.5 * (3.0 / H) * 0.6;
    for (int n = 2; n <= 32; n *= 2) {
        obs_params p = camera_normals(n), rp;
        obs__frame f;
        char err[OBS_ERR_LEN];
        obs_params_resolve(&p, &rp);
        assert_int_equal(obs__frame_setup(NULL, &s->gb, &rp, &f, err), OBS_OK);
        double bound[9], worst = 0;
        const double r = 0.5 * f.radius;
        for (int k = 0; k < 9; k++) {
            double loss = 0, F = 0;
            for (int i = 0; i < n; i++) {
                double qx = f.sample_xy[2 * i], qy = f.sample_xy[2 * i + 1];
                double ox = r * (f.rot[k][0] * qx - f.rot[k][1] * qy);
                double oy = r * (f.rot[k][1] * qx + f.rot[k][0] * qy);
                double h = r * sqrt(1 - qx * qx - qy * qy);
                /* P at the origin, centre c = r N; view z of the plane
                 * under c.xy + o, and of the pipe's far end */
                double zp = -(nrm[0] * (r * nrm[0] + ox) + nrm[1] * (r * nrm[1] + oy)) / nrm[2];
                double gap = (r * nrm[2] - h) - zp;
                loss += fmax(0.0, D - gap);
                F += 2 * h;
            }
            bound[k] = loss / F;
            worst = fmax(worst, bound[k]);
        }
        obs_result res;
        run(s, &p, &res);
        float mn = 1;
        const int margin = (int)ceil(r / (3.0 / H)) + 2; /* sphere radius in pixels */
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                float ao = res.ao.data[y * W + x];
                assert_true(ao <= 1.0f + 1e-5f);
                if (x < margin || y < margin || x >= W - margin || y >= H - margin)
                    continue;
                mn = fminf(mn, ao);
                assert_true(ao >= 1.0f - bound[3 * (x % 3) + (y % 3)] - 1e-5f);
            }
        print_message("open plane, ortho, %2d samples: min AO %.5f, bound %.5f\n", n, mn,
                      1 - worst);
        obs_result_free(&res);
    }
    free(s);
}

/* A plane facing a perspective camera: every pipe ends in front of it. */
static void test_open_plane_frontal(void **state)
{
    scene *s = malloc(sizeof *s);
    (void)state;
    float P[16];
    perspective(P, 60.0f);
    plane pl = {{0, 0, 1}, -5.0f};
    render(s, P, &pl, 1);
    obs_params p = camera_normals(16);
    obs_result r;
    run(s, &p, &r);
    for (int i = 0; i < W * H; i++)
        assert_float_equal(r.ao.data[i], 1.0f, 1e-6f);
    obs_result_free(&r);
    free(s);
}

/* A tilted plane under perspective: the pipes run along view Z while the
 * depth is looked up along the camera ray through each sample, so a pipe
 * can end slightly behind the plane.  VAO accepts this error; it stays
 * small for moderate tilts (measured here: mean > 0.99, min > 0.95). */
static void test_open_plane_tilted_perspective(void **state)
{
    scene *s = malloc(sizeof *s);
    (void)state;
    float P[16];
    perspective(P, 50.0f);
    float l = sqrtf(1 + 0.25f);
    plane pl = {{0, 0.5f / l, 1 / l}, -6.0f / l};
    render(s, P, &pl, 1);
    obs_params p = camera_normals(16);
    obs_result r;
    run(s, &p, &r);
    double sum = 0;
    float mn = 1;
    for (int i = 0; i < W * H; i++) {
        sum += r.ao.data[i];
        mn = fminf(mn, r.ao.data[i]);
    }
    print_message("tilted plane, perspective: mean AO %.5f, min %.5f\n", sum / (W * H), mn);
    assert_true(sum / (W * H) > 0.99);
    assert_true(mn > 0.95f);
    obs_result_free(&r);
    free(s);
}

/* A floor seen at a grazing angle (n.z = 1/sqrt 5, depths 3 to 88) with
 * a tangent sphere smaller than a pixel (radius 0.002; a pixel is 0.04
 * wide at depth 3): every sample lands on the shaded pixel itself, which
 * reads its own tangent plane under the pipe.  With the depth at the
 * pixel's centre, p's depth, instead, a pipe of half length h = r l
 * through c = p + r n would be open for only n.z r + h of its 2 h, an
 * occluder made of the surface itself.  Both definitions, rays after its
 * conversion. */
static void test_open_plane_subpixel(void **state)
{
    scene *s = malloc(sizeof *s);
    (void)state;
    float P[16];
    perspective(P, 50.0f);
    float l = sqrtf(5.0f);
    plane pl = {{0, 2.0f / l, 1 / l}, -6.0f / l};
    render(s, P, &pl, 1);
    for (int v = 0; v < 2; v++) {
        char err[OBS_ERR_LEN];
        obs_params p = camera_normals(16);
        p.radius = 0.002f;
        obs_param_set(&p, "ao_definition", v ? "rays" : "volume", err);
        obs_result r;
        run(s, &p, &r);
        float mn = 1;
        for (int i = 0; i < W * H; i++)
            mn = fminf(mn, r.ao.data[i]);
        print_message("grazing floor, sphere under a pixel, %s: min AO %.6f\n", v ? "rays" : "volume",
                      mn);
        assert_true(mn > 0.999f);
        obs_result_free(&r);
    }
    free(s);
}

/* The same on real input: room_small (320x240) with a radius of 1 cm, a
 * sphere of about a pixel; nothing there is that close to an occluder but
 * at the creases, so the image is nearly open (mean 0.87 with the depth at
 * the pixel's centre). */
static void test_small_radius_room(void **state)
{
    (void)state;
    obs_gbuffer_file gf = {0};
    char err[OBS_ERR_LEN] = "";
    load(scenes[0], &gf); /* room_small */
    obs_params p = {0};
    p.radius = 0.01f;
    obs_result r;
    assert_int_equal(obs_run_cpu(&gf.gb, &p, OBS_OUTPUT_AO, &r, err), OBS_OK);
    double sum = 0;
    long n = 0;
    for (int i = 0; i < gf.gb.width * gf.gb.height; i++) {
        float d = gf.gb.depth.data[i];
        if (d > 0.0f && d < OBS_BACKGROUND_DEPTH) {
            sum += r.ao.data[i];
            n++;
        }
    }
    print_message("room_small at radius 0.01: mean AO %.4f over %ld px\n", sum / n, n);
    assert_true(sum / n > 0.99);
    obs_result_free(&r);
    obs_gbuffer_free(&gf);
}

/* The inner corner: P on the floor (normal +Y) where it meets a wall
 * (normal +Z, facing an orthographic camera).  The tangent sphere's centre
 * P + R/2 N lies in the wall's plane, so every pipe, spanning depths
 * [dc - h_i, dc + h_i] with dc the wall's depth, is cut in half:
 *   V = sum h_i / sum 2 h_i = 1/2 exactly, for any sample set and rotation.
 * Moving P a distance e off the wall towards the camera adds e to each
 * open length while e < h_i: V = 1/2 + n e / F with F of eq 2. */
static void test_inner_corner(void **state)
{
    scene *s = malloc(sizeof *s);
    (void)state;
    float P[16];
    ortho(P, 2.0f, 1.5f);
    plane wall = {{0, 0, 1}, -5.0f};
    render(s, P, &wall, 1);

    for (int n = 2; n <= 32; n *= 2) { /* the sets of section 4.5 */
        obs_params p = camera_normals(n);
        obs_params rp;
        obs__frame f;
        char err[OBS_ERR_LEN];
        obs_params_resolve(&p, &rp);
        assert_int_equal(obs__frame_setup(NULL, &s->gb, &rp, &f, err), OBS_OK);
        float *pos = malloc(sizeof(float) * 4 * W * H);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                obs__prep_position(&f, s->depth[y * W + x], x, y, pos + 4 * (y * W + x));

        const float floor_n[3] = {0, 1, 0};
        const float R = f.radius;
        double F = 0, hmin = 1e9;
        for (int i = 0; i < n; i++) {
            float sx = f.sample_xy[2 * i], sy = f.sample_xy[2 * i + 1];
            float l = sqrtf(1 - sx * sx - sy * sy);
            F += R * l;                      /* eq 2 */
            hmin = fmin(hmin, 0.5 * R * l);
        }
        const float e = (float)(0.5 * hmin); /* the closed form needs e < every h_i */
        for (int k = 0; k < 9; k++) { /* every rotation of the 3x3 tile */
            int x = W / 2 + k / 3, y = H / 2 + k % 3;
            const float corner[3] = {0.0f, -0.5f, -5.0f};
            assert_float_equal(obs__vao_pixel(&f, pos, s->normal, x, y, corner, floor_n, NULL),
                               0.5f, 1e-5f);
            const float near[3] = {0.0f, -0.5f, -5.0f + e};
            assert_float_equal(obs__vao_pixel(&f, pos, s->normal, x, y, near, floor_n, NULL),
                               (float)(0.5 + n * e / F), 1e-5f);
        }
        free(pos);
    }
    free(s);
}

/* The same corner as a perspective G-buffer: floor pixels next to the wall
 * are about half occluded, pixels farther than R from it are open up to
 * the tilted-plane error measured above (mean > 0.99, each > 0.95).  The
 * corner pixels in the image's first and last columns, whose disks are
 * half off the image, are as occluded as the others: samples off the image
 * are left out, not counted as open (which would give them about 3/4). */
static void test_corner_scene(void **state)
{
    scene *s = malloc(sizeof *s);
    (void)state;
    float P[16];
    perspective(P, 60.0f);
    /* floor y = -1; the wall's depth is chosen so that the centre of pixel
     * row 52 sees the floor exactly where it meets the wall */
    float wall_depth = P[5] / ((52 + 0.5f) / H * 2 - 1);
    plane pl[2] = {{{0, 1, 0}, -1.0f}, {{0, 0, 1}, -wall_depth}};
    render(s, P, pl, 2);
    obs_params p = camera_normals(32);
    p.radius = 0.5f;
    obs_result r;
    run(s, &p, &r);
    int near_n = 0, far_n = 0, edge_n = 0;
    double near_sum = 0, far_sum = 0, edge_sum = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float o[3], d[3];
            pixel_ray(P, x, y, o, d);
            float depth = s->depth[y * W + x];
            float py = depth * d[1], pz = -depth;
            float ao = r.ao.data[y * W + x];
            int on_floor = s->normal[3 * (y * W + x) + 1] > 0.5f;
            float dist = on_floor ? pz + wall_depth : py + 1.0f; /* distance to the other plane */
            if (on_floor && dist < 1e-3f) {
                near_sum += ao;
                near_n++;
                if (x < 2 || x >= W - 2) {
                    edge_sum += ao;
                    edge_n++;
                }
            }
            if (dist > 0.6f && x > 2 && x < W - 3 && y > 2 && y < H - 3) {
                assert_true(ao > 0.95f);
                far_sum += ao;
                far_n++;
            }
        }
    assert_true(near_n > 0 && far_n > 100);
    assert_true(far_sum / far_n > 0.99);
    print_message("perspective corner: %d floor pixels on the corner line, mean AO %.4f\n", near_n,
                  near_sum / near_n);
    assert_true(near_sum / near_n > 0.47 && near_sum / near_n < 0.55);
    print_message("perspective corner: %d of them in the first/last two columns, mean AO %.4f\n",
                  edge_n, edge_sum / edge_n);
    assert_true(edge_n > 0);
    assert_true(fabs(edge_sum / edge_n - near_sum / near_n) < 0.05);
    obs_result_free(&r);
    free(s);
}

/* Depth range check (section 4.4, eq 4), in closed form: P on a plane
 * facing an orthographic camera, with a surface D in front of it covering
 * every sample (a foreground object).  Each pipe i spans depths
 * [dc - h_i, dc + h_i] around the sphere centre dc = z_P - R/2, so it lies
 * d_i = D - R/2 - h_i behind the surface (case C).  Without the check every
 * pipe is closed: V = 0.  With it, pipe i is occluded by s(d_i) of its
 * length: V = sum 2 h_i (1 - s(d_i)) / F, s(d) = u / max(u, d / R).
 * Passes 3 and 4 give the occluder's normal plane a tilt of 60 degrees
 * (n.z = 1/2; the depths stay those of the plane facing the camera):
 * range_distance normal measures d along that normal, d_i / 2, and view
 * along view Z, d_i, which the normal plane does not change. */
static void test_range_check_closed_form(void **state)
{
    scene *s = malloc(sizeof *s);
    (void)state;
    float P[16];
    ortho(P, 2.0f, 1.5f);
    plane front = {{0, 0, 1}, -4.0f}; /* the occluder, at depth 4 */
    render(s, P, &front, 1);
    const float n_cam[3] = {0, 0, 1};
    float *tilted = malloc(sizeof(float) * 3 * W * H);
    for (int i = 0; i < W * H; i++) {
        tilted[3 * i] = 0.0f;
        tilted[3 * i + 1] = sqrtf(3.0f) / 2.0f;
        tilted[3 * i + 2] = 0.5f;
    }

    for (int pass = 0; pass < 5; pass++) {
        obs_params p = camera_normals(16), rp;
        char err[OBS_ERR_LEN];
        /* R = 0.5 (the occluder depths below are chosen for it): radius is
         * the AO distance D, and the volume definition's R = D (frame.h) */
        p.radius = 0.5f;
        if (pass == 1)
            obs_param_set(&p, "range_check", "off", err);
        if (pass == 2)
            p.range_u = 0.2f;
        if (pass == 4)
            obs_param_set(&p, "range_distance", "view", err);
        const float *nrm = pass >= 3 ? tilted : s->normal;
        float along = pass == 3 ? 0.5f : 1.0f; /* |n.z| when d is taken along the normal */
        obs__frame f;
        obs_params_resolve(&p, &rp);
        assert_int_equal(obs__frame_setup(NULL, &s->gb, &rp, &f, err), OBS_OK);
        float *pos = malloc(sizeof(float) * 4 * W * H);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                obs__prep_position(&f, s->depth[y * W + x], x, y, pos + 4 * (y * W + x));
        const float R = f.radius, u = f.range_u;
        for (int k = 0; k < 4; k++) {
            float D = 0.51f + 0.3f * k; /* > R/2 + max h = R: every pipe is behind */
            double open = 0, F = 0;
            for (int i = 0; i < f.samples; i++) {
                float sx = f.sample_xy[2 * i], sy = f.sample_xy[2 * i + 1];
                float l = sqrtf(1 - sx * sx - sy * sy), h = 0.5f * R * l;
                float d = (D - 0.5f * R - h) * along;
                F += R * l; /* eq 2 */
                float sd = u / fmaxf(u, d / R); /* eq 4 */
                open += f.range_check ? 2 * h * (1 - sd) : 0.0;
            }
            const float pt[3] = {0.0f, 0.0f, -4.0f - D};
            float v = obs__vao_pixel(&f, pos, nrm, W / 2, H / 2, pt, n_cam, NULL);
            assert_float_equal(v, (float)(open / F), 1e-5f);
            if (pass == 1)
                assert_float_equal(v, 0.0f, 0.0f);
            else
                assert_true(v > 0.0f);
        }
        free(pos);
    }
    free(tilted);
    free(s);
}

/* The crease profiles of frame.h, written out here: a wall at distance
 * x = b D from p on the floor fills vol(b) of the tangent sphere of
 * radius D and blocks ray(b) of the cosine-weighted rays of length D. */
static double crease_vol(double b) { return b >= 1 ? 0 : (1 - b) * (1 - b) * (2 + b) / 4; }
static double crease_ray(double b) { return b >= 1 ? 0 : (acos(b) - b * sqrt(1 - b * b)) / M_PI; }

/* ao_definition rays in closed form: the volume AO of a crease at b
 * becomes the ray AO of the same crease (values of bench/QUALITY.md's
 * crease table: 0.436 at b = 0.1, 0.343 at 0.25, 0.196 at 0.5, 0.072 at
 * 0.75 blocked); open stays open, the corner stays 1/2, an occlusion over
 * 1/2 is unchanged, and the map is monotone. */
static void test_rays_closed_form(void **state)
{
    (void)state;
    static const double table[][2] = {{0.1, 0.436}, {0.25, 0.343}, {0.5, 0.196}, {0.75, 0.072}};
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++) {
        double b = table[i][0];
        assert_float_equal(crease_ray(b), table[i][1], 5e-4);
        float ao = obs__rays_from_volume((float)(1 - crease_vol(b)));
        assert_float_equal(ao, 1 - table[i][1], 1e-3);
        assert_float_equal(ao, 1 - crease_ray(b), 2e-5);
    }
    for (double b = 0; b <= 1.0; b += 1.0 / 64)
        assert_float_equal(obs__rays_from_volume((float)(1 - crease_vol(b))), 1 - crease_ray(b),
                           5e-5);
    assert_float_equal(obs__rays_from_volume(1.0f), 1.0f, 1e-6f);
    assert_float_equal(obs__rays_from_volume(0.5f), 0.5f, 1e-6f);
    assert_float_equal(obs__rays_from_volume(0.3f), 0.3f, 0.0f);
    assert_float_equal(obs__rays_from_volume(0.0f), 0.0f, 0.0f);
    float last = -1.0f;
    for (int i = 0; i <= 1000; i++) {
        float ao = obs__rays_from_volume((float)i / 1000.0f);
        assert_true(ao >= last && ao <= (float)i / 1000.0f + 1e-6f); /* never lighter */
        last = ao;
    }
}

/* ao_definition rays through obs_run_cpu on the scenes above: an open
 * plane facing the camera stays exactly open, and the floor in front of a
 * wall follows the ray tracer's crease profile 1 - ray(x / D) (R = 2 D)
 * where the paper's volume (R = D) follows 1 - vol(x / (D / 2)), zero from
 * x = D / 2 on although the rays reach the wall up to x = D. */
static void test_rays_crease(void **state)
{
    scene *s = malloc(sizeof *s);
    (void)state;
    float P[16];
    char err[OBS_ERR_LEN];
    perspective(P, 60.0f);
    plane facing = {{0, 0, 1}, -5.0f};
    render(s, P, &facing, 1);
    obs_params p = camera_normals(16);
    obs_param_set(&p, "ao_definition", "rays", err);
    obs_result r;
    run(s, &p, &r);
    for (int i = 0; i < W * H; i++)
        assert_float_equal(r.ao.data[i], 1.0f, 1e-6f);
    obs_result_free(&r);

    /* the corner of test_corner_scene, D = 0.5 */
    float wall_depth = P[5] / ((52 + 0.5f) / H * 2 - 1);
    plane pl[2] = {{{0, 1, 0}, -1.0f}, {{0, 0, 1}, -wall_depth}};
    render(s, P, pl, 2);
    const double D = 0.5;
    double dev[2] = {0, 0}, at_reach[2] = {0, 0};
    int n = 0, n_reach = 0;
    for (int v = 0; v < 2; v++) {
        obs_params q = camera_normals(32);
        q.radius = (float)D;
        obs_param_set(&q, "ao_definition", v ? "volume" : "rays", err);
        run(s, &q, &r);
        n = n_reach = 0;
        for (int y = 0; y < H; y++)
            for (int x = 3; x < W - 3; x++) {
                float o[3], d[3];
                pixel_ray(P, x, y, o, d);
                if (s->normal[3 * (y * W + x) + 1] < 0.5f)
                    continue; /* the wall */
                double dist = wall_depth - s->depth[y * W + x]; /* floor to wall */
                if (dist > D)
                    continue;
                double e = r.ao.data[y * W + x] - (1 - crease_ray(dist / D));
                dev[v] += fabs(e);
                n++;
                if (dist > 0.5 * D) { /* beyond the volume sphere's reach */
                    at_reach[v] += r.ao.data[y * W + x];
                    n_reach++;
                }
            }
        dev[v] /= n;
        at_reach[v] /= n_reach;
        obs_result_free(&r);
    }
    print_message("crease, %d floor px within D of the wall: mean |AO - (1 - ray(x/D))| rays "
                  "%.4f, volume %.4f; mean AO from D/2 to D (%d px): rays %.4f, volume %.4f\n",
                  n, dev[0], dev[1], n_reach, at_reach[0], at_reach[1]);
    assert_true(n > 100 && n_reach > 20);
    assert_true(dev[0] < 0.03);
    assert_true(dev[0] < dev[1] / 3);
    assert_true(at_reach[1] > 0.99 && at_reach[0] < 0.97);
    free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_open_plane_ortho),
        cmocka_unit_test(test_open_plane_frontal),
        cmocka_unit_test(test_open_plane_tilted_perspective),
        cmocka_unit_test(test_open_plane_subpixel),
        cmocka_unit_test(test_small_radius_room),
        cmocka_unit_test(test_inner_corner),
        cmocka_unit_test(test_corner_scene),
        cmocka_unit_test(test_range_check_closed_form),
        cmocka_unit_test(test_rays_closed_form),
        cmocka_unit_test(test_rays_crease),
    };
    return cmocka_run_group_tests_name("vao_math", tests, NULL, NULL);
}
