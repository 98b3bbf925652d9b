#include <hairvox/core/gauss_legendre.h>
#include "shade_kernel.h"

#include <hairvox/core/math.h>
#include <hairvox/shading/azimuthal.h>
#include <hairvox/shading/marschner.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <vector>

namespace hairvox {

namespace {

constexpr float kPi = static_cast<float>(Pi);
constexpr float kPiOver2 = static_cast<float>(PiOver2);

/// cos θ_d samples over [0, 1], uniform as in Tungsten's azimuthal tables:
/// N_p is smooth in cos θ_d up to the end-on limit (TT and TRT vanish as
/// (1 − F)² ~ cos²θ_d there), where a uniform θ_d grid is too coarse. The TRT
/// caustic azimuth moves ~0.7° per step where it moves fastest.
constexpr int kCosThetaSamples = 91;
/// φ steps at most 1°, and at most w_c/5 so that the narrowest caustic lobe
/// (w_c = 1°) is interpolated to ~1% at its peak.
int phiSamples(float causticWidth) {
    const double step = std::min(radians(1.0), 0.2 * double(causticWidth));
    return static_cast<int>(std::ceil(Pi / step)) + 1;
}
/// θ samples of the lobe albedo tables (the lobe selection weights of sample()).
constexpr int kAlbedoSamples = 91;
/// Share of sample()'s φ density that is uniform: keeps it positive wherever
/// f_s is, whatever the proposal rows miss.
constexpr float kUniformPhiShare = 0.02f;

/// Φ⁻¹(p), the standard normal quantile, p ∈ (0, 1): Acklam's rational
/// approximation (relative error 1.2e-9) refined by one Halley step on erfc.
double inverseNormalCdf(double p) {
    static constexpr double a[6] = {-3.969683028665376e+01, 2.209460984245205e+02,
                                    -2.759285104469687e+02, 1.383577518672690e+02,
                                    -3.066479806614716e+01, 2.506628277459239e+00};
    static constexpr double b[5] = {-5.447609879822406e+01, 1.615858368580409e+02,
                                    -1.556989798598866e+02, 6.680131188771972e+01,
                                    -1.328068155288572e+01};
    static constexpr double c[6] = {-7.784894002430293e-03, -3.223964580411365e-01,
                                    -2.400758277161838e+00, -2.549732539343734e+00,
                                    4.374664141464968e+00,  2.938163982698783e+00};
    static constexpr double d[4] = {7.784695709041462e-03, 3.224671290700398e-01,
                                    2.445134137142996e+00, 3.754408661907416e+00};
    constexpr double low = 0.02425;
    p = std::clamp(p, 1e-300, 1.0 - 1e-16);
    double x;
    if (p < low || p > 1 - low) {
        const double q = std::sqrt(-2 * std::log(p < low ? p : 1 - p));
        x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
        if (p > 1 - low)
            x = -x;
    } else {
        const double q = p - 0.5, r = q * q;
        x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
            (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
    }
    const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
    const double u = e * Sqrt2Pi * std::exp(0.5 * x * x);
    return x - u / (1 + 0.5 * x * u);
}

/// Standard normal CDF Φ(z) and its complement Q(z) = 1 − Φ(z), each without cancellation.
double normalCdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }
double normalTail(double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); }

/// cos 2φ_h samples for eccentric fibers (η* is linear in cos 2φ_h). TRT moves
/// its caustics with η*: 33 samples keep its L1 error over φ below 0.2% for
/// a = 0.85 and 2.5% for a = 0.5 (9 samples: 2.6% and 25%).
constexpr int kEccentricSamples = 33;

} // namespace

std::ostream& operator<<(std::ostream& os, const LobeValues& v) {
    return os << "LobeValues(R=" << v.R << ", TT=" << v.TT << ", TRT=" << v.TRT << ")";
}

FiberAngles FiberAngles::fromDirections(const Vec3f& wi, const Vec3f& wo, const Vec3f& u) {
    // A point through the kernel: the renderer's batches run the same code.
    const std::array<float, detail::kDirectionRows> in{wi.x, wi.y, wi.z, wo.x, wo.y,
                                                       wo.z, u.x,  u.y,  u.z};
    std::array<float, detail::kAngleRows> out;
    detail::anglesFromDirection(in.data(), out.data());
    return std::bit_cast<FiberAngles>(out);
}

