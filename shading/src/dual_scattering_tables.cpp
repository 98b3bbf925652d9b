#include <hairvox/core/gauss_legendre.h>
#include "shade_kernel.h"

#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/math.h>
#include <hairvox/shading/azimuthal.h>
#include <hairvox/shading/dual_scattering_tables.h>
#include <hairvox/shading/longitudinal.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>

namespace hairvox {

namespace fs = std::filesystem;
using quadrature::GaussLegendre;
using Sample = DualScatteringTables::Sample;

namespace {

/// Bumped whenever the integration or the file layout changes: old cache files then miss.
constexpr std::uint32_t kFormatVersion = 2; // 2: N^G over (θ_d, φ)
constexpr char kMagic[8] = {'H', 'V', 'X', 'D', 'S', 'T', 'B', 'L'};

/// Eqs. 10–12 are geometric series in ā_f² that diverge as ā_f → 1, which
/// the model reaches for σ_a → 0 at grazing θ (its albedo slightly exceeds 1
/// there, DESIGN.md §3). Capping ā_f at 0.95 keeps 1 − ā_f² ≥ 0.0975, i.e.
/// Eq. 11's (1 − ā_f²)⁻³ below ~1.1e3; lighter-than-this hair is not darker for it.
constexpr double kMaxForwardAttenuation = 0.95;

/// Cross-section orientations φ_h averaged over for eccentric fibers.
constexpr int kEccentricOrder = 8;

struct Field {
    const char* name;
    Rgb Sample::*member;
};
constexpr std::array<Field, 9> kFields{{
    {"af", &Sample::aBar_f},
    {"ab", &Sample::aBar_b},
    {"alphaf", &Sample::alphaBar_f},
    {"alphab", &Sample::alphaBar_b},
    {"beta2f", &Sample::beta2Bar_f},
    {"beta2b", &Sample::beta2Bar_b},
    {"Ab", &Sample::ABar_b},
    {"Deltab", &Sample::DeltaBar_b},
    {"sigma2b", &Sample::sigma2Bar_b},
}};
constexpr int kNGPhi = DualScatteringTables::kNGPhiSamples;
/// Floats per θ row in the cache file: the fields, then N^G per φ and lobe.
constexpr std::size_t kFloatsPerRow = kFields.size() * 3 + std::size_t(kNGPhi) * 9;

void requireRange(const char* name, double value, double lo, double hi) {
    if (!(value >= lo && value <= hi))
        throw InputError(strCat("dual-scattering tables: ", name, " = ", value,
                                " should be in the range [", lo, ", ", hi, "]"));
}

// ---- azimuthal integrals ----------------------------------------------------

/// ∫ N_p dφ over the half circle |wrap(φ − μ)| < π/2 centred on an azimuth μ,
/// and over the other half. Centred on μ = 0 they are the back half Ω_b and
/// the front half Ω_f.
struct Halves {
    Rgbd inside, outside;

