/* One GL context of one backend: created by trying the backends in order,
 * its entry points loaded into a table, made current on the calling
 * thread.  Knows nothing of frames or passes: the obs_ctx above it
 * (core/context.c) keeps those and tears them down before this. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl.h"

_Thread_local const obs__gl *obs__glp;
/* beside obs__glp: bound with it (progcache.c reads it, device.c calls
 * nothing of progcache.c; context.c opens the cache) */
_Thread_local obs__progcache *obs__progcache_cur;

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
    const obs__gl_device *d = (const obs__gl_device *)user;
    obs_log_level lvl = type == GL_DEBUG_TYPE_ERROR ? OBS_LOG_ERROR
                        : severity == GL_DEBUG_SEVERITY_NOTIFICATION ? OBS_LOG_DEBUG
                                                                     : OBS_LOG_WARN;
    obs__logf(d->log, d->log_user, lvl, "GL: %s", message);
}

static obs_status make_current(obs__gl_device *d)
{
    return d->backend == OBS_BACKEND_OSMESA ? obs__osmesa_make_current(&d->st)
                                            : obs__egl_make_current(&d->st);
}

obs_status obs__gl_device_bind(obs__gl_device *d, char err[OBS_ERR_LEN])
{
    if (make_current(d) != OBS_OK)
        return obs__fail(err, OBS_GL_ERROR, "%s: the context could not be made current",
                         obs_backend_name(d->backend));
    obs__glp = &d->gl;
    obs__progcache_cur = &d->cache;
    return OBS_OK;
}

static void destroy_backend(obs__gl_device *d)
{
    if (d->backend == OBS_BACKEND_OSMESA)
        obs__osmesa_destroy(&d->st);
    else
        obs__egl_destroy(&d->st);
    if (obs__glp == &d->gl)
        obs__glp = NULL;
    if (obs__progcache_cur == &d->cache)
        obs__progcache_cur = NULL;
}

static obs_status try_backend(obs__gl_device *d, obs_backend b, char err[OBS_ERR_LEN])
{
    obs__getproc_fn getproc = NULL;
    obs_status s;
    switch (b) {
    case OBS_BACKEND_EGL_DEVICE: s = obs__egl_create(d->debug, 1, &d->st, &getproc, err); break;
    case OBS_BACKEND_EGL_SURFACELESS: s = obs__egl_create(d->debug, 0, &d->st, &getproc, err); break;
    case OBS_BACKEND_OSMESA: s = obs__osmesa_create(&d->st, &getproc, err); break;
    default: return obs__fail(err, OBS_INVALID_ARGUMENT, "unknown backend %d", (int)b);
    }
    if (s != OBS_OK)
        return s;
    d->backend = b;
    s = obs__gl_load(&d->gl, getproc, err);
    if (s != OBS_OK)
        goto fail;
    obs__glp = &d->gl;

    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (major < 4 || (major == 4 && minor < 3)) {
        s = obs__fail(err, OBS_GL_UNAVAILABLE, "%s: OpenGL %d.%d, need 4.3 core",
                      obs_backend_name(b), major, minor);
        goto fail;
    }
    snprintf(d->version, sizeof d->version, "%s", (const char *)glGetString(GL_VERSION));
    snprintf(d->vendor, sizeof d->vendor, "%s", (const char *)glGetString(GL_VENDOR));
    snprintf(d->renderer, sizeof d->renderer, "%s", (const char *)glGetString(GL_RENDERER));
    return OBS_OK;

fail:
    destroy_backend(d);
    return s;
}

obs_status obs__gl_device_create(obs__gl_device *d, obs_backend backend, char err[OBS_ERR_LEN])
{
    static const obs_backend order[] = {OBS_BACKEND_EGL_DEVICE, OBS_BACKEND_EGL_SURFACELESS,
                                        OBS_BACKEND_OSMESA};
    if ((unsigned)backend >= OBS_BACKEND_COUNT)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "unknown backend %d", (int)backend);
    obs_status s = OBS_GL_UNAVAILABLE;
    if (backend != OBS_BACKEND_AUTO) {
        s = try_backend(d, backend, err);
    } else {
        char tried[OBS_ERR_LEN] = "";
        for (size_t i = 0; i < sizeof order / sizeof order[0] && s != OBS_OK; i++) {
            char e[OBS_ERR_LEN] = "";
            s = try_backend(d, order[i], e);
            if (s != OBS_OK) {
                obs__logf(d->log, d->log_user, OBS_LOG_DEBUG, "backend %s unavailable: %s",
                          obs_backend_name(order[i]), e);
                size_t n = strlen(tried);
                snprintf(tried + n, sizeof tried - n, "%s%s", n ? "; " : "", e);
            }
        }
        if (s != OBS_OK)
            obs__fail(err, s, "no OpenGL backend: %s", tried);
    }
    if (s != OBS_OK)
        return s;

    if (d->debug && d->gl.DebugMessageCallback) {
        glEnable(GL_DEBUG_OUTPUT);
        glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
        d->gl.DebugMessageCallback(debug_cb, d);
    }
    glGenVertexArrays(1, &d->vao);
    obs__progcache_cur = &d->cache;
    return OBS_OK;
}

void obs__gl_device_destroy(obs__gl_device *d)
{
    if (obs__gl_device_bind(d, NULL) == OBS_OK)
        glDeleteVertexArrays(1, &d->vao);
    destroy_backend(d);
}