FiberAngles FiberAngles::fromAngles(float theta_i, float theta_o, float phi, float phi_h) {
    FiberAngles a;
    a.theta_i = std::clamp(theta_i, -kPiOver2, kPiOver2);
    a.theta_o = std::clamp(theta_o, -kPiOver2, kPiOver2);
    a.sinTheta_i = std::sin(a.theta_i);
    a.sinTheta_o = std::sin(a.theta_o);
    a.cosTheta_i = cosFromSin(a.sinTheta_i);
    a.cosTheta_o = cosFromSin(a.sinTheta_o);
    a.theta_h = 0.5f * (a.theta_i + a.theta_o);
    a.theta_d = 0.5f * (a.theta_o - a.theta_i);
    a.cos2Theta_d = std::max(
        0.5f * (1.0f + a.cosTheta_i * a.cosTheta_o + a.sinTheta_i * a.sinTheta_o), kMinCos2Theta_d);
    a.phi = wrapAngle(phi);
    a.cosPhi = std::cos(a.phi);
    a.cos2Phi_h = std::cos(2.0f * phi_h);
    return a;
}

std::ostream& operator<<(std::ostream& os, const FiberAngles& a) {
    return os << "FiberAngles(theta_i=" << degrees(a.theta_i)
              << "deg, theta_o=" << degrees(a.theta_o) << "deg, phi=" << degrees(a.phi)
              << "deg, cos2Phi_h=" << a.cos2Phi_h << ")";
}

/// N_p sampled on a regular grid: R and TT interleaved (4 floats per node),
/// TRT separately because only it depends on cos 2φ_h.
struct MarschnerBcsdf::AzimuthalTable {
    int thetaCount = 0, phiCount = 0, eccCount = 0;
    float phiScale = 0;     ///< grid index per radian of φ
    std::vector<float> rtt; ///< [cos θ_d][φ][R, TT.r, TT.g, TT.b]
    std::vector<float> trt; ///< [cos θ_d][cos 2φ_h][φ][r, g, b]

    explicit AzimuthalTable(const FiberParams& params)
        : thetaCount(kCosThetaSamples)
        , phiCount(phiSamples(params.causticWidth))
        , eccCount(params.eccentricity == 1.0f ? 1 : kEccentricSamples)
        , phiScale(static_cast<float>((phiCount - 1) / Pi)) {
        const auto nTheta = static_cast<std::size_t>(thetaCount);
        const auto nPhi = static_cast<std::size_t>(phiCount);
        const auto nEcc = static_cast<std::size_t>(eccCount);
        rtt.resize(nTheta * nPhi * 4);
        trt.resize(nTheta * nEcc * nPhi * 3);
        // Every node is independent: the result does not depend on the thread count.
        tbb::parallel_for(std::size_t(0), nTheta, [&](std::size_t i) {
            const double theta_d = std::acos(double(i) / double(nTheta - 1));
            for (std::size_t j = 0; j < nPhi; ++j) {
                const double phi = Pi * double(j) / double(nPhi - 1);
                const Rgbd r = azimuthal::N(0, params, theta_d, phi);
                const Rgbd tt = azimuthal::N(1, params, theta_d, phi);
                float* node = &rtt[(i * nPhi + j) * 4];
                node[0] = static_cast<float>(r.r);
                node[1] = static_cast<float>(tt.r);
                node[2] = static_cast<float>(tt.g);
                node[3] = static_cast<float>(tt.b);
                for (std::size_t k = 0; k < nEcc; ++k) {
                    const double cos2Phi_h =
                        nEcc == 1 ? 1.0 : -1.0 + 2.0 * double(k) / double(nEcc - 1);
                    const Rgbd trtValue = azimuthal::N(2, params, theta_d, phi, cos2Phi_h);
                    float* t = &trt[((i * nEcc + k) * nPhi + j) * 3];
                    t[0] = static_cast<float>(trtValue.r);
                    t[1] = static_cast<float>(trtValue.g);
                    t[2] = static_cast<float>(trtValue.b);
                }
            }
        });
    }