    Halves& operator+=(const Halves& o) {
        inside += o.inside;
        outside += o.outside;
        return *this;
    }
    friend Halves operator*(double s, const Halves& h) { return {s * h.inside, s * h.outside}; }
};

/// ∫_{μ−π/2}^{μ+π/2} g(wrap(φ − ν); w) dφ: the part of a wrapped-difference
/// Gaussian lobe at ν that falls in the half circle centred on μ.
double lobeMassInHalf(double nu, double w, double mu) {
    const auto cdf = [w](double x) {
        return 0.5 * std::erfc(-x / (w * std::sqrt(2.0)));
    };
    const double offset = wrapAngle(nu - mu);
    double mass = 0;
    for (int k = -1; k <= 1; ++k) {
        const double lo = std::max(-PiOver2 - offset + TwoPi * k, -Pi);
        const double hi = std::min(PiOver2 - offset + TwoPi * k, Pi);
        if (hi > lo)
            mass += cdf(hi) - cdf(lo);
    }
    return mass;
}

/// ∫ N_p(θ_d, φ) dφ over the half circle centred on μ and over the rest, for
/// the index η (η* for eccentric TRT), as ½ ∫ A_p(h)·fade dh with h = sin γ
/// over the γ-pieces between the points where the exit azimuth crosses μ ± π/2.
Halves integrateAzimuth(int p, const FiberParams& params, double eta, double theta_d, double mu,
                        const GaussLegendre& gl) {
    const azimuthal::Geometry geo = azimuthal::Geometry::make(eta, theta_d);
    azimuthal::TrtCaustic caustic;
    if (p == 2)
        caustic = azimuthal::trtCaustic(geo, params);

    // Unused slots stay at π/2 and sort to the end as empty pieces.
    std::array<double, 8> cuts;
    cuts.fill(PiOver2);
    cuts[0] = -PiOver2;
    std::size_t cutCount = 1;
    for (double boundary : {wrapAngle(mu + PiOver2), wrapAngle(mu - PiOver2)}) {
        const azimuthal::Roots roots = azimuthal::solveExitAzimuth(p, boundary, geo.etaPrime);
        for (int k = 0; k < roots.count; ++k)
            cuts[cutCount++] = roots.gamma_i[static_cast<std::size_t>(k)];
    }
    std::sort(cuts.begin(), cuts.end());

    const auto exitPhi = [&](double gamma) {
        return azimuthal::exitAzimuth(p, std::sin(gamma), geo.etaPrime);
    };
    Halves halves;
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
        const double a = cuts[k], b = cuts[k + 1];
        if (!(b - a > 1e-14))
            continue;
        const bool inside = std::cos(exitPhi(0.5 * (a + b)) - mu) > 0;
        const Rgbd piece = gl.integrate<Rgbd>(a, b, [&](double gamma) {
            double weight = 0.5 * std::cos(gamma);
            if (p == 2)
                weight *= azimuthal::trtFade(caustic, exitPhi(gamma));
            return weight * azimuthal::attenuation(p, geo, gamma, params.sigma_a);
        });
        (inside ? halves.inside : halves.outside) += piece;
    }
    if (p == 2 && caustic.t > 0) {
        const double w = caustic.width;
        const double total = 2 * std::erf(Pi / (w * std::sqrt(2.0)));
        const double in = lobeMassInHalf(caustic.phi_c, w, mu) + lobeMassInHalf(-caustic.phi_c, w, mu);
        halves.inside += in * caustic.amplitude;
        halves.outside += (total - in) * caustic.amplitude;
    }
    return halves;
}

/// The same, averaged over the cross-section orientation for eccentric TRT.
Halves integrateAzimuth(int p, const FiberParams& params, double theta_d, double mu,
                        const GaussLegendre& gl, const GaussLegendre& eccentricGl) {
    if (p != 2 || params.eccentricity == 1.0f)
        return integrateAzimuth(p, params, params.eta, theta_d, mu, gl);
    // φ_h uniform: over [0, π/2] cos 2φ_h takes every value once.
    return eccentricGl.integrate<Halves>(0, PiOver2, [&](double phi_h) {
        const double eta =
            azimuthal::eccentricEta(params.eta, params.eccentricity, std::cos(2 * phi_h));
        return (1 / PiOver2) * integrateAzimuth(p, params, eta, theta_d, mu, gl);
    });
}

// ---- one θ row ----------------------------------------------------------------

double sigma2Bar_b(double aF, double aB, double beta2F, double beta2B, double d_b) {
    aF = std::min(aF, kMaxForwardAttenuation);
    const double aB3 = aB * aB * aB;
    const double num =
        aB * std::sqrt(2 * beta2F + beta2B) + aB3 * std::sqrt(2 * beta2F + 3 * beta2B);
    const double den = aB + aB3 * (2 * std::sqrt(beta2F) + 3 * std::sqrt(beta2B));
    // ā_b → 0: the ratio tends to sqrt(2β̄_f² + β̄_b²).
    const double sigma =
        (1 + d_b * aF * aF) * (den > 0 ? num / den : std::sqrt(2 * beta2F + beta2B));
    return sigma * sigma;
}

Sample buildRow(const FiberParams& params, const TableBuildOptions& options, double theta,
                const GaussLegendre& gl, const GaussLegendre& eccentricGl) {
    const double alpha_R = params.alpha_R, beta_R = params.beta_R;
    const std::array<double, 3> alpha{alpha_R, -0.5 * alpha_R, -1.5 * alpha_R};
    const std::array<double, 3> beta{beta_R, 0.5 * beta_R, 2.0 * beta_R};

    // Per lobe and half: ∫ f_p cos θ_o dω = ∫ M_p(θ_h) I_p(θ_d) cos²θ_o / cos²θ_d dθ_o.
    std::array<Halves, 3> lobe;
    for (std::size_t p = 0; p < 3; ++p) {
        const double centre = 2 * alpha[p] - theta, spread = 12 * beta[p]; // ±6σ in θ_o
        const std::array<double, 4> cuts{-PiOver2, std::clamp(centre - spread, -PiOver2, PiOver2),
                                         std::clamp(centre + spread, -PiOver2, PiOver2), PiOver2};
        for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
            if (!(cuts[k + 1] - cuts[k] > 1e-14))
                continue;
            lobe[p] += gl.integrate<Halves>(cuts[k], cuts[k + 1], [&](double theta_o) {
                const double theta_h = 0.5 * (theta + theta_o), theta_d = 0.5 * (theta_o - theta);
                const double cosO = std::cos(theta_o), cosD = std::cos(theta_d);
                const double m = longitudinalLobe(theta_h - alpha[p], beta[p] * beta[p]);
                return (m * cosO * cosO / (cosD * cosD)) *
                       integrateAzimuth(static_cast<int>(p), params, theta_d, 0.0, gl,
                                        eccentricGl);
            });
        }
    }
    Sample s;
    for (int c = 0; c < 3; ++c) {
        double aF = 0, aB = 0, alphaF = 0, alphaB = 0, beta2F = 0, beta2B = 0;
        for (std::size_t p = 0; p < 3; ++p) {
            const double wF = lobe[p].outside[c], wB = lobe[p].inside[c];
            aF += wF;
            aB += wB;
            alphaF += wF * alpha[p];
            alphaB += wB * alpha[p];
            beta2F += wF * beta[p] * beta[p];
            beta2B += wB * beta[p] * beta[p];
        }
        // R always contributes to both halves; the fallbacks only guard 0/0.
        alphaF = aF > 0 ? alphaF / aF : alpha[0];
        alphaB = aB > 0 ? alphaB / aB : alpha[0];
        beta2F = aF > 0 ? beta2F / aF : beta[0] * beta[0];
        beta2B = aB > 0 ? beta2B / aB : beta[0] * beta[0];

        const double aFc = std::min(aF, kMaxForwardAttenuation);
        const double aF2 = aFc * aFc, oneMinus = 1 - aF2;
        const double ABar =
            std::min(aB * aF2 / oneMinus + aB * aB * aB * aF2 / (oneMinus * oneMinus), 1.0);
        // Eq. 11's (1 − ā_f²)⁻³ still reaches ~1e3 at the cap: for light hair
        // with extreme α_R the "shift" exceeds the sphere. Beyond ±π/2 it
        // would only move the lobe off the domain of θ_h.
        const double DeltaBar =
            std::clamp(alphaB * (1 - 2 * aB * aB / (oneMinus * oneMinus)) +
                           alphaF * (2 * oneMinus * oneMinus + 4 * aF2 * aB * aB) /
                               (oneMinus * oneMinus * oneMinus),
                       -PiOver2, PiOver2);

        s.aBar_f[c] = static_cast<float>(aF);
        s.aBar_b[c] = static_cast<float>(aB);
        s.alphaBar_f[c] = static_cast<float>(alphaF);
        s.alphaBar_b[c] = static_cast<float>(alphaB);
        s.beta2Bar_f[c] = static_cast<float>(beta2F);
        s.beta2Bar_b[c] = static_cast<float>(beta2B);
        s.ABar_b[c] = static_cast<float>(ABar);
        s.DeltaBar_b[c] = static_cast<float>(DeltaBar);
        s.sigma2Bar_b[c] = static_cast<float>(sigma2Bar_b(aF, aB, beta2F, beta2B, options.d_b));
    }
    return s;
}

