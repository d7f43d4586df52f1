/* The A-buffer rasteriser (scene.h, obs_raster_deep): every fragment of
 * the scene kept in per-pixel linked lists on the GL context, the PPLL of
 * OITAO section IV-A (core/shaders/raster_deep.frag.glsl), then read back
 * and sorted per pixel on the CPU into an obs_deep_image.  Its resources
 * live for one call only. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "obscura/deep.h"
#include "obs_shaders.h"
#include "ground/raster_internal.h"

/* Words of one node; raster_deep.frag.glsl's NODE_WORDS. */
enum { W_DEPTH, W_ALPHA, W_R, W_G, W_B, W_NX, W_NY, W_NZ, W_NEXT, W_PRIM, W_FACING, NODE_WORDS };
#define NIL 0xffffffffu

typedef struct deep_gl {
    GLuint prog, vao, fbo, target;
    GLuint vbo[3], ibo;
    GLuint heads, nodes, counter, opacity;
} deep_gl;

static void release(deep_gl *g, obs_ctx *ctx)
{
    if (g->prog)
        glDeleteProgram(g->prog);
    if (g->fbo)
        glDeleteFramebuffers(1, &g->fbo);
    if (g->target)
        glDeleteTextures(1, &g->target);
    glDeleteBuffers(3, g->vbo);
    GLuint bufs[5] = {g->ibo, g->heads, g->nodes, g->counter, g->opacity};
    for (int k = 0; k < 5; k++)
        if (bufs[k])
            glDeleteBuffers(1, &bufs[k]);
    if (g->vao)
        glDeleteVertexArrays(1, &g->vao);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindVertexArray(ctx->dev.vao);
}

/* One geometry pass into a pool of `capacity` nodes; *fragments gets the
 * number of fragments the pass produced (more than capacity: some were
 * not stored). */
static obs_status draw_lists(deep_gl *g, const obs_scene *scene, int width, int height,
                             uint64_t capacity, const uint32_t *empty_heads, uint64_t *fragments,
                             char err[OBS_ERR_LEN])
{
    const GLuint zero = 0;
    if (g->nodes)
        glDeleteBuffers(1, &g->nodes);
    g->nodes = 0;
    glGenBuffers(1, &g->nodes);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->nodes);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(capacity * NODE_WORDS * sizeof(uint32_t)),
                 NULL, GL_DYNAMIC_COPY);
    obs_status s = obs__gl_check("allocating the A-buffer's node pool", err);
    if (s != OBS_OK)
        return s;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, g->nodes);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g->heads);
    glBufferData(GL_SHADER_STORAGE_BUFFER,
                 (GLsizeiptr)((size_t)width * (size_t)height * sizeof(uint32_t)), empty_heads,
                 GL_DYNAMIC_COPY);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, g->heads);
    glBindBuffer(GL_ATOMIC_COUNTER_BUFFER, g->counter);
    glBufferData(GL_ATOMIC_COUNTER_BUFFER, sizeof zero, &zero, GL_DYNAMIC_COPY);
    glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, 0, g->counter);

    glUseProgram(g->prog);
    glUniform1i(glGetUniformLocation(g->prog, "u_capacity"), (GLint)capacity);
    glBindVertexArray(g->vao);
    glDrawElements(GL_TRIANGLES, (GLsizei)(scene->triangle_count * 3), GL_UNSIGNED_INT, NULL);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_ATOMIC_COUNTER_BARRIER_BIT |
                    GL_SHADER_STORAGE_BARRIER_BIT);
    GLuint count = 0;
    glBindBuffer(GL_ATOMIC_COUNTER_BUFFER, g->counter);
    glGetBufferSubData(GL_ATOMIC_COUNTER_BUFFER, 0, sizeof count, &count);
    *fragments = count;
    return obs__gl_check("the A-buffer draw", err);
}

typedef struct sort_key {
    float z;
    uint32_t prim, node;
} sort_key;

