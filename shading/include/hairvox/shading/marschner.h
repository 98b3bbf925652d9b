// hairvox shading: Marschner et al. 2003 single scattering f_s for a hair
// fiber, RGB, with the R, TT and TRT lobes (docs/DESIGN.md §3):
//
//   f_s(ω_i, ω_o) = Σ_{p ∈ {R, TT, TRT}} M_p(θ_h) N_p(θ_d, φ) / cos²θ_d
//
// ω_i points toward the light, ω_o toward the camera, u is the unit tangent
// root → tip; all unit vectors. f_s includes the 1/cos²θ_d and excludes
// cos θ_i (the renderer multiplies by incident radiance and cos θ_i).
//
// M_p(θ_h) = ½·g(θ_h − α_p; β_p): a Gaussian of standard deviation β_p in θ_h,
// normalised to unit area over θ_o (dθ_o = 2 dθ_h; DESIGN.md §3 explains why
// the printed unit area over θ_h doubles the energy).
//
// N_p is the exact azimuthal model of azimuthal.h. eval() reads it from a
// table built at construction (~10 ms; cos θ_d × φ, plus cos 2φ_h for TRT
// when the eccentricity is not 1, ~0.2 s) with bilinear interpolation. Decided
// by measurement (bench/shading_bench.cpp): evalExact() with its root solves
// costs ~0.8 µs, eval() ~0.1 µs including the angles, which the renderer's
// budget of 0.2 µs per shade needs. The table's L1 error over φ is < 0.1% of
// N (tests/shading/marschner_test.cpp); evalExact() is the reference.
//
// Importance sampling of f_s·cos θ_i (sample(), pdf(); the path tracer's
// scattering at a fiber): a lobe p is chosen with probability proportional to
// its albedo A_p(θ_o) = ∫ f_p cos θ_i dω_i (tabulated over θ_o); θ_i from M_p,
// i.e. θ_h ~ N(α_p, β_p²) truncated so that θ_i ∈ [−π/2, π/2] (inverse CDF);
// φ from N_p's own table: the row of cos θ_d on either side is chosen with its
// bilinear weight and |φ| drawn from that row's piecewise-linear density
// (exact inverse CDF), the sign at random; a 2% uniform share in φ keeps the
// density positive wherever f_s is (eccentric TRT, whose proposal averages
// the cross-section orientations). The density of the whole mixture,
//   pdf(ω_i) = Σ_p w_p(θ_o) pdf_θ,p(θ_i | θ_o) pdf_φ,p(φ | θ_d) / cos θ_i,
// is exact, so weight = f_s·cos θ_i / pdf is unbiased for any table error,
// and its variance is small where the proposal follows f_s (d'Eon et al.
// 2013 sample Marschner-like lobes the same way: lobe, then θ, then φ).
//
// Eccentricity needs the azimuthal half angle φ_h = (φ_i + φ_o)/2, i.e. the
// orientation of the fiber's elliptical cross-section, which a curve does not
// carry: FiberAngles measures azimuths from the first axis of
// coordinateSystem(u), a fixed but arbitrary orientation per tangent (real
// fibers are twisted at random, so no orientation is privileged).
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/shading/fiber_params.h>
#include <hairvox/shading/longitudinal.h>

#include <array>
#include <memory>
#include <ostream>

namespace hairvox {

class MarschnerBcsdf;
namespace detail {
struct MarschnerView;
/// What the SIMD kernel reads of a bcsdf (shading/src/shade_kernel.h).
MarschnerView marschnerView(const MarschnerBcsdf& bcsdf);
} // namespace detail

/// Marschner's scattering paths, indexed by the number p of internal segments.
enum class Lobe : int { R = 0, TT = 1, TRT = 2 };
inline constexpr std::array<Lobe, 3> kLobes{Lobe::R, Lobe::TT, Lobe::TRT};

struct LobeValues {
    Rgb R, TT, TRT;

    Rgb sum() const { return R + TT + TRT; }
    Rgb& operator[](Lobe p) { return p == Lobe::R ? R : (p == Lobe::TT ? TT : TRT); }
    const Rgb& operator[](Lobe p) const { return p == Lobe::R ? R : (p == Lobe::TT ? TT : TRT); }
};

std::ostream& operator<<(std::ostream& os, const LobeValues& v);

/// The angles of a light/camera pair about a fiber (DESIGN.md §2).
struct FiberAngles {
    float sinTheta_i = 0, cosTheta_i = 1; ///< θ_i: inclination of ω_i (sin θ = ω·u)
    float sinTheta_o = 0, cosTheta_o = 1; ///< θ_o: inclination of ω_o
    float theta_i = 0, theta_o = 0;
    float theta_h = 0;     ///< (θ_i + θ_o)/2
    float theta_d = 0;     ///< (θ_o − θ_i)/2
    float cos2Theta_d = 1; ///< cos²θ_d, floored at kMinCos2Theta_d (f_s is finite end-on)
    float phi = 0;         ///< φ_o − φ_i ∈ [−π, π]; 0 backward, ±π forward
    float cosPhi = 1;      ///< cos φ
    float cos2Phi_h = 1;   ///< cos 2φ_h = cos(φ_i + φ_o), for eccentricity

