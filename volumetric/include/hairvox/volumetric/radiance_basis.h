// hairvox volumetric: the directional representation of radiance in a cache
// cell (docs/DESIGN.md §9) — in the frame of the cell's fibers.
//
// Light that has scattered in hair is organised about the fibers: a fiber
// sends what it scatters into a cone about its tangent (Marschner's M_p is a
// Gaussian of a few degrees in θ_h, so θ_o ≈ −θ_i + 2α_p), and where fibers
// are combed the next fiber scatters it back onto the same cones. A
// world-frame basis (spherical harmonics, Moon, Walter & Marschner 2008) would
// need order ~18 to hold a band of 10° about the fiber; in the fiber's frame
// the same field is narrow in one coordinate only. So a cell stores radiance
// over directions ω in the frame (ū, e₁, e₂) of its mean fiber tangent ū:
//     s = sin θ = ω·ū ∈ [−1, 1],   φ = atan2(ω·e₂, ω·e₁),
// as N_θ bins uniform in s (equal solid angle, 2π·Δs each, Δs = 2/N_θ; about
// 7° at θ = 0 for N_θ = 16), each holding an azimuthal Fourier series of order K:
//     L(ω) = Σ_i χ_i(s) [a_i0 + Σ_{k=1..K} (a_ik cos kφ + b_ik sin kφ)].
// Coefficient m of a bin is a_0 (m = 0), a_k (m = 2k − 1) or b_k (m = 2k).
// Deposits are the projection onto this orthogonal basis: a sample of weight W
// (radiance × solid angle, i.e. W δ(ω − ω_k)) in bin i adds W/(2πΔs) to a_i0
// and W·cos kφ/(πΔs), W·sin kφ/(πΔs) to a_ik, b_ik. The azimuthal series is
// what makes the scattering integral cheap: f_s depends on φ only through
// φ_o − φ_i, so it is diagonal in k (scattering_kernel.h).
#pragma once

#include <hairvox/core/vecmath.h>

#include <array>
#include <cstdint>
#include <ostream>

namespace hairvox {

struct RadianceBasis {
    int thetaBins = 12;     ///< N_θ, [2, 64]
    int azimuthalOrder = 3; ///< K, [0, 8]

    static constexpr int kMaxOrder = 8;

    int coefficientsPerBin() const { return 2 * azimuthalOrder + 1; }
    /// Coefficients per colour channel: N_θ·(2K + 1).
    int coefficients() const { return thetaBins * coefficientsPerBin(); }
    float binWidth() const { return 2.0f / float(thetaBins); } ///< Δs
    /// The bin of s = sin θ (clamped).
    int bin(float s) const;
    /// The centre s of bin i.
    float binCentre(int i) const { return -1.0f + (float(i) + 0.5f) * binWidth(); }

    /// Throws InputError naming the setting and its range.
    void validate() const;
};

std::ostream& operator<<(std::ostream& os, const RadianceBasis& b);

/// A fiber's frame: its unit tangent (the axis) and two unit vectors ⟂ it,
/// {e₁, e₂, axis} right-handed.
struct FiberFrame {
    Vec3f axis{0.0f, 1.0f, 0.0f}, e1{1.0f, 0.0f, 0.0f}, e2{0.0f, 0.0f, -1.0f};

    /// The frame of unit `axis` (coordinateSystem's perpendiculars).
    static FiberFrame about(const Vec3f& axis);
    /// The frame of unit `tangent` whose azimuths start at `reference`'s:
    /// e₁ is reference.e₁ made ⟂ to the tangent (reference.e₂ where the two
    /// are nearly parallel), so fibers of one cell share an azimuth origin.
    static FiberFrame along(const Vec3f& tangent, const FiberFrame& reference);
};

/// A direction in a frame, as the basis reads it: s = sin θ and the azimuth's
/// harmonics cos kφ, sin kφ for k = 0..K (φ = 0 where ω is along the axis).
struct AzimuthalHarmonics {
    float s = 0;
    /// harmonic[m] in the coefficient order: 1, cos φ, sin φ, cos 2φ, sin 2φ, ...
    std::array<float, 2 * RadianceBasis::kMaxOrder + 1> harmonic{};

    static AzimuthalHarmonics of(const Vec3f& omega, const FiberFrame& frame, int order);
};

} // namespace hairvox
