// hairvox film (internal): half_convert.h for every SIMD target (Highway's
// foreach_target.h re-includes this file once per target).
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_SSSE3 | HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV)
#endif

// Highway's order: the target list, then this file once per target.
// clang-format off
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "film/src/half_convert.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep
#include <hwy/highway.h>
// clang-format on

#include "half_convert.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <half.h>
#include <limits>

HWY_BEFORE_NAMESPACE();
namespace hairvox::detail::HWY_NAMESPACE {
namespace {

namespace hn = hwy::HWY_NAMESPACE;
using D = hn::ScalableTag<float>;

/// Targets whose DemoteTo(float16) is the F16C instruction (round to
/// nearest even); elsewhere Highway truncates, so Imath converts instead.
constexpr bool kHardwareHalf =
    HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL;

std::uint16_t halfBits(float x) {
    return Imath::half(x).bits();
}

float maxAbsScalar(const float* values, std::size_t stride, std::size_t begin, std::size_t count) {
    float m = 0;
    for (std::size_t i = begin; i < count; ++i) {
        const float a = std::abs(values[i * stride]);
        m = std::isnan(a) ? std::numeric_limits<float>::infinity() : std::max(m, a);
    }
    return m;
}

/// Whole vectors are read only up to this many values: with stride 3 a
/// vector reads 3·lanes floats from the channel's first, which for the last
/// value would pass the end of the layer.
std::size_t vectorCount(std::size_t stride, std::size_t count) {
    return stride == 3 ? (count > 0 ? count - 1 : 0) : count;
}

/// Values i, i + 1, ... of a channel `stride` (1 or 3) floats apart.
hn::Vec<D> loadChannel(const float* values, std::size_t stride, std::size_t i) {
    if (stride != 3)
        return hn::LoadU(D(), values + i);
    hn::Vec<D> v, g, b;
    hn::LoadInterleaved3(D(), values + 3 * i, v, g, b);
    return v;
}

} // namespace

float MaxAbs(const float* values, std::size_t stride, std::size_t count);
void ToHalf(const float* values, std::size_t stride, std::size_t count, std::uint16_t* out);

float MaxAbs(const float* values, std::size_t stride, std::size_t count) {
    const D d;
    const std::size_t lanes = hn::Lanes(d);
    auto m = hn::Zero(d);
    auto nan = hn::FirstN(d, 0); // no lane
    std::size_t i = 0;
    for (; i + lanes <= vectorCount(stride, count); i += lanes) {
        const hn::Vec<D> v = loadChannel(values, stride, i);
        nan = hn::Or(nan, hn::IsNaN(v));
        m = hn::Max(m, hn::Abs(v));
    }
    if (!hn::AllFalse(d, nan))
        return std::numeric_limits<float>::infinity();
    return std::max(hn::GetLane(hn::MaxOfLanes(d, m)), maxAbsScalar(values, stride, i, count));
}

void ToHalf(const float* values, std::size_t stride, std::size_t count, std::uint16_t* out) {
    std::size_t i = 0;
    if constexpr (kHardwareHalf) {
        const D d;
        const hn::Rebind<hwy::float16_t, D> d16;
        const std::size_t lanes = hn::Lanes(d);
        auto* out16 = reinterpret_cast<hwy::float16_t*>(out);
        for (; i + lanes <= vectorCount(stride, count); i += lanes)
            hn::StoreU(hn::DemoteTo(d16, loadChannel(values, stride, i)), d16, out16 + i);
    }
    for (; i < count; ++i)
        out[i] = halfBits(values[i * stride]);
}

} // namespace hairvox::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace hairvox::detail {

HWY_EXPORT(MaxAbs);
HWY_EXPORT(ToHalf);

float maxAbs(const float* values, std::size_t stride, std::size_t count) {
    return HWY_DYNAMIC_DISPATCH(MaxAbs)(values, stride, count);
}

void toHalf(const float* values, std::size_t stride, std::size_t count, std::uint16_t* out) {
    HWY_DYNAMIC_DISPATCH(ToHalf)(values, stride, count, out);
}

} // namespace hairvox::detail
#endif
