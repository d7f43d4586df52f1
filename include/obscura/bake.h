/* Baking ambient obscurance onto the vertices of a level (obscura bake).
 *
 * The pipeline, one file of core/bake/ per step:
 *   load.c     the file through assimp, node graph kept (meshes, node
 *              transforms, instances, node names, glTF extras)
 *   flatten.c  every (node, mesh) instance in world space, checked
 *   samples.c  surface samples per face: area-proportional, capped
 *   trace.c    obscurance (eq 1) at two distances, Embree closest hits
 *   weld.c     triangle soup welded for the fit
 *   fit.c      least-squares vertex fit (Kavan et al. 2011), CHOLMOD
 *   lod.c      LODs: lod_file.c (a .glb's MSFT_lod), simplify.c
 *              (meshoptimizer), closest.c (nearest full-detail point),
 *              the resampled fit (section 2.2.1)
 *   instanced.c volume.c  instanced trees (section 2.2): local AO per
 *              mesh x a linear global AO per instance (eq 3) fitted to a
 *              sparse SH volume
 *   decor.c occl.c small.c  decorators (section 2.2): their classes, shrubs
 *              as fog and trees semi-transparent (2.1), small ones' scalar
 *              (2.2.1)
 *   glb.c ply.c  the output files
 *   bake.c     the steps in order, timed (obs_bake_run)
 * The paper is "Baked ambient obscurance on the vertices of game levels"
 * (shared/papers/baked-ambient-obscurance-vertices.txt).
 *
 * Matrices are row-major with column vectors, as in obscura.h. */
#ifndef OBSCURA_BAKE_H
#define OBSCURA_BAKE_H

#include <stddef.h>
#include <stdint.h>

#include "obscura/status.h"
#include "obscura/table.h"