    LobeValues lookup(float cosTheta_d, float phi, float cos2Phi_h) const {
        // Grid coordinates; !(x > 0) also maps NaN to the first node.
        const auto coordinate = [](float x, float maxIndex, int& index, float& frac) {
            x = x > 0 ? std::min(x, maxIndex) : 0.0f;
            index = std::min(static_cast<int>(x), static_cast<int>(maxIndex) - 1);
            frac = x - static_cast<float>(index);
        };
        int i, j;
        float fx, fy;
        coordinate(cosTheta_d * static_cast<float>(thetaCount - 1),
                   static_cast<float>(thetaCount - 1), i, fx);
        coordinate(std::abs(phi) * phiScale, static_cast<float>(phiCount - 1), j, fy);
        const float w00 = (1 - fx) * (1 - fy), w01 = (1 - fx) * fy;
        const float w10 = fx * (1 - fy), w11 = fx * fy;
        const auto nPhi = static_cast<std::size_t>(phiCount);
        const auto ui = static_cast<std::size_t>(i), uj = static_cast<std::size_t>(j);

        LobeValues v;
        const float* a = &rtt[(ui * nPhi + uj) * 4];
        const float* b = a + nPhi * 4;
        const auto bilinear4 = [&](int c) {
            const auto uc = static_cast<std::size_t>(c);
            return w00 * a[uc] + w01 * a[uc + 4] + w10 * b[uc] + w11 * b[uc + 4];
        };
        v.R = Rgb(bilinear4(0));
        v.TT = Rgb(bilinear4(1), bilinear4(2), bilinear4(3));

        const auto trtSlice = [&](std::size_t k) {
            const auto nEcc = static_cast<std::size_t>(eccCount);
            const float* c = &trt[((ui * nEcc + k) * nPhi + uj) * 3];
            const float* d = c + nEcc * nPhi * 3;
            Rgb s;
            for (int ch = 0; ch < 3; ++ch) {
                const auto uc = static_cast<std::size_t>(ch);
                s[ch] = w00 * c[uc] + w01 * c[uc + 3] + w10 * d[uc] + w11 * d[uc + 3];
            }
            return s;
        };
        if (eccCount == 1) {
            v.TRT = trtSlice(0);
        } else {
            int k;
            float fz;
            coordinate(0.5f * (cos2Phi_h + 1.0f) * static_cast<float>(eccCount - 1),
                       static_cast<float>(eccCount - 1), k, fz);
            const auto uk = static_cast<std::size_t>(k);
            v.TRT = (1 - fz) * trtSlice(uk) + fz * trtSlice(uk + 1);
        }
        return v;
    }
};


/// What sample() draws from: per lobe and cos θ_d row of the N_p table, the
/// proposal density over |φ| ∈ [0, π] (the mean of N_p over RGB — and, for
/// eccentric TRT, over the cross-section orientations — linear between the
/// table's φ nodes) with its running integral; per lobe, the albedo A_p(θ).
struct MarschnerBcsdf::SamplingTables {
    int thetaCount = 0, phiCount = 0;
    float phiStep = 0;
    /// [lobe][row][φ node]: density nodes, and ∫_0^{φ_j} of the linear interpolant.
    std::array<std::vector<float>, 3> density, cdf;
    /// [lobe][θ sample]: A_p(θ) over θ ∈ [−π/2, π/2].
    std::array<std::vector<float>, 3> albedo;

