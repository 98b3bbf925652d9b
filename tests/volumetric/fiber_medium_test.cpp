#include "../transmittance/slab.h"

#include <hairvox/core/math.h>
#include <hairvox/core/sampling.h>
#include <hairvox/volumetric/fiber_medium.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <gtest/gtest.h>

#include <cmath>

namespace hairvox {
namespace {

/// Random unit-length segments of uniformly random direction in a 4 cm box:
/// fibers with no preferred orientation (coherence near 0).
Groom isotropicSegments(int count, std::uint64_t seed) {
    Groom g;
    Pcg32 rng(seed);
    for (int i = 0; i < count; ++i) {
        const Vec3f c(rng.uniform(-0.02f, 0.02f), rng.uniform(-0.02f, 0.02f),
                      rng.uniform(-0.02f, 0.02f));
        const Vec3f d = uniformSphere(rng.uniformFloat(), rng.uniformFloat()) * 0.002f;
        const Vec3f line[2] = {c - d, c + d};
        g.addStrand(line);
    }
    return g;
}

TEST(FiberMedium, ExtinctionOfASlabIsItsClosedForm) {
    const test::Slab slab;
    const FiberGrid grid = test::splatSlab(slab, 0.002);
    const FiberMedium medium(grid);
    // Inside the slab, away from its faces, over many points: λ·D·|ω × x̂|.
    for (const Vec3f omega : {Vec3f(0, 1, 0), glm::normalize(Vec3f(1, 1, 0)), Vec3f(0, 0, 1)}) {
        Pcg32 rng(3);
        double sum = 0;
        const int n = 4000;
        for (int i = 0; i < n; ++i) {
            const Vec3f x(rng.uniform(-0.03f, 0.03f), rng.uniform(0.003f, 0.007f),
                          rng.uniform(-0.08f, 0.08f));
            sum += double(medium.extinction(x, omega));
        }
        const double expected = slab.lambda() * double(test::kSlabDiameter) *
                                double(glm::length(glm::cross(omega, Vec3f(1, 0, 0))));
        EXPECT_NEAR(sum / n, expected, 0.03 * slab.lambda() * double(test::kSlabDiameter))
            << "omega " << omega;
    }
    EXPECT_EQ(medium.extinction(Vec3f(0, 0.5f, 0), Vec3f(0, 1, 0)), 0.0f); // far outside
}

TEST(FiberMedium, FreeFlightsThroughASlabFollowBeerLambert) {
    const test::Slab slab;
    const FiberGrid grid = test::splatSlab(slab, 0.002);
    const FiberMedium medium(grid);
    for (const Vec3f omega : {Vec3f(0, 1, 0), glm::normalize(Vec3f(0, 1, 0.6f)),
                              glm::normalize(Vec3f(0.8f, 1, 0))}) {
        Pcg32 rng(7);
        const int n = 20000;
        int through = 0;
        double sumT = 0;
        int collided = 0;
        for (int i = 0; i < n; ++i) {
            const Vec3f start(rng.uniform(-0.02f, 0.02f), -0.005f, rng.uniform(-0.05f, 0.05f));
            const std::optional<MediumCollision> c =
                medium.sampleCollision(start, omega, std::numeric_limits<float>::infinity(), rng);
            if (!c) {
                ++through;
            } else {
                ++collided;
                sumT += double(c->position.y);
                EXPECT_NEAR(c->position.y, start.y + c->t * omega.y, 1e-5f);
            }
        }
        const double expected = std::exp(-slab.expectedN(omega, test::kSlabDiameter));
        // Poisson fluctuations of λ between voxel columns raise E[e^{−τ}]
        // above e^{−E[τ]} by ~var(τ)/2 (a few percent here).
        EXPECT_NEAR(double(through) / n, expected, 0.06 * expected + 0.006) << "omega " << omega;
        EXPECT_GT(collided, 0);
        // Collisions lie in the slab (its faces smeared by half a voxel at most).
        EXPECT_GT(sumT / collided, 0.0);
        EXPECT_LT(sumT / collided, double(slab.thicknessY));
    }
}

TEST(FiberMedium, CollisionsMeetTheSlabsFibersAlongTheirDirection) {
    const test::Slab slab;
    const FiberGrid grid = test::splatSlab(slab, 0.002);
    const FiberMedium medium(grid);
    Pcg32 rng(5);
    int collisions = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3f start(rng.uniform(-0.02f, 0.02f), -0.005f, rng.uniform(-0.05f, 0.05f));
        if (const auto c = medium.sampleCollision(start, Vec3f(0, 1, 0), 1.0f, rng)) {
            ++collisions;
            EXPECT_NEAR(c->tangent.x, 1.0f, 1e-4f) << *c;
            EXPECT_EQ(c->fiberType, 0);
        }
    }
    EXPECT_GT(collisions, 1000);
}

TEST(FiberMedium, IsotropicFibersAreMetInProportionToTheirCrossSection) {
    const Groom groom = isotropicSegments(20000, 9);
    SplatOptions options;
    options.voxelSize = 0.004;
    const FiberGrid grid = splatStrands(groom, options);
    const FiberMedium medium(grid);
    // A fiber of random direction is met with probability ∝ cos θ = |ω × u|:
    // the mean cos θ of the fibers met is E[cos²θ]/E[cos θ] = (2/3)/(π/4).
    // The voxels' coherence is not 0 (a few fibers per voxel), so the
    // coherent part pulls the mean toward 1 a little.
    Pcg32 rng(1);
    const Vec3f omega(0, 0, 1);
    double sum = 0;
    int n = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f start(rng.uniform(-0.015f, 0.015f), rng.uniform(-0.015f, 0.015f), -0.03f);
        if (const auto c = medium.sampleCollision(start, omega, 1.0f, rng)) {
            sum += double(glm::length(glm::cross(omega, c->tangent)));
            ++n;
        }
    }
    ASSERT_GT(n, 5000);
    EXPECT_NEAR(sum / n, (2.0 / 3.0) / (Pi / 4.0), 0.03);
}

