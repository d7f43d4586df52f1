/* What the steps of the vertex bake hand each other (core/bake/,
 * obscura/bake.h); the level and its rays are core/level's (level.h). */
#ifndef OBSCURA_BAKE_INTERNAL_H
#define OBSCURA_BAKE_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "level/level.h"
#include "obscura/bake.h"

/* Surface samples (samples.c); ao and valid are filled by the trace. */
typedef struct obs__bake_samples {
    size_t count;
    uint32_t *tri;  /* the face; the one allocation holding all six arrays */
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
/* Instance in's values from the welded solution x (short, long per welded
 * vertex), its n vertices welded as of[0 .. n) (wd->of from its first
 * vertex on), into r: each distance clamped to [0, 1] and _AO, the
 * artists' blend of the two (section 2).  The full detail (bake.c) and
 * each LOD (lod.c) end so.  0, or -1 when out of memory. */
int obs__bake_instance_values(obs_bake_instance *r, const obs__bake_inst *in, size_t n,
                              const uint32_t *of, const double *x, float blend);

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

#endif