/// N^G_p(θ_d, φ_j) = (1/π) ∫_{φ_j−π/2}^{φ_j+π/2} N_p(θ_d, φ') dφ' for every tabulated φ_j.
void buildNG(const FiberParams& params, double theta_d, const GaussLegendre& gl,
             const GaussLegendre& eccentricGl, LobeValues* out) {
    for (int j = 0; j < kNGPhi; ++j) {
        const double phi = Pi * double(j) / double(kNGPhi - 1);
        for (Lobe p : kLobes)
            out[j][p] = Rgb((1 / Pi) * integrateAzimuth(static_cast<int>(p), params, theta_d, phi,
                                                        gl, eccentricGl)
                                           .inside);
    }
}

std::uint64_t computeCacheKey(const FiberParams& params, const TableBuildOptions& options) {
    Hasher h;
    h.string("hairvox dual-scattering tables").value(kFormatVersion);
    params.hashInto(h);
    options.hashInto(h);
    return h.digest();
}

} // namespace

// ---- options ------------------------------------------------------------------

void TableBuildOptions::validate() const {
    requireRange("theta samples", thetaSamples, 3, 10001);
    requireRange("quadrature order", quadratureOrder, 4, 256);
    requireRange("d_b", d_b, 0.0, 1.0);
}

void TableBuildOptions::hashInto(Hasher& hasher) const {
    hasher.value(thetaSamples).value(quadratureOrder).value(d_b);
}

