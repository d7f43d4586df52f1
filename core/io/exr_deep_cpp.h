// What the two C++ deep writers share (exr_deep_write.cpp: deep input;
// exr_deep_ao_write.cpp: the deep AO out): the error text, the header's
// provenance and camera attributes, and the write under a temporary name
// with OpenEXR's exceptions turned into statuses.  C++ only, not
// installed.
#ifndef OBSCURA_EXR_DEEP_CPP_H
#define OBSCURA_EXR_DEEP_CPP_H

#include <ImfHeader.h>
#include <ImfMatrixAttribute.h>
#include <ImfStringAttribute.h>
#include <ImathMatrix.h>
#include <cstdarg>
#include <cstdio>
#include <exception>
#include <new>

#include "io/out_file.h"
#include "obscura/io.h"

// exr_internal.h (a C header that includes openexr.h) declares it too.
extern "C" void obs__exr_camera_matrices(const obs_camera *cam, float wtc[16], float ndc[16]);

static inline obs_status obs__deep_fail(char *err, obs_status s, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        std::vsnprintf(err, OBS_ERR_LEN, fmt, ap);
        va_end(ap);
    }
    return s;
}

// obscura/version, and the camera as worldToCamera/worldToNDC (the flat
// writer's attributes, exr_write.c) when it has a world_to_camera.
static inline void obs__deep_header_attrs(OPENEXR_IMF_NAMESPACE::Header &hdr, const obs_camera *cam)
{
    using namespace OPENEXR_IMF_NAMESPACE;
    hdr.insert("obscura/version", StringAttribute(OBS_VERSION));
    if (!cam->has_world_to_camera)
        return;
    float wtc[16], ndc[16];
    obs__exr_camera_matrices(cam, wtc, ndc);
    IMATH_NAMESPACE::M44f mw, mn;
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            mw[r][c] = wtc[4 * r + c];
            mn[r][c] = ndc[4 * r + c];
        }
    hdr.insert("worldToCamera", M44fAttribute(mw));
    if (cam->has_projection)
        hdr.insert("worldToNDC", M44fAttribute(mn));
}

// Runs write(tmp), tmp a hidden sibling of path (out_file.h), and renames
// it into place when it returns; an exception is a status naming `what`.
template <class Write>
static obs_status obs__deep_write_file(const char *path, const char *what, char *err, Write write)
{
    obs__out_file out;
    const char *tmp = obs__out_begin(&out, path);
    obs_status st = OBS_OK;
    try {
        write(tmp);
    } catch (const std::bad_alloc &) {
        st = obs__deep_fail(err, OBS_NO_MEMORY, "%s: out of memory writing the %s", path, what);
    } catch (const std::exception &e) {
        st = obs__deep_fail(err, OBS_IO, "%s: %s", path, e.what());
    } catch (...) {
        st = obs__deep_fail(err, OBS_IO, "%s: cannot write the %s", path, what);
    }
    if (st != OBS_OK)
        return obs__out_end(&out, st, NULL);
    char sub[OBS_ERR_LEN] = "";
    if ((st = obs__out_end(&out, st, sub)) != OBS_OK)
        return obs__deep_fail(err, st, "%s: %s", path, sub);
    return OBS_OK;
}

#endif
