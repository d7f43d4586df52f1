/* What the steps of the dynamic-object bake hand each other
 * (core/dynamic/, obscura/dynamic.h); the level and its rays are
 * core/level's (level.h). */
#ifndef OBSCURA_DYN_INTERNAL_H
#define OBSCURA_DYN_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "level/level.h"
#include "level/part.h"
#include "obscura/dynamic.h"

/* ---- dyn_regions.c ---------------------------------------------------------- */

/* Face adjacency of boxes: pairs whose boxes touch on a face with
 * positive area (tolerance: tol times the larger box's size). */
obs_status obs__dyn_adjacency(obs_dyn_regions *r, char err[OBS_ERR_LEN]);
/* Shared face of boxes a and b: its area, its centre in b. 0 when they
 * share none. */
double obs__dyn_shared_face(const obs_dyn_box *a, const obs_dyn_box *b, float centre[3]);
/* Regions by adaptive subdivision of the level's box (dyn_regions.c). */
obs_status obs__dyn_regions_build(const obs__bake_world *w, const obs__bake_bvh *bvh,
                                  const obs_dyn_params *p, obs_dyn_regions *out,
                                  char err[OBS_ERR_LEN]);

/* ---- dyn_probes.c ----------------------------------------------------------- */

/* Inside-geometry test of one point: the fraction of `rays` directions
 * (a fixed spiral) that meet a one-sided face from behind, > limit. */
int obs__dyn_inside(const obs__bake_bvh *bvh, const float p[3], int rays, float limit);

/* The valid points of every region and their spherical obscurance.
 * Point k of region r: pos[3 k], sh[OBS_DYN_CHANNELS k] (convolved),
 * region[k]; held[k] 1 when held back from the fit; id[k] its index
 * over the level's grid points (its rays' stream); dropped[k] 1 when its
 * rays met back faces more often than the limit (2: no memory). */
typedef struct obs__dyn_points {
    size_t count;
    float *pos; /* the one allocation holding all six arrays */
    double *sh;
    uint32_t *region;
    uint8_t *held;
    uint64_t *id;
    uint8_t *dropped;
    size_t grid, inside, hidden, backface;
    uint64_t rays;
} obs__dyn_points;

/* The three steps of obs__dyn_points_make, apart for the shards
 * (dyn_shard.c): the grid points flagged, the valid ones listed (count,
 * pos, region, held, id; sh 0); points [first, end) traced (sh, dropped,
 * rays); the dropped ones removed, the order kept. */
obs_status obs__dyn_points_flag(const obs__bake_bvh *bvh, const obs_dyn_regions *rg,
                                const obs_dyn_params *p, obs__dyn_points *out,
                                char err[OBS_ERR_LEN]);
void obs__dyn_points_trace(const obs__bake_bvh *bvh, const obs_dyn_params *p,
                           obs__dyn_points *pt, size_t first, size_t end,
                           void (*progress)(void *, size_t, size_t), void *user);
obs_status obs__dyn_points_compact(obs__dyn_points *pt, char err[OBS_ERR_LEN]);

obs_status obs__dyn_points_make(const obs__bake_world *w, const obs__bake_bvh *bvh,
                                const obs_dyn_regions *rg, const obs_dyn_params *p,
                                obs__dyn_points *out, double *valid_seconds,
                                void (*progress)(void *, size_t, size_t), void *user,
                                char err[OBS_ERR_LEN]);
/* *pt: n points (count n), their six arrays zeroed in one allocation,
 * every other field 0; free them with obs__dyn_points_free. */
obs_status obs__dyn_points_alloc(obs__dyn_points *pt, size_t n, char err[OBS_ERR_LEN]);
void obs__dyn_points_free(obs__dyn_points *pt);

/* Eq 1 at point o for the unit normal n by `rays` cosine-weighted rays
 * (the bake's estimator): ao[0] short, ao[1] long. */
void obs__dyn_trace_eq1(const obs__bake_bvh *bvh, const float o[3], const float n[3],
                        int rays, const float distance[2], uint64_t seed, uint64_t stream,
                        double ao[2]);

/* ---- dyn_fit.c ---------------------------------------------------------- */

/* The columns of eq 4 for the offset q = p - c: 1, then for each axis i
 * max(q_i, 0) and min(q_i, 0) (v_2i+s_i, s_i = q_i < 0). */
void obs__dyn_eq4_row(const float q[3], double row[OBS_DYN_TERMS]);

