/* The baked channels with a dynamic object (core/ground/raster_dynamic.c):
 * a floor with baked vertex values and a cube marked dynamic, under a
 * region model written here in closed form.  The cube's pixels are the
 * model's closed form at their position and normal, the floor's the
 * baked values rasterised without the model; the level check. */
#include <math.h>

#include "testutil.h"

#include "obscura/io.h"
#include "obscura/scene.h"

#define W 96
#define H 72
#define Y0 0.28209479177387814
#define Y1 0.4886025119029199

static obs_ctx *ctx;

static int setup(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    if (obs_ctx_create(NULL, &ctx, err) != OBS_OK) {
        fprintf(stderr, "no GL context: %s\n", err);
        return -1;
    }
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    obs_ctx_destroy(ctx);
    return 0;
}

/* The floor z = 0 (4 x 4 m, 2 triangles, baked values varying over it)
 * then a cube of side 0.8 standing on it at the origin (12 triangles,
 * 4 vertices a face), mesh 1, dynamic. */
static void scene(obs_scene *s)
{
    memset(s, 0, sizeof *s);
    s->vertex_count = 4 + 24;
    s->triangle_count = 2 + 12;
    s->positions = calloc(3 * s->vertex_count, sizeof(float));
    s->normals = calloc(3 * s->vertex_count, sizeof(float));
    s->baked = calloc(3 * s->vertex_count, sizeof(float));
    s->indices = calloc(3 * s->triangle_count, sizeof(uint32_t));
    s->meshes = calloc(2, sizeof *s->meshes);
    assert_non_null(s->meshes);
    const float fl[4][2] = {{-2, -2}, {2, -2}, {2, 2}, {-2, 2}};
    for (int v = 0; v < 4; v++) {
        float *p = s->positions + 3 * v, *n = s->normals + 3 * v, *b = s->baked + 3 * v;
        p[0] = fl[v][0], p[1] = fl[v][1];
        n[2] = 1.0f;
        b[0] = 0.3f + 0.1f * (float)v, b[1] = 0.2f, b[2] = 0.9f - 0.1f * (float)v;
    }
    const uint32_t ft[6] = {0, 1, 2, 0, 2, 3};
    memcpy(s->indices, ft, sizeof ft);
    /* the cube: per face normal n and two axes u, v with u x v = n */
    const int faces[6][3][3] = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},  {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
                                {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
                                {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
    const float su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1}, h = 0.4f;
    for (int f = 0; f < 6; f++) {
        uint32_t base = 4 + 4 * (uint32_t)f;
        for (int k = 0; k < 4; k++)
            for (int a = 0; a < 3; a++) {
                s->positions[3 * (base + k) + a] =
                    h * ((float)faces[f][0][a] + su[k] * (float)faces[f][1][a] +
                         sv[k] * (float)faces[f][2][a]) + (a == 2 ? h : 0.0f);
                s->normals[3 * (base + k) + a] = (float)faces[f][0][a];
                s->baked[3 * (base + k) + a] = 1.0f;
            }
        const uint32_t t[6] = {base, base + 1, base + 2, base, base + 2, base + 3};
        memcpy(s->indices + 6 + 6 * f, t, sizeof t);
    }
    s->mesh_count = 2;
    s->meshes[0] = (obs_scene_mesh){strdup("floor"), strdup("floor"), 0, 2, 0};
    s->meshes[1] = (obs_scene_mesh){strdup("cube"), strdup("car"), 2, 12, 1};
    s->baked_mask = 7;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_scene_check(s, err), OBS_OK);
}

/* One region over the floor: short = 0.6 + 0.2 x (x >= 0) or 0.6 + 0.1 x
 * (x < 0), long = 0.7 + 0.2 n_z, blend 0.25; its level, the floor. */
static void model(obs_dyn_model *m)
{
    memset(m, 0, sizeof *m);
    m->region_count = m->model_count = 1;
    m->regions = calloc(1, sizeof *m->regions);
    m->models = calloc(1, sizeof *m->models);
    m->edge = calloc(1, sizeof *m->edge);
    assert_non_null(m->models);
    m->regions[0] = (obs_dyn_model_region){{{-2, -2, 0}, {2, 2, 2}}, 0, 0, 100};
    obs_dyn_fit *f = &m->models[0];
    f->coef[0][0] = (float)(0.6 / Y0);
    f->coef[0][1] = (float)(0.2 / Y0); /* +x */
    f->coef[0][2] = (float)(0.1 / Y0); /* -x */
    f->coef[OBS_DYN_SH][0] = (float)(0.7 / Y0);
    f->coef[OBS_DYN_SH + 2][0] = (float)(0.2 / Y1); /* Y_1,0 = Y1 z */
    m->distance[0] = 2.0f, m->distance[1] = 300.0f;
    m->blend = 0.25f;
    m->level = (obs_dyn_level){.fingerprint = 1, .triangles = 2, .lo = {-2, -2, 0}, .hi = {2, 2, 0}};
}