TEST(FiberMedium, WalkingVoxelsIntegratesTheDensityAlongALine) {
    const test::Slab slab;
    const double h = 0.002;
    const FiberGrid grid = test::splatSlab(slab, h);
    const FiberMedium medium(grid);
    Pcg32 rng(2);
    for (int line = 0; line < 20; ++line) {
        const Vec3f origin(rng.uniform(-0.04f, 0.04f), rng.uniform(-0.01f, 0.02f),
                           rng.uniform(-0.09f, 0.09f));
        const Vec3f dir = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
        const float length = 0.05f;
        double walked = 0, lastExit = 0;
        medium.walkVoxels(origin, dir, length,
                          [&](std::size_t v, const glm::ivec3&, float t0, float t1) {
                              EXPECT_GE(double(t0), lastExit - 1e-6);
                              EXPECT_GT(t1, t0);
                              lastExit = double(t1);
                              walked += double(grid.density[v]) * double(t1 - t0);
                          });
        // The same integral by midpoints of 20,000 steps: λ of the voxel
        // whose box holds each point.
        double sampled = 0;
        const int steps = 20000;
        for (int i = 0; i < steps; ++i) {
            const Vec3f x = origin + (float(i) + 0.5f) * (length / float(steps)) * dir;
            const Vec3f q = x / float(h) + 0.5f;
            const std::size_t v = grid.find(openvdb::Coord(int(std::floor(q.x)),
                                                           int(std::floor(q.y)),
                                                           int(std::floor(q.z))));
            if (v != FiberGrid::kInactive)
                sampled += double(grid.density[v]) * double(length) / steps;
        }
        EXPECT_NEAR(walked, sampled, 2e-3 * (sampled + slab.lambda() * 0.002))
            << "line from " << origin << " along " << dir;
    }
}

