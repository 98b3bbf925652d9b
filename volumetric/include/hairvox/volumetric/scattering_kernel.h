// hairvox volumetric: a fiber's scattering function projected onto the
// radiance basis (radiance_basis.h) — Moon, Walter & Marschner 2008's
// "scattering matrix", in the fiber's own frame.
//
// The radiance a fiber of tangent ū sends toward ω_o from incident radiance L
// is (docs/DESIGN.md §3, the renderer's convention)
//     L_o(ω_o) = ∫ f_s(ω_i, ω_o) cos θ_i L(ω_i) dω_i,   dω_i = ds_i dφ_i.
// With L in the basis and f_s even in Δφ = φ_o − φ_i (Marschner's N_p, with
// the cross-section's orientation averaged out), the φ integral diagonalises:
//     L_o(θ_o, φ_o) = Σ_i [a_i0 Ĝ_i0(θ_o) + Σ_k (a_ik cos kφ_o + b_ik sin kφ_o) Ĝ_ik(θ_o)],
//     Ĝ_ik(θ_o) = ∫_{bin i} ds_i ∫_{−π}^{π} f_s(θ_i, θ_o, Δφ) cos θ_i cos(kΔφ) dΔφ   (RGB).
// The kernel tabulates Ĝ at N_θ outgoing inclinations, the bins' centres in
// s_o = sin θ_o (an outgoing radiance is then a basis-shaped table that a
// lookup interpolates linearly in s_o), by Gauss–Legendre quadrature over each
// bin (8 points) and the midpoint rule over the period in Δφ (256 points;
// spectrally accurate for a periodic integrand).
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/volumetric/radiance_basis.h>

#include <span>
#include <vector>

namespace hairvox {

class MarschnerBcsdf;

/// Which of Marschner's lobes a kernel holds.
enum class KernelLobes {
    All,
    Forward,  ///< TT
    Backward, ///< R and TRT
};

class ScatteringKernel {
public:
    ScatteringKernel(const MarschnerBcsdf& bcsdf, const RadianceBasis& basis,
                     KernelLobes lobes = KernelLobes::All);

    const RadianceBasis& basis() const { return basis_; }
    /// Ĝ_ik at the centre of outgoing bin j.
    const Rgb& at(int j, int i, int k) const {
        return g_[(std::size_t(j) * std::size_t(basis_.thetaBins) + std::size_t(i)) *
                      std::size_t(basis_.azimuthalOrder + 1) +
                  std::size_t(k)];
    }
    /// The outgoing table of an incident radiance: both are planar
    /// [channel][bin][coefficient] arrays of 3·basis().coefficients() floats;
    /// out[c][j][m] = Σ_i Ĝ_{i,k(m)}(θ_o,j)[c] · in[c][i][m].
    void apply(std::span<const float> incident, std::span<float> outgoing) const;

private:
    RadianceBasis basis_;
    std::vector<Rgb> g_; ///< [j][i][k]
    /// apply()'s form of g_: [channel][j][i][m], Ĝ_{i,k(m)}(θ_o,j) repeated
    /// for a_k and b_k, so that a row of coefficients is one contiguous
    /// multiply-add.
    std::vector<float> expanded_;
};

} // namespace hairvox
