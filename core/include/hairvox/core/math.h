// hairvox core: scalar maths shared by every stage.
//
// Safe inverse trigonometry and square roots clamp their argument (pbrt-v4
// util/math.h): inputs that are out of range only by rounding are legal, and
// debug builds assert that nothing worse reaches them. Every function here is
// finite for every finite input.
#pragma once

#include <algorithm>
#include <cassert>
#include <cmath>
#include <concepts>

namespace hairvox {

inline constexpr double Pi = 3.14159265358979323846;
inline constexpr double InvPi = 0.31830988618379067154;
inline constexpr double TwoPi = 6.28318530717958647692;
inline constexpr double PiOver2 = 1.57079632679489661923;
inline constexpr double Sqrt2Pi = 2.50662827463100050242; // sqrt(2π)

template <std::floating_point T>
constexpr T sqr(T x) {
    return x * x;
}

template <std::floating_point T>
constexpr T radians(T degrees) {
    return degrees * T(Pi / 180.0);
}

template <std::floating_point T>
constexpr T degrees(T radians) {
    return radians * T(180.0 / Pi);
}

/// sqrt(max(x, 0)); x may be negative only by rounding error.
template <std::floating_point T>
T safeSqrt(T x) {
    assert(x > T(-1e-3));
    return std::sqrt(std::max(x, T(0)));
}

/// asin(clamp(x, -1, 1)); |x| may exceed 1 only by rounding error.
template <std::floating_point T>
T safeASin(T x) {
    assert(x > T(-1.0001) && x < T(1.0001));
    return std::asin(std::clamp(x, T(-1), T(1)));
}

/// acos(clamp(x, -1, 1)); |x| may exceed 1 only by rounding error.
template <std::floating_point T>
T safeACos(T x) {
    assert(x > T(-1.0001) && x < T(1.0001));
    return std::acos(std::clamp(x, T(-1), T(1)));
}

/// cos θ from sin θ for θ ∈ [−π/2, π/2], exact near |sin θ| = 1.
template <std::floating_point T>
T cosFromSin(T sinTheta) {
    return safeSqrt(std::fma(-sinTheta, sinTheta, T(1)));
}

/// Hermite smoothstep: 0 for x ≤ a, 1 for x ≥ b (requires a < b).
template <std::floating_point T>
T smoothStep(T a, T b, T x) {
    const T t = std::clamp((x - a) / (b - a), T(0), T(1));
    return t * t * (T(3) - T(2) * t);
}

/// Wraps an angle to [−π, π].
template <std::floating_point T>
T wrapAngle(T phi) {
    if (phi >= T(-Pi) && phi <= T(Pi))
        return phi;
    phi = std::remainder(phi, T(TwoPi));
    return std::clamp(phi, T(-Pi), T(Pi));
}

/// Normalised Gaussian g(x; σ) = exp(−x²/(2σ²)) / (σ√(2π)) of standard deviation σ > 0.
template <std::floating_point T>
T gaussian(T x, T sigma) {
    return std::exp(-x * x / (T(2) * sigma * sigma)) / (sigma * T(Sqrt2Pi));
}

/// Linear interpolation (1 − t)·a + t·b.
template <typename V, std::floating_point T>
constexpr V lerp(T t, const V& a, const V& b) {
    return (T(1) - t) * a + t * b;
}

} // namespace hairvox
