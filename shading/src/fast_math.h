// hairvox shading (internal): single-precision helpers for the per-fragment
// angle set-up (FiberAngles::fromDirections), a third of a shade() call.
//
// asin: glibc's asinf costs ~12 ns and the set-up makes three calls. This is
// Cephes asinf (S. Moshier): a degree-4 minimax polynomial in z = x² on
// |x| ≤ ½ and asin x = π/2 − 2 asin sqrt((1 − x)/2) above; peak relative
// error 2.5e-7 (measured in tests/shading/marschner_test.cpp).
#pragma once

#include <hairvox/core/math.h>

#include <algorithm>
#include <cmath>

namespace hairvox::fast {

/// cos θ from sin θ as sqrt((1 − s)(1 + s)): as exact near |s| = 1 as the
/// fma form of core's cosFromSin (1 − |s| is exact there), without the
/// software fmaf call that a baseline x86-64 build makes of std::fma.
inline float cosFromSin(float s) { return std::sqrt(std::max((1.0f - s) * (1.0f + s), 0.0f)); }

/// asin(clamp(x, −1, 1)).
inline float asin(float x) {
    const float a = std::min(std::abs(x), 1.0f);
    const bool upper = a > 0.5f;
    const float z = upper ? 0.5f * (1.0f - a) : a * a;
    const float s = upper ? std::sqrt(z) : a;
    const float r = ((((4.2163199048e-2f * z + 2.4181311049e-2f) * z + 4.5470025998e-2f) * z +
                      7.4953002686e-2f) * z + 1.6666752422e-1f) * z * s + s;
    // Selects rather than branches: random directions would mispredict half of them.
    return std::copysign(upper ? static_cast<float>(PiOver2) - 2.0f * r : r, x);
}

} // namespace hairvox::fast
