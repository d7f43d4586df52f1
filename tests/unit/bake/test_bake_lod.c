/* LODs of the bake (core/bake/lod.c, simplify.c, closest.c, lod_file.c;
 * paper 2.2.1): the simplifier, the nearest point, the resampling, the fit
 * onto the LOD's vertices, the whole stage through obs_bake_run, a file's
 * own LODs, bad parameters. */
#include <stdio.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "level/bake_testutil.h"
#include "bake/closest.h"
#include "bake/lod.h"
#include "bake/simplify.h"

static const float O[3] = {-3, 0.5f, -2}, U[3] = {0, 0.8f, 5}, V[3] = {6, 0.3f, 0};

/* The test's two linear signals, short and long. */
static double lin(const float p[3], int ch)
{
    return ch == 0 ? 0.2 + 0.05 * p[0] + 0.03 * p[2] : 0.9 - 0.02 * p[0] + 0.01 * p[1];
}

/* m's triangles as soup: three vertices of their own each. */
static void explode(obs_bake_mesh *m)
{
    size_t n = 3 * m->triangle_count;
    float *p = malloc(3 * n * sizeof *p), *q = malloc(3 * n * sizeof *q);
    assert_non_null(p);
    assert_non_null(q);
    for (size_t i = 0; i < n; i++) {
        memcpy(p + 3 * i, m->positions + 3 * (size_t)m->indices[i], 3 * sizeof *p);
        memcpy(q + 3 * i, m->normals + 3 * (size_t)m->indices[i], 3 * sizeof *q);
        m->indices[i] = (uint32_t)i;
    }
    free(m->positions);
    free(m->normals);
    m->positions = p;
    m->normals = q;
    m->vertex_count = n;
}

/* A flat plane collapses to its two corner triangles; a level keeps the
 * material, names itself _LOD<l> and uses only the mesh's own positions
 * (on the plane); soup welds first, so it simplifies as the indexed mesh
 * does (meshopt_simplify alone could not merge the soup's corners). */
static void test_simplify_plane(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bake_mesh m, soup, l1, l2, ls;
    bt_grid(&m, "plane", O, U, V, 16, 16);
    bt_grid(&soup, "soup", O, U, V, 16, 16);
    explode(&soup);
    m.material = soup.material = 3;
    assert_int_equal(obs__bake_simplify(&m, 1, 0.5f, 0.01f, 0, 1e-5f, 120.0f, &l1, err), OBS_OK);
    assert_string_equal(l1.name, "plane_LOD1");
    assert_int_equal(l1.material, 3);
    assert_true(l1.triangle_count > 0 && l1.triangle_count < m.triangle_count);
    assert_true(l1.triangle_count <= m.triangle_count / 2);
    assert_non_null(l1.normals);
    /* every LOD vertex is a vertex of the mesh */
    for (size_t v = 0; v < l1.vertex_count; v++) {
        int found = 0;
        for (size_t w = 0; w < m.vertex_count && !found; w++)
            found = !memcmp(l1.positions + 3 * v, m.positions + 3 * w, 3 * sizeof(float));
        assert_true(found);
    }
    for (size_t i = 0; i < 3 * l1.triangle_count; i++)
        assert_true(l1.indices[i] < l1.vertex_count);
    assert_int_equal(obs__bake_simplify(&m, 2, 0.01f, 0.01f, 0, 1e-5f, 120.0f, &l2, err), OBS_OK);
    print_message("plane of %zu triangles: LOD1 %zu, ratio 0.01 -> %zu\n", m.triangle_count,
                  l1.triangle_count, l2.triangle_count);
    assert_int_equal(l2.triangle_count, 2);
    assert_int_equal(l2.vertex_count, 4);
    assert_int_equal(obs__bake_simplify(&soup, 2, 0.01f, 0.01f, 0, 1e-5f, 120.0f, &ls, err),
                     OBS_OK);
    assert_int_equal(ls.triangle_count, 2);
    obs__bake_mesh_free(&l1);
    obs__bake_mesh_free(&l2);
    obs__bake_mesh_free(&ls);
    obs__bake_mesh_free(&m);
    obs__bake_mesh_free(&soup);
}

/* A mesh whose faces are all far smaller than the weld's tolerance (a
 * fraction of its box): a small quad beside slivers 2e7 long and 1e-6
 * wide.  The weld collapses every triangle; the level was left empty, and
 * a level of such meshes alone failed the bake's --lods ("no triangles
 * under the scene's nodes") where the plain bake takes it.  The mesh is
 * kept whole; a mesh without area (slivers alone) stays empty. */
