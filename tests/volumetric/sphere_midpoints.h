// hairvox tests: a regular grid of directions over the sphere — midpoints in
// z = cos θ and in φ, n × n cells of equal solid angle 4π/n² — which
// integrates the spherical harmonics a radiance cache holds exactly for
// n above its order (up to rounding).
#pragma once

#include <hairvox/core/math.h>
#include <hairvox/core/vecmath.h>

#include <cmath>

namespace hairvox::test {

/// f(ω) for each of the n² unit directions.
template <typename F>
void forEachSphereMidpoint(int n, F&& f) {
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
            const float z = -1.0f + (float(a) + 0.5f) * 2.0f / float(n);
            const float phi = (float(b) + 0.5f) * float(TwoPi) / float(n);
            const float r = std::sqrt(1.0f - z * z);
            f(Vec3f(r * std::cos(phi), r * std::sin(phi), z));
        }
}

} // namespace hairvox::test
