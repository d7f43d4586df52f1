// Deep scanline EXR output (deep.h, obs_deep_write_exr) through OpenEXR's
// C++ deep API: the C API of OpenEXR 3.1 reads deep data but cannot write
// it.  The one C++ file of libobscura; it never throws across its C
// interface.  What it writes, core/io/exr_deep.c reads: channels Z, ZBack,
// A, R, G, B, N.X/N.Y/N.Z, Facing (as the image has them), the camera as
// worldToCamera/worldToNDC (the flat writer's attributes, exr_write.c),
// and obscura/version (the provenance every output carries, io.h).
#include <ImfChannelList.h>
#include <ImfDeepFrameBuffer.h>
#include <ImfDeepScanLineOutputFile.h>
#include <ImfHeader.h>
#include <ImfMatrixAttribute.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <ImathBox.h>
#include <ImathMatrix.h>
#include <cstdarg>
#include <cstdio>
#include <exception>
#include <new>
#include <vector>

#include "io/out_file.h"
#include "obscura/deep.h"

// exr_internal.h (a C header that includes openexr.h) declares it too.
extern "C" void obs__exr_camera_matrices(const obs_camera *cam, float wtc[16], float ndc[16]);

using namespace OPENEXR_IMF_NAMESPACE;

static obs_status fail(char *err, obs_status s, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        std::vsnprintf(err, OBS_ERR_LEN, fmt, ap);
        va_end(ap);
    }
    return s;
}

extern "C" obs_status obs_deep_write_exr(const char *path, const obs_deep_image *d,
                                         char err[OBS_ERR_LEN])
{
    if (!path || !*path || !d || !d->offset || !d->samples || d->width <= 0 || d->height <= 0)
        return fail(err, OBS_INVALID_ARGUMENT, "obs_deep_write_exr: no path or no deep image");
    const int w = d->width, h = d->height;
    const size_t npx = (size_t)w * (size_t)h;
    for (size_t i = 0; i < npx; i++)
        if (d->offset[i + 1] < d->offset[i] || d->offset[i + 1] - d->offset[i] > OBS_DEEP_MAX_PER_PIXEL)
            return fail(err, OBS_INVALID_ARGUMENT, "%s: pixel %zu holds %llu samples; at most %d",
                        path, i, (unsigned long long)(d->offset[i + 1] - d->offset[i]),
                        OBS_DEEP_MAX_PER_PIXEL);
    if (d->offset[npx] > OBS_DEEP_MAX_SAMPLES)
        return fail(err, OBS_TOO_LARGE, "%s: %llu samples; at most %llu", path,
                    (unsigned long long)d->offset[npx], (unsigned long long)OBS_DEEP_MAX_SAMPLES);
    // a temporary sibling renamed into place once the file is closed (out_file.h)
    obs__out_file out;
    const char *tmp = obs__out_begin(&out, path);
    obs_status st = OBS_OK;
    try {
        const int dispw = d->display_width > 0 ? d->display_width : w;
        const int disph = d->display_height > 0 ? d->display_height : h;
        // display_x/y: the data window's origin in the display window.
        IMATH_NAMESPACE::Box2i display(IMATH_NAMESPACE::V2i(0, 0),
                                       IMATH_NAMESPACE::V2i(dispw - 1, disph - 1));
        IMATH_NAMESPACE::Box2i data(IMATH_NAMESPACE::V2i(d->display_x, d->display_y),
                                    IMATH_NAMESPACE::V2i(d->display_x + w - 1, d->display_y + h - 1));
        Header hdr(display, data);
        hdr.compression() = ZIPS_COMPRESSION;
        hdr.setType(DEEPSCANLINE);

        struct ch {
            const char *name;
            int index;
            bool present;
        } chans[] = {
            {"Z", OBS_DEEP_Z, true},          {"ZBack", OBS_DEEP_ZBACK, d->has_zback != 0},
            {"A", OBS_DEEP_A, d->has_alpha != 0}, {"R", OBS_DEEP_R, d->has_color != 0},
            {"G", OBS_DEEP_G, d->has_color != 0}, {"B", OBS_DEEP_B, d->has_color != 0},
            {"N.X", OBS_DEEP_NX, d->has_normal != 0}, {"N.Y", OBS_DEEP_NY, d->has_normal != 0},
            {"N.Z", OBS_DEEP_NZ, d->has_normal != 0}, {"Facing", OBS_DEEP_FACING, d->has_facing != 0},
        };
        for (const ch &c : chans)
            if (c.present)
                hdr.channels().insert(c.name, Channel(FLOAT));

        hdr.insert("obscura/version", StringAttribute(OBS_VERSION));
        const obs_camera *cam = &d->camera;
        if (cam->has_world_to_camera) {
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

        // Per pixel: its sample count and, per channel, a pointer to its
        // first value (samples are interleaved, OBS_DEEP_CH floats each).
        std::vector<unsigned int> count(npx);
        std::vector<const float *> base(npx);
        for (size_t i = 0; i < npx; i++) {
            count[i] = (unsigned int)(d->offset[i + 1] - d->offset[i]);
            base[i] = d->samples + d->offset[i] * OBS_DEEP_CH;
        }
        std::vector<std::vector<const float *>> ptr(OBS_DEEP_CH);
        // Slices address pixel (x, y) of the data window at base + x xs + y ys.
        const ptrdiff_t origin = (ptrdiff_t)d->display_y * w + d->display_x;
        DeepFrameBuffer fb;
        fb.insertSampleCountSlice(Slice(UINT, (char *)(count.data() - origin), sizeof(unsigned int),
                                        sizeof(unsigned int) * (size_t)w));
        for (const ch &c : chans) {
            if (!c.present)
                continue;
            std::vector<const float *> &p = ptr[c.index];
            p.resize(npx);
            for (size_t i = 0; i < npx; i++)
                p[i] = base[i] + c.index;
            fb.insert(c.name, DeepSlice(FLOAT, (char *)(p.data() - origin), sizeof(float *),
                                        sizeof(float *) * (size_t)w, OBS_DEEP_CH * sizeof(float)));
        }
        DeepScanLineOutputFile file(tmp, hdr);
        file.setFrameBuffer(fb);
        file.writePixels(h);
    } catch (const std::bad_alloc &) {
        st = fail(err, OBS_NO_MEMORY, "%s: out of memory writing the deep EXR", path);
    } catch (const std::exception &e) {
        st = fail(err, OBS_IO, "%s: %s", path, e.what());
    } catch (...) {
        st = fail(err, OBS_IO, "%s: cannot write the deep EXR", path);
    }
    if (st != OBS_OK)
        return obs__out_end(&out, st, NULL);
    char sub[OBS_ERR_LEN] = "";
    if ((st = obs__out_end(&out, st, sub)) != OBS_OK)
        return fail(err, st, "%s: %s", path, sub);
    return OBS_OK;
}