static void test_simplify_all_collapsed(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    float pos[] = {-1e7f, 0, 0, 1e7f, 0, 0, 1e7f, 1e-6f, 0,       /* a sliver */
                   -1e7f, 1, 0, 1e7f, 1, 0, 1e7f, 1 + 1e-6f, 0,   /* another */
                   0, 0.5f, 0, 0.6f, 0.5f, 0, 0.6f, 0.5f, 0.5f, 0, 0.5f, 0.5f}; /* a quad */
    uint32_t idx[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 6, 8, 9};
    obs_bake_mesh m = {.name = "slivers", .vertex_count = 10, .triangle_count = 4,
                       .positions = pos, .indices = idx, .material = -1};
    obs_bake_mesh l1;
    assert_int_equal(obs__bake_simplify(&m, 1, 0.5f, 0.02f, 0, 1e-5f, 120.0f, &l1, err), OBS_OK);
    assert_int_equal(l1.triangle_count, 4);
    assert_memory_equal(l1.indices, idx, sizeof idx);
    assert_memory_equal(l1.positions, pos, sizeof pos);
    obs__bake_mesh_free(&l1);
    m.triangle_count = 2; /* the slivers alone: no area */
    assert_int_equal(obs__bake_simplify(&m, 1, 0.5f, 0.02f, 0, 1e-5f, 120.0f, &l1, err), OBS_OK);
    assert_int_equal(l1.triangle_count, 0);
    obs__bake_mesh_free(&l1);
}

/* A curved height field: with the error bound 0 the simplifier may only
 * take collapses that move nothing, so it stays near the full count;
 * with a loose bound it reaches its ratio.  Never empty either way. */
static void test_simplify_error_bound(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bake_mesh m, tight, loose;
    const float o[3] = {0, 0, 0}, u[3] = {4, 0, 0}, v[3] = {0, 0, 4};
    bt_grid(&m, "bumps", o, u, v, 20, 20);
    for (size_t k = 0; k < m.vertex_count; k++) {
        float *p = m.positions + 3 * k;
        p[1] = 0.4f * sinf(1.7f * p[0]) * cosf(1.3f * p[2]);
    }
    assert_int_equal(obs__bake_simplify(&m, 1, 0.25f, 0.0f, 0, 1e-5f, 180.0f, &tight, err),
                     OBS_OK);
    assert_int_equal(obs__bake_simplify(&m, 1, 0.25f, 0.5f, 0, 1e-5f, 180.0f, &loose, err),
                     OBS_OK);
    print_message("bumps of %zu triangles, ratio 0.25: error 0 -> %zu, error 0.5 -> %zu\n",
                  m.triangle_count, tight.triangle_count, loose.triangle_count);
    assert_true(loose.triangle_count > 0);
    assert_true(loose.triangle_count <= m.triangle_count / 4 + 2);
    assert_true(tight.triangle_count > m.triangle_count / 2);
    obs__bake_mesh_free(&tight);
    obs__bake_mesh_free(&loose);
    obs__bake_mesh_free(&m);
}

/* The vertices of mesh m with x == at (the shared edge below), as
 * their z, sorted; returns the count. */
static size_t edge_z(const obs_bake_mesh *m, float at, float *z)
{
    size_t n = 0;
    for (size_t v = 0; v < m->vertex_count; v++)
        if (m->positions[3 * v] == at) {
            size_t k = n++;
            while (k > 0 && z[k - 1] > m->positions[3 * v + 2]) {
                z[k] = z[k - 1];
                k--;
            }
            z[k] = m->positions[3 * v + 2];
        }
    return n;
}

/* Two bumpy tiles meeting along x = 4 (17 shared vertices; 16 x 16 and
 * 8 x 16 quads, so their interiors simplify differently), each
 * simplified alone as the bake does.  Border locked (lod_lock_border 1,
 * the default): each level keeps all 17 edge vertices, the two sides
 * meet vertex for vertex.  Unlocked: the tiles drop edge vertices, and
 * not the same ones, so the level has T-junctions (cracks) there; the
 * locked level keeps more triangles. */