    /// cos²θ_d reaches 0 only for ω_i = ±u, ω_o = ∓u; 1e-7 is the smallest
    /// value that float directions off that corner produce.
    static constexpr float kMinCos2Theta_d = 1e-7f;

    /// From unit directions (degenerate azimuths, e.g. ω along u, give φ = 0).
    static FiberAngles fromDirections(const Vec3f& wi, const Vec3f& wo, const Vec3f& u);
    /// From angles: θ_i, θ_o ∈ [−π/2, π/2], any φ (wrapped), φ_h the half azimuth.
    static FiberAngles fromAngles(float theta_i, float theta_o, float phi, float phi_h = 0);
};

std::ostream& operator<<(std::ostream& os, const FiberAngles& a);

/// A direction sampled from f_s·cos θ_i for a given ω_o (MarschnerBcsdf::sample).
struct BcsdfSample {
    Vec3f wi{0.0f};       ///< unit; zero for an invalid sample (weight 0)
    LobeValues f;         ///< f_s per lobe at (ω_i, ω_o)
    float pdf = 0;        ///< solid-angle density of ω_i (the whole mixture)
    Rgb weight{0.0f};     ///< f_s·cos θ_i / pdf, summed over the lobes
    Lobe lobe = Lobe::R;  ///< the lobe ω_i was drawn from

    bool valid() const { return pdf > 0; }
};

class MarschnerBcsdf {
public:
    /// Validates `params` (InputError with the valid range) and tabulates N_p.
    explicit MarschnerBcsdf(const FiberParams& params);

    /// f_s per lobe (tabulated N_p).
    LobeValues eval(const Vec3f& wi, const Vec3f& wo, const Vec3f& u) const {
        return eval(FiberAngles::fromDirections(wi, wo, u));
    }
    LobeValues eval(const FiberAngles& a) const;
    /// f_s per lobe from the exact N_p (root solves): the reference for tests.
    LobeValues evalExact(const FiberAngles& a) const;

    /// A direction ω_i for the outgoing ω_o about the tangent u (all unit),
    /// from four uniforms in [0, 1) (see the file comment). Deterministic in
    /// its inputs.
    BcsdfSample sample(const Vec3f& wo, const Vec3f& u, const std::array<float, 4>& uniforms) const;
    /// The solid-angle density sample() draws ω_i with, for ω_o.
    float pdf(const Vec3f& wi, const Vec3f& wo, const Vec3f& u) const;
    float pdf(const FiberAngles& a) const;
    /// The density of sample() given that it chose lobe p (what the mixture weighs).
    float pdf(const FiberAngles& a, Lobe p) const;
    /// A_p(θ) = ∫ f_p(θ, ω) cos θ_ω dω, the mean over RGB (the lobe selection
    /// weights; tabulated over θ with linear interpolation).
    float lobeAlbedo(Lobe p, float theta) const;

    /// M_p(θ_h) = ½·g(θ_h − α_p; β_p).
    float M(Lobe p, float theta_h) const;
    /// Tabulated N_p(θ_d, φ) (cos2Phi_h matters for TRT when the eccentricity is not 1).
    LobeValues N(float theta_d, float phi, float cos2Phi_h = 1) const;
    /// Exact N_p (azimuthal::N), in double so that tests can place η' precisely.
    LobeValues NExact(double theta_d, double phi, double cos2Phi_h = 1) const;

    /// α_R, α_TT = −α_R/2, α_TRT = −3α_R/2 (radians).
    float alpha(Lobe p) const { return alpha_[static_cast<std::size_t>(p)]; }
    /// β_R, β_TT = β_R/2, β_TRT = 2β_R (radians).
    float beta(Lobe p) const { return beta_[static_cast<std::size_t>(p)]; }

    const FiberParams& params() const { return params_; }

    /// Samples of the N_p table: cos θ_d over [0, 1], φ over [0, π] (N_p is
    /// even in θ_d and φ), cos 2φ_h over [−1, 1] (1 sample when the
    /// eccentricity is 1). Uniform grids, (bi/tri)linear interpolation.
    struct TableSize {
        int theta_d = 0, phi = 0, cos2Phi_h = 0;
    };
    TableSize tableSize() const;

private:
    struct AzimuthalTable;
    friend detail::MarschnerView detail::marschnerView(const MarschnerBcsdf& bcsdf);

    struct SamplingTables;

    /// n_p·M_p(θ_h)/cos²θ_d per lobe (evalExact's; eval's is the kernel's).
    LobeValues withLongitudinal(LobeValues n, const FiberAngles& a) const;
    /// Lobe selection probabilities at θ_o.
    std::array<float, 3> lobeWeights(float theta_o) const;

    FiberParams params_;
    std::array<float, 3> alpha_{}, beta_{};
    std::array<LongitudinalLobe, 3> M_;           ///< M_p (longitudinal.h)
    std::shared_ptr<const AzimuthalTable> table_; ///< shared: copies are cheap
    std::shared_ptr<const SamplingTables> sampling_;
};

std::ostream& operator<<(std::ostream& os, const MarschnerBcsdf& b);

} // namespace hairvox
