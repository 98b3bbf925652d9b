// hairvox shading: the longitudinal lobe, the one function of θ_h that every
// term of the model uses (docs/DESIGN.md §3, §5):
//
//   M(θ_h; α, σ²) = ½·g(θ_h − α; σ),   g(x; σ) = exp(−x²/2σ²) / (σ√2π)
//
// a Gaussian of variance σ² in the half angle θ_h = (θ_i + θ_o)/2, normalised
// to unit area over θ_o (dθ_o = 2 dθ_h; the printed unit area over θ_h
// doubles the energy). Its instances:
//  - Marschner's M_p (Eq. 4 of Marschner et al. 2003):    α = α_p,  σ² = β_p²
//  - dual scattering's M^G_p (Sadeghi & Tamstorf Eq. 17): α = α_p,  σ² = β_p² + σ_f²
//  - the back-scattering spread S̄_b (Zinke et al. Eq. 9): α = Δ̄_b,  σ² = σ̄_b² (+ σ_f²)
// The renderer evaluates it across SIMD lanes in shading/src/shade_kernel-inl.h
// (longitudinalLobe there: the same expression), the tables here.
#pragma once

#include <hairvox/core/math.h>

#include <cmath>
#include <concepts>

namespace hairvox {

/// ½·g(x; √variance): x = θ_h − α, variance > 0.
template <std::floating_point T>
T longitudinalLobe(T x, T variance) {
    return std::sqrt(T(1) / (T(8.0 * Pi) * variance)) * std::exp(-x * x / (T(2) * variance));
}

/// The same lobe with its shift and variance fixed and its constants
/// precomputed: Marschner's M_p, evaluated per shading point.
class LongitudinalLobe {
public:
    LongitudinalLobe() = default;
    LongitudinalLobe(float shift, float variance)
        : shift_(shift)
        , invTwoVariance_(0.5f / variance)
        , scale_(std::sqrt(1.0f / (static_cast<float>(8.0 * Pi) * variance))) {}

    float operator()(float theta_h) const {
        const float x = theta_h - shift_;
        return scale_ * std::exp(-x * x * invTwoVariance_);
    }
    float shift() const { return shift_; }
    /// The constants of scale·exp(−(θ_h − shift)²·invTwoVariance), for code
    /// that evaluates the lobe elsewhere (the SIMD kernel).
    float scale() const { return scale_; }
    float invTwoVariance() const { return invTwoVariance_; }

private:
    float shift_ = 0, invTwoVariance_ = 0, scale_ = 0;
};

} // namespace hairvox