static void test_simplify_lock_border(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    const float oa[3] = {0, 0, 0}, ob[3] = {4, 0, 0}, u[3] = {4, 0, 0}, v[3] = {0, 0, 4};
    obs_bake_mesh t[2], lk[2], fr[2];
    bt_grid(&t[0], "tile_a", oa, u, v, 16, 16);
    bt_grid(&t[1], "tile_b", ob, u, v, 8, 16);
    for (int i = 0; i < 2; i++)
        for (size_t k = 0; k < t[i].vertex_count; k++) {
            float *p = t[i].positions + 3 * k;
            p[1] = 0.3f * sinf(1.7f * p[0]) * cosf(1.3f * p[2]);
        }
    float za[64], zb[64];
    assert_int_equal(edge_z(&t[0], 4.0f, za), 17);
    assert_int_equal(edge_z(&t[1], 4.0f, zb), 17);
    for (int i = 0; i < 2; i++) {
        assert_int_equal(obs__bake_simplify(&t[i], 1, 0.05f, 0.5f, 1, 1e-5f, 180.0f, &lk[i], err),
                         OBS_OK);
        assert_int_equal(obs__bake_simplify(&t[i], 1, 0.05f, 0.5f, 0, 1e-5f, 180.0f, &fr[i], err),
                         OBS_OK);
        assert_true(lk[i].triangle_count < t[i].triangle_count);
        assert_true(fr[i].triangle_count < lk[i].triangle_count);
    }
    size_t la = edge_z(&lk[0], 4.0f, za), lb = edge_z(&lk[1], 4.0f, zb);
    assert_int_equal(la, 17);
    assert_int_equal(lb, 17);
    assert_memory_equal(za, zb, 17 * sizeof(float));
    size_t fa = edge_z(&fr[0], 4.0f, za), fb = edge_z(&fr[1], 4.0f, zb);
    print_message("tiles of %zu + %zu triangles, ratio 0.05: locked %zu + %zu (edge vertices "
                  "%zu / %zu), free %zu + %zu (edge vertices %zu / %zu)\n",
                  t[0].triangle_count, t[1].triangle_count, lk[0].triangle_count,
                  lk[1].triangle_count, la, lb, fr[0].triangle_count, fr[1].triangle_count, fa,
                  fb);
    assert_true(fa < 17 || fb < 17);
    assert_true(fa != fb || memcmp(za, zb, fa * sizeof(float)) != 0);
    for (int i = 0; i < 2; i++) {
        obs__bake_mesh_free(&lk[i]);
        obs__bake_mesh_free(&fr[i]);
        obs__bake_mesh_free(&t[i]);
    }
}

/* The nearest point of a triangle: inside the face, beyond a corner,
 * beyond an edge. */
static void test_closest_tri(void **state)
{
    (void)state;
    const float a[3] = {0, 0, 0}, b[3] = {2, 0, 0}, c[3] = {0, 0, 2};
    float bary[3];
    const float in[3] = {0.5f, 3, 0.5f};
    assert_true(fabs(obs__bake_closest_tri(in, a, b, c, bary) - 9.0) < 1e-6);
    assert_true(fabs(bary[1] - 0.25f) < 1e-6 && fabs(bary[2] - 0.25f) < 1e-6);
    const float corner[3] = {3, 1, -1};
    assert_true(fabs(obs__bake_closest_tri(corner, a, b, c, bary) - 3.0) < 1e-6);
    assert_true(fabs(bary[1] - 1.0f) < 1e-6);
    const float edge[3] = {2, 0, 2}; /* beyond the middle of b-c */
    assert_true(fabs(obs__bake_closest_tri(edge, a, b, c, bary) - 2.0) < 1e-6);
    assert_true(fabs(bary[0]) < 1e-6 && fabs(bary[1] - 0.5f) < 1e-6);
    const float below[3] = {-1, -2, 1}; /* beyond the edge a-c, below */
    assert_true(fabs(obs__bake_closest_tri(below, a, b, c, bary) - 5.0) < 1e-6);
    assert_true(fabs(bary[1]) < 1e-6 && fabs(bary[2] - 0.5f) < 1e-6);
}

/* The hierarchy's nearest point is the nearest of all triangles: a soup
 * of random triangles (some degenerate), random points in and around it,
 * against a search over every triangle. */
