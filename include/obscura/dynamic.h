/* Baked obscurance for dynamic objects (obscura bake-dynamic): section 2.3
 * and 3 of "Baked ambient obscurance on the vertices of game levels"
 * (shared/papers/baked-ambient-obscurance-vertices.txt).
 *
 * The steps, one file of core/bake/ each:
 *   regions.c    the regions: boxes and their face adjacency, read from a
 *                JSON or built by an adaptive subdivision of the level's
 *                empty space
 *   probes.c     the 8x8x8 grid of each region, its one-bit valid flags,
 *                spherical obscurance at the valid points (Embree through
 *                trace.c)
 *   sh.c         quadratic spherical harmonics: projection, the clamped
 *                cosine convolution, evaluation
 *   dyn_fit.c    eq 4 per region (two candidate centres), tiny regions
 *                absorbed, the neighbour regularisation (block coordinate
 *                descent)
 *   dyn_model.c  the runtime: evaluation, the temporal blender, the JSON
 *                file an engine loads
 *   dyn_measure.c  probe paths: the model against ray-traced obscurance
 *   dyn_params.c the parameter table (OBS_DYN_PARAM_TABLE)
 *   dynamic.c    the steps in order (obs_dyn_bake)
 *
 * Positions are in the level's world space (the node graph applied). */
#ifndef OBSCURA_DYNAMIC_H
#define OBSCURA_DYNAMIC_H

#include <stddef.h>
#include <stdint.h>

#include "obscura/bake.h"
#include "obscura/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 9 quadratic SH coefficients at each of the two distances (short, long):
 * channel 9 * d + k, k the SH index l * (l + 1) + m. */
#define OBS_DYN_SH 9
#define OBS_DYN_CHANNELS 18
/* v_mean and the 6 directional derivatives of eq 4, in the paper's order
 * +x, -x, +y, -y, +z, -z. */
#define OBS_DYN_TERMS 7

/* The parameter table of obscura bake-dynamic, the pattern of
 * OBS_BAKE_PARAM_TABLE (its own table, its own struct):
 * X(name, type, default, min, max, choices, doc). */
#define OBS_DYN_PARAM_TABLE(X)                                                 \
    X(distance_short, FLOAT, 2.0, 1e-4, 1e6, NULL,                             \
      "the short distance d of the kernel rho(x) = 1 - exp(a x), "             \
      "a = ln 0.5 / d (section 2; paper: 2 m)")                                \
    X(distance_long, FLOAT, 300.0, 1e-4, 1e6, NULL,                            \
      "the long distance (paper: 300 m)")                                      \
    X(blend, FLOAT, 0.03, 0.0, 1.0, NULL,                                      \
      "weight of the short distance in the evaluated AO (section 3: 3 %)")    \
    X(rays, INT, 1024, 8, 65536, NULL,                                         \
      "rays over the sphere per valid point (section 4: 1024 for volume "      \
      "points)")                                                               \
    X(grid, INT, 8, 2, 32, NULL,                                               \
      "points per axis of each region's grid (section 2.3: 8 x 8 x 8)")        \
    X(backface_limit, FLOAT, 0.25, 0.0, 1.0, NULL,                             \
      "a point whose rays hit back faces more often than this fraction is "   \
      "inside geometry: not valid, and dropped before the fit")                \
    X(max_regions, INT, 64, 1, 100000, NULL,                                   \
      "regions built without --regions: boxes holding geometry are split at " \
      "the middle of their longest side, largest first, until this many")     \
    X(min_region_size, FLOAT, 1.0, 1e-4, 1e6, NULL,                            \
      "regions built without --regions: a box whose longest side is shorter " \
      "than this is not split")                                                \
    X(absorb_points, INT, 24, 0, 32768, NULL,                                  \
      "a region with fewer valid points than this is absorbed into its most " \
      "compatible neighbour (section 3); 0: none")                             \
    X(beta, FLOAT, 1.0, 0.0, 1e6, NULL,                                        \
      "weight beta of the neighbour regularisation (section 2.3); 0: off")     \
    X(iterations, INT, 8, 0, 10000, NULL,                                      \
      "sweeps of block coordinate descent over the regions")                   \
    X(boundary_points, INT, 1, 1, 16, NULL,                                    \
      "neighbours are compared at the centre of their shared face (1, the "    \
      "paper's b_ij) or at an N x N grid over it sharing w_ij")                \
    X(holdout, FLOAT, 0.0, 0.0, 0.9, NULL,                                     \
      "this fraction of each region's valid points is held back from the fit " \
      "and measures eq 4 against a constant and a single gradient (the "      \
      "report); 0: off")                                                       \
    /* the static bake's occluders (section 2.1), its rows (obscura/bake.h) */ \
    OBS_BAKE_PARAM_DECORATOR_SOURCE(X)                                         \
    OBS_BAKE_PARAM_SHRUB_DENSITY(X)                                            \
    OBS_BAKE_PARAM_TREE_ATTENUATION(X)                                         \
    X(seed, INT, 1, 0, 2147483647, NULL,                                       \
      "random seed; the result depends on it alone, not on the thread count") \
    X(threads, INT, 0, 0, 64, NULL, "ray-tracing threads (0: every core); "     \
      "obscura's --threads N sets it, obscurad's --render-threads bounds it")    \
    X(max_triangles, INT, 100000000, 1, 2147483647, NULL,                      \
      "refuse a level with more triangles than this once instances are "      \
      "flattened")