#ifdef __cplusplus
extern "C" {
#endif

/* How the fit's mass matrix M of eq 2's data term is made (parameter
 * `mass`). */
#define OBS_BAKE_MASS_LIST(X)                                                  \
    X(OBS_BAKE_MASS_SAMPLES, samples)   /* sum over the samples of w phi_i phi_j */ \
    X(OBS_BAKE_MASS_ANALYTIC, analytic) /* A/12 [[2,1,1],[1,2,1],[1,1,2]] per face */
#define OBS__BAKE_ENUM(value, choice) value,
#define OBS__BAKE_CHOICE(value, choice) "|" #choice
typedef enum obs_bake_mass {
    OBS_BAKE_MASS_DEFAULT,
    OBS_BAKE_MASS_LIST(OBS__BAKE_ENUM)
} obs_bake_mass;

/* Which vertex values the bake writes (parameter `values`): the fit, or
 * one of the two baselines the common tools use, from the same samples,
 * for comparisons (bench/bake_quality.sh). */
#define OBS_BAKE_VALUES_LIST(X)                                                \
    X(OBS_BAKE_VALUES_FIT, fit)             /* the least-squares fit (eq 2) */ \
    X(OBS_BAKE_VALUES_FACE_MEAN, face_mean) /* per-face averaging */           \
    X(OBS_BAKE_VALUES_POINT, point)         /* point sampling at the vertex */
typedef enum obs_bake_values {
    OBS_BAKE_VALUES_DEFAULT,
    OBS_BAKE_VALUES_LIST(OBS__BAKE_ENUM)
} obs_bake_values;

/* The most LOD levels a bake makes (parameter lods). */
#define OBS_BAKE_MAX_LODS 8

/* Where the LODs come from (parameter lod_source). */
#define OBS_BAKE_LOD_SOURCE_LIST(X)                                            \
    X(OBS_BAKE_LOD_SOURCE_FILE, file)         /* the file's MSFT_lod, else simplified */ \
    X(OBS_BAKE_LOD_SOURCE_SIMPLIFY, simplify) /* meshoptimizer's for every mesh */
typedef enum obs_bake_lod_source {
    OBS_BAKE_LOD_SOURCE_DEFAULT,
    OBS_BAKE_LOD_SOURCE_LIST(OBS__BAKE_ENUM)
} obs_bake_lod_source;
/* Which nodes are decorators (parameter `decorator_source`, section 2.2;
 * core/level/decor.c): from the glTF extras, the node names and the
 * --decorators file, from the file alone, or none (all opaque). */
#define OBS_BAKE_DECOR_LIST(X)                                                 \
    X(OBS_BAKE_DECOR_AUTO, auto) /* file, then extras, then names */        \
    X(OBS_BAKE_DECOR_FILE, file) /* only the --decorators file */            \
    X(OBS_BAKE_DECOR_OFF, off)   /* no decorators: everything opaque */
typedef enum obs_bake_decor_mode {
    OBS_BAKE_DECOR_DEFAULT,
    OBS_BAKE_DECOR_LIST(OBS__BAKE_ENUM)
} obs_bake_decor_mode;

/* Which instances take the instanced-decorator path of section 2.2
 * (parameter `instanced`; core/bake/instanced.c): a local AO per mesh
 * baked in isolation times a per-instance linear global AO (eq 3). */
#define OBS_BAKE_INSTANCED_LIST(X)                                             \
    X(OBS_BAKE_INSTANCED_TREES, trees) /* nodes of class tree */              \
    X(OBS_BAKE_INSTANCED_OFF, off)     /* none: every instance traced in place */
typedef enum obs_bake_instanced_mode {
    OBS_BAKE_INSTANCED_DEFAULT,
    OBS_BAKE_INSTANCED_LIST(OBS__BAKE_ENUM)
} obs_bake_instanced_mode;

/* What the vertices of an instanced decorator get (parameter
 * `instanced_values`): the paper's model, or one of its two halves alone
 * for comparisons (bench/bake_instanced.sh). */
#define OBS_BAKE_IVALUES_LIST(X)                                               \
    X(OBS_BAKE_IVALUES_PRODUCT, product) /* local x global (section 2.2) */   \
    X(OBS_BAKE_IVALUES_LINEAR, linear)   /* the linear global fit alone */    \
    X(OBS_BAKE_IVALUES_LOCAL, local)     /* the local AO alone */              \
    X(OBS_BAKE_IVALUES_VOLUME, volume)   /* the volume's AO, what eq 3 fits */
typedef enum obs_bake_ivalues {
    OBS_BAKE_IVALUES_DEFAULT,
    OBS_BAKE_IVALUES_LIST(OBS__BAKE_ENUM)
} obs_bake_ivalues;

/* The decorator rows, shared with bake-dynamic's table
 * (OBS_DYN_PARAM_TABLE, obscura/dynamic.h), which traces the same
 * occluders: one name, default, range and doc for both. */
#define OBS_BAKE_PARAM_DECORATOR_SOURCE(X)                                     \
    X(decorator_source, ENUM, "auto", 0, 0, (OBS_BAKE_DECOR_LIST(OBS__BAKE_CHOICE) + 1), \
      "which nodes are decorators (section 2.2): auto (the --decorators "     \
      "file first, then the glTF extras' class/kind, then words of the node " \
      "name: tree, bush, shrub, hedge, grass; a node without any takes its "   \
      "parent's class), file (the --decorators file only) or off (every "     \
      "node opaque geometry)")
#define OBS_BAKE_PARAM_SHRUB_DENSITY(X)                                        \
    X(shrub_density, FLOAT, 1.0, 0.0, 1000.0, NULL,                            \
      "fog density (1/m) of a shrub's world box when neither the "            \
      "--decorators file nor the node's extras give one: a ray's visibility " \
      "is multiplied by exp(-density * length inside the box) (section 2.1)")
#define OBS_BAKE_PARAM_TREE_ATTENUATION(X)                                     \
    X(tree_attenuation, FLOAT, 0.5, 0.0, 1.0, NULL,                            \
      "fraction of a ray's visibility each tree triangle it crosses takes "   \
      "away: trees are semi-transparent occluders (section 2.1; paper: 50 %)")

/* The bake parameters: X(name, type, default, min, max, choices, doc),
 * type FLOAT, INT or ENUM (choices '|'-separated, stored 1-based).  The
 * CLI's flags, `obscura bake --params` and README's bake table come from
 * this table. */
#define OBS_BAKE_PARAM_TABLE(X)                                                \
    X(distance_short, FLOAT, 2.0, 1e-4, 1e7, NULL,                             \
      "short obscurance distance d (world units): eq 1's kernel "              \
      "rho(x) = 1 - exp(a x), a = ln(0.5) / d, halves visibility at d "        \
      "(paper: 2 m)")                                                          \
    X(distance_long, FLOAT, 300.0, 1e-4, 1e7, NULL,                            \
      "long obscurance distance (paper: 300 m); rays stop at 16 times it, "    \
      "where the kernel is within 2^-16 of 1")                                 \
    X(blend, FLOAT, 0.03, 0.0, 1.0, NULL,                                      \
      "weight of the short distance in _AO = blend _AO_SHORT + (1 - blend) "   \
      "_AO_LONG (paper: 3 % short)")                                           \
    X(rays, INT, 256, 1, 65536, NULL,                                          \
      "cosine-importance-sampled rays per surface sample (paper: 256)")        \
    X(samples_per_face, FLOAT, 4.0, 0.01, 4096.0, NULL,                        \
      "sample budget as a mean per face: the budget is spread over the "      \
      "faces in proportion to their area, each face taking at least 1 and "   \
      "at most max_samples_per_face (section 2.1)")                            \
    X(max_samples_per_face, INT, 16, 1, 4096, NULL,                            \
      "the paper's cap on the samples of one face, so that large coarse "      \
      "distant faces do not take the budget of the playable area")            \
    X(backface_limit, FLOAT, 0.25, 0.0, 1.0, NULL,                             \
      "a sample whose rays hit back faces more often than this fraction is "  \
      "dropped (inside geometry; paper: 25 %); 1 keeps every sample")          \
    X(alpha, FLOAT, 1.0, 0.0, 1e6, NULL,                                       \
      "weight alpha of the edge regulariser in eq 2 (paper: 1)")               \
    X(mass, ENUM, "samples", 0, 0, (OBS_BAKE_MASS_LIST(OBS__BAKE_CHOICE) + 1), \
      "mass matrix of eq 2's data term: samples (from the same samples as "    \
      "b, so the fit is the least-squares fit of the samples and reproduces " \
      "a linear signal exactly) or analytic (the hat basis integrated "        \
      "exactly, A/12 [[2,1,1],[1,2,1],[1,1,2]], scaled by the face's share "   \
      "of valid samples)")                                                     \
    X(values, ENUM, "fit", 0, 0, (OBS_BAKE_VALUES_LIST(OBS__BAKE_CHOICE) + 1),  \
      "vertex values written: fit (the least-squares fit), or a baseline "     \
      "from the same samples for comparisons: face_mean (the area-weighted "   \
      "mean of the samples of the vertex's faces) or point (the sample "       \
      "nearest the vertex); the report's fit rows are then the baseline's")    \
    X(ridge, FLOAT, 1e-4, 0.0, 1.0, NULL,                                      \
      "a small pull of each vertex towards the mean of its own samples (or "   \
      "its neighbours' when it has none), weighted by its lumped area: "       \
      "keeps the system definite where samples are missing; 0 for none")      \
    X(weld_tolerance, FLOAT, 1e-5, 0.0, 0.01, NULL,                            \
      "vertices of one instance closer than this fraction of its box "         \
      "diagonal (quantised) are one vertex for the fit")                       \
    X(weld_angle, FLOAT, 120.0, 0.0, 180.0, NULL,                              \
      "welded vertices must have normals less than this many degrees apart, " \
      "so back-to-back faces stay apart")                                      \
    X(holdout, FLOAT, 0.0, 0.0, 4096.0, NULL,                                  \
      "held-out check: this many samples per face (mean, placed and capped "   \
      "as above, other positions and rays) traced after the fit and compared " \
      "with the fit and the two baselines (the report's holdout rows); 0: off") \
    OBS_BAKE_PARAM_DECORATOR_SOURCE(X)                                         \
    OBS_BAKE_PARAM_SHRUB_DENSITY(X)                                            \
    X(instanced, ENUM, "trees", 0, 0, (OBS_BAKE_INSTANCED_LIST(OBS__BAKE_CHOICE) + 1), \
      "large instanced decorators (section 2.2): trees (every node of class "  \
      "tree whose mesh at least instanced_min tree nodes use gets a local AO " \
      "per mesh, baked alone, times a linear global AO per instance fitted "   \
      "by eq 3 to a sparse volume of spherical visibility) or off (traced "    \
      "in place like any other geometry)")                                     \
    X(instanced_min, INT, 1, 1, 1000000, NULL,                                 \
      "a mesh takes the instanced path when at least this many tree nodes "   \
      "hold it")                                                               \
    X(instanced_values, ENUM, "product", 0, 0, (OBS_BAKE_IVALUES_LIST(OBS__BAKE_CHOICE) + 1), \
      "the instanced decorators' vertex values: product (local x global, "    \
      "the paper's), or for comparisons linear (the global linear function "  \
      "fitted alone, local AO taken as 1), local (the local AO alone) or "    \
      "volume (no model: the volume's AO at each vertex, what eq 3 fits; "    \
      "no _AO_LOCAL nor coefficients written)")                               \
    X(volume_spacing, FLOAT, 2.0, 1e-3, 1e6, NULL,                             \
      "spacing (world units) of the sparse volume's points around the "       \
      "instanced decorators (section 2.2)")                                    \
    X(volume_rays, INT, 128, 4, 65536, NULL,                                   \
      "rays over the sphere per volume point, projected to quadratic SH at "  \
      "both distances")                                                        \
    OBS_BAKE_PARAM_TREE_ATTENUATION(X)                                         \
    X(small_radius, FLOAT, 1.0, 1e-4, 1e4, NULL,                               \
      "radius (world units) of the sphere around a small decorator's "        \
      "origin, added to the half diagonal of its box, over which the "        \
      "surrounding AO is resampled into its one scalar (section 2.2.1)")      \
    X(seed, INT, 1, 0, 2147483647, NULL,                                       \
      "random seed; the bake depends on it alone, not on the thread count")    \
    X(threads, INT, 0, 0, 64, NULL, "ray-tracing threads (0: every core); "     \
      "obscura's --threads N sets it, obscurad's --render-threads bounds it")    \
    X(max_triangles, INT, 100000000, 1, 2147483647, NULL,                      \
      "refuse a level with more triangles than this once instances are "      \
      "flattened")                                                             \
    X(lods, INT, 0, 0, OBS_BAKE_MAX_LODS, NULL,                                \
      "lower levels of detail per mesh (the file's own or meshoptimizer's, "   \
      "see lod_source), valued by resampling the full-detail bake onto their " \
      "surface "                                                               \
      "samples and the fit of eq 2 (section 2.2.1), written as MSFT_lod "      \
      "levels of the .glb's nodes; 0: none")                                   \
    X(lod_source, ENUM, "file", 0, 0,                                          \
      (OBS_BAKE_LOD_SOURCE_LIST(OBS__BAKE_CHOICE) + 1),                        \
      "where level l of a mesh comes from: file (the file's own, glTF "       \
      "MSFT_lod, where it has one; the simplifier's elsewhere) or simplify "  \
      "(the simplifier's for every mesh)")                                     \
    X(lod_ratio, FLOAT, 0.5, 0.01, 0.99, NULL,                                 \
      "target triangle count of LOD level l: lod_ratio^l of the mesh's")       \
    X(lod_error, FLOAT, 0.02, 0.0, 1.0, NULL,                                  \
      "the simplifier's error bound for LOD level l: l times this fraction "  \
      "of the mesh's extent; a level stops short of its ratio rather than "   \
      "move the surface further")                                              \
    X(lod_lock_border, INT, 0, 0, 1, NULL,                                     \
      "1: the simplifier keeps every vertex of a mesh's open border where it "\
      "is (meshoptimizer's LockBorder), so meshes that meet along their "    \
      "borders (terrain tiles, modular walls) meet at every level, whatever " \
      "level each one shows, at the cost of fewer triangles saved; 0: "      \
      "borders simplify too, towards lod_ratio, and neighbours can show "    \
      "cracks between them")                                                  \
    X(lod_check, INT, 0, 0, 1, NULL,                                           \
      "1: also bake each LOD level directly (its samples traced on the LOD " \
      "geometry, every instance at that level, and fitted) and report the "   \
      "RMS of the resampled fit and of the vertex baseline against it, and "  \
      "against the resampled values at held-out samples (one more trace per " \
      "level)")

#define OBS__BAKE_DECL_FLOAT(n) float n;
#define OBS__BAKE_DECL_INT(n) int n;
#define OBS__BAKE_DECL_ENUM(n) int n;

/* Zero-initialised means "all defaults"; obs_bake_param_set records which
 * fields were given (set), so a given 0 stays 0. */
typedef struct obs_bake_params {
#define OBS__BAKE_DECL(name, type, def, lo, hi, choices, doc) OBS__BAKE_DECL_##type(name)
    OBS_BAKE_PARAM_TABLE(OBS__BAKE_DECL)
#undef OBS__BAKE_DECL
    uint64_t set; /* bit i: row i of the table was given */
} obs_bake_params;

/* The rows are the table engine's (obscura/table.h); the names below
 * are the ones the bake's callers have always used. */
typedef obs_table_type obs_bake_param_type;
#define OBS_BAKE_PARAM_FLOAT OBS_TABLE_FLOAT
#define OBS_BAKE_PARAM_INT OBS_TABLE_INT
#define OBS_BAKE_PARAM_ENUM OBS_TABLE_ENUM
typedef obs_table_row obs_bake_param_info;

int obs_bake_param_count(void);
const obs_bake_param_info *obs_bake_param_at(int i); /* NULL out of range */
/* '-' and '_' are the same; NULL when unknown. */
const obs_bake_param_info *obs_bake_param_find(const char *name);
/* Parses value into p, checking the range; the message names the row. */
obs_status obs_bake_param_set(obs_bake_params *p, const char *name, const char *value,
                              char err[OBS_ERR_LEN]);
/* out = in with the fields not given set to their defaults. */
void obs_bake_params_resolve(const obs_bake_params *in, obs_bake_params *out);
void obs_bake_param_format(const obs_bake_params *p, const obs_bake_param_info *pi, char *buf,
                           size_t len);

/* ---- the level -------------------------------------------------------- */

/* One mesh of the file, in its own space.  normals may be NULL. */
typedef struct obs_bake_mesh {
    char *name;
    size_t vertex_count, triangle_count;
    float *positions; /* 3 per vertex */
    float *normals;   /* 3 per vertex, unit, or NULL */
    uint32_t *indices; /* 3 per triangle, each < vertex_count */
    int two_sided;    /* its material is double-sided */
    int material;     /* index into the scene's materials, -1 for none */
} obs_bake_mesh;

/* A material as far as the output carries it: no textures. */
typedef struct obs_bake_material {
    char *name;
    float base_color[4]; /* linear RGBA (glTF base colour, else diffuse) */
    int double_sided;
    int blend;           /* glTF alphaMode BLEND */
} obs_bake_material;

/* One node of the graph.  Nodes are depth first, a parent before its
 * children; world = parent's world * local. */
typedef struct obs_bake_node {
    char *name;
    int parent;          /* index, -1 for the root */
    float local[16], world[16];
    uint32_t *meshes;    /* indices into the meshes */
    uint32_t mesh_count;
    char *extras;        /* the node's extras (glTF) as JSON text, or NULL */
} obs_bake_node;

typedef struct obs_bake_scene {
    obs_bake_mesh *meshes;
    size_t mesh_count;
    obs_bake_material *materials;
    size_t material_count;
    obs_bake_node *nodes;
    size_t node_count;
    size_t instance_count;  /* (node, mesh) pairs */
    size_t world_triangles; /* triangles with instances flattened */
    /* The file's own LODs (a .glb's MSFT_lod, core/level/lod_file.c):
     * level l of mesh m is file_lods[(l - 1) * mesh_count + m], with no
     * triangles where the file has none; file_lod_error the reason they
     * could not be read (the bake refuses --lods then), else NULL. */
    obs_bake_mesh *file_lods;
    size_t file_lod_levels;
    char *file_lod_error;
} obs_bake_scene;

/* Loads a level through assimp (glTF/GLB, AC3D, OBJ, ...), keeping the node
 * graph, and a .glb's own LODs (MSFT_lod) into file_lods.  Refuses a file without triangles, with non-finite coordinates, or
 * with more than max_triangles once flattened (0: no limit), naming the
 * mesh.  Free with obs_bake_scene_free(). */
obs_status obs_bake_load(const char *path, size_t max_triangles, obs_bake_scene *out,
                         char err[OBS_ERR_LEN]);
void obs_bake_scene_free(obs_bake_scene *s);

/* ---- the bake --------------------------------------------------------- */

/* Per-vertex results of one instance: node `node`'s mesh `mesh`, one value
 * per vertex of the mesh. */
typedef struct obs_bake_instance {
    uint32_t node, mesh;
    float *ao, *ao_short, *ao_long;
    /* Instanced decorators (section 2.2, parameter instanced): ao_local
     * the mesh's local AO per vertex (the blend of its two distances; NULL
     * for other instances) and global[c] the coefficients (g0, gx, gy, gz)
     * of the linear global AO G(q) = g0 + gx qx + gy qy + gz qz, q the
     * vertex's position in the mesh's own space, for c = 0 the blend
     * (_AO), 1 short, 2 long; ao is ao_local x G (clamped to [0, 1]). */
    float *ao_local;
    float global[3][4];
} obs_bake_instance;

/* Stages of the bake, in order (the report's rows). */
#define OBS_BAKE_STAGE_LIST(X)                                                 \
    X(flatten, "instances to world space")                                     \
    X(samples, "surface samples")                                              \
    X(bvh, "Embree BVH build")                                                 \
    X(trace, "ray trace samples")                                              \
    X(weld, "weld")                                                            \
    X(assemble, "least-squares system")                                        \
    X(solve, "CHOLMOD factorise and solve")                                    \
    X(local, "instanced: local AO of each mesh alone")                         \
    X(volume, "instanced: sparse volume of spherical visibility")              \
    X(global, "instanced: eq 3 fits per instance")                             \
    X(lod, "LOD simplify, resample and solve")
typedef enum obs_bake_stage {
#define OBS__BAKE_STAGE(n, d) OBS_BAKE_STAGE_##n,
    OBS_BAKE_STAGE_LIST(OBS__BAKE_STAGE)
#undef OBS__BAKE_STAGE
    OBS_BAKE_STAGE_COUNT
} obs_bake_stage;
const char *obs_bake_stage_name(int stage);

typedef struct obs_bake_stats {
    double seconds[OBS_BAKE_STAGE_COUNT];
    size_t instances, triangles, degenerate_triangles, vertices;
    size_t faces_against_normals; /* winding disagrees with the normals */
    size_t two_sided_triangles;   /* of double-sided materials: no back */
    size_t samples, samples_dropped_backface;
    uint64_t rays;
    size_t welded_vertices, interior_edges, boundary_edges, nonmanifold_edges;
    size_t vertices_without_samples; /* valued from their neighbours */
    size_t vertices_isolated;        /* no neighbour had a value either */
    /* RMS over the valid samples (weights w) of the fitted signal minus
     * the traced value, [0] short, [1] long; and the same for the two
     * baselines from the same rays: the vertex value the mean of the
     * samples of its faces (per-face averaging, area weighted), and the
     * nearest samples' value (point sampling at the vertex). */
    double residual_fit[2], residual_face_mean[2], residual_point[2];
    /* The same three at held-out samples (parameter holdout): other
     * positions, other rays, never fitted; 0 when holdout is 0. */
    double holdout_fit[2], holdout_face_mean[2], holdout_point[2];
    size_t holdout_samples;
    double regulariser_energy[2]; /* alpha x^T R x of the solution */
    double ao_mean, ao_min, ao_max;
    /* LODs (parameter lods): per level l (index l - 1), over every
     * instance; the RMS of the fit and of the vertex baseline (each LOD
     * vertex the full-detail value at its nearest full-detail point)
     * against the resampled values at the LOD's samples, and, with
     * lod_check, of both and of the resampled values themselves against
     * the direct bake of the LOD (its samples traced on the LOD geometry
     * and fitted), over the LOD's samples; lod_direct_residual is that
     * bake's own in-sample RMS (residual_fit's kind: the trace's noise
     * and what the fit cannot follow). */
    size_t lod_levels;
    size_t lod_triangles[OBS_BAKE_MAX_LODS], lod_vertices[OBS_BAKE_MAX_LODS];
    size_t lod_welded[OBS_BAKE_MAX_LODS], lod_samples[OBS_BAKE_MAX_LODS];
    size_t lod_file_meshes[OBS_BAKE_MAX_LODS]; /* meshes whose level is the file's own */
    double lod_fit[OBS_BAKE_MAX_LODS][2], lod_vertex[OBS_BAKE_MAX_LODS][2];
    double lod_traced_fit[OBS_BAKE_MAX_LODS][2], lod_traced_vertex[OBS_BAKE_MAX_LODS][2];
    double lod_traced_resampled[OBS_BAKE_MAX_LODS][2];
    double lod_direct_residual[OBS_BAKE_MAX_LODS][2];
    /* lod_check: the fit's and the baseline's RMS against the resampled
     * values at held-out LOD samples (the holdout's seed; never fitted) */
    double lod_holdout_fit[OBS_BAKE_MAX_LODS][2], lod_holdout_vertex[OBS_BAKE_MAX_LODS][2];
    size_t lod_traced_samples[OBS_BAKE_MAX_LODS];
    /* the lod stage's parts: simplify, resample, fit, check */
    double lod_seconds[4];
    /* Decorators (section 2.2, core/level/decor.c): nodes per class, none,
     * shrub, tree, small; and the classification's warning (entries of
     * the decorators file that match no node), "" when none. */
    size_t decorator_nodes[4];
    char decorator_warning[OBS_ERR_LEN];
    /* Instanced decorators (section 2.2, core/bake/instanced.c): meshes
     * baked alone, instances fitted, the volume's bricks and points (and
     * those inside geometry by the back-face rule, left out of the
     * interpolation), its rays, and the RMS over the instances' vertices
     * of the volume's AO minus the model's (eq 3's residual, blend). */
    size_t instanced_meshes, instanced_instances, volume_bricks, volume_points,
        volume_points_inside;
    uint64_t volume_rays;
    double instanced_residual;
    /* Small decorators (section 2.2.1) given one scalar, and those whose
     * rays met no geometry (they keep their own fit). */
    size_t small_decorators, small_unresolved;
} obs_bake_stats;

typedef struct obs_bake_result {
    obs_bake_instance *instances;
    size_t instance_count;
    /* Small decorators (section 2.2.1): 3 per node, _AO, _AO_SHORT,
     * _AO_LONG, the one scalar of a small decorator resampled from the
     * AO around it (its vertices have it too), NaN for other nodes; NULL
     * (node_count 0) when the level has none. */
    size_t node_count;
    float *node_ao;
    obs_bake_stats stats;
    /* LODs (parameter lods; core/bake/lod.c): level l = 1 .. lod_levels of
     * the scene's mesh m is lod_meshes[(l - 1) * mesh_count + m], in the
     * mesh's own space; instance i's values at level l are
     * lod_instances[(l - 1) * instance_count + i] (node and mesh those of
     * instances[i], one value per vertex of that level's mesh).  Owned by
     * the result. */
    size_t lod_levels;
    obs_bake_mesh *lod_meshes;
    obs_bake_instance *lod_instances;
} obs_bake_result;

typedef struct obs_bake_desc {
    obs_bake_params params;
    /* Called from the tracing threads (serialised) with the samples done
     * so far, after each batch of samples, and with every sample done
     * during the instanced trees' stages; may be NULL.  A nonzero return
     * stops the bake: obs_bake_run returns OBS_CANCELLED. */
    int (*progress)(void *user, size_t done, size_t total);
    void *progress_user;
    /* The text of a decorators file (README's bake section, parameter
     * decorator_source), or NULL; read by the bake, kept by the caller. */
    const char *decorators_json;
} obs_bake_desc;

/* Bakes the level: per-vertex obscurance for every instance.  Free with
 * obs_bake_result_free(). */
obs_status obs_bake_run(const obs_bake_scene *scene, const obs_bake_desc *desc,
                        obs_bake_result *out, char err[OBS_ERR_LEN]);
void obs_bake_result_free(obs_bake_result *r);

/* ---- a bake spread over many machines (shard.c) ------------------------ */

/* Traces shard `index` of `count` (0 <= index < count) of the level's
 * surface samples: the contiguous range [index n / count, (index + 1) n /
 * count) of the n samples obs_bake_run makes, each with the rays it gets
 * there, and writes them to `path` as a part (core/bake/shard.c has the
 * layout).  st (may be NULL) gets the counts and the trace's times. */
obs_status obs_bake_shard(const obs_bake_scene *scene, const obs_bake_desc *desc, int index,
                          int count, const char *path, obs_bake_stats *st, char err[OBS_ERR_LEN]);
/* The parts (any order; every shard of one split once, traced from this
 * level) read back and fitted: the result obs_bake_run gives.  The trace
 * parameters (rays, seed, the sample budget, the distances, the back-face
 * limit) not given in desc are the parts'; given ones must agree; desc's
 * parameters hold those the merge used once it returns.  The
 * stats' bvh and trace rows are the parts' times summed (plus the
 * reading); holdout samples are traced here.  Free with
 * obs_bake_result_free(). */
obs_status obs_bake_merge(const obs_bake_scene *scene, obs_bake_desc *desc,
                          const char *const *parts, size_t n, obs_bake_result *out,
                          char err[OBS_ERR_LEN]);

/* The text of a decorators file checked as the bake reads it (JSON, the
 * rules' keys, classes and densities), without a level: what obscurad
 * refuses a bake job for before it queues it.  *rules (may be NULL): the
 * count of rules.  The error names the entry, as the bake's. */
obs_status obs_bake_decorators_check(const char *text, size_t *rules, char err[OBS_ERR_LEN]);

/* ---- what the bake's rays meet, for the per-pixel reference ------------ */

/* The level's occluders as the bake's rays see them (core/level/occl.c):
 * the opaque triangles, the shrubs' fog boxes and the trees'
 * semi-transparent triangles (section 2.1), from the decorators of s
 * (params: decorator_source, shrub_density, tree_attenuation;
 * max_triangles, OBS_TOO_LARGE past it once flattened; decorators_json:
 * the text of a decorators file or NULL).  *out is NULL
 * when the level has no shrub, tree or small decorator: every surface is
 * then opaque, as the scene itself.  warning (may be NULL) receives the
 * classification's warning, "" when none.  Free with
 * obs_bake_occluders_free(); s may be freed before. */
typedef struct obs_bake_occluders obs_bake_occluders;
obs_status obs_bake_occluders_new(const obs_bake_scene *s, const obs_bake_params *params,
                                  const char *decorators_json, obs_bake_occluders **out,
                                  char warning[OBS_ERR_LEN], char err[OBS_ERR_LEN]);
void obs_bake_occluders_free(obs_bake_occluders *o);

/* ---- output ----------------------------------------------------------- */

/* glTF 2.0 binary: the node graph as loaded (names, transforms, extras),
 * every instance its own mesh with POSITION, NORMAL, indices and the
 * float attributes _AO, _AO_SHORT, _AO_LONG (and COLOR_0 = _AO as grey
 * when color is set); the materials' names, base colours, alpha modes
 * and sidedness (no textures).  With LODs each node that holds meshes
 * lists its LOD nodes in the MSFT_lod extension: nodes outside the
 * scene's graph, the same transform, the levels' meshes with the same
 * attributes. */
obs_status obs_bake_write_glb(const char *path, const obs_bake_scene *scene,
                              const obs_bake_result *r, int color, char err[OBS_ERR_LEN]);
/* Binary PLY of the world-space level: x y z (nx ny nz) quality (= _AO)
 * ao_short ao_long per vertex, triangles. */
obs_status obs_bake_write_ply(const char *path, const obs_bake_scene *scene,
                              const obs_bake_result *r, char err[OBS_ERR_LEN]);

#ifdef __cplusplus
}
#endif

#endif
