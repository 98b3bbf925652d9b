// hairvox transmittance (internal): BrickVolume's line integrals for every
// SIMD target. Highway compiles this file once per target (foreach_target.h
// re-includes it) and dispatches to the best one the CPU supports at the
// first call, as the shading kernels do. The code is brick_march-inl.h, the
// body of BrickMarch<Target>; CMakeLists.txt compiles this file with
// -ffp-contract=off, so that every target gives the same bits.

// Targets: those of the shading kernels (shade_kernel.cpp).
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_SSSE3 | HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV)
#endif

// Highway's order: the target list, then this file once per target.
// clang-format off
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "transmittance/src/brick_march.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep
#include <hwy/highway.h>
// clang-format on

#include "brick_volume.h"

#include <hairvox/core/grid_traversal.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>
#include <vector>

HWY_BEFORE_NAMESPACE();
#if HWY_TARGET <= HWY_AVX2 && !defined(__clang__)
// Every CPU with AVX2 has POPCNT, which Highway's target string leaves out:
// a slot's rank (brick_march-inl.h, cornersOf) is then one instruction.
// (Clang expands __builtin_popcountll inline without it; GCC would call
// libgcc.)
#pragma GCC target("popcnt")
#endif
namespace hairvox::detail {

namespace HWY_NAMESPACE {
struct MarchTarget {};
} // namespace HWY_NAMESPACE

template <>
struct BrickMarch<HWY_NAMESPACE::MarchTarget> {
#include "brick_march-inl.h"
};

namespace HWY_NAMESPACE {

using March = BrickMarch<MarchTarget>;

OpticalDepths Integrate(const BrickVolume& v, const Vec3f& origin, const Vec3f& dir, float tStart,
                        float tEnd, float opaqueDepth, bool& touched);
void IntegrateCumulative(const BrickVolume& v, const Vec3f& origin, const Vec3f& dir, float tStart,
                         float step, std::size_t count, float opaqueDepth,
                         std::span<const std::uint32_t> candidates,
                         std::vector<BrickVolume::BrickCrossing>& crossings,
                         std::vector<BrickVolume::CumulativeSample>& out);
OpticalDepths Sample(const BrickVolume& v, const Vec3f& position);

OpticalDepths Integrate(const BrickVolume& v, const Vec3f& origin, const Vec3f& dir, float tStart,
                        float tEnd, float opaqueDepth, bool& touched) {
    return March::integrate(v, origin, dir, tStart, tEnd, opaqueDepth, touched);
}

void IntegrateCumulative(const BrickVolume& v, const Vec3f& origin, const Vec3f& dir, float tStart,
                         float step, std::size_t count, float opaqueDepth,
                         std::span<const std::uint32_t> candidates,
                         std::vector<BrickVolume::BrickCrossing>& crossings,
                         std::vector<BrickVolume::CumulativeSample>& out) {
    March::integrateCumulative(v, origin, dir, tStart, step, count, opaqueDepth, candidates,
                               crossings, out);
}

OpticalDepths Sample(const BrickVolume& v, const Vec3f& position) {
    return March::sample(v, position);
}

} // namespace HWY_NAMESPACE
} // namespace hairvox::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace hairvox::detail {

HWY_EXPORT(Integrate);
HWY_EXPORT(IntegrateCumulative);
HWY_EXPORT(Sample);

OpticalDepths BrickVolume::integrate(const Vec3f& origin, const Vec3f& dir, float tStart,
                                     float tEnd, float opaqueDepth, bool& touched) const {
    return HWY_DYNAMIC_DISPATCH(Integrate)(*this, origin, dir, tStart, tEnd, opaqueDepth, touched);
}

void BrickVolume::integrateCumulative(const Vec3f& origin, const Vec3f& dir, float tStart,
                                      float step, std::size_t count, float opaqueDepth,
                                      std::span<const std::uint32_t> candidates,
                                      std::vector<BrickCrossing>& crossings,
                                      std::vector<CumulativeSample>& out) const {
    HWY_DYNAMIC_DISPATCH(IntegrateCumulative)
    (*this, origin, dir, tStart, step, count, opaqueDepth, candidates, crossings, out);
}

OpticalDepths BrickVolume::sample(const Vec3f& position) const {
    return HWY_DYNAMIC_DISPATCH(Sample)(*this, position);
}

} // namespace hairvox::detail
#endif // HWY_ONCE
