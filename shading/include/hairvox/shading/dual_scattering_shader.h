// hairvox shading: the dual-scattering shader for one light (Zinke et al.
// 2008 Fig. 5, as revised in Sadeghi & Tamstorf 2010 §2.3; conventions in
// docs/DESIGN.md §5):
//
//   F_direct  = V·(f_s + d_b·f_back^direct)
//   F_scatter = T_s·(f_s^scatter + π·d_b·f_back^scatter)
//   result    = (F_direct + F_scatter)·cos θ_i
//
// with, at θ = θ_i for the table entries and (θ_d, φ) for N^G:
//   f_back^direct  = Ā_b·S̄_b(θ_h, φ; σ̄_b²)/cos²θ_d
//   f_back^scatter = Ā_b·S̄_b(θ_h, φ; σ̄_b² + σ_f²)/cos²θ_d
//   S̄_b(θ_h, φ; σ²) = ½·g(θ_h − Δ̄_b; σ) · ½·max(cos φ, 0)
//   f_s^scatter    = Σ_p ½·g(θ_h − α_p; sqrt(β_p² + σ_f²))·N^G_p(θ_d, φ)/cos²θ_d
//
// Decisions (each a departure from the printed text, see DESIGN.md §5):
//  - The report's Eqs. 19 and 20 are swapped relative to its own pseudocode
//    and text: f_back^direct uses σ̄_b², f_back^scatter σ̄_b² + σ_f² (as above).
//  - The pseudocode multiplies F_scatter by d_f a second time. T_s = d_f(P − V)
//    already carries d_f (GlobalTerm), and d_f is the fraction of
//    forward-scattered light that a neighbourhood keeps, which a path pays
//    once; the second factor is dropped.
//  - Normalisation of f_back: the printed 2Ā_b·g(θ_h − Δ̄_b, σ̄_b²)/(π cos²θ_d)
//    integrates (∫ f_back cos θ_o dω) to 4Ā_b over the back half and 8Ā_b over
//    the sphere. S̄_b above is unit-area over θ_o (the ½, as for M_p) and
//    carries Ā_b into the back half only, so ∫_{Ω_b} f_back cos θ dω = Ā_b for
//    narrow σ̄_b on the specular cone (Δ̄_b = 0), and Ā_b·cos²θ_o/cos²θ_d at
//    the lobe's peak otherwise — the 1/cos²θ_d weighting of f_s's own lobes
//    (both tested). Its azimuthal profile ½cos φ (rather than a uniform 1/π
//    on Ω_b) goes to zero at |φ| = π/2, so that the image has no seam where
//    the view crosses the light's terminator.
//  - f_s^scatter carries the same 1/cos²θ_d as f_s (it is f_s with widened
//    M_p and front-averaged N_p); the π in F_scatter is kept as printed.
//  - N^G_p is N_p averaged over incident azimuths across the half circle
//    facing the light, read at φ (DualScatteringTables), not the printed
//    constant (2/π)∫_{π/2}^{π} N_p applied at every φ: that one carries 2ā_f of
//    energy over the circle and sends forward-scattered light back toward the
//    light. Measured against the path tracer: DESIGN.md §8.
//  - σ̄_b² in the tables is computed with the tables' d_b; the shader recomputes
//    it for its own d_b when they differ (DualScatteringTables::withBackwardDensity).
//
// Evaluation: shade(ShadeBatch&) shades many points at once across SIMD lanes
// (shading/src/shade_kernel.h: the one implementation of these formulas,
// dispatched at run time to AVX-512, AVX2+FMA, SSE4 or the baseline); the
// single-point functions are batches of one.
//
// Lifetime: the shader holds copies (the Marschner table is shared, the
// dual-scattering tables are ~30 KB), so its arguments may be destroyed after
// construction. shade() is const and thread-safe.
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/shading/dual_scattering_tables.h>
#include <hairvox/shading/fiber_params.h>
#include <hairvox/shading/global_term.h>
#include <hairvox/shading/marschner.h>

#include <cstddef>
#include <iterator>
#include <vector>

