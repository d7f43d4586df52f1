/* Scenes built in memory for the bake tests: planes as grids of quads. */
#ifndef OBS_BAKE_TESTUTIL_H
#define OBS_BAKE_TESTUTIL_H

#include <dirent.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "obscura/bake.h"
#include "testutil.h"

/* A grid of nu x nv quads from origin o along u and v (full lengths),
 * graded: the i-th line along u at (i/nu)^gu of its length (gu 1:
 * uniform), the same along v; its faces wind counter-clockwise around
 * u x v, its normals u x v. */
static inline void bt_grid_graded(obs_bake_mesh *m, const char *name, const float o[3],
                                  const float u[3], const float v[3], int nu, int nv, double gu,
                                  double gv)
{
    memset(m, 0, sizeof *m);
    m->name = strdup(name);
    m->material = -1;
    m->vertex_count = (size_t)(nu + 1) * (nv + 1);
    m->triangle_count = (size_t)2 * nu * nv;
    m->positions = malloc(m->vertex_count * 3 * sizeof(float));
    m->normals = malloc(m->vertex_count * 3 * sizeof(float));
    m->indices = malloc(m->triangle_count * 3 * sizeof(uint32_t));
    assert_non_null(m->positions);
    assert_non_null(m->normals);
    assert_non_null(m->indices);
    float n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int j = 0; j <= nv; j++)
        for (int i = 0; i <= nu; i++) {
            size_t k = (size_t)j * (nu + 1) + i;
            for (int c = 0; c < 3; c++) {
                m->positions[3 * k + c] = o[c] + u[c] * (float)pow((double)i / nu, gu) +
                                          v[c] * (float)pow((double)j / nv, gv);
                m->normals[3 * k + c] = n[c] / len;
            }
        }
    size_t t = 0;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            uint32_t a = (uint32_t)(j * (nu + 1) + i), b = a + 1, c = a + (uint32_t)nu + 2,
                     d = a + (uint32_t)nu + 1;
            uint32_t q[6] = {a, b, c, a, c, d};
            memcpy(m->indices + 3 * t, q, sizeof q);
            t += 2;
        }
}

static inline void bt_grid(obs_bake_mesh *m, const char *name, const float o[3], const float u[3],
                           const float v[3], int nu, int nv)
{
    bt_grid_graded(m, name, o, u, v, nu, nv, 1.0, 1.0);
}

/* A scene of one root node (identity) holding the meshes; takes them. */
static inline void bt_scene(obs_bake_scene *s, obs_bake_mesh *meshes, size_t n)
{
    memset(s, 0, sizeof *s);
    s->meshes = calloc(n, sizeof *meshes);
    s->nodes = calloc(1, sizeof *s->nodes);
    assert_non_null(s->meshes);
    assert_non_null(s->nodes);
    memcpy(s->meshes, meshes, n * sizeof *meshes);
    s->mesh_count = n;
    s->node_count = 1;
    obs_bake_node *nd = &s->nodes[0];
    nd->name = strdup("root");
    nd->parent = -1;
    for (int i = 0; i < 16; i++)
        nd->local[i] = nd->world[i] = i % 5 == 0 ? 1.0f : 0.0f;
    nd->meshes = malloc(n * sizeof *nd->meshes);
    assert_non_null(nd->meshes);
    nd->mesh_count = (uint32_t)n;
    for (size_t i = 0; i < n; i++) {
        nd->meshes[i] = (uint32_t)i;
        s->world_triangles += meshes[i].triangle_count;
    }
    s->instance_count = n;
}

/* bt_scene's one node split into n: node i named names[i] takes the next
 * counts[i] meshes in order; node 0 the root, the others its children. */
static inline void bt_split(obs_bake_scene *s, const char *const *names, const uint32_t *counts,
                            size_t n)
{
    obs_bake_node *nodes = calloc(n, sizeof *nodes);
    assert_non_null(nodes);
    uint32_t next = 0;
    for (size_t i = 0; i < n; i++) {
        nodes[i] = s->nodes[0];
        nodes[i].name = strdup(names[i]);
        nodes[i].parent = i ? 0 : -1;
        nodes[i].meshes = malloc((counts[i] ? counts[i] : 1) * sizeof(uint32_t));
        assert_non_null(nodes[i].meshes);
        nodes[i].mesh_count = counts[i];
        for (uint32_t k = 0; k < counts[i]; k++)
            nodes[i].meshes[k] = next++;
    }
    assert_int_equal(next, s->mesh_count);
    free(s->nodes[0].name);
    free(s->nodes[0].meshes);
    free(s->nodes);
    s->nodes = nodes;
    s->node_count = n;
}

static inline void bt_set(obs_bake_params *p, const char *name, const char *value)
{
    char err[OBS_ERR_LEN];
    assert_int_equal(obs_bake_param_set(p, name, value, err), OBS_OK);
}

/* A copy of file `from` in `to`: its first `keep` bytes (< 0: all), byte
 * `flip` (< 0: none) with a bit flipped: truncated and damaged parts. */
static inline void bt_copy_cut(const char *from, const char *to, long keep, long flip)
{
    FILE *f = fopen(from, "rb"), *g = fopen(to, "wb");
    assert_non_null(f);
    assert_non_null(g);
    int ch;
    for (long k = 0; (ch = fgetc(f)) != EOF && (keep < 0 || k < keep); k++)
        fputc(k == flip ? ch ^ 0x40 : ch, g);
    fclose(f);
    fclose(g);
}

/* The names in dir, one "name/" a line, sorted, "." and ".." left out:
 * what a writer left behind, temporaries (".NAME.PID.tmp") included. */
static inline void bt_dir_list(const char *dir, char *out, size_t cap)
{
    struct dirent **e;
    int n = scandir(dir, &e, NULL, alphasort);
    assert_true(n >= 0);
    out[0] = '\0';
    for (int i = 0; i < n; i++) {
        if (strcmp(e[i]->d_name, ".") != 0 && strcmp(e[i]->d_name, "..") != 0) {
            size_t len = strlen(out), nl = strlen(e[i]->d_name);
            assert_true(len + nl + 2 <= cap);
            memcpy(out + len, e[i]->d_name, nl);
            memcpy(out + len + nl, "/", 2);
        }
        free(e[i]);
    }
    free(e);
}

/* Files may grow to `bytes` at most (RLIMIT_FSIZE; SIGXFSZ ignored, so a
 * longer write fails with EFBIG mid-file, as on a full disk); 0: as before.
 * Works for root, unlike a directory without write permission. */
static inline void bt_file_limit(size_t bytes)
{
    static struct rlimit old;
    static int saved;
    if (!saved) {
        assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
        signal(SIGXFSZ, SIG_IGN);
        saved = 1;
    }
    struct rlimit rl = old;
    if (bytes)
        rl.rlim_cur = bytes;
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &rl), 0);
}

#endif
