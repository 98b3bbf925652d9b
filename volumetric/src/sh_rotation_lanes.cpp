// hairvox volumetric (internal): the rotation of real spherical harmonic
// coefficients into fibers' frames (sh_rotation.h), kLanes frames at once
// across the SIMD registers. Highway compiles this file once per target
// (foreach_target.h re-includes it) and dispatches to the best one the CPU
// supports, as the shading kernels do; CMakeLists.txt compiles it with
// -ffp-contract=off, so that every target gives the bits of the scalar
// operations in their order: a·b + c two roundings, on every host.

// Targets: those of the shading kernels (shade_kernel.cpp).
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_SSSE3 | HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV)
#endif

// Highway's order: the target list, then this file once per target.
// clang-format off
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "volumetric/src/sh_rotation_lanes.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep
#include <hwy/highway.h>
// clang-format on

#include "sh_rotation_lanes.h"

#include <algorithm>
#include <array>

HWY_BEFORE_NAMESPACE();
namespace hairvox::detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr std::size_t kLanes = ShLaneRotation::kLanes;

void RotateLanes(const ShLaneRotation& r, const float* in, float* out, int channels);

namespace {

/// g ↦ g∘R_z(θ) in place, lane by lane (sh_rotation.h):
///   c_lm ← c_lm cos mθ + c_l,−m sin mθ,   c_l,−m ← c_l,−m cos mθ − c_lm sin mθ.
void RotateZ(float* c, int order, const ShLaneRotation::PerLane& cosM,
             const ShLaneRotation::PerLane& sinM) {
    const hn::CappedTag<float, kLanes> d;
    const std::size_t n = hn::Lanes(d);
    for (int l = 1; l <= order; ++l)
        for (int m = 1; m <= l; ++m) {
            float* a = c + std::size_t(SphericalHarmonics::index(l, m)) * kLanes;
            float* b = c + std::size_t(SphericalHarmonics::index(l, -m)) * kLanes;
            for (std::size_t j = 0; j < kLanes; j += n) {
                const auto va = hn::LoadU(d, a + j), vb = hn::LoadU(d, b + j);
                const auto cm = hn::LoadU(d, &cosM[m][j]), sm = hn::LoadU(d, &sinM[m][j]);
                hn::StoreU(hn::Add(hn::Mul(va, cm), hn::Mul(vb, sm)), d, a + j);
                hn::StoreU(hn::Sub(hn::Mul(vb, cm), hn::Mul(va, sm)), d, b + j);
            }
        }
}

/// out[row] += value · in[col] over the quarter turn's entries (transposed:
/// out[col] += value · in[row]), lane by lane, entry by entry.
template <bool kTransposed>
void QuarterTurn(const ShLaneRotation& r, const float* in, float* out) {
    const hn::CappedTag<float, kLanes> d;
    const std::size_t n = hn::Lanes(d);
    for (std::size_t k = 0; k < r.entries; ++k) {
        const std::size_t to = kTransposed ? r.col[k] : r.row[k];
        const std::size_t from = kTransposed ? r.row[k] : r.col[k];
        const auto v = hn::Set(d, r.value[k]);
        float* o = out + to * kLanes;
        const float* i = in + from * kLanes;
        for (std::size_t j = 0; j < kLanes; j += n)
            hn::StoreU(hn::Add(hn::LoadU(d, o + j), hn::Mul(v, hn::LoadU(d, i + j))), d, o + j);
    }
}

} // namespace

void RotateLanes(const ShLaneRotation& r, const float* in, float* out, int channels) {
    const std::size_t nc = std::size_t(SphericalHarmonics::coefficients(r.order)) * kLanes;
    alignas(64) std::array<float, SphericalHarmonics::kMaxCoefficients * kLanes> t;
    for (int ch = 0; ch < channels; ++ch) {
        const float* c = in + std::size_t(ch) * nc;
        float* o = out + std::size_t(ch) * nc;
        // R_z(α), then Q.
        std::copy(c, c + nc, o);
        RotateZ(o, r.order, r.cosA, r.sinA);
        std::fill(t.begin(), t.begin() + std::ptrdiff_t(nc), 0.0f);
        QuarterTurn<false>(r, o, t.data());
        // R_z(β), then Q⁻¹ = Qᵀ.
        RotateZ(t.data(), r.order, r.cosB, r.sinB);
        std::fill(o, o + nc, 0.0f);
        QuarterTurn<true>(r, t.data(), o);
    }
}

} // namespace HWY_NAMESPACE
} // namespace hairvox::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace hairvox::detail {

HWY_EXPORT(RotateLanes);

void rotateLanes(const ShLaneRotation& r, const float* in, float* out, int channels) {
    HWY_DYNAMIC_DISPATCH(RotateLanes)(r, in, out, channels);
}

} // namespace hairvox::detail
#endif // HWY_ONCE
