// hairvox volumetric: a world-frame SH expansion (spherical_harmonics.h)
// re-expressed in the frame of a fiber — the rotation of real spherical
// harmonic coefficients the radiance cache's reading needs
// (scattering_kernel.h; docs/DESIGN.md §9).
//
// The frame of unit u is (e₁, e₂, u) = F(x̂, ŷ, ẑ), F = R_z(α) R_y(β) with
// (β, α) u's polar angles: u = (sin β cos α, sin β sin α, cos β) (α = 0 on
// the poles). A field L(ω) = Σ c_lm Y_lm(ω) seen in that frame is
// L∘F = Σ c'_lm Y_lm, c' = C_F c, C_A the coefficients' map of g ↦ g∘A (one
// (2l + 1)² block per band: rotations keep the bands). With the y-rotation
// written as a z-rotation between two fixed quarter turns about x
// (Kautz, Sloan & Snyder 2002, "Fast, arbitrary BRDF shading for
// low-frequency lighting using spherical harmonics", §4: the "zxzxz"
// factorisation),
//     R_y(β) = Q R_z(β) Q⁻¹,   Q = R_x(−90°) (Q ẑ = ŷ),
//     C_F = C_Q⁻¹ · C_{R_z(β)} · C_Q · C_{R_z(α)},   C_Q⁻¹ = C_Qᵀ,
// and a z-rotation only mixes each (m, −m) pair with cos mθ, sin mθ:
//     (g∘R_z(θ))_lm = c_lm cos mθ + c_l,−m sin mθ,
//     (g∘R_z(θ))_l,−m = −c_lm sin mθ + c_l,−m cos mθ   (m > 0).
// C_Q's blocks are fixed: projected once, exactly, by a Gauss–Legendre ×
// equal-azimuth product rule; three quarters of their Σ(2l + 1)² entries are
// 0 (at L = 8, 247 of 969 are not) and skipped. Per rotation: 2 × 247
// multiply-adds per channel for the two quarter turns at L = 8, O(L²) for
// the z-rotations — exact to rounding, no table over β, no recurrence per
// fragment (Ivanic & Ruedenberg 1996's would cost more to build the dense
// (2l + 1)² blocks of R_y(β) than the quarter turns cost to apply).
// applyLanes() rotates 16 frames at once, a frame a SIMD lane: the sparse
// entries are the same for every frame, so each is one vector multiply-add
// across the lanes (sh_rotation_lanes.cpp; 27k → 5.8k instructions a
// rotation on the AVX2 target).
#pragma once

#include <hairvox/core/vecmath.h>
#include <hairvox/volumetric/spherical_harmonics.h>

#include <array>
#include <cstddef>
#include <span>

namespace hairvox {

class ShFrameRotation {
public:
    /// The frame of unit tangent u, for expansions to SH order ≤ `order`
    /// ([1, SphericalHarmonics::kMaxOrder]).
    ShFrameRotation(const Vec3f& u, int order);

    /// e₁ = F x̂, e₂ = F ŷ: ω's coordinates in the frame are (ω·e₁, ω·e₂, ω·u).
    const Vec3f& e1() const { return e1_; }
    const Vec3f& e2() const { return e2_; }
    /// The tangent: the frame's third axis.
    const Vec3f& u() const { return u_; }

    /// c' = C_F c for `channels` planar expansions ([channel][lm], (L + 1)²
    /// floats each): the coefficients of L∘F. `in` and `out` may not overlap.
    void apply(const float* in, float* out, int channels) const;

    /// Frames rotated together by applyLanes(): one a lane.
    static constexpr std::size_t kLanes = 16;
    /// apply() for up to kLanes frames of one order at once, the frames' k-th
    /// expansion in lane k: `in` and `out` hold `channels` planar expansions,
    /// lane-interleaved [channel][lm][lane] (kLanes floats a coefficient;
    /// lanes past frames.size() are not read back). The lanes run across the
    /// SIMD registers of the CPU's best target (Highway), each with the bits
    /// of apply(). `in` and `out` may not overlap.
    static void applyLanes(std::span<const ShFrameRotation> frames, const float* in, float* out,
                           int channels);

private:
    int order_;
    Vec3f e1_, e2_, u_;
    /// cos mα, sin mα, cos mβ, sin mβ for m ≤ order.
    std::array<float, SphericalHarmonics::kMaxOrder + 1> cosA_{}, sinA_{}, cosB_{}, sinB_{};
};

} // namespace hairvox