/* Front to back; a tie (two triangles at one depth) by triangle, so the
 * order does not depend on the GPU's. */
static int cmp_key(const void *pa, const void *pb)
{
    const sort_key *a = pa, *b = pb;
    if (a->z != b->z)
        return a->z < b->z ? -1 : 1;
    return a->prim < b->prim ? -1 : a->prim > b->prim;
}

/* The lists into an obs_deep_image: counted (each list checked against
 * the pool and the per-pixel limit), then filled top row first and
 * sorted. */
static obs_status build_image(const uint32_t *heads, const uint32_t *nodes, uint64_t stored,
                              int width, int height, int has_albedo, const float *tri_id,
                              size_t triangles, obs_deep_image *d, float **ids,
                              char err[OBS_ERR_LEN])
{
    const size_t npx = (size_t)width * (size_t)height;
    sort_key *keys = NULL;
    size_t keys_len = 0;
    if (!(d->offset = malloc((npx + 1) * sizeof *d->offset)))
        return obs__fail(err, OBS_NO_MEMORY, "A-buffer of %dx%d", width, height);
    d->offset[0] = 0;
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            size_t i = (size_t)y * width + x;
            uint64_t n = 0;
            for (uint32_t k = heads[(size_t)(height - 1 - y) * width + x]; k != NIL;
                 k = nodes[(size_t)k * NODE_WORDS + W_NEXT]) {
                if (k >= stored || n >= stored)
                    return obs__fail(err, OBS_GL_ERROR, "A-buffer list of pixel (%d, %d) is broken",
                                     x, y);
                n++;
            }
            if (n > OBS_DEEP_MAX_PER_PIXEL)
                return obs__fail(err, OBS_TOO_LARGE,
                                 "pixel (%d, %d) has %llu fragments; at most %d per pixel", x, y,
                                 (unsigned long long)n, OBS_DEEP_MAX_PER_PIXEL);
            d->offset[i + 1] = d->offset[i] + n;
        }
    if (!(d->samples = malloc((size_t)(stored ? stored : 1) * OBS_DEEP_CH * sizeof(float))))
        return obs__fail(err, OBS_NO_MEMORY, "%llu deep samples", (unsigned long long)stored);
    if (ids && !(*ids = calloc((size_t)(stored ? stored : 1), sizeof **ids)))
        return obs__fail(err, OBS_NO_MEMORY, "IDs of %llu deep samples", (unsigned long long)stored);
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            size_t i = (size_t)y * width + x, n = (size_t)(d->offset[i + 1] - d->offset[i]), c = 0;
            if (n == 0)
                continue;
            if (n > keys_len) {
                free(keys);
                keys_len = n < 64 ? 64 : n;
                if (!(keys = malloc(keys_len * sizeof *keys)))
                    return obs__fail(err, OBS_NO_MEMORY, "sorting a list of %zu fragments", n);
            }
            for (uint32_t k = heads[(size_t)(height - 1 - y) * width + x]; k != NIL;
                 k = nodes[(size_t)k * NODE_WORDS + W_NEXT]) {
                const uint32_t *w = nodes + (size_t)k * NODE_WORDS;
                memcpy(&keys[c].z, &w[W_DEPTH], sizeof(float));
                keys[c].prim = w[W_PRIM];
                keys[c++].node = k;
            }
            qsort(keys, n, sizeof *keys, cmp_key);
            for (size_t j = 0; j < n; j++) {
                const uint32_t *w = nodes + (size_t)keys[j].node * NODE_WORDS;
                float v[NODE_WORDS], *o = d->samples + (d->offset[i] + j) * OBS_DEEP_CH;
                memcpy(v, w, sizeof v);
                o[OBS_DEEP_Z] = o[OBS_DEEP_ZBACK] = v[W_DEPTH];
                o[OBS_DEEP_A] = v[W_ALPHA];
                o[OBS_DEEP_R] = v[W_R];
                o[OBS_DEEP_G] = v[W_G];
                o[OBS_DEEP_B] = v[W_B];
                o[OBS_DEEP_NX] = v[W_NX];
                o[OBS_DEEP_NY] = v[W_NY];
                o[OBS_DEEP_NZ] = v[W_NZ];
                o[OBS_DEEP_FACING] = v[W_FACING];
                if (ids) /* the object of the sample's triangle; 0: none known */
                    (*ids)[d->offset[i] + j] = keys[j].prim < triangles ? tri_id[keys[j].prim] : 0.0f;
            }
        }
    free(keys);
    d->width = d->display_width = width;
    d->height = d->display_height = height;
    d->has_alpha = d->has_normal = d->has_facing = 1;
    d->has_color = has_albedo;
    return OBS_OK;
}

