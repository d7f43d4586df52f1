/* The GL context: one function creates it (trying the backends in order),
 * and it is reused for every frame until destroyed. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl.h"

_Thread_local const obs__gl *obs__glp;

static const char *const backend_names[OBS_BACKEND_COUNT] = {
    "auto", "egl-device", "egl-surfaceless", "osmesa"};

const char *obs_backend_name(obs_backend b)
{
    return (unsigned)b < OBS_BACKEND_COUNT ? backend_names[b] : "unknown";
}

obs_status obs_backend_parse(const char *name, obs_backend *out)
{
    for (int i = 0; name && i < OBS_BACKEND_COUNT; i++)
        if (strcmp(name, backend_names[i]) == 0) {
            *out = (obs_backend)i;
            return OBS_OK;
        }
    return OBS_INVALID_ARGUMENT;
}

void obs__log(obs_ctx *ctx, obs_log_level level, const char *fmt, ...)
{
    if (!ctx || !ctx->log)
        return;
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    ctx->log(ctx->log_user, level, msg);
}

obs_status obs__gl_load(obs__gl *gl, obs__getproc_fn getproc, char err[OBS_ERR_LEN])
{
#define LOAD(type, name)                                                               \
    gl->name = (type)getproc("gl" #name);                                              \
    if (!gl->name)                                                                     \
        return obs__fail(err, OBS_GL_UNAVAILABLE, "OpenGL entry point gl%s is missing", #name);
    OBS__GL_FUNCS(LOAD)
#undef LOAD
#define LOAD_OPT(type, name) gl->name = (type)getproc("gl" #name);
    OBS__GL_FUNCS_OPT(LOAD_OPT)
#undef LOAD_OPT
    return OBS_OK;
}

static void APIENTRY debug_cb(GLenum source, GLenum type, GLuint id, GLenum severity,
                                GLsizei length, const GLchar *message, const void *user)
{
    (void)source;
    (void)id;
    (void)length;
    obs_ctx *ctx = (obs_ctx *)user;
    obs_log_level lvl = type == GL_DEBUG_TYPE_ERROR ? OBS_LOG_ERROR
                        : severity == GL_DEBUG_SEVERITY_NOTIFICATION ? OBS_LOG_DEBUG
                                                                     : OBS_LOG_WARN;
    obs__log(ctx, lvl, "GL: %s", message);
}

static obs_status make_current(obs_ctx *ctx)
{
    return ctx->backend == OBS_BACKEND_OSMESA ? obs__osmesa_make_current(&ctx->st)
                                              : obs__egl_make_current(&ctx->st);
}

obs_status obs__ctx_bind(obs_ctx *ctx, char err[OBS_ERR_LEN])
{
    if (make_current(ctx) != OBS_OK)
        return obs__fail(err, OBS_GL_ERROR, "%s: the context could not be made current",
                         obs_backend_name(ctx->backend));
    obs__glp = &ctx->gl;
    return OBS_OK;
}

static obs_status try_backend(obs_ctx *ctx, obs_backend b, char err[OBS_ERR_LEN])
{
    obs__getproc_fn getproc = NULL;
    obs_status s;
    switch (b) {
    case OBS_BACKEND_EGL_DEVICE: s = obs__egl_create(ctx->debug, 1, &ctx->st, &getproc, err); break;
    case OBS_BACKEND_EGL_SURFACELESS: s = obs__egl_create(ctx->debug, 0, &ctx->st, &getproc, err); break;
    case OBS_BACKEND_OSMESA: s = obs__osmesa_create(&ctx->st, &getproc, err); break;
    default: return obs__fail(err, OBS_INVALID_ARGUMENT, "unknown backend %d", (int)b);
    }
    if (s != OBS_OK)
        return s;
    ctx->backend = b;
    s = obs__gl_load(&ctx->gl, getproc, err);
    if (s != OBS_OK)
        goto fail;
    obs__glp = &ctx->gl;

    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (major < 4 || (major == 4 && minor < 3)) {
        s = obs__fail(err, OBS_GL_UNAVAILABLE, "%s: OpenGL %d.%d, need 4.3 core",
                      obs_backend_name(b), major, minor);
        goto fail;
    }
    snprintf(ctx->version, sizeof ctx->version, "%s", (const char *)glGetString(GL_VERSION));
    snprintf(ctx->vendor, sizeof ctx->vendor, "%s", (const char *)glGetString(GL_VENDOR));
    snprintf(ctx->renderer, sizeof ctx->renderer, "%s", (const char *)glGetString(GL_RENDERER));
    return OBS_OK;

fail:
    if (b == OBS_BACKEND_OSMESA)
        obs__osmesa_destroy(&ctx->st);
    else
        obs__egl_destroy(&ctx->st);
    obs__glp = NULL;
    return s;
}

obs_status obs_ctx_create(const obs_ctx_desc *desc, obs_ctx **out, char err[OBS_ERR_LEN])
{
    static const obs_backend order[] = {OBS_BACKEND_EGL_DEVICE, OBS_BACKEND_EGL_SURFACELESS,
                                        OBS_BACKEND_OSMESA};
    obs_ctx_desc d = {0};
    if (desc)
        d = *desc;
    *out = NULL;
    if ((unsigned)d.backend >= OBS_BACKEND_COUNT)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "unknown backend %d", (int)d.backend);

    obs_ctx *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return obs__fail(err, OBS_NO_MEMORY, "out of memory creating the context");
#ifdef OBS_DEBUG
    ctx->debug = 1; /* debug builds always install the KHR_debug callback */