static void test_closest_bvh(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    enum { NT = 700, NP = 300 };
    obs_bake_mesh m;
    memset(&m, 0, sizeof m);
    m.name = strdup("soup");
    m.material = -1;
    m.vertex_count = 3 * NT;
    m.triangle_count = NT;
    m.positions = malloc(9 * NT * sizeof(float));
    m.indices = malloc(3 * NT * sizeof(uint32_t));
    assert_non_null(m.positions);
    assert_non_null(m.indices);
    uint32_t seed = 12345;
#define RND() ((seed = seed * 1664525u + 1013904223u) >> 8) / 16777216.0f
    for (int t = 0; t < NT; t++) {
        float c[3] = {10 * RND(), 3 * RND(), 10 * RND()};
        for (int k = 0; k < 3; k++) {
            float *p = m.positions + 9 * t + 3 * k;
            for (int a = 0; a < 3; a++)
                p[a] = c[a] + (t % 50 == 0 && k == 2 ? 0.0f : 0.8f * RND() - 0.4f);
            m.indices[3 * t + k] = (uint32_t)(3 * t + k);
        }
        if (t % 50 == 0) /* degenerate: the third corner on the first */
            memcpy(m.positions + 9 * t + 6, m.positions + 9 * t, 3 * sizeof(float));
    }
    obs_bake_scene sc;
    bt_scene(&sc, &m, 1);
    obs__bake_world w;
    assert_int_equal(obs__bake_flatten(&sc, &w, err), OBS_OK);
    assert_true(w.degenerate >= NT / 50);
    obs__bake_closest *c;
    assert_int_equal(obs__bake_closest_new(&w, 0, w.triangle_count, &c, err), OBS_OK);
    for (int i = 0; i < NP; i++) {
        float p[3] = {12 * RND() - 1, 5 * RND() - 1, 12 * RND() - 1}, b[3], bb[3];
        int64_t t;
        double d = obs__bake_closest_query(c, p, &t, b), best = INFINITY;
        for (size_t k = 0; k < w.triangle_count; k++) {
            if (!(w.area[k] > 0.0f))
                continue;
            const uint32_t *v = w.tri + 3 * k;
            best = fmin(best, obs__bake_closest_tri(p, w.pos + 3 * v[0], w.pos + 3 * v[1],
                                                    w.pos + 3 * v[2], bb));
        }
        assert_true(t >= 0 && w.area[t] > 0.0f);
        if (fabs(d - best) > 1e-9 * (1.0 + best))
            fail_msg("point %d: the hierarchy's %.9g, every triangle's %.9g", i, d, best);
        assert_true(fabs(b[0] + b[1] + b[2] - 1.0f) < 1e-5f);
    }
#undef RND
    obs__bake_closest_free(c);
    obs__bake_world_free(&w);
    obs_bake_scene_free(&sc);
}

/* The full-detail world of scene sc, welded, its vertex values the linear
 * signal. */
typedef struct full {
    obs__bake_world w;
    obs__bake_weld wd;
    double *x;
} full;

static void full_make(full *f, const obs_bake_scene *sc)
{
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__bake_flatten(sc, &f->w, err), OBS_OK);
    assert_int_equal(obs__bake_weld_make(&f->w, 1e-5f, 120.0f, &f->wd, err), OBS_OK);
    f->x = malloc(2 * f->wd.count * sizeof *f->x);
    assert_non_null(f->x);
    for (size_t v = 0; v < f->w.vertex_count; v++)
        for (int ch = 0; ch < 2; ch++)
            f->x[2 * f->wd.of[v] + ch] = lin(f->w.pos + 3 * v, ch);
}

static void full_free(full *f)
{
    free(f->x);
    obs__bake_weld_free(&f->wd);
    obs__bake_world_free(&f->w);
}

/* A scene of sc's node graph with each mesh replaced by its level l. */
static void lod_scene(const obs_bake_scene *sc, obs_bake_mesh *lm, int l, float ratio,
                      float error, obs_bake_scene *out)
{
    char err[OBS_ERR_LEN] = "";
    for (size_t m = 0; m < sc->mesh_count; m++)
        assert_int_equal(obs__bake_simplify(&sc->meshes[m], l, ratio, error, 0, 1e-5f, 120.0f,
                                            &lm[m], err),
                         OBS_OK);
    *out = *sc;
    out->meshes = lm;
}

/* Resampling on a plane simplified to 2 triangles: every sample of the
 * LOD takes the plane's own value there (the LOD lies on the plane), and
 * each LOD vertex too; a LOD moved off the plane along its normal takes
 * the values of the points below it. */
