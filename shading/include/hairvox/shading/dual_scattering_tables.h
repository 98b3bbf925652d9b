// hairvox shading: the precomputed functions of the dual-scattering model
// (Zinke et al. 2008 §4; Sadeghi & Tamstorf 2010 §2, Eqs. 10–18; conventions
// and corrections in docs/DESIGN.md §4), RGB, over the incident inclination
// θ ∈ [−π/2, π/2]:
//
//   ā_f, ā_b     ∫_{Ω_f|Ω_b} f_s(θ, ω) cos θ_ω dω, dω = cos θ_ω dθ_ω dφ
//                (Ω_f: |φ| ≥ π/2, Ω_b: |φ| < π/2)
//   ᾱ_f, ᾱ_b     lobe shifts α_p averaged with weights ∫ f_p cos θ dω over Ω_f|Ω_b
//   β̄_f², β̄_b²   the same average of the lobe variances β_p² (Zinke's form; the
//                RenderMan report's Eqs. 15–16 average β_p instead: variances are
//                what add along a path, and σ_f² = Σ β̄_f² in the global term)
//   Ā_b          Eq. 10, Δ̄_b Eq. 11 (as printed)
//   σ̄_b²         the square of Zinke's Eq. 12 as given in DESIGN.md §4, with d_b = options.d_b
//   N^G_p        (1/π) ∫_{φ−π/2}^{φ+π/2} N_p(θ_d, φ') dφ' — N_p averaged over
//                incident azimuths spread across the half circle facing the
//                light, read at the azimuth φ (DESIGN.md §5): a function of
//                θ_d (the row's θ) and φ ∈ [0, π] (kNGPhiSamples, uniform).
//                At φ = π it is Zinke's printed (2/π) ∫_{π/2}^{π} N_p dφ'
//                (Eq. 18); unlike that constant it carries the lobe's own
//                energy, ∫ N^G_p dφ = ∫ N_p dφ, and none of the forward
//                lobes' energy back toward the light.
//
// Integration (documented, convergence tested in
// tests/shading/dual_scattering_tables_test.cpp): the azimuthal integrals are
// done in h, not φ (∫_S N_p dφ = ½ ∫_{Φ(p,h) ∈ S} A_p(h) dh, with h = sin γ so
// that the integrand is smooth), split where the exit azimuth crosses
// ±π/2, each piece by Gauss–Legendre; the TRT caustic lobes are integrated in
// closed form (erf). The θ_o integral is split around each lobe's peak
// (θ_o = 2α_p − θ, width 2β_p) into three Gauss–Legendre pieces. Fibers with
// eccentricity ≠ 1 are averaged over the cross-section orientation φ_h
// (uniform, 8 nodes), which is the same as averaging over φ_i. Measured
// against order 96: order 8 is off by 3e-2, 16 by 1.5e-4, the default 24 by
// 5e-5 (ā, Ā_b, N^G); a default build takes ~0.3 s on one core.
//
// Numerical traps (DESIGN.md §4): Eqs. 10–12 are geometric series in ā_f²
// that diverge as ā_f → 1 (σ_a → 0; the model's albedo even exceeds 1 near
// the poles and for |α_R| ≳ 10°). ā_f is capped at 0.95 inside them, Ā_b at 1
// (a half-space cannot send back more than it receives) and Δ̄_b at ±π/2 (a
// larger shift only moves the lobe off the sphere). ā_f, ā_b themselves are
// stored as integrated. Every entry is finite for every valid parameter set.
#pragma once

#include <hairvox/core/hash.h>
#include <hairvox/core/rgb.h>
#include <hairvox/shading/fiber_params.h>
#include <hairvox/shading/marschner.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <ostream>
#include <vector>

namespace hairvox {

class DualScatteringTables;
namespace detail {
struct DualScatteringTablesView;
/// What the SIMD kernel reads of the tables (shading/src/shade_kernel.h).
DualScatteringTablesView tablesView(const DualScatteringTables& tables);
} // namespace detail

struct TableBuildOptions {
    int thetaSamples = 181;  ///< uniform θ grid over [−π/2, π/2] (1° steps), [3, 10001]
    int quadratureOrder = 24; ///< Gauss–Legendre nodes per integration piece, [4, 256]
    float d_b = 1.0f;        ///< backward density factor inside σ̄_b (Zinke Eq. 12), [0, 1]
    bool threaded = true;    ///< TBB over θ rows (the result is the same either way)

    /// Throws InputError naming the first option outside its range.
    void validate() const;
    /// Everything that changes the tables (not `threaded`).
    void hashInto(Hasher& hasher) const;
};

std::ostream& operator<<(std::ostream& os, const TableBuildOptions& o);

class DualScatteringTables {
public:
    /// One θ row; all RGB. Angles in radians, variances in rad².
    struct Sample {
        Rgb aBar_f, aBar_b;         ///< average forward/backward attenuation
        Rgb alphaBar_f, alphaBar_b; ///< average forward/backward longitudinal shift
        Rgb beta2Bar_f, beta2Bar_b; ///< average forward/backward longitudinal variance
        Rgb ABar_b;                 ///< average backscattering attenuation (Eq. 10)
        Rgb DeltaBar_b;             ///< average backscattering shift (Eq. 11)
        Rgb sigma2Bar_b;            ///< average backscattering variance (Eq. 12 squared)
    };