#else
    ctx->debug = d.debug;
#endif
    ctx->log = d.log;
    ctx->log_user = d.log_user;

    obs_status s = OBS_GL_UNAVAILABLE;
    if (d.backend != OBS_BACKEND_AUTO) {
        s = try_backend(ctx, d.backend, err);
    } else {
        char tried[OBS_ERR_LEN] = "";
        for (size_t i = 0; i < sizeof order / sizeof order[0] && s != OBS_OK; i++) {
            char e[OBS_ERR_LEN] = "";
            s = try_backend(ctx, order[i], e);
            if (s != OBS_OK) {
                obs__log(ctx, OBS_LOG_DEBUG, "backend %s unavailable: %s",
                         obs_backend_name(order[i]), e);
                size_t n = strlen(tried);
                snprintf(tried + n, sizeof tried - n, "%s%s", n ? "; " : "", e);
            }
        }
        if (s != OBS_OK)
            obs__fail(err, s, "no OpenGL backend: %s", tried);
    }
    if (s != OBS_OK) {
        free(ctx);
        return s;
    }

    if (ctx->debug && ctx->gl.DebugMessageCallback) {
        glEnable(GL_DEBUG_OUTPUT);
        glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
        ctx->gl.DebugMessageCallback(debug_cb, ctx);
    }
    glGenVertexArrays(1, &ctx->vao);
    obs__log(ctx, OBS_LOG_INFO, "GL context: %s, OpenGL %s, %s", obs_backend_name(ctx->backend),
             ctx->version, ctx->renderer);
    *out = ctx;
    return OBS_OK;
}

void obs_ctx_get_info(const obs_ctx *ctx, obs_ctx_info *info)
{
    info->backend = ctx->backend;
    info->gl_version = ctx->version;
    info->gl_vendor = ctx->vendor;
    info->gl_renderer = ctx->renderer;
}

void obs_ctx_destroy(obs_ctx *ctx)
{
    if (!ctx)
        return;
    if (obs__ctx_bind(ctx, NULL) == OBS_OK) {
        obs__frame_release(ctx);
        obs__deep_release(ctx);
        glDeleteVertexArrays(1, &ctx->vao);
        if (ctx->queries[0])
            glDeleteQueries(OBS_PASS_COUNT, ctx->queries);
    }
    if (ctx->backend == OBS_BACKEND_OSMESA)
        obs__osmesa_destroy(&ctx->st);
    else
        obs__egl_destroy(&ctx->st);
    if (obs__glp == &ctx->gl)
        obs__glp = NULL;
    free(ctx);
}
