// The multiple-scattering solve (volumetric/multiple_scattering.h) in a white
// furnace: a thick ball of σ_a = 0 fibers of every direction under uniform
// illumination. With a lossless f_s the radiance inside would equal the
// illumination everywhere; Marschner's f_s keeps 0.69–1.02 of the light at
// each scattering (its white-furnace albedo, tests/shading/marschner_test.cpp),
// so the radiance inside is the illumination times the mean product of the
// albedos along the paths that reach it. That product is estimated here by
// an independent walk — the path tracer's step (a fiber met in proportion to
// the cross-section it shows the ray, the continuation by
// MarschnerBcsdf::sample) in the homogeneous medium the ball's fibers make on
// average — with none of the solve's grid, voxel walk, deposits or cache.
#include "sphere_midpoints.h"

#include <hairvox/core/math.h>
#include <hairvox/core/rng.h>
#include <hairvox/core/sampling.h>
#include <hairvox/shading/marschner.h>
#include <hairvox/volumetric/multiple_scattering.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <vector>

namespace hairvox {
namespace {

/// The furnace: a ball of straight segments of uniformly random direction,
/// their midpoints uniform in the ball.
struct FiberBall {
    float radius = 0.012f;        ///< R, metres
    float segmentLength = 0.002f; ///< each segment's length
    float diameter = 1e-5f;       ///< D (k = 1): many thin fibers, ~20 segments a voxel
    double voxelSize = 0.001;
    /// λ̄·D·π/4·R, the optical radius of the ball (fibers of every direction
    /// show a ray π/4 of their length on average).
    double opticalRadius = 4.0;

