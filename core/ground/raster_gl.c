/* The G-buffer rasteriser: a scene drawn once through the camera into
 * float render targets (depth, normals, position, albedo + coverage) on
 * the context's GL thread.  Its resources live for one call only; the AO
 * chain's cached targets (run_gl.c) are not touched. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl.h"
#include "obs_shaders.h"
#include "ground/raster_internal.h"
#include "obscura/scene.h"

enum { T_DEPTH, T_NORMAL, T_NORMAL_CAM, T_POSITION, T_COLOR, T_COUNT };

typedef struct raster_gl {
    GLuint prog, vao, fbo, zbuf;
    GLuint tex[T_COUNT];
    GLuint vbo[3], ibo;
} raster_gl;

void obs_raster_free(obs_raster *r)
{
    if (!r)
        return;
    obs_image_free(&r->depth);
    obs_image_free(&r->normal);
    obs_image_free(&r->normal_cam);
    obs_image_free(&r->position);
    obs_image_free(&r->color);
    memset(r, 0, sizeof *r);
}

static void release(raster_gl *g, obs_ctx *ctx)
{
    if (g->prog)
        glDeleteProgram(g->prog);
    if (g->fbo)
        glDeleteFramebuffers(1, &g->fbo);
    glDeleteTextures(T_COUNT, g->tex);
    if (g->zbuf)
        glDeleteTextures(1, &g->zbuf);
    glDeleteBuffers(3, g->vbo);
    if (g->ibo)
        glDeleteBuffers(1, &g->ibo);
    if (g->vao)
        glDeleteVertexArrays(1, &g->vao);
    /* Back to the state the AO chain expects. */
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindVertexArray(ctx->dev.vao);
    glDisable(GL_DEPTH_TEST);
}

/* Reads one colour attachment into a top-row-first image of `channels`
 * of its components (GL's rows run bottom-up). */
static void read_target(int attachment, obs_image *img, float *rgba)
{
    const int w = img->width, h = img->height, c = img->channels;
    glReadBuffer((GLenum)(GL_COLOR_ATTACHMENT0 + attachment));
    glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, rgba);
    for (int y = 0; y < h; y++) {
        const float *src = rgba + (size_t)(h - 1 - y) * w * 4;
        float *dst = img->data + (size_t)y * w * c;
        for (int x = 0; x < w; x++)
            for (int k = 0; k < c; k++)
                dst[(size_t)x * c + k] = src[(size_t)x * 4 + k];
    }
}

GLuint obs__gl_buffer(GLenum target, const void *data, size_t bytes)
{
    GLuint b = 0;
    glGenBuffers(1, &b);
    glBindBuffer(target, b);
    glBufferData(target, (GLsizeiptr)bytes, data, GL_STATIC_DRAW);
    return b;
}

void obs__raster_upload_mesh(const obs_scene *scene, GLuint *vao, GLuint vbo[3], GLuint *ibo)
{
    const size_t vbytes = scene->vertex_count * 3 * sizeof(float);
    glGenVertexArrays(1, vao);
    glBindVertexArray(*vao);
    const float *attrs[3] = {scene->positions, scene->normals, scene->albedo};
    for (GLuint a = 0; a < 3; a++) {
        if (!attrs[a])
            continue;
        vbo[a] = obs__gl_buffer(GL_ARRAY_BUFFER, attrs[a], vbytes);
        glVertexAttribPointer(a, 3, GL_FLOAT, GL_FALSE, 0, NULL);
        glEnableVertexAttribArray(a);
    }
    *ibo = obs__gl_buffer(GL_ELEMENT_ARRAY_BUFFER, scene->indices,
                          scene->triangle_count * 3 * sizeof(uint32_t));
}

void obs__raster_set_scene(GLuint prog, const obs_scene *scene)
{
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_has_normals"), scene->normals != NULL);
    glUniform1i(glGetUniformLocation(prog, "u_has_albedo"), scene->albedo != NULL);
}

