/* Scenes of libobscura: triangle meshes loaded through assimp (OBJ, PLY,
 * glTF/GLB, OFF, ...) and rasterised into a G-buffer on the GL context.
 * The ray-traced reference over the same scenes is in reference.h.
 *
 * Conventions are those of obscura.h: world space as the file gives it
 * (node transforms applied), matrices row-major with column vectors,
 * images row-major with row 0 at the top. */
#ifndef OBSCURA_SCENE_H
#define OBSCURA_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "obscura/dynamic.h"
#include "obscura/obscura.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Planar depth written where no geometry is (Blender's value; the AO
 * chain takes depth >= 1e9 as sky). */
#define OBS_SKY_DEPTH 1e10f

/* The largest coordinate (world space, in magnitude) of a scene that
 * gbuffer, reference and both bakes take: a planar depth of 1e9 and beyond
 * is sky to the AO chain, float spacing there is 64 units, and the
 * products of coordinates the stages compute overflow float or lose
 * their digits not far above (measured: the rasteriser's normals are NaN
 * from 1e11, Embree finds no hit at 1e10 and aborts on a ray origin past
 * 1.844e18).  obs_scene_check and the bake's flatten refuse a vertex
 * beyond it, with OBS_SCENE_COORD_RULE in the message. */
#define OBS_SCENE_MAX_COORD 1e9f
#define OBS_SCENE_COORD_RULE                                                                   \
    "a coordinate beyond +-1e9 (the bound of obscura's scenes: depth 1e9 is sky, float "        \
    "spacing there is 64 units and products of coordinates overflow; scale the scene down or "  \
    "move it towards the origin)"

/* 1 when a coordinate of p lies beyond OBS_SCENE_MAX_COORD. */
static inline int obs_scene_coord_beyond(const float p[3])
{
    return p[0] > OBS_SCENE_MAX_COORD || p[0] < -OBS_SCENE_MAX_COORD ||
           p[1] > OBS_SCENE_MAX_COORD || p[1] < -OBS_SCENE_MAX_COORD ||
           p[2] > OBS_SCENE_MAX_COORD || p[2] < -OBS_SCENE_MAX_COORD;
}

/* One mesh of a scene file: its names (assimp's mesh name, and the name
 * of the first node that holds it; either may be "") and its run of
 * triangles. */
typedef struct obs_scene_mesh {
    char *name, *node;
    size_t first_triangle, triangle_count;
    int dynamic; /* a dynamic object's (obs_scene_load_baked_dynamic) */
} obs_scene_mesh;

/* An indexed triangle mesh in world space.  Arrays are malloc'd;
 * obs_scene_free() releases them.  normals and albedo may be NULL:
 * without normals the rasteriser uses each triangle's geometric normal;
 * albedo is per vertex, linear RGB, present only when some material of
 * the file has a diffuse or base colour.  opacity is per triangle, in
 * [0, 1], present only when some material is not opaque (assimp's
 * AI_MATKEY_OPACITY, glTF's base colour alpha with alphaMode BLEND) or
 * obs_scene_set_opacity() set one; NULL means opaque. */
typedef struct obs_scene {
    size_t vertex_count;
    float *positions;    /* 3 per vertex */
    float *normals;      /* 3 per vertex, unit length, or NULL */
    float *albedo;       /* 3 per vertex, or NULL */
    size_t triangle_count;
    uint32_t *indices;   /* 3 per triangle, each < vertex_count */
    float *opacity;      /* 1 per triangle, or NULL (opaque) */
    size_t mesh_count;   /* the file's meshes, in triangle order; 0 for */
    obs_scene_mesh *meshes; /* a scene built in memory */
    float bounds_min[3]; /* filled by obs_scene_check() */
    float bounds_max[3];
    /* A baked level (obs_scene_load_baked): 3 per vertex, the attributes
     * _AO, _AO_SHORT, _AO_LONG of obscura bake; baked_mask bit k set when
     * attribute k is in every primitive (bit 0 always).  NULL otherwise. */
    float *baked;
    unsigned baked_mask;
} obs_scene;

