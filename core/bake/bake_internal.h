/* What the steps of the bake hand each other (core/bake/, obscura/bake.h). */
#ifndef OBSCURA_BAKE_INTERNAL_H
#define OBSCURA_BAKE_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "obscura/bake.h"

/* Every instance in world space (flatten.c).  Vertices and triangles of
 * instance i are the runs starting at inst[i].first_vertex and
 * inst[i].first_triangle, in the order of the mesh's own. */
typedef struct obs__bake_inst {
    uint32_t node, mesh;
    size_t first_vertex, first_triangle;
} obs__bake_inst;

typedef struct obs__bake_world {
    size_t vertex_count, triangle_count, instance_count;
    float *pos;         /* 3 per vertex */
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

/* Surface samples (samples.c); ao and valid are filled by the trace. */
typedef struct obs__bake_samples {
    size_t count;
    uint32_t *tri;  /* the face */
    float *bary;    /* 3 per sample: barycentric weights of its corners */
    float *weight;  /* w = A_t / n_t */
    float *ao;      /* 2 per sample: eq 1 at the short and long distance */
    uint8_t *valid; /* 0: dropped by the back-face rule */
    uint32_t *first; /* per face + 1: its samples are first[t] .. first[t+1]-1 */
    size_t dropped;
    uint64_t rays;
} obs__bake_samples;

obs_status obs__bake_samples_make(const obs__bake_world *w, double per_face, int max_face,
                                  uint64_t seed, obs__bake_samples *s, char err[OBS_ERR_LEN]);
void obs__bake_samples_free(obs__bake_samples *s);
/* The world position of sample i. */
void obs__bake_sample_pos(const obs__bake_world *w, const obs__bake_samples *s, size_t i,
                          float p[3]);

typedef struct obs__bake_trace_desc {
    float distance[2]; /* short, long */
    int rays, threads;
    float backface_limit;
    uint64_t seed;
    int (*progress)(void *user, size_t done, size_t total); /* nonzero: stop */
    void *progress_user;
    size_t first, end; /* the samples traced: [first, end), end 0 for all (shard.c) */
    /* Decorators (section 2.1, occl.c): NULL, every triangle opaque */
    const struct obs__bake_decor *decor;
    float tree_attenuation;
} obs__bake_trace_desc;

/* Eq 1 at every sample (trace.c); OBS_CANCELLED when the progress
 * callback asked to stop. */
obs_status obs__bake_trace(const obs__bake_world *w, obs__bake_samples *s,
                           const obs__bake_trace_desc *d, double *bvh_seconds,
                           char err[OBS_ERR_LEN]);

/* Welded vertices (weld.c): of[v] for every world vertex v. */
typedef struct obs__bake_weld {
    size_t count;
    uint32_t *of;
} obs__bake_weld;

obs_status obs__bake_weld_make(const obs__bake_world *w, float tolerance, float angle_deg,
                          obs__bake_weld *out, char err[OBS_ERR_LEN]);
void obs__bake_weld_free(obs__bake_weld *wd);

/* The least-squares fit (fit.c): x holds 2 values (short, long) per welded
 * vertex; face and point the two baselines' values (obs_bake_stats), 2 per
 * welded vertex too.  Fills the fit's counts and residuals in st. */
obs_status obs__bake_fit(const obs__bake_world *w, const obs__bake_weld *wd,
                         const obs__bake_samples *s, const obs_bake_params *p, double *x,
                         double *face, double *point, obs_bake_stats *st,
                         char err[OBS_ERR_LEN]);
/* RMS over the valid samples of s (weights w) of the piecewise-linear
 * signal of the vertex values val minus the traced value, per distance. */
void obs__bake_residual(const obs__bake_world *w, const obs__bake_weld *wd,
                        const obs__bake_samples *s, const double *val, double out[2]);

/* Pieces of the fit, for the tests: the edge regulariser's row of one
 * interior edge (fit.c).  Triangles (a, b, c) and (b, a, d) share the
 * edge a-b; j receives the weights of x_a, x_b, x_c, x_d in the jump of
 * the derivative across the edge, and the return value the weight
 * (A1 h1^2 + A2 h2^2) / 6 of its square.  -1 when a triangle is
 * degenerate. */
double obs__bake_edge_jump(const float a[3], const float b[3], const float c[3],
                           const float d[3], double j[4]);

/* Small decorators (small.c, section 2.2.1): each small node's scalar
 * resampled from the fitted vertex values x (2 per welded vertex, of[]
 * the weld) around it, into out->node_ao and its instances' vertices
 * (out's instances filled); nothing when d has none. */
struct obs__bake_decor;
obs_status obs__bake_small(const obs_bake_scene *scene, const obs__bake_world *w,
                           const uint32_t *of, const struct obs__bake_decor *d, const double *x,
                           const obs_bake_params *p, obs_bake_result *out, char err[OBS_ERR_LEN]);

/* The level's BVH on its own, for points in space (trace.c; the
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

#endif