obs_status obs__raster_set_camera(GLuint prog, const obs_camera *cam, char err[OBS_ERR_LEN])
{
    float clip[16], inv[16], nm[9], eye[4];
    obs__mat4_mul(cam->projection, cam->world_to_camera, clip);
    if (obs__mat4_invert(cam->world_to_camera, inv) != 0)
        return obs__fail(err, OBS_NO_CAMERA, "world_to_camera is singular");
    /* normal matrix = (W^-1)^T, upper 3x3 */
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            nm[3 * r + c] = inv[4 * c + r];
    /* A perspective projection has the row (0, 0, -1, 0) at the bottom:
     * the eye is the camera-space origin; an orthographic one looks along
     * -Z, so the direction towards the camera is +Z. */
    const int persp = cam->projection[14] != 0.0f;
    const float origin[4] = {0, 0, 0, 1}, back[4] = {0, 0, 1, 0};
    obs__mat4_apply(inv, persp ? origin : back, eye);
    if (persp) {
        for (int k = 0; k < 3; k++)
            eye[k] /= eye[3];
        eye[3] = 1.0f;
        /* the scenes' bound (scene.h): a camera beyond it drew nothing,
         * and its header lost the camera, without a word */
        if (!isfinite(eye[0]) || !isfinite(eye[1]) || !isfinite(eye[2]) ||
            obs_scene_coord_beyond(eye))
            return obs__fail(err, OBS_NO_CAMERA, "the camera at (%g, %g, %g): " OBS_SCENE_COORD_RULE,
                             (double)eye[0], (double)eye[1], (double)eye[2]);
    }
    glUseProgram(prog);
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_world_to_clip"), 1, GL_TRUE, clip);
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_world_to_camera"), 1, GL_TRUE,
                       cam->world_to_camera);
    glUniformMatrix3fv(glGetUniformLocation(prog, "u_normal_to_camera"), 1, GL_TRUE, nm);
    glUniform4fv(glGetUniformLocation(prog, "u_eye"), 1, eye);
    return OBS_OK;
}

obs_status obs__raster_check(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam,
                             int width, int height, char err[OBS_ERR_LEN])
{
    obs_status s;
    if (!scene || !scene->positions || !scene->indices || scene->triangle_count == 0)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "empty scene: no triangles");
    if (scene->triangle_count > (size_t)INT32_MAX / 3)
        return obs__fail(err, OBS_TOO_LARGE, "%zu triangles; at most %d", scene->triangle_count,
                         INT32_MAX / 3);
    if (!cam || !cam->has_projection)
        return obs__fail(err, OBS_NO_CAMERA, "the camera has no projection");
    if (width < 1 || height < 1)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "image size %dx%d", width, height);
    if ((s = obs_check_size(NULL, width, height, err)) != OBS_OK)
        return s;
    if ((s = obs__ctx_bind(ctx, err)) != OBS_OK)
        return s;
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    if (width > max_size || height > max_size)
        return obs__fail(err, OBS_TOO_LARGE, "%dx%d exceeds the GL limit %d", width, height,
                         max_size);
    return OBS_OK;
}

obs_status obs__raster_values(obs_ctx *ctx, const obs_scene *scene, float *values,
                              const obs_camera *cam, int width, int height, int channels,
                              obs_raster *r, obs_image *out, char err[OBS_ERR_LEN])
{
    obs_scene as_albedo = *scene;
    as_albedo.albedo = values;
    obs_status s = obs_raster_gbuffer(ctx, &as_albedo, cam, width, height, r, err);
    if (s == OBS_OK && (s = obs__image_alloc(out, width, height, channels, err)) != OBS_OK)
        obs_raster_free(r);
    return s;
}

