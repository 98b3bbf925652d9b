#include "../test_util.h"

#include <hairvox/core/disk_cache.h>
#include <hairvox/core/error.h>
#include <hairvox/core/gauss_legendre.h>
#include <hairvox/core/math.h>
#include <hairvox/core/rng.h>
#include <hairvox/core/sampling.h>
#include <hairvox/shading/marschner.h>
#include <hairvox/volumetric/scattering_kernel.h>
#include <hairvox/volumetric/spherical_harmonics.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <vector>

namespace hairvox {
namespace {

using Y = std::array<float, SphericalHarmonics::kMaxCoefficients>;

Y harmonics(const Vec3f& w, int order) {
    Y y{};
    SphericalHarmonics::evaluate(w, order, y.data());
    return y;
}

/// ∫ f(ω) dω by a midpoint rule in (s, φ) (dω = ds dφ).
template <typename F>
void integrateSphere(int n, F&& f) {
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < 2 * n; ++b) {
            const double s = -1.0 + (a + 0.5) * 2.0 / n, phi = (b + 0.5) * Pi / n;
            const double c = std::sqrt(1.0 - s * s);
            f(Vec3f(float(c * std::cos(phi)), float(c * std::sin(phi)), float(s)),
              (2.0 / n) * (Pi / n));
        }
}

TEST(SphericalHarmonics, AreOrthonormal) {
    constexpr int L = SphericalHarmonics::kMaxOrder, nc = SphericalHarmonics::coefficients(L);
    std::vector<double> gram(std::size_t(nc * nc), 0.0);
    integrateSphere(400, [&](const Vec3f& w, double dw) {
        const Y y = harmonics(w, L);
        for (int i = 0; i < nc; ++i)
            for (int j = 0; j < nc; ++j)
                gram[std::size_t(i * nc + j)] +=
                    double(y[std::size_t(i)]) * double(y[std::size_t(j)]) * dw;
    });
    for (int i = 0; i < nc; ++i)
        for (int j = 0; j < nc; ++j)
            EXPECT_NEAR(gram[std::size_t(i * nc + j)], i == j ? 1.0 : 0.0, 2e-3) << i << ", " << j;
}

TEST(SphericalHarmonics, TheFirstBandsAreTheTextbooksOnes) {
    const Vec3f w = glm::normalize(Vec3f(0.3f, -0.5f, 0.8f));
    const Y y = harmonics(w, 2);
    const double c0 = 0.5 * std::sqrt(1.0 / Pi), c1 = std::sqrt(3.0 / (4.0 * Pi));
    EXPECT_NEAR(y[0], c0, 1e-6);
    EXPECT_NEAR(y[std::size_t(SphericalHarmonics::index(1, 0))], c1 * double(w.z), 1e-6);
    EXPECT_NEAR(y[std::size_t(SphericalHarmonics::index(1, 1))], c1 * double(w.x), 1e-6);
    EXPECT_NEAR(y[std::size_t(SphericalHarmonics::index(1, -1))], c1 * double(w.y), 1e-6);
    EXPECT_NEAR(y[std::size_t(SphericalHarmonics::index(2, 0))],
                0.25 * std::sqrt(5.0 / Pi) * (3.0 * double(w.z) * double(w.z) - 1.0), 1e-6);
}

/// SH coefficients (planar RGB, one value per channel) of a field f(ω).
std::vector<float> project(const std::function<float(const Vec3f&)>& f, int order) {
    const int nc = SphericalHarmonics::coefficients(order);
    std::vector<double> c(std::size_t(nc), 0.0);
    integrateSphere(300, [&](const Vec3f& w, double dw) {
        const Y y = harmonics(w, order);
        const double v = double(f(w)) * dw;
        for (int m = 0; m < nc; ++m)
            c[std::size_t(m)] += v * double(y[std::size_t(m)]);
    });
    std::vector<float> rgb(3 * std::size_t(nc));
    for (int ch = 0; ch < 3; ++ch)
        for (int m = 0; m < nc; ++m)
            rgb[std::size_t(ch * nc + m)] = float(c[std::size_t(m)]);
    return rgb;
}

/// ∫ f_s(u; ω_i, ω_o) cos θ_i L(ω_i) dω_i by an independent midpoint rule in
/// (θ_i, φ_i) about u on a fine grid (dω = cos θ dθ dφ).
Rgb bruteForceOutgoing(const MarschnerBcsdf& bcsdf, const Vec3f& u, const Vec3f& omega_o,
                       const std::function<float(const Vec3f&)>& L) {
    Vec3f e1, e2;
    coordinateSystem(u, e1, e2);
    const int nTheta = 480, nPhi = 480;
    Rgbd sum(0.0);
    for (int a = 0; a < nTheta; ++a) {
        const double theta = -PiOver2 + (a + 0.5) * Pi / nTheta;
        for (int b = 0; b < nPhi; ++b) {
            const double phi = -Pi + (b + 0.5) * TwoPi / nPhi;
            const Vec3f wi =
                float(std::sin(theta)) * u +
                float(std::cos(theta)) * (float(std::cos(phi)) * e1 + float(std::sin(phi)) * e2);
            const double w = std::cos(theta) * std::cos(theta) * (Pi / nTheta) * (TwoPi / nPhi);
            sum += Rgbd(bcsdf.eval(wi, omega_o, u).sum()) * (w * double(L(wi)));
        }
    }
    return Rgb(sum);
}

/// A field of SH order ≤ 2, not symmetric about any axis.
float field(const Vec3f& w) {
    return 1.0f + 0.5f * w.x - 0.3f * w.y * w.z + 0.2f * w.z * w.z;
}

TEST(ScatteringKernel, AFiberOfAnyTangentScattersTheWorldFieldAsABruteForceQuadrature) {
    FiberParams params; // light hair: every lobe matters
    params.sigma_a = FiberParams::sigmaFromMelanin(0.3f, 0.1f);
    const MarschnerBcsdf bcsdf(params);
    constexpr int L = 4;
    const ScatteringKernel kernel(bcsdf, L);
    const std::vector<float> c = project(field, L);
    // Tangents along and across the axes the field is written in: the kernel
    // is applied in each fiber's own frame.
    for (const Vec3f u : {Vec3f(0, 0, 1), glm::normalize(Vec3f(1, 0.4f, -0.3f)),
                          glm::normalize(Vec3f(-0.2f, 1, 0.7f))})
        for (const Vec3f w_o :
             {glm::normalize(Vec3f(0.3f, 0.2f, 1)), glm::normalize(Vec3f(-1, 0.5f, 0.1f))}) {
            const Rgb got = kernel.apply(c.data(), u, w_o);
            const Rgb expected = bruteForceOutgoing(bcsdf, u, w_o, field);
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(got[ch], expected[ch], 0.01f * expected[ch] + 1e-4f)
                    << "channel " << ch << ", tangent " << u << ", toward " << w_o;
        }
}

/// The evaluation the rotation replaced, kept as its oracle: ∫ P_L[K] L̄ dω by
/// the product rule of (L + 1) Gauss–Legendre nodes in s = ω·u by 2L + 1
/// equal azimuths (exact for two functions of order L), in the frame whose e₁
/// lies along ω_o's azimuth about u, where K's coefficients are the kernel's
/// fiberFrameCoefficients.
Rgb nodeOutgoing(const ScatteringKernel& kernel, const float* c, const Vec3f& u,
                 const Vec3f& omega_o) {
    const int order = kernel.order(), nc = SphericalHarmonics::coefficients(order);
    const float s_o = glm::dot(omega_o, u);
    const Vec3f e1 = glm::normalize(omega_o - s_o * u), e2 = glm::cross(u, e1);
    std::vector<float> k(3 * std::size_t(nc));
    kernel.fiberFrameCoefficients(s_o, k.data());
    const quadrature::GaussLegendre gl(order + 1);
    const int nPhi = 2 * order + 1;
    Rgbd sum(0.0);
    for (int q = 0; q < gl.order(); ++q)
        for (int p = 0; p < nPhi; ++p) {
            const double s = gl.node(q), r = std::sqrt(1.0 - s * s), phi = TwoPi * p / nPhi;
            const Vec3f local(float(r * std::cos(phi)), float(r * std::sin(phi)), float(s));
            const Y yl = harmonics(local, order),
                    yw = harmonics(local.x * e1 + local.y * e2 + local.z * u, order);
            for (int ch = 0; ch < 3; ++ch) {
                double K = 0, Lbar = 0;
                for (int i = 0; i < nc; ++i) {
                    K += double(k[std::size_t(ch * nc + i)]) * double(yl[std::size_t(i)]);
                    Lbar += double(c[ch * nc + i]) * double(yw[std::size_t(i)]);
                }
                sum[ch] += gl.weight(q) * (TwoPi / nPhi) * K * Lbar;
            }
        }
    return Rgb(sum);
}

TEST(ScatteringKernel, TheRotatedCoefficientsGiveTheNodeEvaluation) {
    FiberParams params;
    params.sigma_a = FiberParams::sigmaFromMelanin(0.3f, 0.1f);
    const MarschnerBcsdf bcsdf(params);
    Pcg32 rng(11);
    for (const int L : {3, SphericalHarmonics::kMaxOrder}) {
        const ScatteringKernel kernel(bcsdf, L);
        const int nc = SphericalHarmonics::coefficients(L);
        for (int trial = 0; trial < 24; ++trial) {
            // A random field: every coefficient of every band, about a mean of 1.
            std::vector<float> c(3 * std::size_t(nc));
            for (int ch = 0; ch < 3; ++ch)
                for (int i = 0; i < nc; ++i)
                    c[std::size_t(ch * nc + i)] = i == 0 ? 3.5f : rng.uniform(-0.3f, 0.3f);
            const Vec3f u = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
            const Vec3f w_o = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
            const Rgb got = kernel.apply(c.data(), u, w_o);
            const Rgb expected = nodeOutgoing(kernel, c.data(), u, w_o);
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(got[ch], expected[ch], 0.005f * std::abs(expected[ch]))
                    << "order " << L << ", channel " << ch << ", tangent " << u << ", toward "
                    << w_o;
        }
    }
}

// A kernel taken from the disk cache is the kernel built, float for float;
// a damaged entry is rebuilt and written again; other optics, another entry.
TEST(ScatteringKernel, TheDiskCacheGivesTheBuiltKernelAndRebuildsADamagedOne) {
    namespace fs = std::filesystem;
    test::TempDir dir;
    const DiskCache cache(dir / "cache");
    FiberParams params;
    params.sigma_a = FiberParams::sigmaFromMelanin(0.3f, 0.1f);
    constexpr int L = 3;
    const int nc = SphericalHarmonics::coefficients(L);
    const auto same = [&](const ScatteringKernel& a, const ScatteringKernel& b) {
        std::vector<float> ka(3 * std::size_t(nc)), kb(3 * std::size_t(nc));
        for (const float s_o : {-0.93f, -0.2f, 0.0f, 0.41f, 1.0f}) {
            a.fiberFrameCoefficients(s_o, ka.data());
            b.fiberFrameCoefficients(s_o, kb.data());
            if (ka != kb)
                return false;
        }
        return true;
    };
    const ScatteringKernel built(MarschnerBcsdf(params), L);
    const ScatteringKernel first = ScatteringKernel::loadOrBuild(params, L, &cache);
    const auto entries = [&] {
        std::vector<fs::path> files;
        if (fs::exists(dir / "cache" / "kernel"))
            for (const auto& e : fs::directory_iterator(dir / "cache" / "kernel"))
                files.push_back(e.path());
        return files;
    };
    ASSERT_EQ(entries().size(), 1u);
    const fs::path entry = entries()[0];
    const auto size = fs::file_size(entry);
    EXPECT_TRUE(same(first, built));
    EXPECT_TRUE(same(ScatteringKernel::loadOrBuild(params, L, &cache), built));

    fs::resize_file(entry, size / 2); // a write cut short
    EXPECT_TRUE(same(ScatteringKernel::loadOrBuild(params, L, &cache), built));
    EXPECT_EQ(fs::file_size(entry), size);

    FiberParams darker = params;
    darker.sigma_a = FiberParams::sigmaFromMelanin(1.3f, 0.1f);
    const ScatteringKernel other = ScatteringKernel::loadOrBuild(darker, L, &cache);
    EXPECT_EQ(entries().size(), 2u);
    EXPECT_FALSE(same(other, built));
    EXPECT_TRUE(same(other, ScatteringKernel(MarschnerBcsdf(darker), L)));
}

TEST(ScatteringKernel, RotatingTheFiberTheFieldAndTheViewTogetherChangesNothing) {
    FiberParams params;
    const MarschnerBcsdf bcsdf(params);
    constexpr int L = 6;
    const ScatteringKernel kernel(bcsdf, L);
    // R: a rotation by 70° about an oblique axis; the field f∘Rᵀ is f
    // turned by R, expressed in the same world basis.
    const glm::mat3 R = glm::mat3(
        glm::rotate(glm::mat4(1.0f), glm::radians(70.0f), glm::normalize(glm::vec3(1, 2, -1))));
    const auto turned = [&](const Vec3f& w) {
        return field(glm::transpose(R) * w);
    };
    const std::vector<float> c = project(field, L), cTurned = project(turned, L);
    const Vec3f u = glm::normalize(Vec3f(0.2f, 1, 0.1f)),
                w_o = glm::normalize(Vec3f(1, 0.3f, 0.4f));
    const Rgb a = kernel.apply(c.data(), u, w_o), b = kernel.apply(cTurned.data(), R * u, R * w_o);
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(a[ch], b[ch], 2e-3f * a[ch]) << "channel " << ch;
}

TEST(ScatteringKernel, InvalidOrdersNameTheKey) {
    const MarschnerBcsdf bcsdf{FiberParams{}};
    for (const int order : {0, 9})
        try {
            const ScatteringKernel k(bcsdf, order);
            FAIL() << "order " << order << " was accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("sh_order"), std::string::npos) << e.what();
        }
}

} // namespace
} // namespace hairvox
