#include "../transmittance/slab.h"

#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/core/sampling.h>
#include <hairvox/shading/marschner.h>
#include <hairvox/volumetric/radiance_cache.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

namespace hairvox {
namespace {

TEST(RadianceCache, CellsHoldTheFibersLengthAlongTheirAxis) {
    test::Slab slab;
    slab.fibers = 2000;
    const FiberGrid grid = test::splatSlab(slab, 0.002);
    RadianceCacheSettings settings;
    settings.cellVoxels = 2;
    const RadianceCache cache(grid, settings, 1ull << 30);
    ASSERT_GT(cache.cellCount(), 0u);
    double length = 0;
    for (std::size_t s = 0; s < cache.cellCount(); ++s) {
        length += double(cache.fiberLength(s));
        // Straight fibers along +x: every cell's axis is +x.
        EXPECT_NEAR(cache.frame(s).axis.x, 1.0f, 1e-4f);
    }
    // Λ summed over the cells is the groom's length (the splat keeps it).
    EXPECT_NEAR(length, double(slab.fibers) * double(slab.lengthX), 1e-4 * length);
    EXPECT_LT(cache.slotAt(Vec3f(0, 0.5f, 0)), 0);
    EXPECT_GE(cache.slotAt(Vec3f(0, 0.005f, 0)), 0);
}

TEST(RadianceCache, DepositsProjectTheIncidentField) {
    test::Slab slab;
    slab.fibers = 2000;
    const FiberGrid grid = test::splatSlab(slab, 0.002);
    RadianceCacheSettings settings;
    settings.basis.thetaBins = 8;
    settings.basis.azimuthalOrder = 2;
    RadianceCache cache(grid, settings, 1ull << 30);
    const auto slot = std::uint32_t(cache.slotAt(Vec3f(0.0f, 0.005f, 0.0f)));
    const Vec3f x = cache.cellCentre(slot);
    ASSERT_EQ(cache.slotAt(x), std::int64_t(slot));
    // A field L(ω) = 1 + 0.5 cos φ in the cell's frame, as many samples of
    // radiance × solid angle: Σ W = ∫ L dω ⇒ W = L(ω_k)·4π/N, times Λ (the
    // deposit divides the fibers' sum by the cell's fiber length).
    const FiberFrame& frame = cache.frame(slot);
    const int n = 200000;
    Pcg32 rng(1);
    const float lambda = cache.fiberLength(slot);
    for (int k = 0; k < n; ++k) {
        const Vec3f w = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
        const AzimuthalHarmonics h = AzimuthalHarmonics::of(w, frame, 2);
        const float L = 1.0f + 0.5f * h.harmonic[1];
        cache.deposit(slot, w, Rgb(L * float(4.0 * Pi) / float(n) * lambda));
    }
    for (int k = 0; k < 20; ++k) {
        const Vec3f w = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
        const AzimuthalHarmonics h = AzimuthalHarmonics::of(w, frame, 2);
        // A point at the cell's centre reads its field alone.
        const Rgb got = cache.incident(x, w);
        EXPECT_NEAR(got.r, 1.0f + 0.5f * h.harmonic[1], 0.08f) << "direction " << w;
    }
}

TEST(RadianceCache, UniformIncidentLightLeavesAsTheFibersAlbedo) {
    test::Slab slab;
    slab.fibers = 2000;
    const FiberGrid grid = test::splatSlab(slab, 0.002);
    RadianceCacheSettings settings;
    RadianceCache cache(grid, settings, 1ull << 30);
    // Every cell lit by uniform radiance 1 from every direction: a regular
    // grid of directions in the cell's frame, uniform in s = sin θ and φ.
    for (std::size_t s = 0; s < cache.cellCount(); ++s) {
        const FiberFrame& f = cache.frame(s);
        const int ns = 64, nphi = 64;
        for (int a = 0; a < ns; ++a)
            for (int b = 0; b < nphi; ++b) {
                const float z = -1.0f + (float(a) + 0.5f) * 2.0f / float(ns);
                const float phi = (float(b) + 0.5f) * float(TwoPi) / float(nphi);
                const float r = std::sqrt(1.0f - z * z);
                const Vec3f w = z * f.axis + r * (std::cos(phi) * f.e1 + std::sin(phi) * f.e2);
                cache.deposit(std::uint32_t(s), w,
                              Rgb(float(4.0 * Pi) / float(ns * nphi) * cache.fiberLength(s)));
            }
    }
    FiberParams fiber;
    const MarschnerBcsdf bcsdf(fiber);
    std::vector<ScatteringKernel> kernels;
    kernels.emplace_back(bcsdf, settings.basis, KernelLobes::Backward);
    kernels.emplace_back(bcsdf, settings.basis, KernelLobes::Forward);
    cache.finish(kernels);
    // ∫ f_s cos θ_i dω_i, the fiber's albedo toward ω_o (reciprocity), by a
    // midpoint rule over (θ_i, φ) (dω = cos θ dθ dφ).
    for (const Vec3f w : {Vec3f(0, 1, 0), glm::normalize(Vec3f(0.5f, 1, 0)),
                          glm::normalize(Vec3f(-0.7f, 0, 1))}) {
        const Rgb out = cache.outgoing(Vec3f(0.0f, 0.005f, 0.0f), Vec3f(1, 0, 0), w, 0);
        const float theta_o = std::asin(glm::dot(w, Vec3f(1, 0, 0)));
        Rgbd albedo(0.0);
        const int n = 360;
        for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) {
                const double theta = -PiOver2 + (a + 0.5) * Pi / n, phi = -Pi + (b + 0.5) * TwoPi / n;
                albedo += Rgbd(bcsdf.eval(FiberAngles::fromAngles(float(theta), theta_o, float(phi))).sum()) *
                          (std::cos(theta) * std::cos(theta) * (Pi / n) * (TwoPi / n));
            }
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(out[c], albedo[c], 0.02 * albedo[c]) << "toward " << w << ", channel " << c;
    }
}

TEST(RadianceCache, RefusesACacheOverItsBudget) {
    test::Slab slab;
    const FiberGrid grid = test::splatSlab(slab, 0.001);
    RadianceCacheSettings settings;
    settings.cellVoxels = 1;
    try {
        const RadianceCache cache(grid, settings, 1u << 20);
        FAIL() << "a cache of " << cache.memoryBytes() << " bytes was built on a 1 MiB budget";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("MiB"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("cell_voxels"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace hairvox