static void test_resample_plane(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bake_mesh m;
    obs_bake_scene sc, ls;
    bt_grid_graded(&m, "plane", O, U, V, 12, 10, 1.7, 0.6);
    bt_scene(&sc, &m, 1);
    full f = {0};
    full_make(&f, &sc);
    obs_bake_mesh lm;
    lod_scene(&sc, &lm, 1, 0.01f, 0.01f, &ls);
    assert_int_equal(lm.triangle_count, 2);
    for (int moved = 0; moved < 2; moved++) {
        float n[3] = {U[1] * V[2] - U[2] * V[1], U[2] * V[0] - U[0] * V[2],
                      U[0] * V[1] - U[1] * V[0]};
        float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (size_t v = 0; moved && v < lm.vertex_count; v++)
            for (int k = 0; k < 3; k++)
                lm.positions[3 * v + k] += 0.25f * n[k] / len;
        obs__bake_world lw;
        obs__bake_samples s;
        assert_int_equal(obs__bake_flatten(&ls, &lw, err), OBS_OK);
        assert_int_equal(obs__bake_samples_make(&lw, 20.0, 64, 3, &s, err), OBS_OK);
        double *vert = malloc(2 * lw.vertex_count * sizeof *vert);
        assert_non_null(vert);
        assert_int_equal(obs__bake_lod_resample(&f.w, &f.wd, f.x, &lw, &s, vert, 2, err), OBS_OK);
        double worst = 0.0;
        for (size_t i = 0; i < s.count; i++) {
            float p[3];
            obs__bake_sample_pos(&lw, &s, i, p);
            for (int k = 0; k < 3; k++) /* the point below */
                p[k] -= moved ? 0.25f * n[k] / len : 0.0f;
            assert_int_equal(s.valid[i], 1);
            for (int ch = 0; ch < 2; ch++)
                worst = fmax(worst, fabs(s.ao[2 * i + ch] - lin(p, ch)));
        }
        for (size_t v = 0; v < lw.vertex_count; v++) {
            float p[3];
            for (int k = 0; k < 3; k++)
                p[k] = lw.pos[3 * v + k] - (moved ? 0.25f * n[k] / len : 0.0f);
            for (int ch = 0; ch < 2; ch++)
                worst = fmax(worst, fabs(vert[2 * v + ch] - lin(p, ch)));
        }
        print_message("resampled onto the 2-triangle plane%s: %zu samples, worst %.2e\n",
                      moved ? " (moved 0.25 off it)" : "", s.count, worst);
        assert_true(s.count >= 40);
        assert_true(worst < 2e-5);
        free(vert);
        obs__bake_samples_free(&s);
        obs__bake_world_free(&lw);
    }
    /* a LOD world of another graph is refused */
    obs__bake_world lw;
    obs__bake_samples s;
    obs_bake_mesh two[2];
    bt_grid(&two[0], "a", O, U, V, 2, 2);
    bt_grid(&two[1], "b", O, U, V, 2, 2);
    obs_bake_scene other;
    bt_scene(&other, two, 2);
    assert_int_equal(obs__bake_flatten(&other, &lw, err), OBS_OK);
    assert_int_equal(obs__bake_samples_make(&lw, 1.0, 4, 3, &s, err), OBS_OK);
    assert_int_equal(obs__bake_lod_resample(&f.w, &f.wd, f.x, &lw, &s, NULL, 1, err),
                     OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "instances"));
    obs__bake_samples_free(&s);
    obs__bake_world_free(&lw);
    obs_bake_scene_free(&other);
    obs__bake_mesh_free(&lm);
    full_free(&f);
    obs_bake_scene_free(&sc);
}

/* The fit onto the LOD's vertices reproduces a signal linear over the
 * surface exactly (eq 2 with mass = samples is the least-squares fit of
 * the samples): a plane (with the regulariser, zero on a plane's linear
 * signals) and a fold of two planes (the regulariser off: across the fold
 * a linear function of space is not linear in the unfolded pair). */
