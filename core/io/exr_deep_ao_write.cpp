// The deep AO out (deep.h, obs_deep_ao_write_exr; obscura ao --output deep)
// through OpenEXR's C++ deep API, as exr_deep_write.cpp writes deep
// input: a two-part file, the nodes' AO as a deep scanline part ("deep")
// and the flat AO beside it as a scanline part ("flat"), float.  Deep colour is
// premultiplied by alpha in OpenEXR ("Interpreting OpenEXR Deep Pixels"),
// so AO.Y holds A x AO: a deep reader's flatten (Nuke's DeepToImage,
// oiiotool --flatten) gives the AO over black, sum of T_k A_k AO_k, and
// the flat AO is that plus the transmittance left, 1 - A.  It never
// throws across its C interface.
#include <ImfChannelList.h>
#include <ImfDeepFrameBuffer.h>
#include <ImfDeepScanLineOutputPart.h>
#include <ImfFrameBuffer.h>
#include <ImfIO.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImathBox.h>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "io/exr_deep_cpp.h"
#include "obscura/deep.h"

using namespace OPENEXR_IMF_NAMESPACE;

// The header both parts share: the windows, the camera, the version.
static Header base_header(const obs_deep_ao *a)
{
    const int w = a->width, h = a->height;
    const int dispw = a->display_width > 0 ? a->display_width : w;
    const int disph = a->display_height > 0 ? a->display_height : h;
    IMATH_NAMESPACE::Box2i display(IMATH_NAMESPACE::V2i(0, 0), IMATH_NAMESPACE::V2i(dispw - 1, disph - 1));
    IMATH_NAMESPACE::Box2i data(IMATH_NAMESPACE::V2i(a->display_x, a->display_y),
                                IMATH_NAMESPACE::V2i(a->display_x + w - 1, a->display_y + h - 1));
    Header hdr(display, data);
    obs__deep_header_attrs(hdr, &a->camera);
    return hdr;
}

// The deep AO and the flat images are consistent (`path` names the
// output in the message).
static obs_status check_args(const char *path, const obs_deep_ao *a, const obs_image *flat,
                             const obs_image *front, char err[OBS_ERR_LEN])
{
    if (!path || !*path || !a || !a->offset || a->width <= 0 || a->height <= 0)
        return obs__deep_fail(err, OBS_INVALID_ARGUMENT, "obs_deep_ao_write_exr: no path or no deep AO");
    const int w = a->width, h = a->height;
    const size_t npx = (size_t)w * (size_t)h;
    const obs_image *flats[2] = {flat, front};
    for (const obs_image *im : flats)
        if (im && (!im->data || im->width != w || im->height != h || im->channels != 1))
            return obs__deep_fail(err, OBS_INVALID_ARGUMENT, "%s: the flat AO is %dx%d, the deep AO %dx%d", path,
                        im->width, im->height, w, h);
    for (size_t i = 0; i < npx; i++)
        if (a->offset[i + 1] < a->offset[i] || a->offset[i + 1] - a->offset[i] > OBS_DEEP_MAX_LAYERS)
            return obs__deep_fail(err, OBS_INVALID_ARGUMENT, "%s: pixel %zu holds %llu nodes; at most %d", path, i,
                        (unsigned long long)(a->offset[i + 1] - a->offset[i]), OBS_DEEP_MAX_LAYERS);
    return OBS_OK;
}

// The parts' compressions for `c`: `c` for both, but zip (and the
// default, zip) is ZIPS in the deep part: OpenEXR's deep data takes
// none, rle or zips (one scanline a chunk), and no other.
static obs_status compressions(obs_exr_compression c, Compression *deep, Compression *flat, char err[OBS_ERR_LEN])
{
    static const Compression of[] = {ZIP_COMPRESSION, NO_COMPRESSION,   RLE_COMPRESSION, ZIPS_COMPRESSION,
                                     ZIP_COMPRESSION, PIZ_COMPRESSION,  DWAA_COMPRESSION};
    if ((int)c < 0 || (size_t)c >= sizeof of / sizeof of[0])
        return obs__deep_fail(err, OBS_INVALID_ARGUMENT, "deep AO: unknown compression %d", (int)c);
    obs_status s = obs_exr_compression_check(c, err); // dwaa: OpenEXR 3.2's C API reads it
    if (s != OBS_OK)
        return s;
    *deep = of[c] == ZIP_COMPRESSION ? ZIPS_COMPRESSION : of[c];
    *flat = of[c];
    if (*deep != NO_COMPRESSION && *deep != RLE_COMPRESSION && *deep != ZIPS_COMPRESSION)
        return obs__deep_fail(err, OBS_UNSUPPORTED, "compression %s: the deep AO's deep part takes none, rle, zips "
                              "or zip (OpenEXR codes no other for deep data)", obs_exr_compression_name(c));
    return OBS_OK;
}