    SamplingTables(const AzimuthalTable& table, const MarschnerBcsdf& bcsdf)
        : thetaCount(table.thetaCount), phiCount(table.phiCount),
          phiStep(static_cast<float>(Pi / (table.phiCount - 1))) {
        const auto nTheta = static_cast<std::size_t>(thetaCount);
        const auto nPhi = static_cast<std::size_t>(phiCount);
        const auto nEcc = static_cast<std::size_t>(table.eccCount);
        for (std::size_t p = 0; p < 3; ++p) {
            density[p].assign(nTheta * nPhi, 0.0f);
            cdf[p].assign(nTheta * nPhi, 0.0f);
        }
        for (std::size_t i = 0; i < nTheta; ++i)
            for (std::size_t j = 0; j < nPhi; ++j) {
                const float* rtt = &table.rtt[(i * nPhi + j) * 4];
                density[0][i * nPhi + j] = rtt[0];
                density[1][i * nPhi + j] = (rtt[1] + rtt[2] + rtt[3]) / 3.0f;
                float trt = 0;
                for (std::size_t k = 0; k < nEcc; ++k) {
                    const float* t = &table.trt[((i * nEcc + k) * nPhi + j) * 3];
                    trt += (t[0] + t[1] + t[2]) / 3.0f;
                }
                density[2][i * nPhi + j] = trt / static_cast<float>(nEcc);
            }
        for (std::size_t p = 0; p < 3; ++p)
            for (std::size_t i = 0; i < nTheta; ++i) {
                const float* n = &density[p][i * nPhi];
                float* c = &cdf[p][i * nPhi];
                for (std::size_t j = 1; j < nPhi; ++j)
                    c[j] = c[j - 1] + 0.5f * phiStep * (n[j - 1] + n[j]);
            }
        // A_p(θ_o) = ∫ cos²θ_i M_p(θ_h)/cos²θ_d · Ī_p(cos θ_d) dθ_i with
        // Ī_p = ∫_{−π}^{π} N_p dφ, split at the lobe's peak θ_i = 2α_p − θ_o.
        const quadrature::GaussLegendre gl(32);
        for (std::size_t p = 0; p < 3; ++p) {
            albedo[p].resize(kAlbedoSamples);
            const auto lobe = static_cast<Lobe>(p);
            for (int k = 0; k < kAlbedoSamples; ++k) {
                const double theta_o = -PiOver2 + Pi * k / (kAlbedoSamples - 1);
                const double peak =
                    std::clamp(2.0 * double(bcsdf.alpha(lobe)) - theta_o, -PiOver2, PiOver2);
                const auto integrand = [&](double theta_i) {
                    const double theta_d = 0.5 * (theta_o - theta_i);
                    const double cosI = std::cos(theta_i), cosD = std::cos(theta_d);
                    const double m =
                        double(bcsdf.M(lobe, static_cast<float>(0.5 * (theta_o + theta_i))));
                    return cosI * cosI * m / (cosD * cosD) * 2.0 *
                           rowIntegral(p, static_cast<float>(cosD));
                };
                double a = 0;
                for (const auto& [lo, hi] : {std::pair{-PiOver2, peak}, std::pair{peak, PiOver2}})
                    if (hi > lo)
                        a += gl.integrate<double>(lo, hi, integrand);
                albedo[p][static_cast<std::size_t>(k)] = static_cast<float>(a);
            }
        }
    }