static void run_fit_linear(int fold, const char *alpha)
{
    char err[OBS_ERR_LEN] = "";
    obs_bake_mesh m[2];
    obs_bake_scene sc, ls;
    const float wall_o[3] = {-3, 0.5f, -2}, up[3] = {0, 4, 0};
    bt_grid_graded(&m[0], "floor", O, U, V, 14, 12, 1.5, 1.0);
    bt_grid(&m[1], "wall", wall_o, U, up, 14, 8); /* shares the floor's edge along U */
    bt_scene(&sc, m, fold ? 2 : 1);
    if (!fold)
        obs__bake_mesh_free(&m[1]);
    full f = {0};
    full_make(&f, &sc);
    obs_bake_mesh lm[2];
    lod_scene(&sc, lm, 1, 0.1f, 0.01f, &ls);
    obs__bake_world lw;
    obs__bake_samples s;
    obs__bake_weld lwd;
    assert_int_equal(obs__bake_flatten(&ls, &lw, err), OBS_OK);
    assert_true(lw.triangle_count < f.w.triangle_count);
    assert_int_equal(lw.degenerate, 0); /* the simplifier drops its zero-area slivers */
    assert_int_equal(obs__bake_samples_make(&lw, 8.0, 16, 3, &s, err), OBS_OK);
    assert_int_equal(obs__bake_lod_resample(&f.w, &f.wd, f.x, &lw, &s, NULL, 1, err), OBS_OK);
    assert_int_equal(obs__bake_weld_make(&lw, 1e-5f, 120.0f, &lwd, err), OBS_OK);
    obs_bake_params p = {0};
    bt_set(&p, "alpha", alpha);
    bt_set(&p, "ridge", "0");
    obs_bake_params_resolve(&p, &p);
    double *x = malloc(6 * lwd.count * sizeof *x);
    assert_non_null(x);
    obs_bake_stats st = {0};
    obs_status frc = obs__bake_fit(&lw, &lwd, &s, &p, x, x + 2 * lwd.count, x + 4 * lwd.count, &st, err);
    if (frc != OBS_OK)
        fail_msg("fit: %s", err);
    double worst = 0.0;
    for (size_t v = 0; v < lw.vertex_count; v++)
        for (int ch = 0; ch < 2; ch++)
            worst = fmax(worst, fabs(x[2 * lwd.of[v] + ch] - lin(lw.pos + 3 * v, ch)));
    print_message("%s, %zu -> %zu triangles, alpha %s: worst LOD vertex error %.2e\n",
                  fold ? "fold" : "plane", f.w.triangle_count, lw.triangle_count, alpha, worst);
    assert_true(worst < 1e-4);
    free(x);
    obs__bake_weld_free(&lwd);
    obs__bake_samples_free(&s);
    obs__bake_world_free(&lw);
    for (int k = 0; k < (fold ? 2 : 1); k++)
        obs__bake_mesh_free(&lm[k]);
    full_free(&f);
    obs_bake_scene_free(&sc);
}

static void test_fit_linear(void **state)
{
    (void)state;
    run_fit_linear(0, "1");
    run_fit_linear(1, "0");
}

/* The whole stage: a floor and a wall baked with --lods 2: two levels of
 * each mesh, fewer triangles level by level, values in [0, 1], the
 * report's counts, and the .glb's MSFT_lod nodes. */
static void test_bake_run(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bake_mesh m[2];
    const float o[3] = {0, 0, 0}, u[3] = {4, 0, 0}, v[3] = {0, 0, -4}, w[3] = {0, 4, 0};
    bt_grid(&m[0], "floor", o, u, v, 16, 16);
    bt_grid(&m[1], "wall", o, w, u, 16, 16); /* facing the floor */
    obs_bake_scene sc;
    bt_scene(&sc, m, 2);
    obs_bake_desc d = {0};
    bt_set(&d.params, "rays", "16");
    bt_set(&d.params, "lods", "2");
    bt_set(&d.params, "threads", "1");
    obs_bake_result r;
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    assert_int_equal(r.lod_levels, 2);
    assert_int_equal(r.stats.lod_levels, 2);
    for (size_t l = 1; l <= 2; l++) {
        for (size_t k = 0; k < 2; k++) {
            const obs_bake_mesh *lm = &r.lod_meshes[(l - 1) * 2 + k];
            size_t above = l == 1 ? sc.meshes[k].triangle_count
                                  : r.lod_meshes[k].triangle_count;
            assert_true(lm->triangle_count > 0 && lm->triangle_count < above);
            const obs_bake_instance *in = &r.lod_instances[(l - 1) * r.instance_count + k];
            assert_int_equal(in->mesh, k);
            for (size_t q = 0; q < lm->vertex_count; q++)
                assert_true(in->ao[q] >= 0.0f && in->ao[q] <= 1.0f && in->ao_long[q] <= 1.0f);
        }
        assert_true(r.stats.lod_samples[l - 1] > 0);
        assert_true(r.stats.lod_fit[l - 1][1] >= 0.0);
    }
    assert_true(r.stats.lod_triangles[1] < r.stats.lod_triangles[0]);
    assert_true(r.stats.lod_triangles[0] < r.stats.triangles);
    assert_true(r.stats.seconds[OBS_BAKE_STAGE_lod] > 0.0);
    assert_string_equal(obs_bake_stage_name(OBS_BAKE_STAGE_lod), "lod");
    char path[] = "/tmp/obs_lod_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(obs_bake_write_glb(path, &sc, &r, 0, err), OBS_OK);
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    uint32_t hdr[5];
    assert_int_equal(fread(hdr, 4, 5, fp), 5);
    assert_true(hdr[3] > 0 && hdr[3] < (1u << 24));
    char *head = calloc(hdr[3] + 1, 1);
    assert_non_null(head);
    assert_int_equal(fread(head, 1, hdr[3], fp), hdr[3]); /* the JSON chunk */
    fclose(fp);
    unlink(path);
    assert_non_null(strstr(head, "\"extensionsUsed\":[\"MSFT_lod\"]"));
    assert_non_null(strstr(head, "\"MSFT_lod\":{\"ids\":[1,2]}"));
    assert_non_null(strstr(head, "root_LOD2"));
    free(head);
    obs_bake_result_free(&r);
    assert_null(r.lod_meshes);
    obs_bake_scene_free(&sc);
}