namespace hairvox {

/// Points to shade, stored as structure of arrays (the SIMD kernel's
/// layout): reset() to the number of points, setView() each point, then per
/// light setIncident() (each point, or all at once for a directional light)
/// and setGlobalTerm() each point, and DualScatteringShader::shade(batch),
/// which adds that light's E·ShadeResult to each point's radiance(). Reuse
/// one batch to avoid reallocating.
class ShadeBatch {
public:
    /// Starts a batch of `count` points with zero radiance.
    void reset(std::size_t count);
    std::size_t size() const { return count_; }
    /// ω_o toward the camera and u the unit tangent at point i.
    void setView(std::size_t i, const Vec3f& wo, const Vec3f& u);
    /// The current light at point i: ω_i toward it (unit) and its irradiance
    /// E (facing the light); or the same at every point.
    void setIncident(std::size_t i, const Vec3f& wi, const Rgb& E);
    void setIncident(const Vec3f& wi, const Rgb& E);
    /// The current light's global term at point i (inline: a store per row,
    /// once per point and light).
    void setGlobalTerm(std::size_t i, const GlobalTerm& g) {
        const float rows[] = {g.V,          g.T_s.r,      g.T_s.g,     g.T_s.b,
                              g.sigma2_f.r, g.sigma2_f.g, g.sigma2_f.b};
        for (std::size_t r = 0; r < std::size(rows); ++r)
            in(kGlobalTermFirstRow + r, i) = rows[r];
    }
    /// Σ over the lights shaded so far of E·ShadeResult at point i.
    ShadeResult radiance(std::size_t i) const;

private:
    friend class DualScatteringShader;
    /// Rows: ω_i, ω_o, u (9); then V, T_s, σ_f² (7); then E (3).
    static constexpr std::size_t kInputRows = 19, kGlobalTermFirstRow = 9;
    static constexpr std::size_t kOutputRows = 15; ///< ShadeResult's channels
    float& in(std::size_t row, std::size_t i) { return inputs_[row * capacity_ + i]; }

    std::size_t count_ = 0, capacity_ = 0;
    std::vector<float> inputs_, radiance_;
};

class DualScatteringShader {
public:
    /// `tables` must have been built for `bcsdf.params()` (std::invalid_argument
    /// otherwise); `params` is validated (InputError).
    DualScatteringShader(const MarschnerBcsdf& bcsdf, const DualScatteringTables& tables,
                         const DualScatteringParams& params);

    /// Adds the current light's E·ShadeResult to every point of the batch.
    /// `spread2`: the light's angular variance per axis (rad²) when it stands
    /// for an area — a region of an environment map (EnvironmentRegion::
    /// spread2) — whose directions spread θ_i: every longitudinal lobe (M_p,
    /// M^G_p, S̄_b) is widened by the θ_h variance it causes, spread2/4, the
    /// lobe convolved with a Gaussian of the light's extent (its azimuthal
    /// extent is neglected: N_p is broad in φ). 0: a directional light.
    void shade(ShadeBatch& batch, float spread2 = 0) const;

    /// ω_i toward the light, ω_o toward the camera, u the unit tangent; all unit.
    ShadeResult shade(const Vec3f& wi, const Vec3f& wo, const Vec3f& u, const GlobalTerm& g) const;
    ShadeResult shade(const FiberAngles& a, const GlobalTerm& g) const;

    /// f_back with the extra longitudinal variance σ² (0: f_back^direct; σ_f²: f_back^scatter).
    Rgb fBack(const FiberAngles& a, const Rgb& sigma2) const;
    /// f_s^scatter for the accumulated forward variance σ_f².
    Rgb fsScatter(const FiberAngles& a, const Rgb& sigma2_f) const;

    const MarschnerBcsdf& bcsdf() const { return bcsdf_; }
    const DualScatteringTables& tables() const { return tables_; }
    const DualScatteringParams& params() const { return params_; }

private:
    MarschnerBcsdf bcsdf_;
    DualScatteringTables tables_;
    DualScatteringParams params_;
};

} // namespace hairvox