obs_status obs_raster_gbuffer(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam,
                              int width, int height, obs_raster *out, char err[OBS_ERR_LEN])
{
    static const char *const frag[] = {"#version 430 core\n", obs__shader_raster_common,
                                       obs__shader_raster_frag};
    raster_gl g = {0};
    float *rgba = NULL;
    obs_status s;

    memset(out, 0, sizeof *out);
    if ((s = obs__raster_check(ctx, scene, cam, width, height, err)) != OBS_OK)
        return s;

    static const int channels[T_COUNT] = {1, 3, 3, 3, 4};
    obs_image *imgs[T_COUNT] = {&out->depth, &out->normal, &out->normal_cam, &out->position,
                                &out->color};
    for (int t = 0; t < T_COUNT; t++)
        if ((s = obs__image_alloc(imgs[t], width, height, channels[t], err)) != OBS_OK)
            goto fail;
    if (!(rgba = malloc((size_t)width * height * 4 * sizeof(float)))) {
        s = obs__fail(err, OBS_NO_MEMORY, "G-buffer of %dx%d", width, height);
        goto fail;
    }

    if ((s = obs__gl_program("raster", obs__shader_raster_vert, frag, 3, &g.prog, err)) != OBS_OK)
        goto fail;
    if ((s = obs__raster_set_camera(g.prog, cam, err)) != OBS_OK)
        goto fail;
    obs__raster_set_scene(g.prog, scene);

    /* Targets: float planes and a 32-bit float depth buffer. */
    static const GLenum formats[T_COUNT] = {GL_R32F, GL_RGBA32F, GL_RGBA32F, GL_RGBA32F,
                                            GL_RGBA32F};
    GLenum bufs[T_COUNT];
    glGenFramebuffers(1, &g.fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, g.fbo);
    glGenTextures(T_COUNT, g.tex);
    for (int t = 0; t < T_COUNT; t++) {
        glBindTexture(GL_TEXTURE_2D, g.tex[t]);
        glTexStorage2D(GL_TEXTURE_2D, 1, formats[t], width, height);
        glFramebufferTexture2D(GL_FRAMEBUFFER, (GLenum)(GL_COLOR_ATTACHMENT0 + t), GL_TEXTURE_2D,
                               g.tex[t], 0);
        bufs[t] = (GLenum)(GL_COLOR_ATTACHMENT0 + t);
    }
    glGenTextures(1, &g.zbuf);
    glBindTexture(GL_TEXTURE_2D, g.zbuf);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH_COMPONENT32F, width, height);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, g.zbuf, 0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDrawBuffers(T_COUNT, bufs);
    GLenum fb = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (fb != GL_FRAMEBUFFER_COMPLETE) {
        s = obs__fail(err, OBS_GL_ERROR, "G-buffer framebuffer incomplete (0x%04x)", (unsigned)fb);
        goto fail;
    }

    obs__raster_upload_mesh(scene, &g.vao, g.vbo, &g.ibo);

    const float sky[4] = {OBS_SKY_DEPTH, 0, 0, 0}, zero[4] = {0, 0, 0, 0}, far_z = 1.0f;
    glClearBufferfv(GL_COLOR, T_DEPTH, sky);
    for (int t = 1; t < T_COUNT; t++)
        glClearBufferfv(GL_COLOR, t, zero);
    glClearBufferfv(GL_DEPTH, 0, &far_z);
    glViewport(0, 0, width, height);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDrawElements(GL_TRIANGLES, (GLsizei)(scene->triangle_count * 3), GL_UNSIGNED_INT, NULL);
    if ((s = obs__gl_check("the G-buffer draw", err)) != OBS_OK)
        goto fail;

    for (int t = 0; t < T_COUNT; t++)
        read_target(t, imgs[t], rgba);
    if ((s = obs__gl_check("reading the G-buffer", err)) != OBS_OK)
        goto fail;
    out->has_albedo = scene->albedo != NULL;
    obs__log(ctx, OBS_LOG_DEBUG, "rasterised %zu triangles at %dx%d", scene->triangle_count,
             width, height);

fail:
    free(rgba);
    release(&g, ctx);
    if (s != OBS_OK)
        obs_raster_free(out);
    return s;
}