/* A .glb's own LODs (MSFT_lod, lod_file.c): the bake's output loaded
 * again brings its levels, geometry for geometry; baked with --lods they
 * are used as they are (lod_source file: not simplified again, whatever
 * lod_ratio), or simplified anew (lod_source simplify). */
static void test_file_lods(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bake_mesh m[2];
    const float o[3] = {0, 0, 0}, u[3] = {4, 0, 0}, v[3] = {0, 0, -4}, w[3] = {0, 4, 0};
    bt_grid(&m[0], "floor", o, u, v, 16, 16);
    bt_grid(&m[1], "wall", o, w, u, 12, 8);
    obs_bake_scene sc;
    bt_scene(&sc, m, 2);
    obs_bake_desc d = {0};
    bt_set(&d.params, "rays", "8");
    bt_set(&d.params, "lods", "2");
    obs_bake_result r;
    assert_int_equal(obs_bake_run(&sc, &d, &r, err), OBS_OK);
    char path[] = "/tmp/obs_lodf_XXXXXX.glb";
    int fd = mkstemps(path, 4); /* assimp tells the format by the name */
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(obs_bake_write_glb(path, &sc, &r, 0, err), OBS_OK);
    obs_bake_scene back;
    if (obs_bake_load(path, 0, &back, err) != OBS_OK)
        fail_msg("load: %s", err);
    unlink(path);
    assert_null(back.file_lod_error);
    assert_int_equal(back.file_lod_levels, 2);
    assert_int_equal(back.mesh_count, 2);
    for (size_t l = 1; l <= 2; l++)
        for (size_t k = 0; k < 2; k++) {
            const obs_bake_mesh *f = &back.file_lods[(l - 1) * 2 + k];
            /* the original mesh of the same size (the load may reorder) */
            size_t o2 = back.meshes[k].triangle_count == sc.meshes[0].triangle_count ? 0 : 1;
            const obs_bake_mesh *a = &r.lod_meshes[(l - 1) * 2 + o2];
            assert_int_equal(f->triangle_count, a->triangle_count);
            assert_int_equal(f->vertex_count, a->vertex_count);
            assert_memory_equal(f->positions, a->positions, 3 * a->vertex_count * sizeof(float));
            assert_memory_equal(f->indices, a->indices, 3 * a->triangle_count * sizeof(uint32_t));
        }
    obs_bake_result r2;
    bt_set(&d.params, "lod_ratio", "0.2");
    assert_int_equal(obs_bake_run(&back, &d, &r2, err), OBS_OK);
    for (int l = 0; l < 2; l++) {
        assert_int_equal(r2.stats.lod_file_meshes[l], 2);
        assert_int_equal(r2.stats.lod_triangles[l], r.stats.lod_triangles[l]);
    }
    obs_bake_result_free(&r2);
    bt_set(&d.params, "lod_source", "simplify");
    assert_int_equal(obs_bake_run(&back, &d, &r2, err), OBS_OK);
    assert_int_equal(r2.stats.lod_file_meshes[0], 0);
    assert_true(r2.stats.lod_triangles[0] < r.stats.lod_triangles[0]);
    obs_bake_result_free(&r2);
    obs_bake_scene_free(&back);
    obs_bake_result_free(&r);
    obs_bake_scene_free(&sc);
}


