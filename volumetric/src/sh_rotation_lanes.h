// hairvox volumetric (internal): ShFrameRotation::applyLanes's kernel — the
// rotation of sh_rotation.h for kLanes frames at once, one frame a lane,
// compiled for every SIMD target (sh_rotation_lanes.cpp).
#pragma once

#include <hairvox/volumetric/sh_rotation.h>
#include <hairvox/volumetric/spherical_harmonics.h>

#include <cstddef>
#include <cstdint>

namespace hairvox::detail {

/// What one rotation of the lanes reads: the quarter turn's non-zero entries
/// (out[row] += value · in[col], band by band) and, per m ≤ order and lane,
/// cos mα, sin mα, cos mβ, sin mβ of the lane's frame.
struct ShLaneRotation {
    static constexpr std::size_t kLanes = ShFrameRotation::kLanes;
    using PerLane = float[SphericalHarmonics::kMaxOrder + 1][kLanes];

    int order = 1;
    const std::uint8_t* row = nullptr;
    const std::uint8_t* col = nullptr;
    const float* value = nullptr;
    std::size_t entries = 0;
    alignas(64) PerLane cosA{}, sinA{}, cosB{}, sinB{};
};

/// c' = C_F c lane by lane for `channels` expansions held [channel][lm][lane]
/// (`in` and `out` may not overlap); the best target the CPU supports.
void rotateLanes(const ShLaneRotation& r, const float* in, float* out, int channels);

} // namespace hairvox::detail
