// Writes tests/data/deep_small.exr, the small deep scanline fixture of
// tests/unit/core/test_deep.c, with OpenEXR's C++ deep API (the C API of
// OpenEXR 3.1 cannot write deep data).  Built and run by `make
// deep-fixture` only; its output is committed.
//
// 48 x 32 pixels, ZIPS, channels R G B A Z ZBack (half colour, float
// depth), no normals, a camera (worldToCamera, worldToNDC: 40 degrees
// vertical field of view, camera at the origin).  Per pixel, written back
// to front (the reader sorts):
//   every pixel    a wall, Z 8, alpha 1, colour (0.2, 0.4, 0.6)
//   16 <= x, 12 <= y    an opaque box face, Z 6, colour (0, 0.5, 0)
//   8 <= x < 24, 8 <= y < 24   a glass pane, Z 4, alpha 0.5, colour (0.5, 0, 0) premultiplied
//   pixel (0, 0)   ten more samples, Z 1 .. 1.9, alpha 0.3 (a list to compress)
// The test recomputes this layout.
#include <ImfChannelList.h>
#include <ImfDeepFrameBuffer.h>
#include <ImfDeepScanLineOutputFile.h>
#include <ImfHeader.h>
#include <ImfMatrixAttribute.h>
#include <ImfPartType.h>
#include <ImfStandardAttributes.h>
#include <ImathMatrix.h>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace OPENEXR_IMF_NAMESPACE;

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "tests/data/deep_small.exr";
    const int W = 48, H = 32;
    Header hdr(W, H);
    hdr.compression() = ZIPS_COMPRESSION;
    hdr.setType(DEEPSCANLINE);
    hdr.channels().insert("R", Channel(HALF));
    hdr.channels().insert("G", Channel(HALF));
    hdr.channels().insert("B", Channel(HALF));
    hdr.channels().insert("A", Channel(HALF));
    hdr.channels().insert("Z", Channel(FLOAT));
    hdr.channels().insert("ZBack", Channel(FLOAT));
    // Imath row-vector matrices; camera space +Z forward (OpenEXR's
    // convention, as core/io/exr_read.c reads it).
    IMATH_NAMESPACE::M44f wtc; // identity
    float t = std::tan(20.0f * float(M_PI) / 180.0f), aspect = float(W) / float(H);
    // NDC (0,0) top-left .. (1,1) bottom-right: x_ndc = 0.5 + 0.5 x / (z t aspect),
    // y_ndc = 0.5 - 0.5 y / (z t), as homogeneous (., ., ., z).
    IMATH_NAMESPACE::M44f ndc(0.5f / (t * aspect), 0, 0, 0,
                              0, -0.5f / t, 0, 0,
                              0.5f, 0.5f, 0, 1,
                              0, 0, 0, 0);
    addWorldToCamera(hdr, wtc);
    addWorldToNDC(hdr, ndc);

    std::vector<unsigned int> count(W * H);
    std::vector<std::vector<float>> r(W * H), g(W * H), b(W * H), a(W * H), z(W * H);
    auto add = [&](int i, float rr, float gg, float bb, float aa, float zz) {
        r[i].push_back(rr); g[i].push_back(gg); b[i].push_back(bb); a[i].push_back(aa);
        z[i].push_back(zz);
    };
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int i = y * W + x;
            add(i, 0.2f, 0.4f, 0.6f, 1.0f, 8.0f);
            if (x >= 16 && y >= 12)
                add(i, 0.0f, 0.5f, 0.0f, 1.0f, 6.0f);
            if (x >= 8 && x < 24 && y >= 8 && y < 24)
                add(i, 0.5f, 0.0f, 0.0f, 0.5f, 4.0f);
            if (i == 0)
                for (int k = 9; k >= 0; k--)
                    add(i, 0.3f, 0.3f, 0.3f, 0.3f, 1.0f + 0.1f * float(k));
            count[i] = (unsigned)z[i].size();
        }
    std::vector<half *> pr(W * H), pg(W * H), pb(W * H), pa(W * H);
    std::vector<float *> pz(W * H);
    std::vector<std::vector<half>> cr(W * H), cg(W * H), cb(W * H), ca(W * H);
    for (int i = 0; i < W * H; i++) {
        for (size_t k = 0; k < z[i].size(); k++) {
            cr[i].push_back(half(r[i][k])); cg[i].push_back(half(g[i][k]));
            cb[i].push_back(half(b[i][k])); ca[i].push_back(half(a[i][k]));
        }
        pr[i] = cr[i].data(); pg[i] = cg[i].data(); pb[i] = cb[i].data(); pa[i] = ca[i].data();
        pz[i] = z[i].data();
    }
    DeepFrameBuffer fb;
    fb.insertSampleCountSlice(Slice(UINT, (char *)count.data(), sizeof(unsigned), sizeof(unsigned) * W));
    fb.insert("R", DeepSlice(HALF, (char *)pr.data(), sizeof(half *), sizeof(half *) * W, sizeof(half)));
    fb.insert("G", DeepSlice(HALF, (char *)pg.data(), sizeof(half *), sizeof(half *) * W, sizeof(half)));
    fb.insert("B", DeepSlice(HALF, (char *)pb.data(), sizeof(half *), sizeof(half *) * W, sizeof(half)));
    fb.insert("A", DeepSlice(HALF, (char *)pa.data(), sizeof(half *), sizeof(half *) * W, sizeof(half)));
    fb.insert("Z", DeepSlice(FLOAT, (char *)pz.data(), sizeof(float *), sizeof(float *) * W, sizeof(float)));
    fb.insert("ZBack", DeepSlice(FLOAT, (char *)pz.data(), sizeof(float *), sizeof(float *) * W, sizeof(float)));
    DeepScanLineOutputFile file(path, hdr);
    file.setFrameBuffer(fb);
    file.writePixels(H);
    std::printf("wrote %s (%dx%d deep scanline)\n", path, W, H);
    return 0;
}
