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
    return obs_deep_write_exr_extra(path, d, NULL, NULL, err);
}

extern "C" obs_status obs_deep_write_exr_extra(const char *path, const obs_deep_image *d,
                                               const char *extra, const float *values,
                                               char err[OBS_ERR_LEN])
{
    if (!path || !*path || !d || !d->offset || !d->samples || d->width <= 0 || d->height <= 0)
        return obs__deep_fail(err, OBS_INVALID_ARGUMENT, "obs_deep_write_exr: no path or no deep image");
    if (extra && (!*extra || !values))
        return obs__deep_fail(err, OBS_INVALID_ARGUMENT, "obs_deep_write_exr_extra: no channel name or no values");
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
        if (extra) // one value a sample, beside the others
            hdr.channels().insert(extra, Channel(FLOAT));

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
        std::vector<const float *> pe(extra ? npx : 0);
        for (size_t i = 0; extra && i < npx; i++)
            pe[i] = values + d->offset[i];
        if (extra)
            fb.insert(extra, DeepSlice(FLOAT, (char *)(pe.data() - origin), sizeof(float *),
                                       sizeof(float *) * (size_t)w, sizeof(float)));
        DeepScanLineOutputFile file(tmp, hdr);
        file.setFrameBuffer(fb);
        file.writePixels(h);
    });
}
