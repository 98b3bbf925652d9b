// hairvox core: warps from uniform numbers to directions (pbrt-v4
// util/sampling.h), the one place every Monte Carlo stage takes them from.
#pragma once

#include <hairvox/core/math.h>
#include <hairvox/core/vecmath.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace hairvox {

/// The k-th point (k ≥ 1) of the R2 sequence in [0, 1)² (Roberts 2018: the
/// additive recurrence on the powers of the plastic number's inverse), shifted
/// by `shift` read as two 32-bit fractions (Cranley–Patterson rotation).
inline Vec2f r2Point(double k, std::uint64_t shift) {
    constexpr double a1 = 0.7548776662466927, a2 = 0.5698402909980532;
    return {float(std::fmod(double(shift & 0xffffffffu) * 0x1p-32 + k * a1, 1.0)),
            float(std::fmod(double(shift >> 32) * 0x1p-32 + k * a2, 1.0))};
}

/// A unit vector uniformly distributed on the sphere (density 1/(4π)) from
/// u1, u2 ∈ [0, 1).
inline Vec3f uniformSphere(float u1, float u2) {
    const float z = 1.0f - 2.0f * u1;
    const float r = safeSqrt(1.0f - z * z);
    const float phi = float(TwoPi) * u2;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

/// A unit vector of the hemisphere about unit n with density cos θ/π
/// (Malley's method: the unit disk's uniform point lifted).
inline Vec3f cosineHemisphere(const Vec3f& n, float u1, float u2) {
    const float r = std::sqrt(u1), phi = float(TwoPi) * u2;
    Vec3f s, t;
    coordinateSystem(n, s, t);
    return glm::normalize(r * std::cos(phi) * s + r * std::sin(phi) * t +
                          std::sqrt(std::max(0.0f, 1.0f - u1)) * n);
}

/// A point of the unit disk, uniformly (density 1/π), from u1, u2 ∈ [0, 1)
/// (Shirley & Chiu's concentric map: neighbouring inputs stay neighbours, which
/// keeps low-discrepancy points evenly spread).
inline Vec2f concentricDisk(float u1, float u2) {
    const float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
    if (a == 0.0f && b == 0.0f)
        return {0.0f, 0.0f};
    float r, theta;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        theta = float(Pi / 4.0) * (b / a);
    } else {
        r = b;
        theta = float(PiOver2) - float(Pi / 4.0) * (a / b);
    }
    return {r * std::cos(theta), r * std::sin(theta)};
}

} // namespace hairvox