/* A .glb with MSFT_lod whose header gives a length of almost 4 GiB, the
 * file 200 bytes (tests/fuzz/fuzz_files.c found it): refused as
 * truncated, the buffer sized by the file.  Read in a child whose address
 * space has 256 MiB to spare, where a buffer sized by the header cannot
 * be had (without the limit, under the sanitizers, it only checks the
 * message). */
static void test_file_lods_damaged(void **state)
{
    (void)state;
    const char json[] = "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"MSFT_lod\"],"
                        "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"name\":\"a\"}]} ";
    unsigned char head[20];
    const uint32_t words[5] = {0x46546C67u, 2, 0xfffffff0u, (uint32_t)(sizeof json - 1),
                               0x4E4F534Au};
    for (int w = 0; w < 5; w++)
        for (int b = 0; b < 4; b++)
            head[4 * w + b] = (unsigned char)(words[w] >> (8 * b));
    char path[] = "/tmp/obs_lodbad_XXXXXX.glb";
    int fd = mkstemps(path, 4);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "wb");
    assert_non_null(f);
    fwrite(head, 1, 20, f);
    fwrite(json, 1, sizeof json - 1, f);
    for (int k = 0; k < 50; k++)
        fputc(0, f);
    fclose(f);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
#if !defined(__SANITIZE_ADDRESS__)
        long pages = 0;
        FILE *st = fopen("/proc/self/statm", "r");
        if (st && fscanf(st, "%ld", &pages) == 1) {
            rlim_t cap = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + ((rlim_t)256 << 20);
            struct rlimit rl = {cap, cap};
            setrlimit(RLIMIT_AS, &rl);
        }
        if (st)
            fclose(st);
#endif
        obs_bake_scene sc = {0};
        char err[OBS_ERR_LEN] = "";
        obs_status rc = obs__bake_lod_file_read(path, &sc, err);
        if (rc != OBS_BAD_FILE || !strstr(err, "truncated"))
            fprintf(stderr, "got %s: %s\n", obs_status_name(rc), err);
        _exit(rc == OBS_BAD_FILE && strstr(err, "truncated") ? 0 : 1);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    unlink(path);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
}

/* Bad parameters: each refused with the row's name; the simplifier's own
 * checks. */
static void test_bad_params(void **state)
{
    (void)state;
    char err[OBS_ERR_LEN] = "";
    obs_bake_params p = {0};
    const char *bad[][2] = {{"lods", "9"},      {"lods", "-1"},      {"lods", "two"},
                            {"lod_ratio", "1"}, {"lod_ratio", "0"},  {"lod-ratio", "x"},
                            {"lod_error", "-0.1"}, {"lod_error", "2"}, {"lod_check", "2"},
                            {"lod_source", "both"}};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        err[0] = '\0';
        assert_int_not_equal(obs_bake_param_set(&p, bad[i][0], bad[i][1], err), OBS_OK);
        char row[32];
        snprintf(row, sizeof row, "%s", bad[i][0]);
        for (char *c = row; *c; c++)
            *c = *c == '-' ? '_' : *c;
        if (!strstr(err, row))
            fail_msg("lods '%s' = '%s': message '%s' does not name the row", bad[i][0],
                     bad[i][1], err);
    }
    obs_bake_mesh m, out;
    bt_grid(&m, "plane", O, U, V, 2, 2);
    assert_int_equal(obs__bake_simplify(&m, 0, 0.5f, 0.01f, 0, 1e-5f, 120.0f, &out, err),
                     OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "level 0"));
    assert_int_equal(obs__bake_simplify(&m, 1, 1.5f, 0.01f, 0, 1e-5f, 120.0f, &out, err),
                     OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "ratio 1.5"));
    obs__bake_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_simplify_plane),
        cmocka_unit_test(test_simplify_error_bound),
        cmocka_unit_test(test_simplify_all_collapsed),
        cmocka_unit_test(test_simplify_lock_border),
        cmocka_unit_test(test_closest_tri),
        cmocka_unit_test(test_closest_bvh),
        cmocka_unit_test(test_resample_plane),
        cmocka_unit_test(test_fit_linear),
        cmocka_unit_test(test_bake_run),
        cmocka_unit_test(test_file_lods),
        cmocka_unit_test(test_file_lods_damaged),
        cmocka_unit_test(test_bad_params),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
