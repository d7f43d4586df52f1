/* EGL backends: the device platform (a real GPU, EGL_EXT_platform_device)
 * and Mesa's surfaceless platform (EGL_MESA_platform_surfaceless).  Both
 * make an OpenGL 4.3+ core context current with no surface. */
#include <pthread.h>
#include <string.h>

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include "gl/backend.h"

/* The EGL entry points, from libEGL.so.1 opened at the first EGL context
 * (libs.c): nothing of EGL is linked. */
#define EGL_FNS(X)                                                                         \
    X(eglBindAPI) X(eglChooseConfig) X(eglCreateContext) X(eglDestroyContext)              \
    X(eglGetCurrentContext) X(eglGetError) X(eglGetProcAddress) X(eglInitialize)           \
    X(eglMakeCurrent) X(eglQueryString) X(eglReleaseThread)
static struct {
#define EGL_FIELD(f) __typeof__(f) *f;
    EGL_FNS(EGL_FIELD)
#undef EGL_FIELD
} E;
static pthread_once_t egl_once = PTHREAD_ONCE_INIT;
static obs_status egl_loaded = OBS_GL_UNAVAILABLE;
static char egl_err[OBS_ERR_LEN];

static void egl_load(void)
{
    void *h = obs__gl_lib_open("libEGL.so.1", "libegl1", egl_err);
    if (!h)
        return;
#define EGL_SYM(f)                                                                         \
    if (!(E.f = (__typeof__(E.f))obs__gl_lib_sym(h, "libEGL.so.1", #f, egl_err)))          \
        return;
    EGL_FNS(EGL_SYM)
#undef EGL_SYM
    egl_loaded = OBS_OK;
}

/* libEGL loaded (once, by any thread), else why not, for backend `who` */
static obs_status egl_lib(const char *who, char err[OBS_ERR_LEN])
{
    pthread_once(&egl_once, egl_load);
    return egl_loaded == OBS_OK ? OBS_OK : obs__fail(err, egl_loaded, "%s: %s", who, egl_err);
}

static int has_ext(const char *exts, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = exts; p && (p = strstr(p, name)) != NULL; p += n)
        if ((p == exts || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0'))
            return 1;
    return 0;
}

static obs__glproc egl_getproc(const char *name)
{
    return (obs__glproc)E.eglGetProcAddress(name);
}

int obs__egl_device_client_ok(const char *client, char err[OBS_ERR_LEN])
{
    if (!has_ext(client, "EGL_EXT_platform_device")) {
        obs__fail(err, OBS_GL_UNAVAILABLE, "egl-device: EGL_EXT_platform_device is not available");
        return 0;
    }
    /* EGL_EXT_device_base is the older name of device_enumeration plus
     * device_query, and the only one NVIDIA's driver lists (580.159) */
    if (!has_ext(client, "EGL_EXT_device_enumeration") && !has_ext(client, "EGL_EXT_device_base")) {
        obs__fail(err, OBS_GL_UNAVAILABLE,
                  "egl-device: neither EGL_EXT_device_enumeration nor EGL_EXT_device_base is available");
        return 0;
    }
    return 1;
}

/* The first device that is not Mesa's software rasteriser: the device
 * backend is for real GPUs; llvmpipe is reached through surfaceless. */
static EGLDisplay device_display(char err[OBS_ERR_LEN])
{
    if (!obs__egl_device_client_ok(E.eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS), err))
        return EGL_NO_DISPLAY;
    PFNEGLQUERYDEVICESEXTPROC query_devices =
        (PFNEGLQUERYDEVICESEXTPROC)E.eglGetProcAddress("eglQueryDevicesEXT");
    PFNEGLQUERYDEVICESTRINGEXTPROC query_string =
        (PFNEGLQUERYDEVICESTRINGEXTPROC)E.eglGetProcAddress("eglQueryDeviceStringEXT");
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)E.eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!query_devices || !query_string || !get_display) {
        obs__fail(err, OBS_GL_UNAVAILABLE, "egl-device: device enumeration entry points missing");
        return EGL_NO_DISPLAY;
    }
    EGLDeviceEXT devs[16];
    EGLint n = 0;
    if (!query_devices(16, devs, &n) || n <= 0) {
        obs__fail(err, OBS_GL_UNAVAILABLE, "egl-device: no EGL devices");
        return EGL_NO_DISPLAY;
    }
    for (EGLint i = 0; i < n; i++) {
        const char *exts = query_string(devs[i], EGL_EXTENSIONS);
        if (has_ext(exts, "EGL_MESA_device_software"))
            continue;
        EGLDisplay d = get_display(EGL_PLATFORM_DEVICE_EXT, devs[i], NULL);
        if (d != EGL_NO_DISPLAY)
            return d;
    }
    obs__fail(err, OBS_GL_UNAVAILABLE, "egl-device: no hardware EGL device among %d device(s)", (int)n);
    return EGL_NO_DISPLAY;
}

static EGLDisplay surfaceless_display(char err[OBS_ERR_LEN])
{
    const char *client = E.eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_ext(client, "EGL_MESA_platform_surfaceless")) {
        obs__fail(err, OBS_GL_UNAVAILABLE,
                  "egl-surfaceless: EGL_MESA_platform_surfaceless is not available");
        return EGL_NO_DISPLAY;
    }
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)E.eglGetProcAddress("eglGetPlatformDisplayEXT");
    EGLDisplay d = get_display ? get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL)
                               : EGL_NO_DISPLAY;
    if (d == EGL_NO_DISPLAY)
        obs__fail(err, OBS_GL_UNAVAILABLE, "egl-surfaceless: no display (EGL error 0x%x)",
                  (unsigned)E.eglGetError());
    return d;
}

