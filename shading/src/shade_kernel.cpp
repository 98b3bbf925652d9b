// hairvox shading (internal): shade_kernel.h for every SIMD target. Highway
// compiles this file once per target (foreach_target.h re-includes it) and
// dispatches to the best one the CPU supports at the first call.
// The maths is in shade_kernel-inl.h.

// Targets: x86 (AVX-512, AVX2+FMA, SSE4, and the baseline) and NEON. Sizeless
// vector targets (SVE, RVV) cannot be members of the kernel's structs.
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_SSSE3 | HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV)
#endif

// Highway's order: the target list, then this file once per target.
// clang-format off
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "shading/src/shade_kernel.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep
#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>
// clang-format on

#include "shade_kernel.h"

#include <hairvox/core/math.h>

HWY_BEFORE_NAMESPACE();
namespace hairvox::detail::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

// The kernel at two widths from one source: every lane of the widest vector
// for batches, and one lane for a single point (the scalar entry points),
// which would otherwise pay for 15 idle lanes of divisions and gathers.
// Lanes never interact, so a point gets the same bits at either width.
namespace wide {
using D = hn::ScalableTag<float>;
#include "shade_kernel-inl.h"
} // namespace wide

namespace single {
using D = hn::CappedTag<float, 1>;
#include "shade_kernel-inl.h"
} // namespace single

// The exported functions (declared for -Wmissing-declarations).
void AnglesFromDirections(const Batch& directions, const MutableBatch& angles);
void EvalMarschner(const MarschnerView& fs, const Batch& angles, const MutableBatch& lobes);
void ShadeDirections(const ShadeKernelParams& p, const Batch& directions, const Batch& globalTerms,
                     const Batch& irradiance, const MutableBatch& radiance);
void AnglesFromDirection(const float* directions, float* angles);
void EvalMarschnerOne(const MarschnerView& fs, const float* angles, float* lobes);
void ShadeDirection(const ShadeKernelParams& p, const float* directions, const float* globalTerm,
                    const float* irradiance, float* radiance);
void ShadeAngle(const ShadeKernelParams& p, const float* angles, const float* globalTerm,
                float* out);
const char* Target();

void AnglesFromDirections(const Batch& directions, const MutableBatch& angles) {
    wide::anglesFromDirections(directions, angles);
}
void EvalMarschner(const MarschnerView& fs, const Batch& angles, const MutableBatch& lobes) {
    wide::evalMarschner(fs, angles, lobes);
}
void ShadeDirections(const ShadeKernelParams& p, const Batch& directions, const Batch& globalTerms,
                     const Batch& irradiance, const MutableBatch& radiance) {
    wide::shadeDirections(p, directions, globalTerms, irradiance, radiance);
}

// One point: its rows are one float apart.
void AnglesFromDirection(const float* directions, float* angles) {
    single::anglesFromDirections({1, 1, directions}, {1, 1, angles});
}
void EvalMarschnerOne(const MarschnerView& fs, const float* angles, float* lobes) {
    single::evalMarschner(fs, {1, 1, angles}, {1, 1, lobes});
}
void ShadeDirection(const ShadeKernelParams& p, const float* directions, const float* globalTerm,
                    const float* irradiance, float* radiance) {
    single::shadeDirections(p, {1, 1, directions}, {1, 1, globalTerm}, {1, 1, irradiance},
                            {1, 1, radiance});
}
void ShadeAngle(const ShadeKernelParams& p, const float* angles, const float* globalTerm,
                float* out) {
    single::shadeAngles(p, {1, 1, angles}, {1, 1, globalTerm}, {1, 1, out}, true);
}

const char* Target() {
    return hwy::TargetName(HWY_TARGET);
}

} // namespace hairvox::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace hairvox::detail {

HWY_EXPORT(AnglesFromDirections);
HWY_EXPORT(EvalMarschner);
HWY_EXPORT(ShadeDirections);
HWY_EXPORT(AnglesFromDirection);
HWY_EXPORT(EvalMarschnerOne);
HWY_EXPORT(ShadeDirection);
HWY_EXPORT(ShadeAngle);
HWY_EXPORT(Target);

void anglesFromDirections(const Batch& directions, const MutableBatch& angles) {
    HWY_DYNAMIC_DISPATCH(AnglesFromDirections)(directions, angles);
}
void evalMarschner(const MarschnerView& fs, const Batch& angles, const MutableBatch& lobes) {
    HWY_DYNAMIC_DISPATCH(EvalMarschner)(fs, angles, lobes);
}
void shadeDirections(const ShadeKernelParams& p, const Batch& directions, const Batch& globalTerms,
                     const Batch& irradiance, const MutableBatch& radiance) {
    HWY_DYNAMIC_DISPATCH(ShadeDirections)(p, directions, globalTerms, irradiance, radiance);
}
void anglesFromDirection(const float* directions, float* angles) {
    HWY_DYNAMIC_DISPATCH(AnglesFromDirection)(directions, angles);
}
void evalMarschner(const MarschnerView& fs, const float* angles, float* lobes) {
    HWY_DYNAMIC_DISPATCH(EvalMarschnerOne)(fs, angles, lobes);
}
void shadeDirection(const ShadeKernelParams& p, const float* directions, const float* globalTerm,
                    const float* irradiance, float* radiance) {
    HWY_DYNAMIC_DISPATCH(ShadeDirection)(p, directions, globalTerm, irradiance, radiance);
}
void shadeAngle(const ShadeKernelParams& p, const float* angles, const float* globalTerm,
                float* out) {
    HWY_DYNAMIC_DISPATCH(ShadeAngle)(p, angles, globalTerm, out);
}
const char* shadeKernelTarget() {
    return HWY_DYNAMIC_DISPATCH(Target)();
}

} // namespace hairvox::detail
#endif
