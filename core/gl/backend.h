/* The GL backends (EGL device, EGL surfaceless, OSMesa).  No GL headers
 * here: OSMesa's own header brings the legacy gl.h, which must not meet
 * glcorearb.h in one translation unit. */
#ifndef OBSCURA_GL_BACKEND_H
#define OBSCURA_GL_BACKEND_H

#include "internal.h"

typedef void (*obs__glproc)(void);
typedef obs__glproc (*obs__getproc_fn)(const char *name);

/* ---- their libraries (libs.c) ------------------------------------------ */

/* dlopen(soname): the handle, else NULL with err naming the library, the
 * Debian package that has it, and the CPU device. */
void *obs__gl_lib_open(const char *soname, const char *package, char err[OBS_ERR_LEN]);
/* dlsym(h, name), else NULL with err naming what is missing. */
void *obs__gl_lib_sym(void *h, const char *soname, const char *name, char err[OBS_ERR_LEN]);

/* ---- backends ---------------------------------------------------------- */

typedef struct obs__backend_state {
    void *egl_display;
    void *egl_context;
    void *osmesa;
    unsigned char *osmesa_buf;
} obs__backend_state;

obs_status obs__egl_create(int debug, int device, obs__backend_state *st,
                           obs__getproc_fn *getproc, char err[OBS_ERR_LEN]);
void obs__egl_destroy(obs__backend_state *st);
/* The EGL client extensions (eglQueryString(EGL_NO_DISPLAY,
 * EGL_EXTENSIONS)) let the device platform enumerate devices: 1, else 0
 * with err naming the missing extension. */
int obs__egl_device_client_ok(const char *client, char err[OBS_ERR_LEN]);
obs_status obs__egl_make_current(obs__backend_state *st);

obs_status obs__osmesa_create(obs__backend_state *st,
                              obs__getproc_fn *getproc, char err[OBS_ERR_LEN]);
void obs__osmesa_destroy(obs__backend_state *st);
obs_status obs__osmesa_make_current(obs__backend_state *st);

#endif
