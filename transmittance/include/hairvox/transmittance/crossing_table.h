// hairvox transmittance: what one fiber crossing contributes to the global term.
//
// A shadow ray with direction ω that crosses a fiber of tangent u meets it at
// inclination θ with sin θ = ω·u (docs/DESIGN.md §2). Each crossing multiplies
// the forward transmittance by ā_f(θ) and adds β̄_f²(θ) to the forward variance
// (RenderMan report Eq. 3 and 5, Zinke et al. 2008). The expected number of
// fibers crossed per unit length is λ·D·cos θ (DESIGN.md §5), so the grid
// estimators integrate the cos θ-weighted versions of these functions.
//
// The table holds ā_f and β̄_f² on a uniform grid of θ ∈ [−π/2, π/2] (linear
// interpolation; functions of θ are smooth where functions of sin θ are not,
// at the poles) and derives, for one fiber's dual-scattering tables:
//   logABar_f     ln ā_f(θ)              (per crossing; exact mode multiplies in log space)
//   beta2Bar_f    β̄_f²(θ)                (per crossing)
//   cosTheta      cos θ = sqrt(1 − s²)   (rate of n; evaluated exactly, not interpolated,
//                                         because its slope is infinite at s = ±1)
//   wAbsorb       cos θ·(1 − ā_f(θ))     (rate of the Poisson estimate of E[P])
//   wLogA         cos θ·(−ln ā_f(θ))     (rate of the paper's geometric form ā_f^n)
//   wBeta2        cos θ·β̄_f²(θ)          (rate of Σβ̄_f²)
// and the rates' isotropic averages ½∫_{−1}^{1} w(s) ds (fibers in all directions).
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/shading/dual_scattering_tables.h>

#include <functional>
#include <vector>

namespace hairvox {

class CrossingTable {
public:
    struct Values {
        Rgb logABar_f;  ///< ln ā_f(θ), ≤ 0, finite (ā_f is clamped away from 0)
        Rgb beta2Bar_f; ///< β̄_f²(θ), ≥ 0
    };
    /// cos θ-weighted rates (see the file comment).
    struct Rates {
        float cosTheta = 0;
        Rgb wAbsorb, wLogA, wBeta2;

        Rates& operator+=(const Rates& o) {
            cosTheta += o.cosTheta;
            wAbsorb += o.wAbsorb;
            wLogA += o.wLogA;
            wBeta2 += o.wBeta2;
            return *this;
        }
        Rates operator*(float w) const {
            return {cosTheta * w, wAbsorb * w, wLogA * w, wBeta2 * w};
        }
        Rates operator+(const Rates& o) const { return Rates(*this) += o; }
    };

    /// Tabulates from functions of the inclination θ ∈ [−π/2, π/2] (radians).
    /// Throws std::invalid_argument if either returns a non-finite value.
    static CrossingTable build(const std::function<Rgb(float theta)>& aBar_f,
                               const std::function<Rgb(float theta)>& beta2Bar_f,
                               int samples = 1025);
    /// From a fiber's dual-scattering tables (ā_f and β̄_f²).
    static CrossingTable fromDualScattering(const DualScatteringTables& tables);

    /// Per-crossing values at s = sin θ = ω·u (clamped to [−1, 1]).
    Values crossing(float sinTheta) const;
    /// cos θ-weighted rates at s = sin θ = ω·u.
    Rates rates(float sinTheta) const;
    /// ½∫ rates(s) ds over s ∈ [−1, 1]: fibers of uniformly random direction.
    const Rates& isotropicRates() const { return isotropic_; }

private:
    struct Entry {
        Values values;
        Rgb oneMinusABar_f;
    };
    /// Index and weight of the entries around sin θ = s.
    std::pair<std::size_t, float> locate(float s) const;

    std::vector<Entry> entries_;
    float scale_ = 0; ///< (samples − 1)/π: maps θ ∈ [−π/2, π/2] to [0, samples − 1]
    Rates isotropic_;
};

/// One table per fiber type, indexed by Groom::fiberType (strands/groom.h);
/// a single table for an untyped groom.
using CrossingTables = std::vector<CrossingTable>;

/// Throws InputError unless there is a table for each of `fiberTypes` types.
void checkCrossingTables(const CrossingTables& tables, std::size_t fiberTypes);


} // namespace hairvox