    /// λ̄ = N·ℓ/V, fiber length per volume.
    double lambda() const {
        return opticalRadius / (double(diameter) * (Pi / 4.0) * double(radius));
    }
    double sigmaT() const { return opticalRadius / double(radius); }
    int segments() const {
        const double volume = 4.0 / 3.0 * Pi * std::pow(double(radius), 3.0);
        return int(std::lround(lambda() * volume / double(segmentLength)));
    }
    Groom groom() const {
        Groom g;
        Pcg32 rng(5);
        for (int i = 0, n = segments(); i < n; ++i) {
            Vec3f c;
            do {
                c = Vec3f(rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f),
                          rng.uniform(-1.0f, 1.0f));
            } while (glm::dot(c, c) > 1.0f);
            const Vec3f d =
                uniformSphere(rng.uniformFloat(), rng.uniformFloat()) * (0.5f * segmentLength);
            const Vec3f line[2] = {radius * c - d, radius * c + d};
            g.addStrand(line);
        }
        return g;
    }
};

/// How far a ray from x (inside the ball) along unit d travels to its surface.
float distanceToSurface(const Vec3f& x, const Vec3f& d, float radius) {
    const float b = glm::dot(x, d), c = glm::dot(x, x) - radius * radius;
    return -b + std::sqrt(std::max(0.0f, b * b - c));
}

/// The mean over directions of the radiance that reaches x after at least one
/// scattering, for illumination of radiance 1 from every direction outside a
/// homogeneous ball of fibers of uniformly random direction (σ_t the same
/// toward every ω): walks from x backward, as the path tracer walks from the
/// camera. Mean and standard error.
std::pair<double, double> scatteredByWalks(const FiberBall& ball, const MarschnerBcsdf& bcsdf,
                                           const Vec3f& x0, int walks, std::uint64_t seed) {
    Pcg32 rng(seed);
    const double sigmaT = ball.sigmaT();
    double sum = 0, sum2 = 0;
    for (int i = 0; i < walks; ++i) {
        Vec3f x = x0, d = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
        double throughput = 1, value = 0;
        for (int depth = 0;; ++depth) {
            const double s = -std::log1p(-double(rng.uniformFloat())) / sigmaT;
            if (s >= double(distanceToSurface(x, d, ball.radius))) {
                value = depth >= 1 ? throughput : 0.0;
                break;
            }
            x += float(s) * d;
            // The fiber met: a direction u kept with probability |d × u|.
            Vec3f u;
            do
                u = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
            while (!(rng.uniformFloat() < glm::length(glm::cross(d, u))));
            const BcsdfSample b = bcsdf.sample(
                -d, u,
                {rng.uniformFloat(), rng.uniformFloat(), rng.uniformFloat(), rng.uniformFloat()});
            if (!b.valid())
                break;
            throughput *= double(b.weight.g);
            d = b.wi;
            if (depth >= 3) { // Russian roulette, as the solve and the path tracer
                const double q = std::min(1.0, throughput);
                if (!(double(rng.uniformFloat()) < q))
                    break;
                throughput /= q;
            }
        }
        sum += value;
        sum2 += value * value;
    }
    const double mean = sum / walks;
    return {mean, std::sqrt(std::max(0.0, sum2 / walks - mean * mean) / walks)};
}

/// The mean over directions of the cache's L̄ at x (midpoints in z = cos and
/// φ: exact for the harmonics of the orders a cache holds).
double meanIncident(const RadianceCache& cache, const Vec3f& x) {
    const int n = 48;
    double sum = 0;
    test::forEachSphereMidpoint(n, [&](const Vec3f& w) { sum += double(cache.incident(x, w).g); });
    return sum / double(n * n);
}

TEST(MultipleScattering, AWhiteFurnaceKeepsTheLightTheFibersAlbedoKeeps) {
    const FiberBall ball;
    SplatOptions splat;
    splat.voxelSize = ball.voxelSize;
    splat.fiberScale.diameter = ball.diameter;
    const FiberGrid grid = splatStrands(ball.groom(), splat);

    FiberParams white;
    white.sigma_a = Rgb(0.0f);
    VolumetricScene scene;
    scene.grid = &grid;
    scene.fibers = {white};
    // Uniform radiance 1 from every direction: irradiance 4π through any
    // plane, here from 64 directional lights of 4π/64 each, spread over the
    // sphere by the spherical Fibonacci lattice.
    constexpr int kLights = 64;
    for (int i = 0; i < kLights; ++i) {
        Light light = Light::directional(uniformSphere((float(i) + 0.5f) / float(kLights),
                                                       std::fmod(float(i) * 0.618034f, 1.0f)));
        light.intensity = float(4.0 * Pi / kLights);
        scene.lights.push_back(light);
    }
    VolumetricSettings settings;
    settings.paths = 240000;
    settings.cache.shOrder = 2; // the mean radiance is band 0: exact at any order
    const MultipleScatteringSolution solution =
        solveMultipleScattering(scene, settings, 1ull << 30);

    std::cout << "white furnace: " << solution.stats.paths << " paths, "
              << double(solution.stats.fiberEvents) / double(solution.stats.paths)
              << " scatterings a path\n";
    const MarschnerBcsdf bcsdf(white);
    // At the centre, and averaged over 14 points halfway out (the six axes
    // and eight diagonals: the mean radiance depends on |x| alone).
    std::vector<Vec3f> shell;
    for (int i = 0; i < 3; ++i)
        for (const float sign : {1.0f, -1.0f}) {
            Vec3f axis(0.0f);
            axis[i] = sign;
            shell.push_back(axis);
        }
    for (int i = 0; i < 8; ++i)
        shell.push_back(glm::normalize(Vec3f(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1)));
    for (const float r : {0.0f, 0.5f}) {
        double solved = 0;
        for (const Vec3f& direction : shell)
            solved += meanIncident(*solution.cache, r * ball.radius * direction);
        solved /= double(shell.size());
        const Vec3f x(r * ball.radius, 0.0f, 0.0f);
        const auto [walked, stderr_] = scatteredByWalks(ball, bcsdf, x, 40000, 17);
        // The light that reaches x unscattered: the mean of e^{−σ_t·t} over
        // directions, for the radiance inside against the illumination.
        double unscattered = 0;
        const int n = 4000;
        for (int i = 0; i < n; ++i) {
            const Vec3f d =
                uniformSphere((float(i) + 0.5f) / float(n), std::fmod(float(i) * 0.618034f, 1.0f));
            unscattered += std::exp(-ball.sigmaT() * double(distanceToSurface(x, d, ball.radius)));
        }
        unscattered /= n;
        std::cout << "white furnace, optical radius " << ball.opticalRadius << ", at r = " << r
                  << " R: scattered light solved " << solved << ", walked " << walked << " ± "
                  << stderr_ << "; the radiance inside over the illumination "
                  << solved + unscattered << " (lossless fibers: 1)\n";
        // Measured (240k paths, 2.5 scatterings a path, 40k walks): r = 0
        // 0.627 against 0.632 ± 0.002, r = R/2 0.655 against 0.642 ± 0.002
        // (read through the cells' gradients; before them 0.634 and 0.646,
        // the solve's seeds 2 and 3 at the centre 0.639, 0.626); the radiance
        // inside 0.65 and 0.70 of the illumination. The walks' figure moves 5%
        // for a ball 10% denser, and 12% for a 3% loss at every scattering.
        EXPECT_NEAR(solved, walked, 0.03 * walked + 4 * stderr_) << "r = " << r << " R";
        // The albedo loses light at most scatterings (0.69–1.02), and the
        // illumination is all there is.
        EXPECT_LT(solved + unscattered, 1.0);
        EXPECT_GT(solved + unscattered, 0.4);
    }
}

} // namespace
} // namespace hairvox
