// hairvox shading: simd.h. simdTarget() asks the shading kernels' own
// dispatch (shade_kernel.cpp); the FMA loop is compiled once per SIMD target
// here, for the same targets as the kernels (its dispatch is checked against
// theirs: tests/shading/simd_test.cpp).
#ifndef HWY_DISABLED_TARGETS // as shade_kernel.cpp's
#define HWY_DISABLED_TARGETS (HWY_SSSE3 | HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV)
#endif

// Highway's order: the target list, then this file once per target.
// clang-format off
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "shading/src/simd.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep
#include <hwy/highway.h>
// clang-format on

#include "shade_kernel.h"

#include <hairvox/shading/simd.h>

#include <algorithm>
#include <chrono>
#include <limits>

HWY_BEFORE_NAMESPACE();
namespace hairvox::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

double FmaFlopsPerSecond();
const char* FmaTarget();

const char* FmaTarget() {
    return hwy::TargetName(HWY_TARGET);
}

/// kChains accumulators: more than FMA latency × issue width (4 × 2), and
/// with the two constants within AVX2's 16 registers.
double FmaFlopsPerSecond() {
    constexpr int kChains = 12, kSteps = 1 << 18;
    const hn::ScalableTag<float> d;
    const auto m = hn::Set(d, 0.999999f), a = hn::Set(d, 1e-7f);
    double best = std::numeric_limits<double>::infinity();
    float sink = 0;
    for (int pass = 0; pass < 3; ++pass) {
        hn::Vec<decltype(d)> acc[kChains];
        for (int k = 0; k < kChains; ++k)
            acc[k] = hn::Set(d, 1.0f + float(k) + sink * 0.0f);
        const auto start = std::chrono::steady_clock::now();
        for (int step = 0; step < kSteps; ++step)
            for (int k = 0; k < kChains; ++k)
                acc[k] = hn::MulAdd(acc[k], m, a);
        best = std::min(
            best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        for (int k = 0; k < kChains; ++k)
            sink += hn::GetLane(hn::SumOfLanes(d, acc[k]));
    }
    const double flops = 2.0 * double(hn::Lanes(d)) * kChains * double(kSteps);
    return sink > 0 ? flops / best : 0;
}

} // namespace hairvox::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace hairvox {

HWY_EXPORT(FmaFlopsPerSecond);
HWY_EXPORT(FmaTarget);

std::string simdTarget() {
    return detail::shadeKernelTarget(); // the kernels' own dispatch, not a second guess
}

SimdFmaPeak simdFmaPeak() {
    return {HWY_DYNAMIC_DISPATCH(FmaTarget)(), HWY_DYNAMIC_DISPATCH(FmaFlopsPerSecond)()};
}

} // namespace hairvox
#endif
