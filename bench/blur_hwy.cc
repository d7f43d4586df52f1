// The blur kernel (VAO++ section 4.6) in Google's Highway against the
// library's OpenMP simd form (core/chain/blur_cpu.c), one thread, on a
// 1920x1080 synthetic frame: the same fused bands (the horizontal pass
// into a scratch of 32 + 2R rows, the vertical from there), the same
// arithmetic in the same order, so the outputs must be the same bytes.
// (-ffp-contract=off: no fused multiply-add where C has none.)
// Highway's dynamic dispatch picks the widest target this CPU runs, as
// the library's target_clones do.  Developer benchmark (make bench).
//
//   blur_hwy_bench [FRAMES]
#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <algorithm>
#include <vector>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "bench/blur_hwy.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

extern "C" {
#include "chain/bands_cpu.h"
#include "chain/frame.h"
#include "chain/vao_cpu.h"
}

HWY_BEFORE_NAMESPACE();
namespace obs_hwy {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// blur_span of blur_cpu.c: n pixels from the first (depth at zc[0],
// packed with the normal's z: stride 2), neighbours k * step away.
static void Span(const obs__frame *f, const float *zc, const float *a, float *d, int n,
                 ptrdiff_t step, ptrdiff_t zstep, int kmin, int kmax)
{
    const hn::ScalableTag<float> df;
    const int L = (int)hn::Lanes(df);
    const auto zero = hn::Zero(df), radius = hn::Set(df, f->radius);
    int j = 0;
    for (; j + L <= n; j += L) {
        hn::Vec<decltype(df)> z0, unused;
        hn::LoadInterleaved2(df, zc + 2 * j, z0, unused);
        auto sum = zero, wsum = zero;
        for (int k = kmin; k <= kmax; k++) {
            const auto wk = hn::Set(df, f->blur_w[k < 0 ? -k : k]);
            hn::Vec<decltype(df)> zj, nz;
            hn::LoadInterleaved2(df, zc + 2 * (k * zstep) + 2 * j, zj, nz);
            const auto in = hn::AndNot(hn::Le(zj, zero),
                                       hn::Not(hn::Gt(hn::Abs(hn::Sub(zj, z0)), radius)));
            const auto aq = hn::LoadU(df, a + k * step + j);
            sum = hn::Add(sum, hn::IfThenElseZero(in, hn::Mul(wk, aq)));
            wsum = hn::Add(wsum, hn::IfThenElseZero(in, wk));
        }
        const auto v = hn::Div(sum, wsum), aj = hn::LoadU(df, a + j);
        hn::StoreU(hn::IfThenElse(hn::Le(z0, zero), aj, v), df, d + j);
    }
    for (; j < n; j++) { // the tail: the same arithmetic, one pixel
        float sum = 0.0f, wsum = 0.0f, zc0 = zc[2 * j];
        for (int k = kmin; k <= kmax; k++) {
            const float wk = f->blur_w[k < 0 ? -k : k], zj = zc[2 * (k * zstep) + 2 * j];
            const int in = !(zj <= 0.0f) & !(__builtin_fabsf(zj - zc0) > f->radius);
            sum += in ? wk * a[k * step + j] : 0.0f;
            wsum += in ? wk : 0.0f;
        }
        d[j] = zc0 <= 0.0f ? a[j] : sum / wsum;
    }
}

// Both passes, fused in bands of 32 rows, as blur_cpu.c's blur().
void Blur(const obs__frame *f, const float *pos, const float *dnz, const float *src, float *dst,
          float *buf)
{
    const int w = f->width, h = f->height, R = f->blur_radius;
    for (int y0 = 0; y0 < h; y0 += 32) {
        const int y1 = std::min(h, y0 + 32), ya = std::max(0, y0 - R), yb = std::min(h, y1 + R);
        for (int y = ya; y < yb; y++) {
            float *drow = buf + (size_t)(y - ya) * w;
            const size_t row = (size_t)y * w;
            for (int x = 0; x < R; x++)
                drow[x] = obs__blur_pixel(f, pos, src, x, y, 1, 0);
            Span(f, dnz + 2 * (row + R), src + row + R, drow + R, w - 2 * R, 1, 1, -R, R);
            for (int x = w - R; x < w; x++)
                drow[x] = obs__blur_pixel(f, pos, src, x, y, 1, 0);
        }
        for (int y = y0; y < y1; y++) {
            const int kmin = std::max(-y, -R), kmax = std::min(h - 1 - y, R);
            Span(f, dnz + 2 * (size_t)y * w, buf + (size_t)(y - ya) * w, dst + (size_t)y * w, w,
                 w, w, kmin, kmax);
        }
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace obs_hwy
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace obs_hwy {
HWY_EXPORT(Blur);
}

static double now_ms()
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

int main(int argc, char **argv)
{
    const int W = 1920, H = 1080, frames = argc > 1 ? atoi(argv[1]) : 9;
    obs__frame f;
    memset(&f, 0, sizeof f);
    f.width = W;
    f.height = H;
    f.radius = 0.5f;
    f.blur_radius = 2; // the default chain's 5 taps
    for (int k = 0; k <= f.blur_radius; k++)
        f.blur_w[k] = expf(-0.5f * (float)(k * k) / 2.0f);
    std::vector<float> pos(4 * (size_t)W * H), dnz(2 * (size_t)W * H), ao((size_t)W * H),
        a((size_t)W * H), b((size_t)W * H), tmp((size_t)W * H), buf((size_t)W * (32 + 2 * 2));
    unsigned seed = 1;
    for (int y = 0; y < H; y++) // steps in depth, a background patch, noisy AO
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + x;
            float z = (x / 97 + y / 61) % 5 == 0 ? 0.0f : 3.0f + 0.4f * (float)((x / 13) % 4);
            pos[4 * i + 3] = dnz[2 * i] = z;
            dnz[2 * i + 1] = 0.7f;
            seed = seed * 1103515245u + 12345u;
            ao[i] = (float)(seed >> 8) / 16777216.0f;
        }
    obs__cpu_set_threads(1); // the kernel, not the pool
    std::vector<double> t_omp, t_hwy;
    for (int i = 0; i <= frames; i++) { // i = 0: warm-up
        memcpy(a.data(), ao.data(), sizeof(float) * a.size());
        double t0 = now_ms();
        float *res = obs__blur_dnz(&f, pos.data(), dnz.data(), a.data(), tmp.data(), 0);
        double t1 = now_ms();
        HWY_DYNAMIC_DISPATCH(obs_hwy::Blur)(&f, pos.data(), dnz.data(), ao.data(), b.data(),
                                            buf.data());
        double t2 = now_ms();
        if (i == 0 && memcmp(res, b.data(), sizeof(float) * b.size())) {
            size_t k = 0;
            while (!memcmp(&res[k], &b[k], sizeof(float)))
                k++;
            fprintf(stderr, "blur_hwy_bench: pixel %zu differs: %.9g, Highway %.9g\n", k,
                    (double)res[k], (double)b[k]);
            return 1;
        }
        if (i > 0) {
            t_omp.push_back(t1 - t0);
            t_hwy.push_back(t2 - t1);
        }
    }
    std::sort(t_omp.begin(), t_omp.end());
    std::sort(t_hwy.begin(), t_hwy.end());
    double mo = t_omp[t_omp.size() / 2], mh = t_hwy[t_hwy.size() / 2];
    printf("| kernel | 1920x1080, 1 thread, median of %d | Mpixel/s |\n|---|---|---|\n", frames);
    printf("| blur, OpenMP simd (target_clones, gcc) | %.2f ms | %.0f |\n", mo, W * H / mo / 1e3);
    printf("| blur, Highway %s (dynamic dispatch) | %.2f ms | %.0f |\n",
           hwy::TargetName(hwy::SupportedAndGeneratedTargets()[0]), mh, W * H / mh / 1e3);
    printf("\nHighway / OpenMP simd: %.2f; outputs the same bytes\n", mh / mo);
    return 0;
}
#endif
