/* What both bakes share (core/level/): the level loaded and flattened to
 * world space, its BVH and rays, spherical harmonics and a point's
 * visibility in them.  The vertex bake (core/bake/) and the region model
 * (core/dynamic/) build on this and never on each other.  The names keep
 * the obs__bake_ prefix of "the bakes'" code. */
#ifndef OBSCURA_LEVEL_H
#define OBSCURA_LEVEL_H

#include <stddef.h>
#include <stdint.h>
#include <time.h>

#include "obscura/bake.h"
#include "obscura/dynamic.h"

struct obs__bake_decor; /* decor.h */

/* Seconds on the monotonic clock: the bakes' stage timings. */
static inline double obs__bake_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Every instance in world space (flatten.c).  Vertices and triangles of
 * instance i are the runs starting at inst[i].first_vertex and
 * inst[i].first_triangle, in the order of the mesh's own. */
typedef struct obs__bake_inst {
    uint32_t node, mesh;
    size_t first_vertex, first_triangle;
} obs__bake_inst;

typedef struct obs__bake_world {
    size_t vertex_count, triangle_count, instance_count;
    float *pos;         /* 3 per vertex; the one allocation holding all seven arrays */
    float *nrm;         /* 3 per vertex, unit; zero where the mesh has none */
    uint32_t *tri;      /* 3 per triangle, world vertex indices */
    float *area;        /* per triangle; 0 for a degenerate one */
    float *fn;          /* 3 per triangle: unit normal of the winding (CCW) */
    uint8_t *two_sided; /* per triangle */
    obs__bake_inst *inst;
    size_t degenerate, against_normals;
} obs__bake_world;

obs_status obs__bake_flatten(const obs_bake_scene *s, obs__bake_world *w, char err[OBS_ERR_LEN]);
void obs__bake_world_free(obs__bake_world *w);
/* Both bakes' first step: the scene refused when empty (the message
 * names `who`) or over max_triangles once flattened, else flattened. */
obs_status obs__bake_flatten_checked(const obs_bake_scene *scene, int max_triangles,
                                     const char *who, obs__bake_world *w, char err[OBS_ERR_LEN]);

/* The LODs a .glb brings itself (lod_file.c), read by the loader
 * (load.c). */
/* The file's own LODs (lod_file.c): a .glb's MSFT_lod levels into
 * s->file_lods (level l of mesh m at (l - 1) * mesh_count + m, an empty
 * mesh where the file has none); OBS_OK with none for another format or
 * a file without them.  Free with obs__bake_lod_file_free (and
 * obs_bake_scene_free). */
obs_status obs__bake_lod_file_read(const char *path, obs_bake_scene *s, char err[OBS_ERR_LEN]);
void obs__bake_lod_file_free(obs_bake_scene *s);
/* Frees a mesh's arrays and name and zeroes it (the scene's meshes and the
 * LODs'). */
void obs__bake_mesh_free(obs_bake_mesh *m);

/* list[0 .. n) compacted in place to the triangles that are no exact copy
 * of one before them: the same three positions in the same order and the
 * same sidedness, whose every hit (distance, face normal, side) and
 * nearest point are that one's.  A BVH cannot split coincident triangles,
 * so each ray or query that reached them tested every copy (bake-dynamic's
 * probes on 2000 copies of one quad: 90 s, the quad alone 1 s).  Returns
 * the count kept, SIZE_MAX when out of memory.  occl.c's; the opaque BVH and
 * the LODs' nearest-point search (bake/closest.c) leave copies out. */
size_t obs__bake_drop_copies(const obs__bake_world *w, uint32_t *list, size_t n);

/* The level's BVH on its own, for points in space (bvh.c; the
 * dynamic-object bake).  w must outlive it. */
typedef struct obs__bake_bvh obs__bake_bvh;
obs_status obs__bake_bvh_new(const obs__bake_world *w, obs__bake_bvh **out,
                             char err[OBS_ERR_LEN]);
/* The same with decorators (section 2.1, occl.c): the closest hits among
 * the opaque triangles, shrub fog boxes and tree triangles attenuating
 * the rays (obs__bake_bvh_cast's trans), as obs__bake_trace traces the
 * surface samples; d NULL: every triangle opaque. */
obs_status obs__bake_bvh_new_decor(const obs__bake_world *w, const struct obs__bake_decor *d,
                                   float tree_attenuation, obs__bake_bvh **out,
                                   char err[OBS_ERR_LEN]);
void obs__bake_bvh_free(obs__bake_bvh *b);
/* Closest hits of the n unit directions dirs (3 each) from o, up to
 * tfar: t[k] the distance (INFINITY for a miss), back[k] 1 when the ray
 * met a one-sided face from behind; trans (NULL: not wanted) the
 * decorators' transmittance of each ray up to its hit (or tfar), 1
 * without decorators.  Thread-safe. */
void obs__bake_bvh_cast(const obs__bake_bvh *b, const float o[3], const float *dirs, int n,
                        float tfar, float *t, uint8_t *back, float *trans);
/* 1 when geometry lies on the segment a-c. */
int obs__bake_bvh_occluded(const obs__bake_bvh *b, const float a[3], const float c[3]);

/* ---- sh.c: real spherical harmonics, bands 0..2 (point visibility) ----- */

/* The 9 basis functions Y_k at the unit direction d, k = l (l + 1) + m. */
void obs__sh_basis(const float d[3], double y[OBS_DYN_SH]);
/* The zonal coefficients of the clamped cosine max(0, cos) per band:
 * pi, 2 pi / 3, pi / 4 (Ramamoorthi and Hanrahan 2001). */
extern const double obs__sh_cosine[3];
/* f's coefficients from a quadrature: f_k = sum_i w_i f(d_i) Y_k(d_i)
 * (n directions d, 3 each). */
void obs__sh_project(const float *dirs, const double *w, const double *f, size_t n,
                         double out[OBS_DYN_SH]);
/* In place: f_k -> A_l f_k / pi, so that the eq 1 AO for the normal n is
 * sum_k out_k Y_k(n). */
void obs__sh_convolve(double c[OBS_DYN_SH]);
/* sum_k c_k Y_k(n) over bands 0..order. */
double obs__sh_eval(const double c[OBS_DYN_SH], const float n[3], int order);
/* n directions over the sphere, equal area and stratified (a Fibonacci
 * spiral) turned by a random rotation from r; each has weight 4 pi / n. */
void obs__sphere_dirs(int n, uint64_t seed, uint64_t stream, float *dirs);

/* point_sh.c: one point's 18 channels (projected, convolved) from p->rays
 * directions keyed by (seed, stream); *dropped when its rays met back
 * faces more often than the limit.  0 when out of memory. */
int obs__point_sh(const obs__bake_bvh *bvh, const float o[3], const obs_dyn_params *p,
                      uint64_t stream, double sh[OBS_DYN_CHANNELS], int *dropped);

#endif
