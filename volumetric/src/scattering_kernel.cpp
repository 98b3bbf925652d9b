#include <hairvox/core/error.h>
#include <hairvox/core/gauss_legendre.h>
#include <hairvox/core/math.h>
#include <hairvox/shading/marschner.h>
#include <hairvox/volumetric/scattering_kernel.h>
#include <hairvox/volumetric/spherical_harmonics.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace hairvox {

namespace {

/// The projection's quadrature: Gauss–Legendre panels over s_i (M_p is a few
/// degrees wide) and the midpoint rule over the period in φ_i.
constexpr int kPanels = 64, kPanelPoints = 6, kProjectionPhi = 96;
/// Cross-section orientations averaged over when the fiber is eccentric
/// (cos 2φ_h uniform in the twist angle: the fiber is twisted at random).
constexpr int kTwistPoints = 4;

/// The point of the unit sphere at s = sin θ, azimuth (cos φ, sin φ) in the
/// frame (x, y, z) = (e₁, e₂, u).
Vec3f local(float s, float c, float cosPhi, float sinPhi) {
    return {c * cosPhi, c * sinPhi, s};
}

} // namespace

ScatteringKernel::ScatteringKernel(const MarschnerBcsdf& bcsdf, int order)
    : order_(order)
    , nodesS_(order + 1)
    , nodesPhi_(2 * order + 1) {
    if (order < 1 || order > SphericalHarmonics::kMaxOrder)
        throw InputError(strCat("volumetric: sh_order = ", order, ": expected an integer in [1, ",
                                SphericalHarmonics::kMaxOrder, "]"));
    const quadrature::GaussLegendre nodes(nodesS_);
    for (int q = 0; q < nodesS_; ++q) {
        s_.push_back(float(nodes.node(q)));
        cosTheta_.push_back(float(cosFromSin(nodes.node(q))));
    }
    for (int p = 0; p < nodesPhi_; ++p) {
        const double phi = TwoPi * p / nodesPhi_;
        cosPhi_.push_back(float(std::cos(phi)));
        sinPhi_.push_back(float(std::sin(phi)));
    }
    const int nc = SphericalHarmonics::coefficients(order);
    const quadrature::GaussLegendre panel(kPanelPoints);
    const bool eccentric = bcsdf.params().eccentricity != 1.0f;
    const int twists = eccentric ? kTwistPoints : 1;
    w_.assign(std::size_t(kRows) * std::size_t(nodesS_ * nodesPhi_), Rgb(0.0f));
    tbb::parallel_for(0, kRows, [&](int j) {
        const double s_o = -1.0 + 2.0 * j / (kRows - 1);
        const auto theta_o = float(safeASin(s_o));
        // k_lm = ∫ K Y_lm dω in the frame where φ_o = 0 (dω = ds dφ).
        std::vector<Rgbd> k(std::size_t(nc), Rgbd(0.0));
        std::array<float, SphericalHarmonics::kMaxCoefficients> y{};
        const double dPhi = TwoPi / kProjectionPhi, half = 1.0 / kPanels;
        for (int a = 0; a < kPanels; ++a) {
            const double mid = -1.0 + (2 * a + 1) * half;
            for (int g = 0; g < panel.order(); ++g) {
                const double s = mid + half * panel.node(g);
                const auto theta_i = float(safeASin(s));
                const double c = cosFromSin(s), ws = panel.weight(g) * half * dPhi;
                for (int p = 0; p < kProjectionPhi; ++p) {
                    const double phi_i = -Pi + (p + 0.5) * dPhi;
                    Rgbd f(0.0);
                    for (int tw = 0; tw < twists; ++tw) {
                        const double phi_h = Pi * (tw + 0.5) / twists;
                        f += Rgbd(bcsdf
                                      .eval(FiberAngles::fromAngles(theta_i, theta_o, float(-phi_i),
                                                                    float(phi_h)))
                                      .sum());
                    }
                    f = f * (c * ws / twists); // f_s cos θ_i ds dφ
                    SphericalHarmonics::evaluate(
                        local(float(s), float(c), float(std::cos(phi_i)), float(std::sin(phi_i))),
                        order, y.data());
                    for (int m = 0; m < nc; ++m)
                        k[std::size_t(m)] += f * double(y[std::size_t(m)]);
                }
            }
        }
        // W_jq = w_q · P_L[K_j](ω_q).
        const double wPhi = TwoPi / nodesPhi_;
        for (int q = 0; q < nodesS_; ++q)
            for (int p = 0; p < nodesPhi_; ++p) {
                SphericalHarmonics::evaluate(local(s_[std::size_t(q)], cosTheta_[std::size_t(q)],
                                                   cosPhi_[std::size_t(p)],
                                                   sinPhi_[std::size_t(p)]),
                                             order, y.data());
                Rgbd P(0.0);
                for (int m = 0; m < nc; ++m)
                    P += k[std::size_t(m)] * double(y[std::size_t(m)]);
                w_[(std::size_t(j) * std::size_t(nodesS_) + std::size_t(q)) *
                       std::size_t(nodesPhi_) +
                   std::size_t(p)] = Rgb(P * (nodes.weight(q) * wPhi));
            }
    });
}

Rgb ScatteringKernel::apply(const float* coefficients, const Vec3f& u, const Vec3f& omega_o) const {
    const float s_o = std::clamp(glm::dot(omega_o, u), -1.0f, 1.0f);
    // e₁ along ω_o's azimuth about u (any ⟂ direction when ω_o is along u).
    Vec3f e1 = omega_o - s_o * u;
    const float r = glm::length(e1);
    Vec3f e2;
    if (r > 1e-6f)
        e1 /= r;
    else
        coordinateSystem(u, e1, e2);
    e2 = glm::cross(u, e1);
    const float p = (s_o + 1.0f) * 0.5f * float(kRows - 1);
    const int j0 = std::min(int(p), kRows - 2);
    const float t = p - float(j0);
    const std::size_t perRow = std::size_t(nodesS_ * nodesPhi_);
    const Rgb* w0 = w_.data() + std::size_t(j0) * perRow;
    const Rgb* w1 = w0 + perRow;
    const int nc = SphericalHarmonics::coefficients(order_);
    std::array<float, SphericalHarmonics::kMaxCoefficients> y{};
    Rgb out(0.0f);
    for (int q = 0; q < nodesS_; ++q) {
        const Vec3f along = s_[std::size_t(q)] * u;
        const float c = cosTheta_[std::size_t(q)];
        for (int ph = 0; ph < nodesPhi_; ++ph) {
            const Vec3f omega =
                along + c * (cosPhi_[std::size_t(ph)] * e1 + sinPhi_[std::size_t(ph)] * e2);
            SphericalHarmonics::evaluate(omega, order_, y.data());
            const std::size_t i = std::size_t(q * nodesPhi_ + ph);
            const Rgb w = (1.0f - t) * w0[i] + t * w1[i];
            for (int ch = 0; ch < 3; ++ch) {
                const float* cc = coefficients + ch * nc;
                float v = 0;
                for (int m = 0; m < nc; ++m)
                    v += cc[m] * y[std::size_t(m)];
                out[ch] += w[ch] * v;
            }
        }
    }
    return out;
}

} // namespace hairvox