    /// The rows around cos θ_d and the second one's weight.
    void rows(float cosTheta_d, std::size_t& row, float& t) const {
        float x = cosTheta_d * static_cast<float>(thetaCount - 1);
        x = x > 0 ? std::min(x, static_cast<float>(thetaCount - 1)) : 0.0f;
        row = std::min(static_cast<std::size_t>(x), static_cast<std::size_t>(thetaCount - 2));
        t = x - static_cast<float>(row);
    }
    float total(std::size_t p, std::size_t row) const {
        return cdf[p][(row + 1) * static_cast<std::size_t>(phiCount) - 1];
    }
    /// ∫_0^π of the proposal at cos θ_d (interpolated between rows).
    double rowIntegral(std::size_t p, float cosTheta_d) const {
        std::size_t row;
        float t;
        rows(cosTheta_d, row, t);
        return double(1 - t) * double(total(p, row)) + double(t) * double(total(p, row + 1));
    }
    /// Density over |φ| ∈ [0, π] of one row (uniform where the row is empty).
    float rowDensity(std::size_t p, std::size_t row, float absPhi) const {
        const float I = total(p, row);
        if (!(I > 0))
            return static_cast<float>(InvPi);
        float x = std::min(absPhi / phiStep, static_cast<float>(phiCount - 1));
        const auto j =
            std::min(static_cast<std::size_t>(x), static_cast<std::size_t>(phiCount - 2));
        x -= static_cast<float>(j);
        const float* n = &density[p][row * static_cast<std::size_t>(phiCount)];
        return ((1 - x) * n[j] + x * n[j + 1]) / I;
    }
    /// Inverts one row's CDF at u ∈ [0, 1): |φ| ∈ [0, π].
    float sampleRow(std::size_t p, std::size_t row, float u) const {
        const auto nPhi = static_cast<std::size_t>(phiCount);
        const float I = total(p, row);
        if (!(I > 0))
            return u * static_cast<float>(Pi);
        const float* c = &cdf[p][row * nPhi];
        const float* n = &density[p][row * nPhi];
        const float target = u * I;
        const std::size_t j =
            std::min(static_cast<std::size_t>(std::upper_bound(c, c + nPhi, target) - c), nPhi - 1) -
            1;
        // Within [φ_j, φ_j + Δ] the density is a + (b − a)x, x ∈ [0, 1]: solve
        // Δ(a x + (b − a)x²/2) = target − c_j for x.
        const float a = n[j], b = n[j + 1], r = (target - c[j]) / phiStep;
        float x;
        if (std::abs(b - a) < 1e-6f * std::max(a, b))
            x = a > 0 ? r / a : 0.5f;
        else
            x = (-a + std::sqrt(std::max(a * a + 2 * (b - a) * r, 0.0f))) / (b - a);
        return (static_cast<float>(j) + std::clamp(x, 0.0f, 1.0f)) * phiStep;
    }
};

MarschnerBcsdf::MarschnerBcsdf(const FiberParams& params)
    : params_(params) {
    params_.validate();
    alpha_ = {params.alpha_R, -0.5f * params.alpha_R, -1.5f * params.alpha_R};
    beta_ = {params.beta_R, 0.5f * params.beta_R, 2.0f * params.beta_R};
    for (std::size_t p = 0; p < 3; ++p)
        M_[p] = LongitudinalLobe(alpha_[p], beta_[p] * beta_[p]);
    table_ = std::make_shared<const AzimuthalTable>(params_);
    sampling_ = std::make_shared<const SamplingTables>(*table_, *this);
}

float MarschnerBcsdf::M(Lobe p, float theta_h) const {
    return M_[static_cast<std::size_t>(p)](theta_h);
}

LobeValues MarschnerBcsdf::N(float theta_d, float phi, float cos2Phi_h) const {
    return table_->lookup(std::cos(theta_d), phi, cos2Phi_h);
}

LobeValues MarschnerBcsdf::NExact(double theta_d, double phi, double cos2Phi_h) const {
    LobeValues v;
    for (Lobe p : kLobes)
        v[p] = Rgb(azimuthal::N(static_cast<int>(p), params_, theta_d, phi, cos2Phi_h));
    return v;
}

LobeValues MarschnerBcsdf::withLongitudinal(LobeValues n, const FiberAngles& a) const {
    const float invCos2Theta_d = 1.0f / a.cos2Theta_d;
    for (Lobe p : kLobes)
        n[p] *= M(p, a.theta_h) * invCos2Theta_d;
    return n;
}

LobeValues MarschnerBcsdf::eval(const FiberAngles& a) const {
    const auto in = std::bit_cast<std::array<float, detail::kAngleRows>>(a);
    std::array<float, detail::kLobeRows> out;
    detail::evalMarschner(detail::marschnerView(*this), in.data(), out.data());
    return std::bit_cast<LobeValues>(out);
}

namespace detail {

MarschnerView marschnerView(const MarschnerBcsdf& bcsdf) {
    MarschnerView v;
    for (std::size_t p = 0; p < 3; ++p) {
        v.alpha[p] = bcsdf.alpha_[p];
        v.variance[p] = bcsdf.beta_[p] * bcsdf.beta_[p];
        v.scale[p] = bcsdf.M_[p].scale();
        v.invTwoVariance[p] = bcsdf.M_[p].invTwoVariance();
    }
    const MarschnerBcsdf::AzimuthalTable& t = *bcsdf.table_;
    v.N = {t.rtt.data(), t.trt.data(), t.thetaCount, t.phiCount, t.eccCount, t.phiScale};
    return v;
}

} // namespace detail