/* Loads every triangle of a mesh file through assimp: meshes are
 * triangulated, node transforms applied, points and lines dropped, and
 * missing normals generated per face.  Fails with OBS_IO when the file
 * cannot be opened, OBS_BAD_FILE when assimp cannot read it or it holds
 * no triangle.  Caller frees with obs_scene_free(). */
obs_status obs_scene_load(const char *path, obs_scene *out, char err[OBS_ERR_LEN]);

/* Loads a level that obscura bake wrote (glTF 2.0 binary, bake.h's
 * obs_bake_write_glb) with its per-vertex _AO, _AO_SHORT and _AO_LONG in
 * `baked` (assimp drops custom attributes, so the .glb is read here): node
 * transforms (matrix or TRS) applied, world space, normals when present,
 * base colours as albedo; only the file's own binary chunk.  Fails with
 * OBS_MISSING_CHANNEL, naming the mesh, when a primitive has no _AO;
 * OBS_BAD_FILE for a file that is not such a .glb or whose accessors lie
 * outside its buffer.  Caller frees with obs_scene_free(). */
obs_status obs_scene_load_baked(const char *path, obs_scene *out, char err[OBS_ERR_LEN]);

/* obs_scene_load_baked for a level with dynamic objects in it (obscura
 * gbuffer --dynamic): the nodes whose name matches the fnmatch(3) pattern
 * dynamic_nodes (NULL: none), those whose glTF extras hold
 * "obscura_dynamic": true, and their descendants are dynamic: their
 * meshes' `dynamic` is set and their primitives need no _AO (their
 * `baked` is 1; obs_raster_baked_dynamic values them).  *marked (may be
 * NULL) gets the number of nodes marked (descendants not counted).
 * Fails with OBS_INVALID_ARGUMENT, listing the nodes' names, when the
 * pattern matches no node; else as obs_scene_load_baked for the static
 * meshes. */
obs_status obs_scene_load_baked_dynamic(const char *path, const char *dynamic_nodes,
                                        obs_scene *out, size_t *marked, char err[OBS_ERR_LEN]);

/* 1 when path is a .glb some of whose primitives have an _AO attribute
 * (a level baked by obscura bake), else 0. */
int obs_scene_file_is_baked(const char *path);

/* Checks a scene built in memory (counts, indices in range, finite
 * positions within OBS_SCENE_MAX_COORD, some triangle not degenerate) and
 * computes its bounds; the message names the vertex or triangle and its
 * mesh.  obs_scene_load() calls it. */
obs_status obs_scene_check(obs_scene *s, char err[OBS_ERR_LEN]);

/* Frees the arrays and zeroes *s; NULL-safe. */
void obs_scene_free(obs_scene *s);

/* Sets the opacity of meshes from a spec: "A" (every triangle) or
 * "NAME=A" (the meshes whose name or node name matches the fnmatch(3)
 * pattern NAME),
 * A a number in [0, 1].  Specs apply in order, a later one overriding.
 * Fails with OBS_INVALID_ARGUMENT on a malformed spec or a pattern no
 * mesh matches (the message lists the mesh names), OBS_NO_MEMORY. */
obs_status obs_scene_set_opacity(obs_scene *s, const char *spec, char err[OBS_ERR_LEN]);

/* A G-buffer rasterised from a scene, one sample per pixel at the pixel
 * centre.  Background pixels: depth OBS_SKY_DEPTH, everything else 0. */
typedef struct obs_raster {
    obs_image depth;      /* 1 channel: planar view depth (-z_view) */
    obs_image normal;     /* 3: world-space shading normal, facing the camera */
    obs_image normal_cam; /* 3: the same normal in camera space */
    obs_image position;   /* 3: world-space position */
    obs_image color;      /* 4: albedo RGB (0 without albedo), alpha = coverage */
    int has_albedo;       /* the scene has albedo */
} obs_raster;

/* Rasterises the scene with the camera (world_to_camera and an OpenGL
 * projection, both required) at width x height on the context's thread.
 * Normals are flipped to face the camera where a triangle is seen from
 * its back (as a path tracer's shading normal is).  Caller frees with
 * obs_raster_free(). */
obs_status obs_raster_gbuffer(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam,
                              int width, int height, obs_raster *out, char err[OBS_ERR_LEN]);