std::ostream& operator<<(std::ostream& os, const TableBuildOptions& o) {
    return os << "TableBuildOptions(thetaSamples=" << o.thetaSamples
              << ", quadratureOrder=" << o.quadratureOrder << ", d_b=" << o.d_b
              << ", threaded=" << o.threaded << ")";
}

std::ostream& operator<<(std::ostream& os, const DualScatteringTables::Sample& s) {
    os << "Sample(";
    for (std::size_t k = 0; k < kFields.size(); ++k)
        os << (k ? ", " : "") << kFields[k].name << "=" << s.*kFields[k].member;
    return os << ")";
}

std::ostream& operator<<(std::ostream& os, const DualScatteringTables& t) {
    return os << "DualScatteringTables(" << t.size() << " samples, " << t.params() << ", "
              << t.options() << ", key=" << hexDigest(t.cacheKey())
              << (t.loadedFromCache() ? ", from cache)" : ")");
}

// ---- build, lookup ------------------------------------------------------------

DualScatteringTables DualScatteringTables::build(const FiberParams& params,
                                                 const TableBuildOptions& options) {
    params.validate();
    options.validate();
    DualScatteringTables t;
    t.params_ = params;
    t.options_ = options;
    t.cacheKey_ = computeCacheKey(params, options);
    const auto n = static_cast<std::size_t>(options.thetaSamples);
    t.rows_.resize(n);
    t.ng_.resize(n * std::size_t(kNGPhi));
    t.invStep_ = static_cast<float>(double(n - 1) / Pi);
    t.lastIndex_ = static_cast<float>(n - 1);

    const GaussLegendre gl(options.quadratureOrder), eccentricGl(kEccentricOrder);
    // Rows are independent, so the result does not depend on the thread count.
    const auto buildRows = [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k) {
            throwIfInterrupted();
            const double theta = double(t.theta(static_cast<int>(k)));
            t.rows_[k] = buildRow(params, options, theta, gl, eccentricGl);
            buildNG(params, theta, gl, eccentricGl, &t.ng_[k * std::size_t(kNGPhi)]);
        }
    };
    if (options.threaded)
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, n, 1),
            [&](const tbb::blocked_range<std::size_t>& r) { buildRows(r.begin(), r.end()); });
    else
        buildRows(0, n);
    return t;
}

float DualScatteringTables::theta(int k) const {
    return static_cast<float>(-PiOver2 + Pi * double(k) / double(rows_.size() - 1));
}

Sample DualScatteringTables::lookup(float theta) const {
    Sample s;
    for (const Field& f : kFields)
        s.*f.member = interpolate(theta, f.member);
    return s;
}

LobeValues DualScatteringTables::NG(float theta_d, float phi) const {
    const auto [k, t] = locate(theta_d);
    float x = std::abs(wrapAngle(phi)) * float(double(kNGPhi - 1) / Pi);
    x = x > 0 ? std::min(x, float(kNGPhi - 1)) : 0.0f; // !(x > 0) also catches NaN
    const int j = std::min(static_cast<int>(x), kNGPhi - 2);
    const float s = x - float(j);
    const int row = static_cast<int>(k);
    const LobeValues& a0 = NGSample(row, j);
    const LobeValues& a1 = NGSample(row, j + 1);
    const LobeValues& b0 = NGSample(row + 1, j);
    const LobeValues& b1 = NGSample(row + 1, j + 1);
    LobeValues v;
    for (Lobe p : kLobes) {
        const Rgb a = a0[p] + s * (a1[p] - a0[p]), b = b0[p] + s * (b1[p] - b0[p]);
        v[p] = a + t * (b - a);
    }
    return v;
}