LobeValues MarschnerBcsdf::evalExact(const FiberAngles& a) const {
    return withLongitudinal(NExact(a.theta_d, a.phi, a.cos2Phi_h), a);
}


float MarschnerBcsdf::lobeAlbedo(Lobe p, float theta) const {
    const std::vector<float>& a = sampling_->albedo[static_cast<std::size_t>(p)];
    float x = (theta + kPiOver2) / kPi * static_cast<float>(kAlbedoSamples - 1);
    x = x > 0 ? std::min(x, static_cast<float>(kAlbedoSamples - 1)) : 0.0f;
    const auto k = std::min(static_cast<std::size_t>(x), static_cast<std::size_t>(kAlbedoSamples - 2));
    const float t = x - static_cast<float>(k);
    return (1 - t) * a[k] + t * a[k + 1];
}

std::array<float, 3> MarschnerBcsdf::lobeWeights(float theta_o) const {
    std::array<float, 3> w;
    float sum = 0;
    for (Lobe p : kLobes)
        sum += w[static_cast<std::size_t>(p)] = std::max(lobeAlbedo(p, theta_o), 0.0f);
    for (float& x : w)
        x = sum > 0 ? x / sum : 1.0f / 3.0f;
    return w;
}

namespace {

/// θ_h of lobe (α, β) truncated to [lo, hi] (so that θ_i = 2θ_h − θ_o ∈
/// [−π/2, π/2]): its probability mass, and θ_h at quantile u. Works in the
/// tail of the side the interval lies on, so neither loses digits.
struct TruncatedLobe {
    double alpha, beta, zLo, zHi, mass;
    bool upper; ///< the interval lies above the mean: use Q(z) = 1 − Φ(z)
    double atLo; ///< Q(zLo) if upper, else Φ(zLo): where quantile() starts

    TruncatedLobe(double alpha_, double beta_, double lo, double hi)
        : alpha(alpha_)
        , beta(beta_)
        , zLo((lo - alpha_) / beta_)
        , zHi((hi - alpha_) / beta_)
        , upper(zLo > 0)
        , atLo(upper ? normalTail(zLo) : normalCdf(zLo)) {
        mass = upper ? atLo - normalTail(zHi) : normalCdf(zHi) - atLo;
    }
    double quantile(double u) const {
        const double z =
            upper ? -inverseNormalCdf(atLo - u * mass) : inverseNormalCdf(atLo + u * mass);
        return alpha + beta * std::clamp(z, zLo, zHi);
    }
};

/// The θ_h interval that keeps θ_i in [−π/2, π/2].
std::pair<double, double> thetaHRange(double theta_o) {
    return {0.5 * (theta_o - PiOver2), 0.5 * (theta_o + PiOver2)};
}

/// A truncated lobe with less mass than this is sampled uniformly in θ_h.
constexpr double kMinLobeMass = 1e-12;

} // namespace

float MarschnerBcsdf::pdf(const Vec3f& wi, const Vec3f& wo, const Vec3f& u) const {
    return pdf(FiberAngles::fromDirections(wi, wo, u));
}

float MarschnerBcsdf::pdf(const FiberAngles& a, Lobe lobe) const {
    if (!(a.cosTheta_i > 1e-6f))
        return 0.0f;
    const auto p = static_cast<std::size_t>(lobe);
    const auto [lo, hi] = thetaHRange(a.theta_o);
    const TruncatedLobe truncated(alpha_[p], beta_[p], lo, hi);
    // θ_i = 2θ_h − θ_o: the density in θ_i is half that in θ_h.
    const double pTheta =
        truncated.mass > kMinLobeMass
            ? 0.5 * gaussian(double(a.theta_h) - double(alpha_[p]), double(beta_[p])) / truncated.mass
            : 0.5 / (hi - lo);
    std::size_t row;
    float t;
    sampling_->rows(std::sqrt(a.cos2Theta_d), row, t);
    const float absPhi = std::abs(a.phi);
    const float pPhi = (1 - kUniformPhiShare) * 0.5f *
                           ((1 - t) * sampling_->rowDensity(p, row, absPhi) +
                            t * sampling_->rowDensity(p, row + 1, absPhi)) +
                       kUniformPhiShare * static_cast<float>(0.5 * InvPi);
    return static_cast<float>(pTheta * double(pPhi) / double(a.cosTheta_i));
}