/* Zero-initialised means "all defaults"; set records the rows given. */
typedef struct obs_dyn_params {
#define OBS__DYN_DECL(name, type, def, lo, hi, choices, doc) OBS__BAKE_DECL_##type(name)
    OBS_DYN_PARAM_TABLE(OBS__DYN_DECL)
#undef OBS__DYN_DECL
    uint64_t set;
} obs_dyn_params;

/* The rows share obs_bake_param_info, the table engine's row (offset into
 * obs_dyn_params). */
int obs_dyn_param_count(void);
const obs_bake_param_info *obs_dyn_param_at(int i); /* NULL out of range */
const obs_bake_param_info *obs_dyn_param_find(const char *name); /* '-' = '_' */
obs_status obs_dyn_param_set(obs_dyn_params *p, const char *name, const char *value,
                             char err[OBS_ERR_LEN]);
void obs_dyn_params_resolve(const obs_dyn_params *in, obs_dyn_params *out);
void obs_dyn_param_format(const obs_dyn_params *p, const obs_bake_param_info *pi, char *buf,
                          size_t len);

/* ---- regions ---------------------------------------------------------- */

typedef struct obs_dyn_box {
    float lo[3], hi[3];
} obs_dyn_box;

/* Boxes and their adjacency: edge k joins regions edge[2k] < edge[2k+1]. */
typedef struct obs_dyn_regions {
    size_t count, edge_count;
    obs_dyn_box *box;
    uint32_t *edge;
} obs_dyn_regions;

/* Reads the JSON of --regions (README, "Regions file"):
 *   {"regions": [{"min": [x, y, z], "max": [x, y, z]}, ...],
 *    "adjacency": [[i, j], ...]}
 * adjacency optional (absent: boxes that share a face of positive area).
 * Refuses, naming the region: a box with min >= max on an axis, two boxes
 * overlapping with positive volume, an adjacency pair out of range, of a
 * region with itself, given twice, or of boxes that share no face.  Free
 * with obs_dyn_regions_free(). */
obs_status obs_dyn_regions_read(const char *path, obs_dyn_regions *out, char err[OBS_ERR_LEN]);
obs_status obs_dyn_regions_parse(const char *json, obs_dyn_regions *out, char err[OBS_ERR_LEN]);
void obs_dyn_regions_free(obs_dyn_regions *r);

/* ---- the model (what an engine loads) --------------------------------- */

/* One fitted model of eq 4: AO channel k at p is
 *   coef[k][0] + sum_i (p - c)_i coef[k][1 + 2 i + s_i],  s_i = (p - c)_i < 0
 * and the SH coefficients are already convolved with the clamped cosine
 * (divided by pi), so AO(n) = sum_k coef Y_k(n). */
typedef struct obs_dyn_fit {
    float c[3];
    float coef[OBS_DYN_CHANNELS][OBS_DYN_TERMS];
} obs_dyn_fit;

typedef struct obs_dyn_model_region {
    obs_dyn_box box;
    int32_t model;   /* index into models, or -1: no model (no valid point) */
    int32_t absorbed; /* 1: a tiny region using its neighbour's model */
    uint32_t points; /* valid points fitted */
} obs_dyn_model_region;

/* The level a model was baked from (the file's "level"): its triangles
 * once instances are flattened, their box, and the fingerprint of the
 * flattened level that the parts of obscura bake and bake-dynamic carry.
 * triangles 0: unknown (a file without it). */
