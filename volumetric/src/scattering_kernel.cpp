#include <hairvox/core/disk_cache.h>
#include <hairvox/core/error.h>
#include <hairvox/core/gauss_legendre.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/math.h>
#include <hairvox/shading/marschner.h>
#include <hairvox/volumetric/scattering_kernel.h>
#include <hairvox/volumetric/sh_rotation.h>
#include <hairvox/volumetric/spherical_harmonics.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <span>
#include <string_view>

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
    : order_(order) {
    if (order < 1 || order > SphericalHarmonics::kMaxOrder)
        throw InputError(strCat("volumetric: sh_order = ", order, ": expected an integer in [1, ",
                                SphericalHarmonics::kMaxOrder, "]"));
    const int nc = SphericalHarmonics::coefficients(order), ng = perChannel();
    const quadrature::GaussLegendre panel(kPanelPoints);
    const bool eccentric = bcsdf.params().eccentricity != 1.0f;
    const int twists = eccentric ? kTwistPoints : 1;
    g_.assign(std::size_t(kRows) * 3 * std::size_t(ng), 0.0f);
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
                // f_s is even in φ_i (above) and so are the m ≥ 0 harmonics:
                // the nodes at φ_i > 0 count twice, and the m < 0 ones (odd) vanish.
                for (int p = kProjectionPhi / 2; p < kProjectionPhi; ++p) {
                    const double phi_i = -Pi + (p + 0.5) * dPhi;
                    Rgbd f(0.0);
                    for (int tw = 0; tw < twists; ++tw) {
                        const double phi_h = Pi * (tw + 0.5) / twists;
                        f += Rgbd(bcsdf
                                      .eval(FiberAngles::fromAngles(theta_i, theta_o, float(-phi_i),
                                                                    float(phi_h)))
                                      .sum());
                    }
                    f = f * (2.0 * c * ws / twists); // f_s cos θ_i ds dφ, at ±φ_i
                    SphericalHarmonics::evaluate(
                        local(float(s), float(c), float(std::cos(phi_i)), float(std::sin(phi_i))),
                        order, y.data());
                    for (int l = 0; l <= order; ++l)
                        for (int m = 0; m <= l; ++m) {
                            const auto i = std::size_t(SphericalHarmonics::index(l, m));
                            k[i] += f * double(y[i]);
                        }
                }
            }
        }
        // G_lm = k_lm (m ≥ 0).
        float* row = g_.data() + std::size_t(j) * 3 * std::size_t(ng);
        for (int l = 0; l <= order; ++l)
            for (int m = 0; m <= l; ++m)
                for (int ch = 0; ch < 3; ++ch)
                    row[ch * ng + l * (l + 1) / 2 + m] =
                        float(k[std::size_t(SphericalHarmonics::index(l, m))][ch]);
    });
}

ScatteringKernel ScatteringKernel::loadOrBuild(const FiberParams& fiber, int order,
                                               const DiskCache* cache) {
    if (!cache || order < 1 || order > SphericalHarmonics::kMaxOrder)
        return ScatteringKernel(MarschnerBcsdf(fiber), order); // (which names a bad order)
    constexpr std::string_view kKind = "kernel";
    constexpr std::uint32_t kFormat = 1; // the layout of g_ and the projection's code
    Hasher h;
    fiber.hashInto(h);
    h.value(kFormat).value(order).value(kRows).value(kPanels).value(kPanelPoints);
    h.value(kProjectionPhi).value(kTwistPoints);
    const std::uint64_t key = h.digest();
    const std::size_t floats = std::size_t(kRows) * 3 * std::size_t(perChannel(order));
    if (const std::optional<std::vector<std::byte>> bytes = cache->load(kKind, key)) {
        if (bytes->size() == floats * sizeof(float)) {
            std::vector<float> g(floats);
            std::memcpy(g.data(), bytes->data(), bytes->size());
            return ScatteringKernel(order, std::move(g));
        }
        cache->discard(kKind, key); // intact, but not a kernel of this layout
    }
    ScatteringKernel built(MarschnerBcsdf(fiber), order);
    cache->store(kKind, key, std::as_bytes(std::span<const float>(built.g_)));
    return built;
}

