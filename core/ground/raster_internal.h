/* Internal to the rasterisers (raster_gl.c: the flat G-buffer,
 * raster_deep_gl.c: the A-buffer): what both set up the same way, and the
 * G-buffer run with other per-vertex values (raster_baked.c, raster_ids.c,
 * raster_dynamic.c).  Call on the context's GL thread.  Not installed. */
#ifndef OBSCURA_RASTER_INTERNAL_H
#define OBSCURA_RASTER_INTERNAL_H

#include "context.h"
#include "obscura/scene.h"

/* The checks both rasterisers make before any GL work: a scene with
 * triangles (at most INT32_MAX / 3), a camera with a projection, an image
 * size within the limits and GL_MAX_TEXTURE_SIZE; binds the context. */
obs_status obs__raster_check(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam,
                             int width, int height, char err[OBS_ERR_LEN]);

/* A buffer object holding a copy of data (GL_STATIC_DRAW), left bound to
 * target. */
GLuint obs__gl_buffer(GLenum target, const void *data, size_t bytes);

/* The camera uniforms of raster.vert.glsl / raster_common.glsl (uses prog). */
obs_status obs__raster_set_camera(GLuint prog, const obs_camera *cam, char err[OBS_ERR_LEN]);

/* The scene's flags uniforms (u_has_normals, u_has_albedo; uses prog). */
void obs__raster_set_scene(GLuint prog, const obs_scene *scene);

/* A vertex array with the scene's positions, normals and albedo
 * (attributes 0, 1, 2, where present) and its index buffer, left bound.
 * The caller deletes the objects. */
void obs__raster_upload_mesh(const obs_scene *scene, GLuint *vao, GLuint vbo[3], GLuint *ibo);

/* obs_raster_gbuffer with values (3 floats a vertex) in the place of the
 * scene's albedo, whose vertex attribute raster.frag.glsl interpolates and
 * writes unchanged: r->color holds the values at each pixel (alpha: the
 * coverage, 0 where no geometry is); then out, width x height x channels,
 * for the caller to fill from it.  On failure nothing is left to free;
 * else the caller frees r with obs_raster_free and out with
 * obs_image_free. */
obs_status obs__raster_values(obs_ctx *ctx, const obs_scene *scene, float *values,
                              const obs_camera *cam, int width, int height, int channels,
                              obs_raster *r, obs_image *out, char err[OBS_ERR_LEN]);

#endif