obs_status obs__egl_create(int debug, int device, obs__backend_state *st,
                           obs__getproc_fn *getproc, char err[OBS_ERR_LEN])
{
    const char *who = device ? "egl-device" : "egl-surfaceless";
    obs_status s = egl_lib(who, err);
    if (s != OBS_OK)
        return s;
    EGLDisplay dpy = device ? device_display(err) : surfaceless_display(err);
    EGLContext gc = EGL_NO_CONTEXT;
    EGLint major = 0, minor = 0;

    if (dpy == EGL_NO_DISPLAY)
        return OBS_GL_UNAVAILABLE;
    if (!E.eglInitialize(dpy, &major, &minor)) {
        s = obs__fail(err, OBS_GL_UNAVAILABLE, "%s: eglInitialize failed (0x%x)", who,
                      (unsigned)E.eglGetError());
        goto fail;
    }
    const char *exts = E.eglQueryString(dpy, EGL_EXTENSIONS);
    if (!has_ext(exts, "EGL_KHR_surfaceless_context")) {
        s = obs__fail(err, OBS_GL_UNAVAILABLE, "%s: EGL_KHR_surfaceless_context missing", who);
        goto fail;
    }
    if (!E.eglBindAPI(EGL_OPENGL_API)) {
        s = obs__fail(err, OBS_GL_UNAVAILABLE, "%s: desktop OpenGL is not supported", who);
        goto fail;
    }
    EGLConfig cfg = NULL;
    if (!has_ext(exts, "EGL_KHR_no_config_context")) {
        const EGLint cattr[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint ncfg = 0;
        if (!E.eglChooseConfig(dpy, cattr, &cfg, 1, &ncfg) || ncfg < 1) {
            s = obs__fail(err, OBS_GL_UNAVAILABLE, "%s: no OpenGL config", who);
            goto fail;
        }
    }
    const EGLint attr[] = {
        EGL_CONTEXT_MAJOR_VERSION, 4,
        EGL_CONTEXT_MINOR_VERSION, 3,
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
        EGL_CONTEXT_OPENGL_DEBUG, debug ? EGL_TRUE : EGL_FALSE,
        EGL_NONE};
    gc = E.eglCreateContext(dpy, cfg ? cfg : (EGLConfig)0, EGL_NO_CONTEXT, attr);
    if (gc == EGL_NO_CONTEXT) {
        s = obs__fail(err, OBS_GL_UNAVAILABLE, "%s: no OpenGL 4.3 core context (0x%x)", who,
                      (unsigned)E.eglGetError());
        goto fail;
    }
    if (!E.eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, gc)) {
        s = obs__fail(err, OBS_GL_UNAVAILABLE, "%s: eglMakeCurrent failed (0x%x)", who,
                      (unsigned)E.eglGetError());
        goto fail;
    }
    st->egl_display = dpy;
    st->egl_context = gc;
    *getproc = egl_getproc;
    return OBS_OK;

fail:
    if (gc != EGL_NO_CONTEXT)
        E.eglDestroyContext(dpy, gc);
    return s;
}

obs_status obs__egl_make_current(obs__backend_state *st)
{
    if (E.eglGetCurrentContext() == (EGLContext)st->egl_context)
        return OBS_OK;
    return E.eglMakeCurrent(st->egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, st->egl_context)
               ? OBS_OK
               : OBS_GL_ERROR;
}

void obs__egl_destroy(obs__backend_state *st)
{
    if (!st->egl_display)
        return;
    E.eglMakeCurrent(st->egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (st->egl_context)
        E.eglDestroyContext(st->egl_display, st->egl_context);
    /* No eglTerminate: the display is per process and cheap to keep, and
     * terminating it unloads Mesa's driver, which leaks its JIT state on
     * every unload.  A context created later reuses the display. */
    E.eglReleaseThread();
    st->egl_display = st->egl_context = NULL;
}