/// One straight strand of `points` points through the origin along unit u, 1 mm apart.
Groom straightStrand(const Vec3f& u, int points = 81) {
    Groom g;
    std::vector<Vec3f> line;
    for (int i = 0; i < points; ++i)
        line.push_back((float(i) - 0.5f * float(points - 1)) * 0.001f * u +
                       Vec3f(0.0003f, -0.0007f, 0.0011f));
    g.addStrand(line);
    return g;
}

// ownDensity() is the voxelizer's own splat of the fiber: every voxel near
// the middle of a long straight strand holds what the closed form says.
TEST(FiberMedium, OwnDensityIsTheSplatOfTheFiber) {
    const double h = 0.002;
    for (const Vec3f u : {Vec3f(1, 0, 0), glm::normalize(Vec3f(1, 2, 0.5f)),
                          glm::normalize(Vec3f(-0.3f, 0.2f, 1))}) {
        SplatOptions options;
        options.voxelSize = h;
        const FiberGrid grid = splatStrands(straightStrand(u), options);
        const FiberMedium medium(grid);
        const OwnFiber own{Vec3f(0.0003f, -0.0007f, 0.0011f), u};
        int checked = 0;
        for (int x = -3; x <= 3; ++x)
            for (int y = -3; y <= 3; ++y)
                for (int z = -3; z <= 3; ++z) {
                    const glm::ivec3 v(x, y, z);
                    const std::size_t i = grid.find(openvdb::Coord(x, y, z));
                    const float splat = i == FiberGrid::kInactive ? 0.0f : grid.density[i];
                    const float closed = medium.ownDensity(own, v);
                    EXPECT_NEAR(closed, splat, 2e-3f / float(h * h)) << "voxel " << v << " u " << u;
                    if (!medium.nearOwnFiber(own, v)) {
                        EXPECT_EQ(closed, 0.0f) << "voxel " << v;
                    }
                    checked += splat > 0;
                }
        EXPECT_GT(checked, 8) << u;
    }
}

// A flight leaving a lone fiber never meets it again; without the
// exclusion it would, about 1 − e^{−n_own} of the time.
TEST(FiberMedium, AFlightDoesNotMeetTheFiberItLeaves) {
    const Vec3f u = glm::normalize(Vec3f(1, 0.3f, 0.2f));
    SplatOptions options;
    options.voxelSize = 0.0005;
    options.fiberScale.diameter = 0.0002f;
    options.fiberScale.densityMultiplier = 4;
    const FiberGrid grid = splatStrands(straightStrand(u), options);
    const FiberMedium medium(grid);
    Pcg32 rng(11);
    int withOwn = 0, without = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
        const OwnFiber own{Vec3f(0.0003f, -0.0007f, 0.0011f) + rng.uniform(-0.01f, 0.01f) * u, u};
        const Vec3f dir = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
        withOwn += medium.sampleCollision(own.position, dir, 1.0f, rng, &own).has_value();
        without += medium.sampleCollision(own.position, dir, 1.0f, rng).has_value();
    }
    EXPECT_LT(withOwn, n / 200) << "met " << withOwn << " of " << n;
    EXPECT_GT(without, n / 20) << "met " << without << " of " << n;
}

TEST(FiberMedium, EmptyGridHasNoCollisions) {
    FiberGrid grid;
    grid.info.voxelSize = 0.01;
    const FiberMedium medium(grid);
    Pcg32 rng(1);
    EXPECT_FALSE(medium.sampleCollision(Vec3f(0), Vec3f(0, 1, 0), 1e9f, rng));
    int visited = 0;
    medium.walkVoxels(Vec3f(0), Vec3f(0, 1, 0), 1e9f,
                      [&](std::size_t, const glm::ivec3&, float, float) { ++visited; });
    EXPECT_EQ(visited, 0);
}

} // namespace
} // namespace hairvox