    /// N^G is tabulated at φ = π·j/(kNGPhiSamples − 1): 5° steps.
    static constexpr int kNGPhiSamples = 37;

    /// Integrates the tables for `params` (validated). ~0.1–0.5 s.
    static DualScatteringTables build(const FiberParams& params,
                                      const TableBuildOptions& options = {});

    /// Loads `cacheDir`/dual-scattering-<key>.bin, whose key hashes the
    /// parameters, the options and the file format version; a missing, corrupt
    /// (checksum) or truncated file is rebuilt and rewritten atomically. A
    /// cache directory that cannot be written is not an error: the tables are
    /// still returned.
    static DualScatteringTables loadOrBuild(const FiberParams& params,
                                            const std::filesystem::path& cacheDir,
                                            const TableBuildOptions& options = {});

    /// All quantities at θ (radians; clamped to [−π/2, π/2]), linearly interpolated.
    Sample lookup(float theta) const;
    /// One quantity at θ, e.g. interpolate(θ, &Sample::ABar_b): two rows read, no allocation.
    Rgb interpolate(float theta, Rgb Sample::*field) const {
        const auto [k, t] = locate(theta);
        const Rgb& a = rows_[k].*field;
        return a + t * (rows_[k + 1].*field - a);
    }
    /// Several quantities at θ with one index computation:
    /// interpolate(θ, &Sample::ABar_b, &Sample::DeltaBar_b) → {Ā_b(θ), Δ̄_b(θ)}.
    template <typename... Fields>
        requires(sizeof...(Fields) >= 2)
    std::array<Rgb, sizeof...(Fields)> interpolate(float theta, Fields... fields) const {
        const auto [k, t] = locate(theta);
        const Sample& a = rows_[k];
        const Sample& b = rows_[k + 1];
        return {(a.*fields + t * (b.*fields - a.*fields))...};
    }
    Rgb aBar_f(float theta) const { return interpolate(theta, &Sample::aBar_f); }
    Rgb beta2Bar_f(float theta) const { return interpolate(theta, &Sample::beta2Bar_f); }
    /// N^G_R, N^G_TT, N^G_TRT at θ_d and the azimuth φ (any angle: N^G is
    /// even and 2π-periodic in φ), bilinearly interpolated.
    LobeValues NG(float theta_d, float phi) const;
    /// The tabulated N^G at row k (θ_d = theta(k)) and φ = π·j/(kNGPhiSamples − 1).
    const LobeValues& NGSample(int k, int j) const {
        return ng_[static_cast<std::size_t>(k) * kNGPhiSamples + static_cast<std::size_t>(j)];
    }

    /// The same tables with σ̄_b² recomputed for another d_b (the only entry that depends on it).
    DualScatteringTables withBackwardDensity(float d_b) const;

    /// One row per θ sample: `theta` (radians), then each quantity per channel
    /// (af_r,af_g,af_b,ab_r,...), then N^G at θ_d = θ per lobe, azimuth and
    /// channel (NGR_phi000_r, ... NGTRT_phi180_b; φ in degrees). Written
    /// atomically.
    void writeCsv(const std::filesystem::path& path) const;

    int size() const { return static_cast<int>(rows_.size()); }
    float theta(int k) const;
    const Sample& sample(int k) const { return rows_[static_cast<std::size_t>(k)]; }
    const FiberParams& params() const { return params_; }
    const TableBuildOptions& options() const { return options_; }
    /// Hash of the parameters, options and format version (the cache file name).
    std::uint64_t cacheKey() const { return cacheKey_; }
    /// Whether loadOrBuild() found these tables in its cache.
    bool loadedFromCache() const { return loadedFromCache_; }

    /// The cache file that loadOrBuild() uses for these parameters.
    static std::filesystem::path cacheFile(const std::filesystem::path& cacheDir,
                                           const FiberParams& params,
                                           const TableBuildOptions& options = {});

private:
    DualScatteringTables() = default;

    struct Location {
        std::size_t k;
        float t;
    };
    Location locate(float theta) const {
        float x = (theta + static_cast<float>(PiOver2)) * invStep_;
        x = x > 0 ? std::min(x, lastIndex_) : 0.0f; // !(x > 0) also catches NaN
        const auto k = std::min(static_cast<std::size_t>(x), rows_.size() - 2);
        return {k, x - static_cast<float>(k)};
    }

    FiberParams params_;
    TableBuildOptions options_;
    std::vector<Sample> rows_;
    std::vector<LobeValues> ng_; ///< [row][φ sample]
    float invStep_ = 0, lastIndex_ = 0;
    std::uint64_t cacheKey_ = 0;
    bool loadedFromCache_ = false;

    friend struct TableIo;
    friend detail::DualScatteringTablesView detail::tablesView(const DualScatteringTables& tables);
};

std::ostream& operator<<(std::ostream& os, const DualScatteringTables::Sample& s);
std::ostream& operator<<(std::ostream& os, const DualScatteringTables& t);

/// $HAIRVOX_CACHE_DIR, else $XDG_CACHE_HOME/hairvox, else ~/.cache/hairvox
/// (else <temp>/hairvox-cache when there is no home directory).
std::filesystem::path defaultTableCacheDir();

} // namespace hairvox
