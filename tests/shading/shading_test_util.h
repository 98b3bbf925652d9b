// hairvox tests: helpers shared by the shading tests (directions from fiber
// angles, brute-force integrals over the sphere of outgoing directions).
#pragma once

#include <hairvox/core/math.h>
#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/shading/marschner.h>

#include <cmath>

namespace hairvox::test {

/// The unit direction of inclination θ and azimuth φ about the unit tangent u,
/// azimuths measured from the first axis of coordinateSystem(u) (the frame
/// FiberAngles uses for φ_h).
inline Vec3f fiberDirection(const Vec3f& u, double theta, double phi) {
    Vec3f s, t;
    coordinateSystem(u, s, t);
    const auto st = static_cast<float>(std::sin(theta)), ct = static_cast<float>(std::cos(theta));
    return st * u + ct * (static_cast<float>(std::cos(phi)) * s + static_cast<float>(std::sin(phi)) * t);
}

/// ∫ f(θ_i, ω) cos θ_ω dω over the back (|φ| < π/2) and front halves, by the
/// midpoint rule on θ_o × φ (dω = cos θ_o dθ_o dφ). `f(FiberAngles)` returns Rgb.
/// The midpoint rule integrates the Gaussian lobes to ~1e-8 once the step is
/// below their width. φ_i fixes the fiber's cross-section orientation
/// (φ_h = φ_i + φ/2), which only matters for eccentric fibers.
struct HalfAlbedo {
    Rgbd back, front;
    Rgbd total() const { return back + front; }
};

template <typename F>
HalfAlbedo integrateOverSphere(double theta_i, int thetaSteps, int phiSteps, F&& f,
                               double phi_i = 0) {
    HalfAlbedo sum;
    const double dTheta = Pi / thetaSteps, dPhi = TwoPi / phiSteps;
    for (int i = 0; i < thetaSteps; ++i) {
        const double theta_o = -PiOver2 + (i + 0.5) * dTheta;
        const double w = std::cos(theta_o) * std::cos(theta_o) * dTheta * dPhi;
        for (int j = 0; j < phiSteps; ++j) {
            const double phi = -Pi + (j + 0.5) * dPhi;
            const FiberAngles a = FiberAngles::fromAngles(static_cast<float>(theta_i),
                                                          static_cast<float>(theta_o),
                                                          static_cast<float>(phi),
                                                          static_cast<float>(phi_i + 0.5 * phi));
            const Rgbd v = w * Rgbd(f(a));
            (std::abs(phi) < PiOver2 ? sum.back : sum.front) += v;
        }
    }
    return sum;
}

} // namespace hairvox::test