void ScatteringKernel::rows(float s_o, const float*& g0, const float*& g1, float& t) const {
    const float p = (std::clamp(s_o, -1.0f, 1.0f) + 1.0f) * 0.5f * float(kRows - 1);
    const int j0 = std::min(int(p), kRows - 2);
    t = p - float(j0);
    const std::size_t perRow = 3 * std::size_t(perChannel());
    g0 = g_.data() + std::size_t(j0) * perRow;
    g1 = g0 + perRow;
}

void ScatteringKernel::fiberFrameCoefficients(float s_o, float* k) const {
    const float *g0, *g1;
    float t;
    rows(s_o, g0, g1, t);
    const int nc = SphericalHarmonics::coefficients(order_), ng = perChannel();
    for (int ch = 0; ch < 3; ++ch)
        for (int l = 0; l <= order_; ++l)
            for (int m = -l; m <= l; ++m) {
                const int i = ch * ng + l * (l + 1) / 2 + std::abs(m);
                k[ch * nc + SphericalHarmonics::index(l, m)] =
                    m < 0 ? 0.0f : (1.0f - t) * g0[i] + t * g1[i];
            }
}

Rgb ScatteringKernel::apply(const float* coefficients, const Vec3f& u, const Vec3f& omega_o) const {
    const ShFrameRotation frame(u, order_);
    std::array<float, 3 * SphericalHarmonics::kMaxCoefficients> c;
    frame.apply(coefficients, c.data(), 3);
    return applyInFrame(c.data(), frame, omega_o);
}

Rgb ScatteringKernel::applyInFrame(const float* c, const ShFrameRotation& frame,
                                   const Vec3f& omega_o) const {
    const int nc = SphericalHarmonics::coefficients(order_), ng = perChannel();
    // cos mφ_o, sin mφ_o from ω_o's azimuth about u (any when ω_o is along u: then K has no
    // m > 0 terms).
    const float x = glm::dot(omega_o, frame.e1()), y = glm::dot(omega_o, frame.e2());
    const float r = std::sqrt(x * x + y * y);
    const float cosPhi = r > 1e-7f ? x / r : 1.0f, sinPhi = r > 1e-7f ? y / r : 0.0f;
    std::array<float, SphericalHarmonics::kMaxOrder + 1> cosM, sinM;
    cosM[0] = 1;
    sinM[0] = 0;
    for (int m = 1; m <= order_; ++m) {
        cosM[std::size_t(m)] =
            cosM[std::size_t(m - 1)] * cosPhi - sinM[std::size_t(m - 1)] * sinPhi;
        sinM[std::size_t(m)] =
            sinM[std::size_t(m - 1)] * cosPhi + cosM[std::size_t(m - 1)] * sinPhi;
    }
    const float *g0, *g1;
    float t;
    rows(glm::dot(omega_o, frame.u()), g0, g1, t);
    Rgb out(0.0f);
    for (int ch = 0; ch < 3; ++ch) {
        const float* cc = c + ch * nc;
        const float* a = g0 + ch * ng;
        const float* b = g1 + ch * ng;
        float sum = 0;
        for (int l = 0; l <= order_; ++l) {
            const int gl = l * (l + 1) / 2, il = l * l + l;
            sum += ((1.0f - t) * a[gl] + t * b[gl]) * cc[il];
            for (int m = 1; m <= l; ++m)
                sum += ((1.0f - t) * a[gl + m] + t * b[gl + m]) *
                       (cc[il + m] * cosM[std::size_t(m)] + cc[il - m] * sinM[std::size_t(m)]);
        }
        out[ch] = sum;
    }
    return out;
}

} // namespace hairvox