/* Frees the images and zeroes *r; NULL-safe. */
void obs_raster_free(obs_raster *r);

/* The object at each pixel as obs_raster_gbuffer rasterises the scene:
 * 1 + the index of its mesh in scene->meshes, 0 where no geometry is
 * (one channel, an integer per pixel: the `id` channel of obscura gbuffer
 * --ids, an object-mask selector's id:id=N).  Caller frees with
 * obs_image_free(). */
obs_status obs_raster_ids(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam, int width,
                          int height, obs_image *out, char err[OBS_ERR_LEN]);

/* The scene's baked values (obs_scene.baked) rasterised as
 * obs_raster_gbuffer rasterises the albedo: the same triangles and
 * pixels, each value interpolated across its triangle with perspective
 * correction, as a game engine interpolates a vertex attribute.  out: 3
 * channels (_AO, _AO_SHORT, _AO_LONG), 1 where no geometry is.  Fails
 * with OBS_MISSING_CHANNEL when the scene has no baked values.  Caller
 * frees with obs_image_free(). */
obs_status obs_raster_baked(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam,
                            int width, int height, obs_image *out, char err[OBS_ERR_LEN]);

/* Checks that the scene's static meshes (those not `dynamic`) are the
 * level the region model was baked from (obscura bake-dynamic; the
 * model's `level`): the same triangle count and box (within 1e-4 of its
 * diagonal).  OBS_INVALID_ARGUMENT, naming both, when not.  A model
 * without a level (m->level.triangles 0) cannot be checked: the caller
 * decides. */
obs_status obs_scene_check_dynamic_level(const obs_scene *s, const obs_dyn_model *m,
                                         char err[OBS_ERR_LEN]);

/* obs_raster_baked for a scene with dynamic meshes
 * (obs_scene_load_baked_dynamic): the static meshes' pixels as there, a
 * dynamic mesh's pixels the region model m evaluated (obs_dyn_eval,
 * quadratic SH when `quadratic`, else linear) at the pixel's world
 * position and normal from g, the G-buffer obs_raster_gbuffer made of
 * the same scene and camera: _AO the blend, _AO_SHORT, _AO_LONG.
 * *dynamic_pixels (may be NULL) gets their count.  Caller frees out
 * with obs_image_free(). */
obs_status obs_raster_baked_dynamic(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam,
                                    int width, int height, const obs_raster *g,
                                    const obs_dyn_model *m, int quadratic, obs_image *out,
                                    size_t *dynamic_pixels, char err[OBS_ERR_LEN]);

struct obs_deep_image; /* deep.h */

/* Rasterises the scene into an A-buffer: every fragment at every pixel
 * centre, depth test off, kept in per-pixel linked lists on the GPU (GL
 * 4.3 shader storage buffers and an atomic counter: OITAO section IV-A,
 * the PPLL of Yang et al.), read back and sorted front to back.  Each
 * sample: Z (planar view depth; ZBack = Z), A (the triangle's opacity;
 * fragments of opacity 0 are left out), R, G, B (albedo premultiplied by
 * A; has_color only when the scene has albedo) and the world-space
 * shading normal facing the camera (N, as obs_raster's).
 * A node pool too small for the frame is grown to the fragment count and
 * the scene drawn again; more than OBS_DEEP_MAX_SAMPLES fragments, or
 * more than OBS_DEEP_MAX_PER_PIXEL at one pixel, is OBS_TOO_LARGE.  The
 * camera is copied into out->camera.  Caller frees with obs_deep_free(). */
obs_status obs_raster_deep(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam, int width,
                           int height, struct obs_deep_image *out, char err[OBS_ERR_LEN]);
/* obs_raster_deep that also gives each sample's object ID, 1 + the index
 * of the mesh its triangle belongs to (obs_raster_ids' numbering), in
 * *ids: out->offset[width * height] floats in the samples' order, freed
 * by the caller (NULL on failure). */
obs_status obs_raster_deep_ids(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam,
                               int width, int height, struct obs_deep_image *out, float **ids,
                               char err[OBS_ERR_LEN]);

#ifdef __cplusplus
}
#endif

#endif