/* Which terms a fit uses: eq 4's seven, a constant, a single gradient
 * (v_mean + g . (p - c), both sides of an axis sharing its slope). */
typedef enum obs__dyn_kind { OBS__DYN_EQ4, OBS__DYN_CONSTANT, OBS__DYN_GRADIENT } obs__dyn_kind;

/* Least squares of one kind for the centre c over the points idx[0..n):
 * fills f (c and coef) and returns the sum of squared residuals over the
 * channels. */
double obs__dyn_fit_centre(const obs__dyn_points *pt, const uint32_t *idx, size_t n,
                           const float c[3], obs__dyn_kind kind, obs_dyn_fit *f);

/* The models of every region: eq 4 with the better of the two centres,
 * tiny regions absorbed, the neighbour regularisation; fills both models
 * of r and the fit's stats. */
obs_status obs__dyn_fit_all(const obs__dyn_points *pt, const obs_dyn_regions *rg,
                            const obs_dyn_params *p, obs_dyn_result *r, char err[OBS_ERR_LEN]);

/* The blended AO of one model for a point's SH at one normal (the
 * stats' measure). */
double obs__dyn_blend_ao(const double *sh, const float n[3], float blend, int order);

/* ---- dyn_shard.c: bake-dynamic over many machines ----------------------- */

/* A part's header as read (dyn_shard.c documents the layout). */
typedef struct obs__dyn_part {
    obs__part_range r;        /* level: the traced fingerprint; items: the valid points */
    uint32_t regions;
    uint64_t points;          /* fingerprint of the regions and their valid points */
    int32_t rays, seed, grid, max_regions;
    float distance_short, distance_long, backface_limit, min_region_size;
    double prep_seconds, trace_seconds;
    uint64_t checksum; /* FNV-1a 64 of the payload */
} obs__dyn_part;

/* dynamic.c: the level's decorators classified as obscura bake does
 * (obs__bake_decor_classify, from p's decorator_source and
 * shrub_density and decorators_json, the text of a decorators file or
 * NULL) and the points' BVH built with them (obs__bake_bvh_new_decor,
 * p's tree_attenuation): the static bake's occluders.  warning gets the
 * classification's warning ("" when none).  w must outlive the BVH; free
 * dc with obs__bake_decor_free, the BVH with obs__bake_bvh_free (both
 * also on failure). */
struct obs__bake_decor;
obs_status obs__dyn_occluders(const obs_bake_scene *scene, const obs__bake_world *w,
                              const obs_dyn_params *p, const char *decorators_json,
                              struct obs__bake_decor *dc, obs__bake_bvh **bvh,
                              char warning[OBS_ERR_LEN], char err[OBS_ERR_LEN]);

/* dyn_bake.c: obs_dyn_bake's steps with a shard's or a merge's job in
 * place of the trace of the valid points (sh NULL: obs_dyn_bake);
 * sh->parts are obs__dyn_parts.  level/part.h's OBS__BAKE_ENTRY. */
obs_status obs__dyn_run_job(const obs_bake_scene *scene, const obs_dyn_desc *desc,
                            obs__part_job *sh, obs_dyn_result *out, char err[OBS_ERR_LEN]);
/* dyn_shard.c: the step, after the points are flagged (pt->count listed,
 * not traced) and before the dropped ones are removed; fills st's trace
 * row.  level: the traced fingerprint (obs__bake_traced_fingerprint),
 * written into a part, checked against the parts read; desc's progress
 * callback follows a shard's trace. */
obs_status obs__dyn_shard_step(obs__part_job *sh, const obs_dyn_desc *desc, uint64_t level,
                               const obs_dyn_regions *rg, const obs_dyn_params *p,
                               const obs__bake_bvh *bvh, obs__dyn_points *pt, obs_dyn_stats *st,
                               char err[OBS_ERR_LEN]);
/* The part file's layout (dyn_shard.c): its header's fields, the
 * parameters they carry (obs__part_header_read reads one, with its
 * checks: magic, version, sizes, the file's length against its count). */
extern const obs__part_format obs__dyn_part_format;
/* FNV-1a 64 of the regions' boxes and the valid points' grid indices,
 * independent of the host's byte order. */
uint64_t obs__dyn_points_fingerprint(const obs_dyn_regions *rg, const obs__dyn_points *pt);
/* The level's triangles, box and fingerprint, for the model file. */
obs_dyn_level obs__dyn_level_of(const obs__bake_world *w);

#endif
