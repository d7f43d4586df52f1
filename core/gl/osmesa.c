/* OSMesa backend: Mesa's off-screen rendering, an OpenGL 4.3+ core context
 * on the CPU.  OSMesa needs a colour buffer to make the context current; a
 * 1x1 buffer does, since every pass renders into framebuffer objects. */
#include <pthread.h>
#include <stdlib.h>

#include <GL/osmesa.h>

#include "gl/backend.h"

/* OSMesa's entry points, from libOSMesa.so.8 opened at the first OSMesa
 * context (libs.c): nothing of OSMesa is linked. */
#define OSMESA_FNS(X)                                                                      \
    X(OSMesaCreateContextAttribs) X(OSMesaDestroyContext) X(OSMesaGetCurrentContext)       \
    X(OSMesaGetProcAddress) X(OSMesaMakeCurrent)
static struct {
#define OSMESA_FIELD(f) __typeof__(f) *f;
    OSMESA_FNS(OSMESA_FIELD)
#undef OSMESA_FIELD
} M;
static pthread_once_t osmesa_once = PTHREAD_ONCE_INIT;
static obs_status osmesa_loaded = OBS_GL_UNAVAILABLE;
static char osmesa_err[OBS_ERR_LEN];

static void osmesa_load(void)
{
    void *h = obs__gl_lib_open("libOSMesa.so.8", "libosmesa6", osmesa_err);
    if (!h)
        return;
#define OSMESA_SYM(f)                                                                      \
    if (!(M.f = (__typeof__(M.f))obs__gl_lib_sym(h, "libOSMesa.so.8", #f, osmesa_err)))    \
        return;
    OSMESA_FNS(OSMESA_SYM)
#undef OSMESA_SYM
    osmesa_loaded = OBS_OK;
}

static obs__glproc osmesa_getproc(const char *name)
{
    return (obs__glproc)M.OSMesaGetProcAddress(name);
}

obs_status obs__osmesa_create(obs__backend_state *st,
                              obs__getproc_fn *getproc, char err[OBS_ERR_LEN])
{
    pthread_once(&osmesa_once, osmesa_load);
    if (osmesa_loaded != OBS_OK)
        return obs__fail(err, osmesa_loaded, "osmesa: %s", osmesa_err);
    const int attr[] = {
        OSMESA_FORMAT, OSMESA_RGBA,
        OSMESA_DEPTH_BITS, 0,
        OSMESA_STENCIL_BITS, 0,
        OSMESA_ACCUM_BITS, 0,
        OSMESA_PROFILE, OSMESA_CORE_PROFILE,
        OSMESA_CONTEXT_MAJOR_VERSION, 4,
        OSMESA_CONTEXT_MINOR_VERSION, 3,
        0};
    OSMesaContext mc = M.OSMesaCreateContextAttribs(attr, NULL);
    if (!mc)
        return obs__fail(err, OBS_GL_UNAVAILABLE, "osmesa: no OpenGL 4.3 core context");
    unsigned char *buf = calloc(1, 4);
    if (!buf) {
        M.OSMesaDestroyContext(mc);
        return obs__fail(err, OBS_NO_MEMORY, "osmesa: out of memory");
    }
    if (!M.OSMesaMakeCurrent(mc, buf, GL_UNSIGNED_BYTE, 1, 1)) {
        M.OSMesaDestroyContext(mc);
        free(buf);
        return obs__fail(err, OBS_GL_UNAVAILABLE, "osmesa: OSMesaMakeCurrent failed");
    }
    st->osmesa = mc;
    st->osmesa_buf = buf;
    *getproc = osmesa_getproc;
    return OBS_OK;
}

obs_status obs__osmesa_make_current(obs__backend_state *st)
{
    if (M.OSMesaGetCurrentContext() == (OSMesaContext)st->osmesa)
        return OBS_OK;
    return M.OSMesaMakeCurrent((OSMesaContext)st->osmesa, st->osmesa_buf, GL_UNSIGNED_BYTE, 1, 1)
               ? OBS_OK
               : OBS_GL_ERROR;
}

void obs__osmesa_destroy(obs__backend_state *st)
{
    if (st->osmesa) {
        /* unbind first: a context destroyed while current keeps its
         * framebuffer alive */
        if (M.OSMesaGetCurrentContext() == (OSMesaContext)st->osmesa)
            M.OSMesaMakeCurrent(NULL, NULL, 0, 0, 0);
        M.OSMesaDestroyContext((OSMesaContext)st->osmesa);
    }
    free(st->osmesa_buf);
    st->osmesa = NULL;
    st->osmesa_buf = NULL;
}
