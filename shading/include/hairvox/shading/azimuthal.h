// hairvox shading: Marschner's azimuthal scattering functions N_p(θ_d, φ),
// evaluated exactly (double precision, exact root solves of Φ(p, h) = φ).
//
// Marschner et al. 2003 §4, as written out step by step in the Khungurn notes
// §1, with the corrections of docs/DESIGN.md §3:
//  - one pass through the fiber attenuates by T = exp(−2σ_a cos γ_t / cos θ_t)
//    (the notes print exp(2σ_a cos γ_t));
//  - η' = sqrt(η² − sin²θ_d) / cos θ_d (the notes' TRT pseudocode has η, not η²);
//  - N_p sums over every root h of Φ(p, h) ≡ φ (mod 2π): one for R and TT,
//    one or three for TRT;
//  - eccentricity enters TRT through η*(φ_h), φ_h = (φ_i + φ_o)/2.
//
// Conventions: h ∈ [−1, 1] is the offset across the fiber in units of its
// radius, γ_i = asin h, γ_t = asin(h/η'), and the exit azimuth of the path
// with p internal segments is Φ(p, h) = 2γ_i − 2pγ_t + pπ (Khungurn's sign;
// Marschner's paper uses −Φ, and since every N_p is even in φ nothing depends
// on the choice). φ = 0 is backward scattering, |φ| = π forward. N_p is a
// density per radian of φ: ∫ N_p dφ over the circle = ½ ∫_{−1}^{1} A_p(h) dh.
//
// This is the reference model: the dual-scattering tables integrate it and
// MarschnerBcsdf tabulates it for rendering (marschner.h).
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/shading/fiber_params.h>

#include <array>

namespace hairvox::azimuthal {

/// Everything that depends only on the refractive index and the inclination θ_d.
struct Geometry {
    double eta = 1.55;            ///< index in use (η, or η* for TRT with eccentricity)
    double etaPrime = 1.55;       ///< Bravais index η' = sqrt(η² − sin²θ_d)/cos θ_d (geometry, s-polarisation)
    double etaDoublePrime = 1.55; ///< η'' = η²/η' (p-polarisation Fresnel)
    double cosTheta_t = 1;        ///< cos θ_t = sqrt(1 − sin²θ_d/η²), longitudinal path factor

    /// θ_d ∈ [−π/2, π/2]; η ≥ 1. Finite at |θ_d| = π/2 (η' is capped at ~1e12).
    static Geometry make(double eta, double theta_d);
};

/// Marschner's eccentricity model (§4.3; Khungurn §1.5.4): the index seen by
/// TRT, η*(φ_h) = ½((η₁ + η₂) + cos 2φ_h·(η₁ − η₂)),
/// η₁ = 2(η − 1)a² − η + 2, η₂ = 2(η − 1)a⁻² − η + 2. Clamped to ≥ 1: for
/// a < 1/√2 the interpolation leaves the physical range (η₁ < 1, a fiber
/// optically thinner than air), where Φ(p, h) has no meaning.
double eccentricEta(double eta, double eccentricity, double cos2Phi_h);

/// Φ(p, h) = 2 asin h − 2p asin(h/η') + pπ, not wrapped.
double exitAzimuth(int p, double h, double etaPrime);

/// dΦ/dγ_i = 2 − 2p cos γ_i / sqrt(η'² − sin²γ_i) (so dΦ/dh = this / cos γ_i).
double exitAzimuthDerivative(int p, double gamma_i, double etaPrime);

/// The roots of Φ(p, h) ≡ φ (mod 2π), h ∈ [−1, 1], ascending.
struct Roots {
    int count = 0;
    std::array<double, 3> gamma_i{}; ///< γ_i = asin h of each root
};

/// Exact solve: Φ is split into its monotonic branches (TRT with η' < 2 has
/// three, separated by the caustics at cos²γ_c = (η'² − 1)/3), and each
/// branch that brackets φ is solved by Newton's method safeguarded by
/// bisection, to ~1e-15 rad. p ∈ {0, 1, 2}, η' ≥ 1.
Roots solveExitAzimuth(int p, double phi, double etaPrime);

/// Fresnel reflectance F(η', η'', γ_i) for the azimuthal projection (Khungurn §1.1).
double fresnel(const Geometry& geo, double gamma_i);

/// A(p, h) with h = sin γ_i: F for R, (1 − F)² F^{p−1} T^p otherwise (RGB σ_a per unit radius).
Rgbd attenuation(int p, const Geometry& geo, double gamma_i, const Rgb& sigma_a);

/// The TRT caustic treatment (Marschner §4.2.2; Khungurn §1.5): for η' < 2
/// two Gaussian lobes at ±φ_c replace the singular N_2 there; for η' ≥ 2 a
/// lobe at φ_c = 0 fades out over [2, 2 + Δη'].
struct TrtCaustic {
    double t = 0;       ///< caustic weight: 1 for η' < 2, 1 − smoothstep(2, 2 + Δη', η') above
    double phi_c = 0;   ///< caustic azimuth (the lobes sit at ±φ_c)
    double h_c = 0;     ///< caustic offset sqrt((4 − η'²)/3), 0 for η' ≥ 2
    double deltaH = 0;  ///< h-interval mapped into the lobe, min(Δh_M, 2 sqrt(2w_c / |Φ''(h_c)|))
    double width = 0;   ///< lobe width w_c (rad)
    Rgbd amplitude;     ///< t·k_G·A(2, h_c)·Δh: the integral of each lobe over φ
};

TrtCaustic trtCaustic(const Geometry& geo, const FiberParams& params);

/// (1 − t·e(φ − φ_c))(1 − t·e(φ + φ_c)), e(x) = exp(−x²/2w_c²) on the wrapped
/// difference: the factor that removes the singular N_2 under the caustic lobes.
double trtFade(const TrtCaustic& caustic, double phi);

/// The caustic lobes t·k_G·A(h_c)·Δh·(g(φ − φ_c) + g(φ + φ_c)), differences wrapped to [−π, π].
Rgbd trtCausticLobes(const TrtCaustic& caustic, double phi);

/// N_p(θ_d, φ) for p ∈ {0, 1, 2} (R, TT, TRT including the caustic
/// treatment). cos2Phi_h = cos 2φ_h only matters for TRT with eccentricity ≠ 1.
Rgbd N(int p, const FiberParams& params, double theta_d, double phi, double cos2Phi_h = 1);

} // namespace hairvox::azimuthal