float MarschnerBcsdf::pdf(const FiberAngles& a) const {
    const std::array<float, 3> w = lobeWeights(a.theta_o);
    float density = 0;
    for (Lobe p : kLobes)
        if (w[static_cast<std::size_t>(p)] > 0)
            density += w[static_cast<std::size_t>(p)] * pdf(a, p);
    return density;
}

BcsdfSample MarschnerBcsdf::sample(const Vec3f& wo, const Vec3f& u,
                                   const std::array<float, 4>& uniforms) const {
    BcsdfSample s;
    const float sinTheta_o = std::clamp(glm::dot(wo, u), -1.0f, 1.0f);
    const float theta_o = std::asin(sinTheta_o);
    const std::array<float, 3> w = lobeWeights(theta_o);

    // The lobe, then the sign of φ from what is left of the same uniform.
    float ul = uniforms[0];
    std::size_t p = 0;
    while (p < 2 && ul >= w[p]) {
        ul -= w[p];
        ++p;
    }
    ul = std::clamp(ul / std::max(w[p], 1e-12f), 0.0f, 1.0f);
    s.lobe = static_cast<Lobe>(p);

    // θ_i from M_p.
    const auto [lo, hi] = thetaHRange(theta_o);
    const TruncatedLobe lobe(alpha_[p], beta_[p], lo, hi);
    const double theta_h = lobe.mass > kMinLobeMass ? lobe.quantile(uniforms[1])
                                                    : lo + double(uniforms[1]) * (hi - lo);
    const double theta_i = std::clamp(2 * theta_h - double(theta_o), -PiOver2, PiOver2);
    const double cosTheta_d = std::cos(0.5 * (double(theta_o) - theta_i));

    // φ: a cos θ_d row by its interpolation weight, then |φ| from the row (or uniform).
    std::size_t row;
    float t;
    sampling_->rows(static_cast<float>(cosTheta_d), row, t);
    float absPhi;
    if (uniforms[2] < kUniformPhiShare) {
        absPhi = uniforms[3] * kPi;
    } else {
        const float uRow = (uniforms[2] - kUniformPhiShare) / (1 - kUniformPhiShare);
        absPhi = sampling_->sampleRow(p, uRow < 1 - t ? row : row + 1, uniforms[3]);
    }
    const float phi = ul < 0.5f ? absPhi : -absPhi;

    // ω_i from (θ_i, φ_i = φ_o − φ) in the frame of u (the one FiberAngles uses).
    Vec3f e1, e2;
    coordinateSystem(u, e1, e2);
    const float phi_o = std::atan2(glm::dot(wo, e2), glm::dot(wo, e1));
    const float phi_i = phi_o - phi;
    const auto cosI = static_cast<float>(std::cos(theta_i));
    const auto sinI = static_cast<float>(std::sin(theta_i));
    s.wi = glm::normalize(sinI * u + cosI * (std::cos(phi_i) * e1 + std::sin(phi_i) * e2));

    const FiberAngles a = FiberAngles::fromDirections(s.wi, wo, u);
    s.pdf = pdf(a);
    if (!(s.pdf > 0)) {
        s.wi = Vec3f(0.0f);
        s.pdf = 0;
        return s;
    }
    s.f = eval(a);
    s.weight = s.f.sum() * (a.cosTheta_i / s.pdf);
    return s;
}

MarschnerBcsdf::TableSize MarschnerBcsdf::tableSize() const {
    return {table_->thetaCount, table_->phiCount, table_->eccCount};
}

std::ostream& operator<<(std::ostream& os, const MarschnerBcsdf& b) {
    const MarschnerBcsdf::TableSize n = b.tableSize();
    return os << "MarschnerBcsdf(" << b.params() << ", N_p table " << n.theta_d << "x" << n.phi
              << "x" << n.cos2Phi_h << ")";
}

} // namespace hairvox
