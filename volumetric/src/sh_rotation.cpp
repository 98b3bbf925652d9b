#include <hairvox/core/error.h>
#include <hairvox/core/gauss_legendre.h>
#include <hairvox/core/math.h>
#include <hairvox/volumetric/sh_rotation.h>

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

/// g ↦ g∘R_z(θ) in place on one expansion (see the header).
void rotateZ(float* c, int order, const float* cosM, const float* sinM) {
    for (int l = 1; l <= order; ++l)
        for (int m = 1; m <= l; ++m) {
            float& a = c[SphericalHarmonics::index(l, m)];
            float& b = c[SphericalHarmonics::index(l, -m)];
            const float cm = cosM[m], sm = sinM[m];
            const float na = a * cm + b * sm;
            b = b * cm - a * sm;
            a = na;
        }
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
    : order_(order) {
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
    const int nc = SphericalHarmonics::coefficients(order_);
    const QuarterTurn& q = quarterTurn();
    static const std::array<std::size_t, kMaxOrder + 1> entries = [] {
        std::array<std::size_t, kMaxOrder + 1> n{};
        for (int l = 1; l <= kMaxOrder; ++l)
            n[std::size_t(l)] = quarterTurnEntries(l);
        return n;
    }();
    const std::size_t n = entries[std::size_t(order_)];
    std::array<float, kMaxCoefficients> t{};
    for (int ch = 0; ch < channels; ++ch) {
        const float* c = in + ch * nc;
        float* o = out + ch * nc;
        // R_z(α), then Q.
        std::copy(c, c + nc, o);
        rotateZ(o, order_, cosA_.data(), sinA_.data());
        std::fill(t.begin(), t.begin() + nc, 0.0f);
        for (std::size_t k = 0; k < n; ++k)
            t[q.row[k]] += q.value[k] * o[q.col[k]];
        // R_z(β), then Q⁻¹ = Qᵀ.
        rotateZ(t.data(), order_, cosB_.data(), sinB_.data());
        std::fill(o, o + nc, 0.0f);
        for (std::size_t k = 0; k < n; ++k)
            o[q.col[k]] += q.value[k] * t[q.row[k]];
    }
}

} // namespace hairvox
