/* The GL backends' libraries, opened at run time (dlopen) the first time
 * a backend asks for its library: libEGL.so.1 (glvnd's, the EGL
 * backends) and libOSMesa.so.8.  The library, obscura and obscurad then
 * link and run on a node without them: the CPU device needs no GL. */
#include <dlfcn.h>

#include "gl/backend.h"

void *obs__gl_lib_open(const char *soname, const char *package, char err[OBS_ERR_LEN])
{
    void *h = dlopen(soname, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        const char *why = dlerror();
        obs__fail(err, OBS_GL_UNAVAILABLE,
                  "%s cannot be loaded (%s): install %s for the GL backends, or run the CPU "
                  "device (--backend cpu)",
                  soname, why ? why : "not found", package);
    }
    return h; /* kept open for the process's life */
}

void *obs__gl_lib_sym(void *h, const char *soname, const char *name, char err[OBS_ERR_LEN])
{
    void *f = dlsym(h, name);
    if (!f)
        obs__fail(err, OBS_GL_UNAVAILABLE, "%s has no %s", soname, name);
    return f;
}
