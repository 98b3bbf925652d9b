#include "fast_math.h"

#include <hairvox/core/math.h>
#include <hairvox/shading/azimuthal.h>
#include <hairvox/shading/marschner.h>

#include <tbb/parallel_for.h>

#include <algorithm>
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
/// cos 2φ_h samples for eccentric fibers (η* is linear in cos 2φ_h). TRT moves
/// its caustics with η*: 33 samples keep its L1 error over φ below 0.2% for
/// a = 0.85 and 2.5% for a = 0.5 (9 samples: 2.6% and 25%).
constexpr int kEccentricSamples = 33;

} // namespace

std::ostream& operator<<(std::ostream& os, const LobeValues& v) {
    return os << "LobeValues(R=" << v.R << ", TT=" << v.TT << ", TRT=" << v.TRT << ")";
}

FiberAngles FiberAngles::fromDirections(const Vec3f& wi, const Vec3f& wo, const Vec3f& u) {
    FiberAngles a;
    a.sinTheta_i = std::clamp(glm::dot(wi, u), -1.0f, 1.0f);
    a.sinTheta_o = std::clamp(glm::dot(wo, u), -1.0f, 1.0f);
    a.cosTheta_i = fast::cosFromSin(a.sinTheta_i);
    a.cosTheta_o = fast::cosFromSin(a.sinTheta_o);
    a.theta_i = fast::asin(a.sinTheta_i);
    a.theta_o = fast::asin(a.sinTheta_o);
    a.theta_h = 0.5f * (a.theta_i + a.theta_o);
    a.theta_d = 0.5f * (a.theta_o - a.theta_i);
    // cos²θ_d = (1 + cos(θ_o − θ_i))/2 without another trigonometric call.
    a.cos2Theta_d = std::max(
        0.5f * (1.0f + a.cosTheta_i * a.cosTheta_o + a.sinTheta_i * a.sinTheta_o), kMinCos2Theta_d);
    // u·(ω_i × ω_o) and ω_i·ω_o − sin θ_i sin θ_o are |ω_i⊥||ω_o⊥| sin φ and
    // |ω_i⊥||ω_o⊥| cos φ (the components along u drop out).
    const float sinPhi = glm::dot(u, glm::cross(wi, wo));
    const float cosPhi = glm::dot(wi, wo) - a.sinTheta_i * a.sinTheta_o;
    const float r2 = sinPhi * sinPhi + cosPhi * cosPhi;
    if (r2 > 0) {
        const float invR = 1.0f / std::sqrt(r2);
        a.cosPhi = std::clamp(cosPhi * invR, -1.0f, 1.0f);
        // |φ| from whichever of asin(|sin φ|), acos(cos φ) is well conditioned:
        // one asin instead of atan2, same precision.
        const bool nearHalfPi = std::abs(a.cosPhi) < 0.7f;
        const float r = fast::asin(nearHalfPi ? a.cosPhi : std::min(std::abs(sinPhi) * invR, 1.0f));
        a.phi = std::copysign(nearHalfPi ? kPiOver2 - r : (a.cosPhi > 0 ? r : kPi - r), sinPhi);
    }
    const float den = a.cosTheta_i * a.cosTheta_o;
    if (den > 0) {
        Vec3f s, t;
        coordinateSystem(u, s, t);
        a.cos2Phi_h = std::clamp(
            (glm::dot(wi, s) * glm::dot(wo, s) - glm::dot(wi, t) * glm::dot(wo, t)) / den, -1.0f,
            1.0f);
    }
    return a;
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

MarschnerBcsdf::MarschnerBcsdf(const FiberParams& params)
    : params_(params) {
    params_.validate();
    alpha_ = {params.alpha_R, -0.5f * params.alpha_R, -1.5f * params.alpha_R};
    beta_ = {params.beta_R, 0.5f * params.beta_R, 2.0f * params.beta_R};
    for (std::size_t p = 0; p < 3; ++p)
        M_[p] = LongitudinalLobe(alpha_[p], beta_[p] * beta_[p]);
    table_ = std::make_shared<const AzimuthalTable>(params_);
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
    return withLongitudinal(table_->lookup(std::sqrt(a.cos2Theta_d), a.phi, a.cos2Phi_h), a);
}

LobeValues MarschnerBcsdf::evalExact(const FiberAngles& a) const {
    return withLongitudinal(NExact(a.theta_d, a.phi, a.cos2Phi_h), a);
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