typedef struct obs_dyn_level {
    uint64_t fingerprint, triangles;
    float lo[3], hi[3];
} obs_dyn_level;

typedef struct obs_dyn_model {
    obs_dyn_level level;
    float distance[2], blend;
    size_t region_count, model_count, edge_count;
    obs_dyn_model_region *regions;
    obs_dyn_fit *models;
    uint32_t *edge; /* 2 per edge, as obs_dyn_regions */
} obs_dyn_model;

void obs_dyn_model_free(obs_dyn_model *m);

/* SH evaluated: `linear` (bands 0 and 1, the paper's engine) or
 * `quadratic` (bands 0 to 2). */
typedef enum obs_dyn_sh_order { OBS_DYN_LINEAR = 1, OBS_DYN_QUADRATIC = 2 } obs_dyn_sh_order;

/* The region holding p (the first box containing it), or, when none
 * does, the nearest region with a model (p is then clamped into its
 * box).  -1 when the model has no region with a model. */
int obs_dyn_model_region_at(const obs_dyn_model *m, const float p[3], float clamped[3]);

/* AO at point p for the unit normal n: ao[0] short, ao[1] long, ao[2]
 * the blend (section 3), each clamped to [0, 1].  Returns the region
 * used, or -1 (ao all 1) when there is none. */
int obs_dyn_eval(const obs_dyn_model *m, const float p[3], const float n[3],
                 obs_dyn_sh_order order, float ao[3]);
/* The same with one region's model, p not clamped (the boundary
 * jumps). */
void obs_dyn_eval_fit(const obs_dyn_fit *f, const float p[3], const float n[3],
                      obs_dyn_sh_order order, float ao[3]);

/* Temporal blending (section 2.3): the value moves towards the current
 * region's value with exponential decay, value += (target - value) *
 * (1 - exp(-dt / tau)).  Zero-initialised: the first step takes the
 * target. */
typedef struct obs_dyn_blender {
    float value[3];
    int primed, region;
} obs_dyn_blender;
/* Steps b by dt seconds at p, n; tau the decay time (<= 0: no blending).
 * Returns the region used. */
int obs_dyn_blend_step(obs_dyn_blender *b, const obs_dyn_model *m, const float p[3],
                       const float n[3], obs_dyn_sh_order order, float dt, float tau,
                       float ao[3]);

/* The model as JSON (README, "Dynamic model file").  Caller-owned path. */
obs_status obs_dyn_model_write(const char *path, const obs_dyn_model *m, char err[OBS_ERR_LEN]);
/* Reads what obs_dyn_model_write wrote, checked.  Free with
 * obs_dyn_model_free(). */
obs_status obs_dyn_model_read(const char *path, obs_dyn_model *out, char err[OBS_ERR_LEN]);

/* ---- the bake --------------------------------------------------------- */

/* Stages, in order (the report's rows). */
#define OBS_DYN_STAGE_LIST(X)                                                  \
    X(flatten, "instances to world space")                                     \
    X(bvh, "Embree BVH build")                                                 \
    X(regions, "regions (read or built)")                                      \
    X(valid, "valid points")                                                   \
    X(trace, "spherical obscurance at the valid points")                       \
    X(fit, "eq 4, absorption, regularisation")
typedef enum obs_dyn_stage {
#define OBS__DYN_STAGE(n, d) OBS_DYN_STAGE_##n,
    OBS_DYN_STAGE_LIST(OBS__DYN_STAGE)
#undef OBS__DYN_STAGE
    OBS_DYN_STAGE_COUNT
} obs_dyn_stage;
const char *obs_dyn_stage_name(int stage);

typedef struct obs_dyn_stats {
    double seconds[OBS_DYN_STAGE_COUNT];
    size_t regions, edges, regions_without_points, regions_absorbed, models;
    size_t grid_points, points_inside, points_hidden, points_backface, points_valid;
    uint64_t rays;
    size_t centre_of_mass_kept; /* models whose centre is the valid points' */
    /* RMS of the AO (blended, quadratic SH, the 6 axis normals) of the
     * model minus the point's own traced SH: at the fitted points for
     * the models as fitted and as regularised; at held-back points
     * (holdout) for eq 4, a constant and a single gradient. */
    double fit_rms, fit_rms_regularised;
    size_t holdout_points;
    double holdout_eq4, holdout_constant, holdout_gradient;
    /* |M_i(b_ij) - M_j(b_ij)| over the edges (blended AO, 6 axis
     * normals): mean and max, before and after the regularisation. */
    double jump_mean[2], jump_max[2];
    double energy[2]; /* the regularisation's E before and after */
    /* Decorators (section 2.1, as obscura bake): nodes per class (none,
     * shrub, tree, small), and the classification's warning ("" when
     * none: entries of the --decorators file that match no node). */
    size_t decorator_nodes[4];
    char decorator_warning[OBS_ERR_LEN];
} obs_dyn_stats;

