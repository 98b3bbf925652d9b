// hairvox volumetric: a fiber's scattering applied, in the fiber's own frame,
// to radiance held in world-frame spherical harmonics — Moon, Walter &
// Marschner 2008's "scattering matrix" (docs/DESIGN.md §9).
//
// The radiance a fiber of tangent u sends toward ω_o from the incident
// radiance L̄ of its cell is (docs/DESIGN.md §3, the renderer's convention)
//     L_o(ω_o) = ∫ K(ω_i) L̄(ω_i) dω_i,   K(ω_i) = f_s(u; ω_i, ω_o) cos θ_i.
// L̄ is held to SH order L (spherical_harmonics.h), so only the projection
// P_L[K] of the kernel onto the same orders counts:
//     L_o = ∫ P_L[K] L̄ dω,
// and the product of two functions of order L is integrated exactly by a
// product rule of (L + 1) Gauss–Legendre nodes in s = sin θ (about u) by
// 2L + 1 equally spaced azimuths. In the frame (e₁, e₂, u) with e₁ along ω_o's
// azimuth (φ_o = 0), P_L[K] depends on s_o = ω_o·u alone, so the kernel
// tabulates, at R outgoing s_o (rows, read linearly between), the weights
//     W_jq = w_q · P_L[K_j](ω_q)   (RGB; K_j at s_o of row j),
// P_L[K_j] projected by a fine quadrature of f_s (Gauss–Legendre panels in s,
// the midpoint rule over the period in φ; the cross-section's twist averaged
// when the fiber is eccentric). A fragment then evaluates its cell's L̄ at
// the nodes rotated into its own frame:
//     L_o = Σ_q W_q(s_o) L̄(s_q u + c_q (cos φ_q e₁ + sin φ_q e₂)).
// This is the rotation of L̄ into the fiber's frame followed by the
// scattering matrix, done at the nodes instead of on the coefficients: exact
// for the order held, whatever the angle between the fiber and its cell's
// other fibers.
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>

#include <vector>

namespace hairvox {

class MarschnerBcsdf;

class ScatteringKernel {
public:
    /// The kernel of `bcsdf` for radiance held to SH order `order` ([1, 8]).
    ScatteringKernel(const MarschnerBcsdf& bcsdf, int order);

    int order() const { return order_; }
    /// Outgoing inclinations tabulated (rows, s_o from −1 to 1).
    static constexpr int kRows = 48;

    /// L_o toward unit ω_o of a fiber of unit tangent u from the incident
    /// radiance whose SH coefficients are `coefficients` (planar [channel][lm],
    /// 3·(L + 1)² floats).
    Rgb apply(const float* coefficients, const Vec3f& u, const Vec3f& omega_o) const;

private:
    int order_;
    int nodesS_, nodesPhi_;
    std::vector<float> s_, cosTheta_;    ///< per s-node: s_q, √(1 − s_q²)
    std::vector<float> cosPhi_, sinPhi_; ///< per φ-node
    std::vector<Rgb> w_;                 ///< [row][s-node][φ-node]: W_jq
};

} // namespace hairvox