namespace detail {

DualScatteringTablesView tablesView(const DualScatteringTables& tables) {
    // The kernel reads Sample and LobeValues as arrays of floats.
    using Sample = DualScatteringTables::Sample;
    constexpr auto floats = [](std::size_t bytes) { return static_cast<int>(bytes / sizeof(float)); };
    static_assert(floats(sizeof(Sample)) == kSampleFloats && floats(sizeof(LobeValues)) == kLobeRows);
    static_assert(floats(offsetof(Sample, ABar_b)) == kSampleABar_b &&
                  floats(offsetof(Sample, DeltaBar_b)) == kSampleDeltaBar_b &&
                  floats(offsetof(Sample, sigma2Bar_b)) == kSampleSigma2Bar_b);
    static_assert(DualScatteringTables::kNGPhiSamples == kNGPhiNodes);
    DualScatteringTablesView v;
    v.rows = &tables.rows_.front().aBar_f.r;
    v.ng = &tables.ng_.front().R.r;
    v.rowCount = static_cast<int>(tables.rows_.size());
    v.invStep = tables.invStep_;
    v.lastIndex = tables.lastIndex_;
    return v;
}

} // namespace detail

DualScatteringTables DualScatteringTables::withBackwardDensity(float d_b) const {
    DualScatteringTables t = *this;
    t.options_.d_b = d_b;
    t.options_.validate();
    t.cacheKey_ = computeCacheKey(t.params_, t.options_);
    t.loadedFromCache_ = false;
    for (Sample& s : t.rows_)
        for (int c = 0; c < 3; ++c)
            s.sigma2Bar_b[c] = static_cast<float>(
                sigma2Bar_b(s.aBar_f[c], s.aBar_b[c], s.beta2Bar_f[c], s.beta2Bar_b[c], d_b));
    return t;
}

// ---- CSV and cache files ------------------------------------------------------

void DualScatteringTables::writeCsv(const fs::path& path) const {
    writeFileAtomically(path, [&](const fs::path& tmp) {
        std::ofstream out(tmp);
        out << "theta";
        for (const Field& f : kFields)
            for (const char* ch : {"_r", "_g", "_b"})
                out << ',' << f.name << ch;
        for (const char* lobe : {"NGR", "NGTT", "NGTRT"})
            for (int j = 0; j < kNGPhi; ++j)
                for (const char* ch : {"_r", "_g", "_b"})
                    out << ',' << lobe << "_phi" << std::setw(3) << std::setfill('0')
                        << (180 * j) / (kNGPhi - 1) << ch;
        out << '\n';
        out.precision(9);
        for (int k = 0; k < size(); ++k) {
            out << theta(k);
            for (const Field& f : kFields) {
                const Rgb& v = sample(k).*f.member;
                out << ',' << v.r << ',' << v.g << ',' << v.b;
            }
            for (Lobe p : kLobes)
                for (int j = 0; j < kNGPhi; ++j) {
                    const Rgb& v = NGSample(k, j)[p];
                    out << ',' << v.r << ',' << v.g << ',' << v.b;
                }
            out << '\n';
        }
        out.flush();
        if (!out)
            throw InputError(strCat(path.string(), ": cannot write the CSV file"));
    });
}

/// Binary cache layout (host byte order; a cache is local to the machine):
/// magic[8], u32 format version, u32 θ samples, u64 key, f32 rows[n][27 +
/// 37·9] (the fields, then N^G per φ and lobe), u64 checksum of everything
/// before it.
struct TableIo {
    static constexpr std::size_t kHeaderSize = 8 + 4 + 4 + 8;

    static std::vector<unsigned char> serialize(const DualScatteringTables& t) {
        const auto n = static_cast<std::uint32_t>(t.rows_.size());
        std::vector<unsigned char> bytes(kHeaderSize + n * kFloatsPerRow * 4 + 8);
        unsigned char* p = bytes.data();
        const auto put = [&p](const void* data, std::size_t size) {
            std::memcpy(p, data, size);
            p += size;
        };
        put(kMagic, 8);
        put(&kFormatVersion, 4);
        put(&n, 4);
        put(&t.cacheKey_, 8);
        const auto putRgb = [&](const Rgb& v) {
            put(&v.r, 4);
            put(&v.g, 4);
            put(&v.b, 4);
        };
        for (int k = 0; k < t.size(); ++k) {
            for (const Field& f : kFields)
                putRgb(t.sample(k).*f.member);
            for (int j = 0; j < kNGPhi; ++j)
                for (Lobe lobe : kLobes)
                    putRgb(t.NGSample(k, j)[lobe]);
        }
        const std::uint64_t checksum =
            Hasher().bytes(bytes.data(), static_cast<std::size_t>(p - bytes.data())).digest();
        put(&checksum, 8);
        return bytes;
    }