typedef struct obs_dyn_desc {
    obs_dyn_params params;
    const obs_dyn_regions *regions; /* NULL: built from the level */
    /* The text of a decorators file (README's bake section, parameter
     * decorator_source), or NULL; read by the bake, kept by the caller. */
    const char *decorators_json;
    void (*progress)(void *user, size_t done, size_t total);
    void *progress_user;
} obs_dyn_desc;

typedef struct obs_dyn_result {
    obs_dyn_model model;    /* regularised */
    obs_dyn_model original; /* the same before the regularisation */
    obs_dyn_stats stats;
} obs_dyn_result;

/* The dynamic-object model of a level.  Free with obs_dyn_result_free(). */
obs_status obs_dyn_bake(const obs_bake_scene *scene, const obs_dyn_desc *desc,
                        obs_dyn_result *out, char err[OBS_ERR_LEN]);
void obs_dyn_result_free(obs_dyn_result *r);

/* ---- the bake over many machines (dyn_shard.c) -------------------------- */

/* Traces shard `index` of `count` (0 <= index < count) of the valid
 * points obs_dyn_bake makes (the same regions and points: the regions
 * are built, or desc->regions, and the points flagged, by every shard):
 * the contiguous range [index n / count, (index + 1) n / count) of the n
 * valid points, each with the directions it gets there, written to
 * `path` as a part (core/dynamic/dyn_shard.c has the layout).  st (may be
 * NULL) gets the counts of the shard's points and the trace's time. */
obs_status obs_dyn_bake_shard(const obs_bake_scene *scene, const obs_dyn_desc *desc, int index,
                              int count, const char *path, obs_dyn_stats *st,
                              char err[OBS_ERR_LEN]);
/* The parts (any order; every shard of one split once, traced from this
 * level over these regions) read back and fitted: the result obs_dyn_bake
 * gives.  The parameters the parts carry (rays, seed, grid, the
 * distances, the back-face limit, max_regions, min_region_size) not
 * given in desc are the parts'; given ones must agree; desc's parameters
 * hold those the merge used once it returns.  The stats' trace row is
 * the parts' times summed (plus the reading).  Free with
 * obs_dyn_result_free(). */
obs_status obs_dyn_bake_merge(const obs_bake_scene *scene, obs_dyn_desc *desc,
                              const char *const *parts, size_t n, obs_dyn_result *out,
                              char err[OBS_ERR_LEN]);

/* ---- measurement -------------------------------------------------------- */

typedef struct obs_dyn_path_stats {
    size_t paths, points, crossings;
    /* evaluated AO (blended) minus ray-traced eq 1 at the path's points
     * and normals: RMS and mean, linear and quadratic SH */
    double rms[2], bias[2];
    /* the same for the point's own quadratic SH from `rays` (of the
     * params) sphere rays, without eq 4: the projection's share */
    double rms_point_sh;
    double rms_unregularised; /* rms[1] for the model before the regularisation */
    /* |AO(k+1) - AO(k)| along the paths at steps that cross a region
     * boundary, and at the other steps: mean, max; [0] unregularised, [1]
     * regularised, [2] regularised and temporally blended */
    double cross_mean[3], cross_max[3], step_mean[3];
} obs_dyn_path_stats;

/* `paths` straight paths, each between two points outside geometry that
 * see each other, drawn in the regions' bounding box (dyn_measure.c),
 * `steps` points along each; at each point
 * two normals (up +y and one drawn at random) are traced with `rays`
 * cosine-weighted rays (eq 1) and evaluated on the models; tau is the
 * blender's decay time in steps.  The reference traces the occluders the
 * bake does (p's decorator rows, decorators_json: the text of a
 * decorators file or NULL): eq 1's rho times each ray's transmittance. */
obs_status obs_dyn_measure_paths(const obs_bake_scene *scene, const obs_dyn_result *r,
                                 const obs_dyn_params *p, const char *decorators_json,
                                 int paths, int steps, int rays,
                                 float tau, obs_dyn_path_stats *out, char err[OBS_ERR_LEN]);

#ifdef __cplusplus
}
#endif

#endif
