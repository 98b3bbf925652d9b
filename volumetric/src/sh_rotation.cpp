#include "sh_rotation_lanes.h"

#include <hairvox/core/error.h>
#include <hairvox/core/gauss_legendre.h>
#include <hairvox/core/math.h>
#include <hairvox/volumetric/sh_rotation.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace hairvox {

namespace {

constexpr int kMaxOrder = SphericalHarmonics::kMaxOrder;
constexpr int kMaxCoefficients = SphericalHarmonics::kMaxCoefficients;

/// C_Q's non-zero entries, band by band: out[row] += value · in[col] (indices l² + l + m).
struct QuarterTurn {
    std::vector<std::uint8_t> row, col;
    std::vector<float> value;
};

/// C_Q[l](m', m) = ∫ Y_lm'(ω) Y_lm(Qω) dω, Qω = (x, z, −y): the product of two band-l
/// harmonics is a polynomial of degree 2l ≤ 16, integrated exactly by 12 Gauss–Legendre nodes in
/// z (degree 23) by 36 equal azimuths (trigonometric degree 35).
const QuarterTurn& quarterTurn() {
    static const QuarterTurn q = [] {
        constexpr int nz = 12, nphi = 36;
        const quadrature::GaussLegendre gl(nz);
        std::vector<double> m(std::size_t(kMaxCoefficients) * std::size_t(kMaxCoefficients), 0.0);
        std::array<float, kMaxCoefficients> y{}, yq{};
        for (int a = 0; a < nz; ++a) {
            const double z = gl.node(a), r = std::sqrt(1.0 - z * z);
            for (int b = 0; b < nphi; ++b) {
                const double phi = TwoPi * b / nphi, w = gl.weight(a) * TwoPi / nphi;
                const double x = r * std::cos(phi), yy = r * std::sin(phi);
                SphericalHarmonics::evaluate(Vec3f(float(x), float(yy), float(z)), kMaxOrder,
                                             y.data());
                SphericalHarmonics::evaluate(Vec3f(float(x), float(z), float(-yy)), kMaxOrder,
                                             yq.data());
                for (int l = 0; l <= kMaxOrder; ++l)
                    for (int i = l * l; i < (l + 1) * (l + 1); ++i)
                        for (int j = l * l; j < (l + 1) * (l + 1); ++j)
                            m[std::size_t(i * kMaxCoefficients + j)] +=
                                w * double(y[std::size_t(i)]) * double(yq[std::size_t(j)]);
            }
        }
        QuarterTurn out;
        for (int l = 0; l <= kMaxOrder; ++l)
            for (int i = l * l; i < (l + 1) * (l + 1); ++i)
                for (int j = l * l; j < (l + 1) * (l + 1); ++j) {
                    const double v = m[std::size_t(i * kMaxCoefficients + j)];
                    if (std::abs(v) > 1e-6) {
                        out.row.push_back(std::uint8_t(i));
                        out.col.push_back(std::uint8_t(j));
                        out.value.push_back(float(v));
                    }
                }
        return out;
    }();
    return q;
}

/// The entries of C_Q for bands ≤ order: a prefix, the entries being stored band by band.
std::size_t quarterTurnEntries(int order) {
    const QuarterTurn& q = quarterTurn();
    const auto nc = std::uint8_t(SphericalHarmonics::coefficients(order));
    std::size_t n = 0;
    while (n < q.row.size() && q.row[n] < nc)
        ++n;
    return n;
}

/// cos mθ, sin mθ for m ≤ order from cos θ, sin θ (de Moivre).
void multiples(float c, float s, int order, float* cosM, float* sinM) {
    cosM[0] = 1;
    sinM[0] = 0;
    for (int m = 1; m <= order; ++m) {
        cosM[m] = cosM[m - 1] * c - sinM[m - 1] * s;
        sinM[m] = sinM[m - 1] * c + cosM[m - 1] * s;
    }
}

} // namespace

ShFrameRotation::ShFrameRotation(const Vec3f& u, int order)
    : order_(order)
    , u_(u) {
    if (order < 1 || order > kMaxOrder)
        throw std::invalid_argument("ShFrameRotation: order outside [1, kMaxOrder]");
    const float sinB = std::sqrt(u.x * u.x + u.y * u.y), cosB = u.z;
    float cosA = 1, sinA = 0;
    if (sinB > 1e-7f) {
        cosA = u.x / sinB;
        sinA = u.y / sinB;
    }
    // F x̂ = R_z(α)(cos β, 0, −sin β), F ŷ = R_z(α) ŷ.
    e1_ = Vec3f(cosB * cosA, cosB * sinA, -sinB);
    e2_ = Vec3f(-sinA, cosA, 0);
    multiples(cosA, sinA, order, cosA_.data(), sinA_.data());
    multiples(cosB, sinB, order, cosB_.data(), sinB_.data());
}

void ShFrameRotation::apply(const float* in, float* out, int channels) const {
    // One lane of applyLanes(): the one place of the rotation's arithmetic.
    const std::size_t nc = std::size_t(SphericalHarmonics::coefficients(order_));
    alignas(64) std::array<float, 3 * kMaxCoefficients * kLanes> lanesIn{}, lanesOut;
    for (int ch = 0; ch < channels; ch += 3) {
        const int n = std::min(3, channels - ch);
        for (std::size_t i = 0; i < std::size_t(n) * nc; ++i)
            lanesIn[i * kLanes] = in[std::size_t(ch) * nc + i];
        applyLanes({this, 1}, lanesIn.data(), lanesOut.data(), n);
        for (std::size_t i = 0; i < std::size_t(n) * nc; ++i)
            out[std::size_t(ch) * nc + i] = lanesOut[i * kLanes];
    }
}

void ShFrameRotation::applyLanes(std::span<const ShFrameRotation> frames, const float* in,
                                 float* out, int channels) {
    if (frames.empty() || frames.size() > kLanes)
        throw std::invalid_argument("ShFrameRotation::applyLanes: 1 to kLanes frames");
    detail::ShLaneRotation r;
    r.order = frames[0].order_;
    const QuarterTurn& q = quarterTurn();
    static const std::array<std::size_t, kMaxOrder + 1> entries = [] {
        std::array<std::size_t, kMaxOrder + 1> n{};
        for (int l = 1; l <= kMaxOrder; ++l)
            n[std::size_t(l)] = quarterTurnEntries(l);
        return n;
    }();
    r.row = q.row.data();
    r.col = q.col.data();
    r.value = q.value.data();
    r.entries = entries[std::size_t(r.order)];
    for (std::size_t lane = 0; lane < kLanes; ++lane) {
        // Lanes past the frames rotate by the last frame (their values are not read).
        const ShFrameRotation& f = frames[std::min(lane, frames.size() - 1)];
        if (f.order_ != r.order)
            throw std::invalid_argument("ShFrameRotation::applyLanes: frames of different orders");
        for (int m = 0; m <= r.order; ++m) {
            r.cosA[m][lane] = f.cosA_[std::size_t(m)];
            r.sinA[m][lane] = f.sinA_[std::size_t(m)];
            r.cosB[m][lane] = f.cosB_[std::size_t(m)];
            r.sinB[m][lane] = f.sinB_[std::size_t(m)];
        }
    }
    detail::rotateLanes(r, in, out, channels);
}

} // namespace hairvox