/* Looking down at the origin from (0.9, -1.2, 3): the floor, the cube's
 * top and two of its sides. */
static void camera(obs_camera *cam)
{
    const float eye[3] = {0.9f, -1.2f, 3.0f};
    float f[3] = {-eye[0], -eye[1], 0.4f - eye[2]}, up[3] = {0, 0, 1}, sd[3], u[3];
    float lf = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; k++)
        f[k] /= lf;
    for (int k = 0; k < 3; k++)
        sd[k] = f[(k + 1) % 3] * up[(k + 2) % 3] - f[(k + 2) % 3] * up[(k + 1) % 3];
    float ls = sqrtf(sd[0] * sd[0] + sd[1] * sd[1] + sd[2] * sd[2]);
    for (int k = 0; k < 3; k++)
        sd[k] /= ls;
    for (int k = 0; k < 3; k++)
        u[k] = sd[(k + 1) % 3] * f[(k + 2) % 3] - sd[(k + 2) % 3] * f[(k + 1) % 3];
    obs_camera_from_fov(50.0f, (float)W / H, 0.1f, 100.0f, cam);
    float *m = cam->world_to_camera;
    memset(m, 0, 16 * sizeof *m);
    for (int k = 0; k < 3; k++) {
        m[k] = sd[k], m[4 + k] = u[k], m[8 + k] = -f[k];
        m[3] -= sd[k] * eye[k], m[7] -= u[k] * eye[k], m[11] += f[k] * eye[k];
    }
    m[15] = 1.0f;
    cam->has_world_to_camera = 1;
}

static void test_cube_from_model(void **state)
{
    (void)state;
    obs_scene s;
    obs_dyn_model m;
    obs_camera cam;
    scene(&s);
    model(&m);
    camera(&cam);
    char err[OBS_ERR_LEN] = "";
    obs_raster g;
    obs_image dyn, plain;
    size_t npx = 0;
    assert_int_equal(obs_raster_gbuffer(ctx, &s, &cam, W, H, &g, err), OBS_OK);
    assert_int_equal(obs_raster_baked_dynamic(ctx, &s, &cam, W, H, &g, &m, 1, &dyn, &npx, err),
                     OBS_OK);
    assert_int_equal(obs_raster_baked(ctx, &s, &cam, W, H, &plain, err), OBS_OK);
    size_t cube = 0, floor = 0, top = 0, side = 0;
    double worst = 0.0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        const float *p = g.position.data + 3 * i, *n = g.normal.data + 3 * i, *o = dyn.data + 3 * i;
        if (!(g.color.data[4 * i + 3] > 0.0f)) {
            assert_true(o[0] == 1.0f && o[1] == 1.0f && o[2] == 1.0f);
            continue;
        }
        if (p[2] < 1e-4f) { /* the floor: its baked values, unchanged */
            assert_memory_equal(o, plain.data + 3 * i, 3 * sizeof *o);
            floor++;
            continue;
        }
        double sh = 0.6 + (p[0] >= 0 ? 0.2 : 0.1) * p[0], lg = 0.7 + 0.2 * n[2];
        double want[3] = {0.25 * sh + 0.75 * lg, sh, lg};
        for (int k = 0; k < 3; k++)
            worst = fmax(worst, fabs(o[k] - want[k]));
        cube++;
        top += n[2] > 0.99f;
        side += fabsf(n[2]) < 0.01f;
    }
    print_message("cube: %zu pixels (%zu top, %zu sides), worst |baked - closed form| %.2e; "
                  "floor %zu pixels unchanged\n", cube, top, side, worst, floor);
    assert_int_equal(npx, cube);
    assert_true(top > 100 && side > 100 && floor > 1000);
    assert_true(worst < 1e-5);
    /* the level check: the floor is the model's level; the cube is not */
    assert_int_equal(obs_scene_check_dynamic_level(&s, &m, err), OBS_OK);
    s.meshes[1].dynamic = 0;
    assert_int_equal(obs_scene_check_dynamic_level(&s, &m, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "another level (2 triangles"));
    assert_non_null(strstr(err, "static nodes have 14 triangles"));
    s.meshes[1].dynamic = 1;
    m.level.hi[0] = 2.5f; /* the same count, another box */
    assert_int_equal(obs_scene_check_dynamic_level(&s, &m, err), OBS_INVALID_ARGUMENT);
    m.level.hi[0] = 2.0f + 1e-6f; /* rounding apart: the same level */
    assert_int_equal(obs_scene_check_dynamic_level(&s, &m, err), OBS_OK);
    /* a G-buffer of another size */
    obs_image bad;
    assert_int_equal(obs_raster_baked_dynamic(ctx, &s, &cam, W + 1, H, &g, &m, 1, &bad, NULL, err),
                     OBS_INVALID_ARGUMENT);
    obs_image_free(&dyn);
    obs_image_free(&plain);
    obs_raster_free(&g);
    obs_dyn_model_free(&m);
    obs_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cube_from_model),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
