/* OSMesa backend: Mesa's off-screen rendering, an OpenGL 4.3+ core context
 * on the CPU.  OSMesa needs a colour buffer to make the context current; a
 * 1x1 buffer does, since every pass renders into framebuffer objects. */
#include <stdlib.h>

#include <GL/osmesa.h>

#include "gl/backend.h"

static obs__glproc osmesa_getproc(const char *name)
{
    return (obs__glproc)OSMesaGetProcAddress(name);
}

obs_status obs__osmesa_create(obs__backend_state *st,
                              obs__getproc_fn *getproc, char err[OBS_ERR_LEN])
{
    const int attr[] = {
        OSMESA_FORMAT, OSMESA_RGBA,
        OSMESA_DEPTH_BITS, 0,
        OSMESA_STENCIL_BITS, 0,
        OSMESA_ACCUM_BITS, 0,
        OSMESA_PROFILE, OSMESA_CORE_PROFILE,
        OSMESA_CONTEXT_MAJOR_VERSION, 4,
        OSMESA_CONTEXT_MINOR_VERSION, 3,
        0};
    OSMesaContext mc = OSMesaCreateContextAttribs(attr, NULL);
    if (!mc)
        return obs__fail(err, OBS_GL_UNAVAILABLE, "osmesa: no OpenGL 4.3 core context");
    unsigned char *buf = calloc(1, 4);
    if (!buf) {
        OSMesaDestroyContext(mc);
        return obs__fail(err, OBS_NO_MEMORY, "osmesa: out of memory");
    }
    if (!OSMesaMakeCurrent(mc, buf, GL_UNSIGNED_BYTE, 1, 1)) {
        OSMesaDestroyContext(mc);
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
    if (OSMesaGetCurrentContext() == (OSMesaContext)st->osmesa)
        return OBS_OK;
    return OSMesaMakeCurrent((OSMesaContext)st->osmesa, st->osmesa_buf, GL_UNSIGNED_BYTE, 1, 1)
               ? OBS_OK
               : OBS_GL_ERROR;
}

void obs__osmesa_destroy(obs__backend_state *st)
{
    if (st->osmesa) {
        /* unbind first: a context destroyed while current keeps its
         * framebuffer alive */
        if (OSMesaGetCurrentContext() == (OSMesaContext)st->osmesa)
            OSMesaMakeCurrent(NULL, NULL, 0, 0, 0);
        OSMesaDestroyContext((OSMesaContext)st->osmesa);
    }
    free(st->osmesa_buf);
    st->osmesa = NULL;
    st->osmesa_buf = NULL;
}
