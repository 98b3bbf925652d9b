#include <hairvox/volumetric/scattering_kernel.h>

#include <hairvox/core/gauss_legendre.h>
#include <hairvox/core/math.h>
#include <hairvox/shading/marschner.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hairvox {

namespace {

constexpr int kBinPoints = 8;    ///< Gauss–Legendre points over a bin's s
constexpr int kPhiPoints = 256;  ///< trapezoidal points over Δφ ∈ [−π, π)
/// Cross-section orientations averaged over when the fiber is eccentric
/// (cos 2φ_h uniform in the twist angle: the fiber is twisted at random).
constexpr int kTwistPoints = 4;

} // namespace

ScatteringKernel::ScatteringKernel(const MarschnerBcsdf& bcsdf, const RadianceBasis& basis,
                                   KernelLobes lobes)
    : basis_(basis) {
    basis.validate();
    const int n = basis.thetaBins, orders = basis.azimuthalOrder + 1;
    g_.assign(std::size_t(n) * std::size_t(n) * std::size_t(orders), Rgb(0.0f));
    const quadrature::GaussLegendre gl(kBinPoints);
    const bool eccentric = bcsdf.params().eccentricity != 1.0f;
    const int twists = eccentric ? kTwistPoints : 1;
    const double dPhi = TwoPi / kPhiPoints;
    tbb::parallel_for(0, n, [&](int j) {
        const auto theta_o = float(std::asin(double(basis.binCentre(j))));
        for (int i = 0; i < n; ++i) {
            const double s0 = -1.0 + i * double(basis.binWidth());
            // ∫_{bin} ds ∫ dΔφ f_s cos θ_i cos kΔφ, per k and channel.
            std::vector<Rgbd> sum(std::size_t(orders), Rgbd(0.0));
            const double half = 0.5 * double(basis.binWidth()), mid = s0 + half;
            for (int q = 0; q < gl.order(); ++q) {
                const double s = mid + half * gl.node(q);
                const auto theta_i = float(safeASin(s));
                const double w = gl.weight(q) * half * cosFromSin(s);
                for (int p = 0; p < kPhiPoints; ++p) {
                    const double phi = -Pi + (p + 0.5) * dPhi;
                    Rgbd f(0.0);
                    for (int tw = 0; tw < twists; ++tw) {
                        const double phi_h = Pi * (tw + 0.5) / twists;
                        const LobeValues v = bcsdf.eval(FiberAngles::fromAngles(
                            theta_i, theta_o, float(phi), float(phi_h)));
                        f += Rgbd(lobes == KernelLobes::All
                                      ? v.sum()
                                      : (lobes == KernelLobes::Forward ? v.TT : v.R + v.TRT));
                    }
                    f = f * (w * dPhi / twists);
                    for (int k = 0; k < orders; ++k)
                        sum[std::size_t(k)] += f * std::cos(k * phi);
                }
            }
            for (int k = 0; k < orders; ++k)
                g_[(std::size_t(j) * std::size_t(n) + std::size_t(i)) * std::size_t(orders) +
                   std::size_t(k)] = Rgb(sum[std::size_t(k)]);
        }
    });
    const int perBin = basis.coefficientsPerBin();
    expanded_.resize(3 * std::size_t(n) * std::size_t(n) * std::size_t(perBin));
    for (int c = 0; c < 3; ++c)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                for (int m = 0; m < perBin; ++m)
                    expanded_[((std::size_t(c) * std::size_t(n) + std::size_t(j)) * std::size_t(n) +
                               std::size_t(i)) *
                                  std::size_t(perBin) +
                              std::size_t(m)] = at(j, i, (m + 1) / 2)[c];
}

void ScatteringKernel::apply(std::span<const float> incident, std::span<float> outgoing) const {
    const auto n = std::size_t(basis_.thetaBins), perBin = std::size_t(basis_.coefficientsPerBin());
    const std::size_t perChannel = n * perBin;
    for (std::size_t c = 0; c < 3; ++c) {
        const float* in = incident.data() + c * perChannel;
        float* out = outgoing.data() + c * perChannel;
        for (std::size_t j = 0; j < n; ++j) {
            float* o = out + j * perBin;
            std::fill(o, o + perBin, 0.0f);
            const float* g = expanded_.data() + (c * n + j) * n * perBin;
            for (std::size_t i = 0; i < n; ++i)
                for (std::size_t m = 0; m < perBin; ++m)
                    o[m] += g[i * perBin + m] * in[i * perBin + m];
        }
    }
}

} // namespace hairvox
