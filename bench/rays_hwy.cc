// ao_definition rays' conversion (obs__rays_rows, core/chain/vao_cpu.c:
// Cephes' asin polynomial, b = 2 sin(asin(1 - 2o) / 3), a sine polynomial)
// in Google's Highway against the library's OpenMP simd form, one thread,
// on 1920x1080 values spread over [0, 1] with a third of them 1 (the open
// pixels): the same arithmetic in the same order, so the outputs must be
// the same bytes (-ffp-contract=off: no fused multiply-add where C has
// none).  Highway's dynamic dispatch picks the widest target this CPU
// runs, as the library's target_clones do.  Developer benchmark (make
// bench).
//
//   rays_hwy_bench [FRAMES]
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <algorithm>
#include <vector>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "bench/rays_hwy.cc"
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

// asin_lane() of vao_cpu.h
template <class D, class V>
static V Asin(D d, V x)
{
    const V a = hn::Abs(x), half = hn::Set(d, 0.5f), one = hn::Set(d, 1.0f);
    const auto big = hn::Gt(a, half);
    const V z = hn::IfThenElse(big, hn::Mul(half, hn::Sub(one, a)), hn::Mul(a, a));
    const V s = hn::IfThenElse(big, hn::Sqrt(z), a);
    V P = hn::Add(hn::Mul(hn::Set(d, 4.2163199048e-2f), z), hn::Set(d, 2.4181311049e-2f));
    P = hn::Add(hn::Mul(P, z), hn::Set(d, 4.5470025998e-2f));
    P = hn::Add(hn::Mul(P, z), hn::Set(d, 7.4953002686e-2f));
    P = hn::Add(hn::Mul(P, z), hn::Set(d, 1.6666752422e-1f));
    const V t = hn::Add(s, hn::Mul(hn::Mul(s, z), P));
    const V r = hn::IfThenElse(
        big, hn::Sub(hn::Set(d, 1.57079632679489662f), hn::Mul(hn::Set(d, 2.0f), t)), t);
    return hn::IfThenElse(hn::Lt(x, hn::Zero(d)), hn::Neg(r), r);
}

// obs__rays_rows: rays_lane() of vao_cpu.c over n values, in place
static void Rays(float *ao, size_t n, float open)
{
    const hn::ScalableTag<float> d;
    const size_t L = hn::Lanes(d);
    const auto zero = hn::Zero(d), one = hn::Set(d, 1.0f), two = hn::Set(d, 2.0f);
    const auto pi = hn::Set(d, 3.14159265358979f), half = hn::Set(d, 0.5f);
    size_t i = 0;
    for (; i + L <= n; i += L) {
        const auto a = hn::LoadU(d, ao + i);
        // o = 1 - min_f(max_f(a, 0), 1) (a NaN fails a >= 0: 0, as max_f)
        const auto mx = hn::IfThenElse(hn::Ge(a, zero), a, zero);
        const auto o = hn::Sub(one, hn::IfThenElse(hn::Le(mx, one), mx, one));
        const auto dd = hn::Div(Asin(d, hn::Sub(one, hn::Mul(two, o))), hn::Set(d, 3.0f));
        const auto d2 = hn::Mul(dd, dd);
        auto p = hn::Add(hn::Set(d, 8.3333333333e-3f), hn::Mul(d2, hn::Set(d, -1.9841269841e-4f)));
        p = hn::Add(hn::Set(d, -1.6666666667e-1f), hn::Mul(d2, p));
        const auto sn = hn::Add(dd, hn::Mul(hn::Mul(dd, d2), p));
        const auto b0 = hn::Mul(two, sn);
        const auto b1 = hn::IfThenElse(hn::Gt(b0, zero), b0, zero);
        const auto b = hn::IfThenElse(hn::Lt(b1, one), b1, one);
        const auto blocked =
            hn::Div(hn::Sub(hn::Sub(hn::Set(d, 1.57079632679489662f), Asin(d, b)),
                            hn::Mul(b, hn::Sqrt(hn::Sub(one, hn::Mul(b, b))))),
                    pi);
        const auto conv = hn::IfThenElse(hn::Ge(o, half), a, hn::Sub(one, blocked));
        hn::StoreU(hn::IfThenElse(hn::Eq(a, one), hn::Set(d, open), conv), d, ao + i);
    }
    if (i < n) // the tail: the library's own, the same floats
        obs__rays_rows(ao + i, n - i);
}

}  // namespace HWY_NAMESPACE
}  // namespace obs_hwy
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace obs_hwy {
HWY_EXPORT(Rays);
}

static double now_ms()
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

int main(int argc, char **argv)
{
    const size_t n = (size_t)1920 * 1080;
    const int frames = argc > 1 ? atoi(argv[1]) : 9;
    std::vector<float> v(n), a(n), b(n);
    unsigned seed = 1;
    for (size_t i = 0; i < n; i++) {
        seed = seed * 1103515245u + 12345u;
        v[i] = i % 3 == 0 ? 1.0f : (float)(seed >> 8) / 16777216.0f;
    }
    const float open = obs__rays_from_volume(1.0f);
    obs__cpu_set_threads(1);
    std::vector<double> t_omp, t_hwy;
    for (int i = 0; i <= frames; i++) { // i = 0: warm-up and the check
        memcpy(a.data(), v.data(), sizeof(float) * n);
        memcpy(b.data(), v.data(), sizeof(float) * n);
        double t0 = now_ms();
        obs__rays_rows(a.data(), n);
        double t1 = now_ms();
        HWY_DYNAMIC_DISPATCH(obs_hwy::Rays)(b.data(), n, open);
        double t2 = now_ms();
        if (i == 0 && memcmp(a.data(), b.data(), sizeof(float) * n)) {
            size_t k = 0;
            while (!memcmp(&a[k], &b[k], sizeof(float)))
                k++;
            fprintf(stderr, "rays_hwy_bench: value %zu (%.9g) differs: %.9g, Highway %.9g\n", k,
                    (double)v[k], (double)a[k], (double)b[k]);
            return 1;
        }
        if (i > 0) {
            t_omp.push_back(t1 - t0);
            t_hwy.push_back(t2 - t1);
        }
    }
    std::sort(t_omp.begin(), t_omp.end());
    std::sort(t_hwy.begin(), t_hwy.end());
    const double mo = t_omp[t_omp.size() / 2], mh = t_hwy[t_hwy.size() / 2];
    printf("| rays conversion, %zu values | %.2f | %.2f | %.2f |\n", n, mo, mh, mh / mo);
    return 0;
}
#endif
