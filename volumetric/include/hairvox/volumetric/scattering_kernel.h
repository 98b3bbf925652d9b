// hairvox volumetric: a fiber's scattering applied, in the fiber's own frame,
// to radiance held in world-frame spherical harmonics — Moon, Walter &
// Marschner 2008's "scattering matrix" (docs/DESIGN.md §9).
//
// The radiance a fiber of tangent u sends toward ω_o from the incident
// radiance L̄ of its cell is (docs/DESIGN.md §3, the renderer's convention)
//     L_o(ω_o) = ∫ K(ω_i) L̄(ω_i) dω_i,   K(ω_i) = f_s(u; ω_i, ω_o) cos θ_i.
// L̄ is held to SH order L (spherical_harmonics.h), so only the projection
// P_L[K] of the kernel onto the same orders counts: L_o = Σ_lm c_lm k_lm,
// c and k the coefficients of L̄ and K in one basis. In the fiber's frame
// (sh_rotation.h: e₁, e₂, u) f_s depends on the azimuths only through
// φ_o − φ_i and is even in it (the twist of an eccentric cross-section
// averaged), so K's projection there is diagonal in m:
//     k'_l0 = G_l0(s_o),  k'_lm = G_lm(s_o) cos mφ_o,  k'_l,−m = G_lm(s_o) sin mφ_o
// (m > 0; s_o = ω_o·u, φ_o ω_o's azimuth about u from e₁), G_lm the
// coefficients of K at φ_o = 0. The kernel tabulates G (RGB, (L + 1)(L + 2)/2
// values) at R outgoing s_o (rows, read linearly between), projected by a
// fine quadrature of f_s (Gauss–Legendre panels in s, the midpoint rule over
// the period in φ; the cross-section's twist averaged when the fiber is
// eccentric). A fiber's cell coefficients are rotated into its frame
// (c' = C_F c, sh_rotation.h) and contracted for each ω_o (applyInFrame):
//     L_o = Σ_l [G_l0 c'_l0 + Σ_{m>0} G_lm (c'_lm cos mφ_o + c'_l,−m sin mφ_o)].
// Moon, Walter & Marschner's rotation followed by their scattering matrix,
// exact for the order held, whatever the angle between the fiber and its
// cell's other fibers: ~500 multiply-adds a channel for the rotation at
// L = 8 (sh_rotation.h) and (L + 1)² for the contraction.
// (Replaced: the same product evaluated at (L + 1) × (2L + 1) quadrature
// nodes in the fragment's frame, an SH synthesis each — 38× the shading
// time of the cell-frame design; docs/DESIGN.md §9.)
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>

#include <vector>

namespace hairvox {

class DiskCache;
struct FiberParams;
class MarschnerBcsdf;
class ShFrameRotation;

class ScatteringKernel {
public:
    /// The kernel of `bcsdf` for radiance held to SH order `order` ([1, 8]).
    ScatteringKernel(const MarschnerBcsdf& bcsdf, int order);

    /// The kernel of `fiber` at `order`, taken from `cache` (kind "kernel",
    /// keyed by the fiber's optics, the order and the projection's
    /// quadrature) where it holds it, built and stored there otherwise: the
    /// same floats either way. Null cache: built. A projection is ~3.4 G
    /// instructions at order 8 for each fiber type; a look-development
    /// session renders the same fibers again and again.
    static ScatteringKernel loadOrBuild(const FiberParams& fiber, int order,
                                        const DiskCache* cache);

    int order() const { return order_; }
    /// Outgoing inclinations tabulated (rows, s_o from −1 to 1).
    static constexpr int kRows = 48;

    /// L_o toward unit ω_o of a fiber of unit tangent u from the incident
    /// radiance whose SH coefficients are `coefficients` (planar [channel][lm],
    /// 3·(L + 1)² floats).
    Rgb apply(const float* coefficients, const Vec3f& u, const Vec3f& omega_o) const;
    /// The same from coefficients already in the fiber's frame (c' = C_F c,
    /// `frame`.apply(); planar [channel][lm]): the contraction alone, (L + 1)²
    /// multiply-adds a channel — for callers that rotate once for several ω_o.
    Rgb applyInFrame(const float* fiberFrameCoefficients, const ShFrameRotation& frame,
                     const Vec3f& omega_o) const;

    /// K's SH coefficients in the fiber's frame at φ_o = 0 (k'_lm = G_lm(s_o)
    /// for m ≥ 0, 0 for m < 0) into `k` (planar [channel][lm], 3·(L + 1)²
    /// floats), read between the rows as apply() reads them.
    void fiberFrameCoefficients(float s_o, float* k) const;

private:
    ScatteringKernel(int order, std::vector<float> g) : order_(order), g_(std::move(g)) {}

    /// The two rows around s_o and the weight of the second.
    void rows(float s_o, const float*& g0, const float*& g1, float& t) const;
    /// Values a row holds per channel: G_lm for l ≤ L, 0 ≤ m ≤ l, at l(l + 1)/2 + m.
    int perChannel() const { return perChannel(order_); }
    static int perChannel(int order) { return (order + 1) * (order + 2) / 2; }

    int order_;
    std::vector<float> g_; ///< [row][channel][l(l + 1)/2 + m]: G_lm(s_o of the row)
};

} // namespace hairvox