    /// The tables in `path` if it is a complete, uncorrupted file for exactly these inputs.
    static std::optional<DualScatteringTables> load(const fs::path& path, const FiberParams& params,
                                                    const TableBuildOptions& options) {
        std::ifstream in(path, std::ios::binary);
        if (!in)
            return std::nullopt;
        std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                         std::istreambuf_iterator<char>());
        const auto n = static_cast<std::size_t>(options.thetaSamples);
        if (bytes.size() != kHeaderSize + n * kFloatsPerRow * 4 + 8)
            return std::nullopt;
        const unsigned char* p = bytes.data();
        std::uint32_t version = 0, count = 0;
        std::uint64_t key = 0, checksum = 0;
        std::memcpy(&version, p + 8, 4);
        std::memcpy(&count, p + 12, 4);
        std::memcpy(&key, p + 16, 8);
        std::memcpy(&checksum, p + bytes.size() - 8, 8);
        const std::uint64_t expectedKey = computeCacheKey(params, options);
        if (std::memcmp(p, kMagic, 8) != 0 || version != kFormatVersion || count != n ||
            key != expectedKey || Hasher().bytes(p, bytes.size() - 8).digest() != checksum)
            return std::nullopt;

        DualScatteringTables t;
        t.params_ = params;
        t.options_ = options;
        t.cacheKey_ = key;
        t.rows_.resize(n);
        t.ng_.resize(n * std::size_t(kNGPhi));
        t.invStep_ = static_cast<float>(double(n - 1) / Pi);
        t.lastIndex_ = static_cast<float>(n - 1);
        p += kHeaderSize;
        const auto getRgb = [&p](Rgb& v) {
            std::memcpy(&v.r, p, 4);
            std::memcpy(&v.g, p + 4, 4);
            std::memcpy(&v.b, p + 8, 4);
            p += 12;
            return v.isFinite();
        };
        for (std::size_t k = 0; k < n; ++k) {
            for (const Field& f : kFields)
                if (!getRgb(t.rows_[k].*f.member))
                    return std::nullopt;
            for (std::size_t j = 0; j < std::size_t(kNGPhi); ++j)
                for (Lobe lobe : kLobes)
                    if (!getRgb(t.ng_[k * std::size_t(kNGPhi) + j][lobe]))
                        return std::nullopt;
        }
        return t;
    }
};

fs::path DualScatteringTables::cacheFile(const fs::path& cacheDir, const FiberParams& params,
                                         const TableBuildOptions& options) {
    return cacheDir /
           strCat("dual-scattering-", hexDigest(computeCacheKey(params, options)), ".bin");
}

DualScatteringTables DualScatteringTables::loadOrBuild(const FiberParams& params,
                                                       const fs::path& cacheDir,
                                                       const TableBuildOptions& options) {
    params.validate();
    options.validate();
    const fs::path path = cacheFile(cacheDir, params, options);
    if (std::optional<DualScatteringTables> cached = TableIo::load(path, params, options)) {
        cached->loadedFromCache_ = true;
        return std::move(*cached);
    }
    DualScatteringTables t = build(params, options);
    try {
        const std::vector<unsigned char> bytes = TableIo::serialize(t);
        writeFileAtomically(path, [&](const fs::path& tmp) {
            std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
            out.write(reinterpret_cast<const char*>(bytes.data()),
                      static_cast<std::streamsize>(bytes.size()));
            out.flush();
            if (!out)
                throw InputError(strCat(path.string(), ": cannot write"));
        });
    } catch (const InputError& e) {
        // The tables are valid; only the next run will have to rebuild them.
        std::cerr << "hairvox: warning: table cache not written: " << e.what() << "\n";
    }
    return t;
}

fs::path defaultTableCacheDir() {
    if (const char* dir = std::getenv("HAIRVOX_CACHE_DIR"); dir && *dir)
        return dir;
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
        return fs::path(xdg) / "hairvox";
    if (const char* home = std::getenv("HOME"); home && *home)
        return fs::path(home) / ".cache" / "hairvox";
    return fs::temp_directory_path() / "hairvox-cache";
}

} // namespace hairvox