// Writes the two parts into dest: a file name or an OStream.
template <class Dest>
static void write_parts(Dest &dest, const obs_deep_ao *a, const obs_image *flat, const obs_image *front,
                        Compression deep_c, Compression flat_c)
{
    const int w = a->width, h = a->height;
    const size_t npx = (size_t)w * (size_t)h;
    const obs_image *flats[2] = {flat, front};
    Header deep = base_header(a);
    deep.setName("deep");
    deep.setType(DEEPSCANLINE);
    deep.compression() = deep_c;
    deep.setVersion(1); // the deep data version the C API (and Nuke) require
    // planar per channel: A, A x AO, Z, ZBack of every node in order
    static const char *const names[] = {"A", "AO.Y", "Z", "ZBack"};
    for (const char *n : names)
        deep.channels().insert(n, Channel(FLOAT));
    Header flt = base_header(a);
    flt.setName("flat");
    flt.setType(SCANLINEIMAGE);
    flt.compression() = flat_c;
    flt.setVersion(1); // OpenEXR's C API wants it on every part of a file with deep data
    if (flat)
        flt.channels().insert("AO.Y", Channel(FLOAT));
    if (front)
        flt.channels().insert("AOFront.Y", Channel(FLOAT));
    const bool has_flat = flat || front;

    const uint64_t total = a->offset[npx];
    std::vector<float> plane[4];
    for (std::vector<float> &p : plane)
        p.resize(total ? total : 1);
    for (uint64_t s = 0; s < total; s++) {
        const float *v = a->node + s * OBS_DEEP_AO_CH;
        plane[0][s] = v[OBS_DEEP_AO_A];
        plane[1][s] = v[OBS_DEEP_AO_A] * v[OBS_DEEP_AO_AO];
        plane[2][s] = v[OBS_DEEP_AO_Z];
        plane[3][s] = v[OBS_DEEP_AO_ZBACK];
    }
    std::vector<unsigned int> count(npx);
    std::vector<float *> ptr[4];
    for (size_t i = 0; i < npx; i++)
        count[i] = (unsigned int)(a->offset[i + 1] - a->offset[i]);
    // Slices address pixel (x, y) of the data window at base + x xs + y ys.
    const ptrdiff_t origin = (ptrdiff_t)a->display_y * w + a->display_x;
    DeepFrameBuffer fb;
    fb.insertSampleCountSlice(Slice(UINT, (char *)(count.data() - origin), sizeof(unsigned int),
                                    sizeof(unsigned int) * (size_t)w));
    for (int c = 0; c < 4; c++) {
        ptr[c].resize(npx);
        for (size_t i = 0; i < npx; i++)
            ptr[c][i] = plane[c].data() + a->offset[i];
        fb.insert(names[c], DeepSlice(FLOAT, (char *)(ptr[c].data() - origin), sizeof(float *),
                                      sizeof(float *) * (size_t)w, sizeof(float)));
    }
    std::vector<Header> headers{deep};
    if (has_flat)
        headers.push_back(flt);
    MultiPartOutputFile file(dest, headers.data(), (int)headers.size());
    DeepScanLineOutputPart dp(file, 0);
    dp.setFrameBuffer(fb);
    dp.writePixels(h);
    if (has_flat) {
        FrameBuffer ff;
        const char *const fnames[2] = {"AO.Y", "AOFront.Y"};
        for (int k = 0; k < 2; k++)
            if (flats[k])
                ff.insert(fnames[k], Slice(FLOAT, (char *)(flats[k]->data - origin), sizeof(float),
                                           sizeof(float) * (size_t)w));
        OutputPart fp(file, 1);
        fp.setFrameBuffer(ff);
        fp.writePixels(h);
    }
}

extern "C" obs_status obs_deep_ao_write_exr(const char *path, const obs_deep_ao *a,
                                            const obs_image *flat, const obs_image *front,
                                            obs_exr_compression compression, char err[OBS_ERR_LEN])
{
    Compression dc, fc;
    obs_status s = check_args(path, a, flat, front, err);
    if (s == OBS_OK)
        s = compressions(compression, &dc, &fc, err);
    if (s != OBS_OK)
        return s;
    return obs__deep_write_file(path, "deep AO", err,
                                [&](const char *tmp) { write_parts(tmp, a, flat, front, dc, fc); });
}

// An OStream into memory (malloc'd, grown by doubling), for the daemon's
// answer.
class MemOStream : public OStream {
  public:
    MemOStream() : OStream("memory") {}
    ~MemOStream() override { std::free(buf); }
    void write(const char c[], int n) override
    {
        if (pos + (uint64_t)n > cap) {
            uint64_t want = cap ? cap : 65536;
            while (want < pos + (uint64_t)n)
                want *= 2;
            char *nb = (char *)std::realloc(buf, want);
            if (!nb)
                throw std::bad_alloc();
            buf = nb, cap = want;
        }
        std::memcpy(buf + pos, c, (size_t)n);
        pos += (uint64_t)n;
        if (pos > len)
            len = pos;
    }
    uint64_t tellp() override { return pos; }
    void seekp(uint64_t p) override { pos = p; }
    char *buf = nullptr;
    uint64_t cap = 0, pos = 0, len = 0;
};

extern "C" obs_status obs_deep_ao_write_exr_mem(const obs_deep_ao *a, const obs_image *flat,
                                                const obs_image *front, obs_exr_compression compression,
                                                obs_bytes *out, char err[OBS_ERR_LEN])
{
    if (!out)
        return obs__deep_fail(err, OBS_INVALID_ARGUMENT, "obs_deep_ao_write_exr_mem: no output");
    *out = obs_bytes{nullptr, 0};
    Compression dc, fc;
    obs_status s = check_args("deep AO", a, flat, front, err);
    if (s == OBS_OK)
        s = compressions(compression, &dc, &fc, err);
    if (s != OBS_OK)
        return s;
    try {
        MemOStream os;
        write_parts(os, a, flat, front, dc, fc);
        out->data = (unsigned char *)os.buf;
        out->size = (size_t)os.len;
        os.buf = nullptr;
    } catch (const std::bad_alloc &) {
        return obs__deep_fail(err, OBS_NO_MEMORY, "out of memory writing the deep AO");
    } catch (const std::exception &e) {
        return obs__deep_fail(err, OBS_IO, "deep AO: %s", e.what());
    } catch (...) {
        return obs__deep_fail(err, OBS_IO, "cannot write the deep AO");
    }
    return OBS_OK;
}
