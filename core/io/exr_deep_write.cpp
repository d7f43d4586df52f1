// Deep scanline EXR output (deep.h, obs_deep_write_exr) through OpenEXR's
// C++ deep API: the C API of OpenEXR 3.1 reads deep data but cannot write
// it.  With exr_deep_ao_write.cpp the C++ of libobscura (what the two
// share: exr_deep_cpp.h); it never throws across its C interface.  What it writes, core/io/exr_deep.c reads: channels Z, ZBack,
// A, R, G, B, N.X/N.Y/N.Z, Facing (as the image has them), the camera as
// worldToCamera/worldToNDC (the flat writer's attributes, exr_write.c),
// and obscura/version (the provenance every output carries, io.h).
#include <ImfChannelList.h>
#include <ImfDeepFrameBuffer.h>
#include <ImfDeepScanLineOutputFile.h>
#include <ImfPartType.h>
#include <ImathBox.h>
#include <vector>

#include "io/exr_deep_cpp.h"
#include "obscura/deep.h"

using namespace OPENEXR_IMF_NAMESPACE;

extern "C" obs_status obs_deep_write_exr(const char *path, const obs_deep_image *d,
                                         char err[OBS_ERR_LEN])
{
    return obs_deep_write_exr_extra(path, d, NULL, 0, NULL, err);
}

extern "C" obs_status obs_deep_write_exr_extra(const char *path, const obs_deep_image *d,
                                               const obs_deep_channel *extra, int n_extra,
                                               const char *const *attrs, char err[OBS_ERR_LEN])
{
    if (!path || !*path || !d || !d->offset || !d->samples || d->width <= 0 || d->height <= 0)
        return obs__deep_fail(err, OBS_INVALID_ARGUMENT, "obs_deep_write_exr: no path or no deep image");
    for (int k = 0; k < n_extra; k++)
        if (!extra[k].name || !*extra[k].name || !extra[k].values || extra[k].stride < 1)
            return obs__deep_fail(err, OBS_INVALID_ARGUMENT,
                                  "obs_deep_write_exr_extra: channel %d has no name, values or stride", k);
    const int w = d->width, h = d->height;
    const size_t npx = (size_t)w * (size_t)h;
    for (size_t i = 0; i < npx; i++)
        if (d->offset[i + 1] < d->offset[i] || d->offset[i + 1] - d->offset[i] > OBS_DEEP_MAX_PER_PIXEL)
            return obs__deep_fail(err, OBS_INVALID_ARGUMENT, "%s: pixel %zu holds %llu samples; at most %d",
                        path, i, (unsigned long long)(d->offset[i + 1] - d->offset[i]),
                        OBS_DEEP_MAX_PER_PIXEL);
    if (d->offset[npx] > OBS_DEEP_MAX_SAMPLES)
        return obs__deep_fail(err, OBS_TOO_LARGE, "%s: %llu samples; at most %llu", path,
                    (unsigned long long)d->offset[npx], (unsigned long long)OBS_DEEP_MAX_SAMPLES);
    // a temporary sibling renamed into place once the file is closed (out_file.h)
    return obs__deep_write_file(path, "deep EXR", err, [&](const char *tmp) {
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
        for (int k = 0; k < n_extra; k++) // one value a sample, beside the others
            hdr.channels().insert(extra[k].name, Channel(FLOAT));
        for (int k = 0; attrs && attrs[k] && attrs[k + 1]; k += 2)
            hdr.insert(attrs[k], StringAttribute(attrs[k + 1]));

        obs__deep_header_attrs(hdr, &d->camera);

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
        std::vector<std::vector<const float *>> pe((size_t)n_extra);
        for (int k = 0; k < n_extra; k++) {
            pe[k].resize(npx);
            for (size_t i = 0; i < npx; i++)
                pe[k][i] = extra[k].values + d->offset[i] * (size_t)extra[k].stride;
            fb.insert(extra[k].name,
                      DeepSlice(FLOAT, (char *)(pe[k].data() - origin), sizeof(float *),
                                sizeof(float *) * (size_t)w, (size_t)extra[k].stride * sizeof(float)));
        }
        DeepScanLineOutputFile file(tmp, hdr);
        file.setFrameBuffer(fb);
        file.writePixels(h);
    });
}