obs_status obs_raster_deep(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam, int width,
                           int height, obs_deep_image *out, char err[OBS_ERR_LEN])
{
    return obs_raster_deep_ids(ctx, scene, cam, width, height, out, NULL, err);
}

obs_status obs_raster_deep_ids(obs_ctx *ctx, const obs_scene *scene, const obs_camera *cam,
                               int width, int height, obs_deep_image *out, float **ids,
                               char err[OBS_ERR_LEN])
{
    float *tri_id = NULL;
    static const char *const frag[] = {"#version 430 core\n", obs__shader_raster_common,
                                       obs__shader_raster_deep_frag};
    deep_gl g = {0};
    uint32_t *heads = NULL, *nodes = NULL;
    obs_status s;

    if (ids)
        *ids = NULL;
    if (!out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_raster_deep: no output");
    memset(out, 0, sizeof *out);
    if ((s = obs__raster_check(ctx, scene, cam, width, height, err)) != OBS_OK)
        return s;
    GLint max_block = 0;
    glGetIntegerv(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    /* The pool's limit: the deep image's, and what one storage block of
     * this GL can address. */
    uint64_t limit = OBS_DEEP_MAX_SAMPLES;
    if (max_block > 0 && (uint64_t)max_block / (NODE_WORDS * sizeof(uint32_t)) < limit)
        limit = (uint64_t)max_block / (NODE_WORDS * sizeof(uint32_t));
    const size_t npx = (size_t)width * (size_t)height;
    if (!(heads = malloc(npx * sizeof *heads))) {
        s = obs__fail(err, OBS_NO_MEMORY, "A-buffer heads of %dx%d", width, height);
        goto fail;
    }
    memset(heads, 0xff, npx * sizeof *heads); /* NIL */

    if ((s = obs__gl_program("raster_deep", obs__shader_raster_vert, frag, 3, &g.prog, err)) !=
        OBS_OK)
        goto fail;
    if ((s = obs__raster_set_camera(g.prog, cam, err)) != OBS_OK)
        goto fail;
    obs__raster_set_scene(g.prog, scene);
    glUniform1i(glGetUniformLocation(g.prog, "u_width"), width);
    glUniform1i(glGetUniformLocation(g.prog, "u_has_opacity"), scene->opacity != NULL);

    /* No colour output: a framebuffer of the image's size whose one
     * attachment is never written (draw buffer NONE). */
    const GLenum none = GL_NONE;
    glGenFramebuffers(1, &g.fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, g.fbo);
    glGenTextures(1, &g.target);
    glBindTexture(GL_TEXTURE_2D, g.target);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_R8, width, height);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, g.target, 0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDrawBuffers(1, &none);
    GLenum fb = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (fb != GL_FRAMEBUFFER_COMPLETE) {
        s = obs__fail(err, OBS_GL_ERROR, "A-buffer framebuffer incomplete (0x%04x)", (unsigned)fb);
        goto fail;
    }

    obs__raster_upload_mesh(scene, &g.vao, g.vbo, &g.ibo);
    const float one = 1.0f;
    g.opacity = obs__gl_buffer(GL_SHADER_STORAGE_BUFFER, scene->opacity ? (const void *)scene->opacity
                                                                        : (const void *)&one,
                               scene->opacity ? scene->triangle_count * sizeof(float) : sizeof one);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, g.opacity);
    glGenBuffers(1, &g.heads);
    glGenBuffers(1, &g.counter);
    glViewport(0, 0, width, height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);

    /* A first guess of two fragments per pixel; a pool too small is grown
     * to the fragment count the pass reported and the pass repeated. */
    uint64_t capacity = 2 * (uint64_t)npx < limit ? 2 * (uint64_t)npx : limit, fragments = 0;
    if ((s = draw_lists(&g, scene, width, height, capacity, heads, &fragments, err)) != OBS_OK)
        goto fail;
    if (fragments > capacity) {
        if (fragments > limit) {
            s = obs__fail(err, OBS_TOO_LARGE,
                          "%llu fragments at %dx%d; the A-buffer holds at most %llu (%s)",
                          (unsigned long long)fragments, width, height, (unsigned long long)limit,
                          limit == OBS_DEEP_MAX_SAMPLES ? "OBS_DEEP_MAX_SAMPLES"
                                                        : "GL_MAX_SHADER_STORAGE_BLOCK_SIZE");
            goto fail;
        }
        obs__log(ctx, OBS_LOG_DEBUG, "A-buffer: %llu fragments, pool of %llu: drawing again",
                 (unsigned long long)fragments, (unsigned long long)capacity);
        capacity = fragments;
        if ((s = draw_lists(&g, scene, width, height, capacity, heads, &fragments, err)) != OBS_OK)
            goto fail;
        if (fragments > capacity) { /* the same scene gave more fragments */
            s = obs__fail(err, OBS_GL_ERROR, "A-buffer: %llu fragments after %llu",
                          (unsigned long long)fragments, (unsigned long long)capacity);
            goto fail;
        }
    }

    /* Read back: the heads (GL rows bottom-up) and the stored nodes. */
    if (!(nodes = malloc((size_t)(fragments ? fragments : 1) * NODE_WORDS * sizeof *nodes))) {
        s = obs__fail(err, OBS_NO_MEMORY, "%llu A-buffer nodes", (unsigned long long)fragments);
        goto fail;
    }
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g.heads);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(npx * sizeof *heads), heads);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, g.nodes);
    if (fragments)
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0,
                           (GLsizeiptr)(fragments * NODE_WORDS * sizeof *nodes), nodes);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    if ((s = obs__gl_check("reading the A-buffer", err)) != OBS_OK)
        goto fail;
    /* --ids: each triangle's object, 1 + its mesh's index (gl_PrimitiveID
     * is the triangle's index in the one draw of every triangle) */
    if (ids && !(tri_id = calloc(scene->triangle_count ? scene->triangle_count : 1,
                                 sizeof *tri_id))) {
        s = obs__fail(err, OBS_NO_MEMORY, "IDs of %zu triangles", scene->triangle_count);
        goto fail;
    }
    for (size_t m = 0; ids && m < scene->mesh_count; m++) {
        const obs_scene_mesh *sm = &scene->meshes[m];
        for (size_t t = sm->first_triangle;
             t < sm->first_triangle + sm->triangle_count && t < scene->triangle_count; t++)
            tri_id[t] = (float)(m + 1);
    }
    if ((s = build_image(heads, nodes, fragments, width, height, scene->albedo != NULL, tri_id,
                         scene->triangle_count, out, ids, err)) != OBS_OK)
        goto fail;
    out->camera = *cam;
    obs__log(ctx, OBS_LOG_DEBUG, "A-buffer: %zu triangles at %dx%d, %llu fragments",
             scene->triangle_count, width, height, (unsigned long long)fragments);

fail:
    free(heads);
    free(nodes);
    free(tri_id);
    release(&g, ctx);
    if (s != OBS_OK) {
        obs_deep_free(out);
        if (ids) {
            free(*ids);
            *ids = NULL;
        }
    }
    return s;
}
