#include "test_util.h"
#include "voxelize/voxelize_test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/rng.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>
#include <openvdb/tools/Interpolation.h>

#include <cmath>
#include <vector>

namespace hairvox {
namespace {

using openvdb::Coord;

Groom groomOf(const std::vector<std::vector<Vec3f>>& strands) {
    Groom g;
    for (const auto& s : strands)
        g.addStrand(s);
    return g;
}

SplatOptions withVoxelSize(double h, bool tensor = false) {
    SplatOptions o;
    o.voxelSize = h;
    o.storeOrientationTensor = tensor;
    return o;
}

/// The value of `values` at voxel c, or the background 0 where it is not active.
template <typename T>
T at(const FiberGrid& g, const std::vector<T>& values, const Coord& c) {
    const std::size_t i = g.find(c);
    return i == FiberGrid::kInactive ? T(0.0f) : values[i];
}
float density(const FiberGrid& g, const Coord& c) {
    return at(g, g.density, c);
}
openvdb::Vec3s orientation(const FiberGrid& g, const Coord& c) {
    return at(g, g.orientation, c);
}

void expectVecNear(const openvdb::Vec3s& v, const Vec3d& expected, double tol, const Coord& c) {
    EXPECT_NEAR(v.x(), expected.x, tol) << "at " << c;
    EXPECT_NEAR(v.y(), expected.y, tol) << "at " << c;
    EXPECT_NEAR(v.z(), expected.z, tol) << "at " << c;
}

/// Every active voxel: orientation = u and E[u uᵀ] = u uᵀ.
void expectSingleDirection(const FiberGrid& g, const Vec3d& u) {
    ASSERT_TRUE(g.hasTensor());
    ASSERT_GT(g.activeVoxelCount(), 0u);
    g.forEachVoxel([&](std::size_t i, const Coord& c) {
        expectVecNear(g.orientation[i], u, 1e-5, c);
        expectVecNear(g.tensorDiag[i], u * u, 1e-5, c);
        expectVecNear(g.tensorOffDiag[i], Vec3d(u.x * u.y, u.x * u.z, u.y * u.z), 1e-5, c);
    });
}

// ---------------------------------------------------------------------------
// Exact values of the vertex-centred trilinear splat.

TEST(Splat, FiberOnALatticeLineGivesItsLineDensity) {
    // A fiber along each axis on a line of voxels, from −5h to 5h, in uneven
    // segments: each voxel within gets ∫ tent = h of length (λ = 1/h²), the
    // end voxels half of that, and no other voxel anything.
    constexpr double h = 0.5;
    for (int axis = 0; axis < 3; ++axis) {
        std::vector<Vec3f> pts;
        for (float x : {-2.5f, -1.3f, 0.1f, 0.6f, 2.5f}) {
            Vec3f p(0.0f);
            p[axis] = x;
            pts.push_back(p);
        }
        const FiberGrid g = splatStrands(groomOf({pts}), withVoxelSize(h));
        EXPECT_EQ(g.activeVoxelCount(), 11u) << "axis " << axis;
        for (int i = -5; i <= 5; ++i) {
            Coord c(0, 0, 0);
            c[std::size_t(axis)] = i;
            const double expected = (std::abs(i) == 5 ? 0.5 : 1.0) / (h * h);
            EXPECT_NEAR(density(g, c), expected, 1e-6 * expected) << "axis " << axis << " " << c;
            Vec3d u(0.0);
            u[axis] = 1;
            expectVecNear(orientation(g, c), u, 1e-6, c);
        }
    }
}

TEST(Splat, OffLatticeFiberSplitsByTrilinearWeights) {
    // Along x at y = 0.25h, z = 0.6h: the voxel rows j, k ∈ {0, 1} get the
    // line density times (0.75, 0.25) in y and (0.4, 0.6) in z.
    constexpr double h = 0.5;
    const float y = 0.125f, z = 0.3f;
    const FiberGrid g = splatStrands(groomOf({{{0.0f, y, z}, {5.0f, y, z}}}), withVoxelSize(h));
    EXPECT_EQ(g.activeVoxelCount(), 11u * 4u);
    const double fy = double(y) / h, fz = double(z) / h;
    const double wy[2] = {1 - fy, fy}, wz[2] = {1 - fz, fz};
    for (int i = 0; i <= 10; ++i)
        for (int j = 0; j <= 1; ++j)
            for (int k = 0; k <= 1; ++k) {
                const double line = (i == 0 || i == 10 ? 0.5 : 1.0) / (h * h);
                const double expected = line * wy[j] * wz[k];
                EXPECT_NEAR(density(g, Coord(i, j, k)), expected, 1e-5 * expected)
                    << Coord(i, j, k);
            }
}

TEST(Splat, FiberOnABrickBoundaryPlaneStaysOnItsVoxels) {
    // x = 16 is voxel plane 32 at h = 0.5, the boundary between two 32³
    // bricks: all length goes to i = 32, none to the neighbouring planes.
    constexpr double h = 0.5;
    const FiberGrid g =
        splatStrands(groomOf({{{16.0f, -3.0f, 0.0f}, {16.0f, 3.0f, 0.0f}}}), withVoxelSize(h));
    EXPECT_EQ(g.activeVoxelCount(), 13u);
    g.forEachVoxel([](std::size_t, const Coord& c) { EXPECT_EQ(c.x(), 32) << c; });
    EXPECT_NEAR(density(g, Coord(32, 0, 0)), 1 / (h * h), 1e-6 / (h * h));
    EXPECT_NEAR(test::splattedLength(g), 6.0, 6e-6);
}

TEST(Splat, TrilinearSamplingIsTheVertexCentredReconstruction) {
    // Voxel ijk is the value at world ijk·h: OpenVDB's BoxSampler through the
    // grid's transform returns it there, and interpolates between voxels.
    const double h = 0.37;
    const FiberGrid g =
        splatStrands(groomOf({{{0.1f, 0.2f, 0.3f}, {2.9f, 1.7f, 0.8f}}}), withVoxelSize(h));
    const FiberVdbGrids vdb = toVdbGrids(g);
    openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(
        *vdb.density);
    // BoxSampler interpolates in float: compare relative to the largest value.
    const double tol = 1e-6 / (h * h);
    g.forEachVoxel([&](std::size_t i, const Coord& c) {
        const openvdb::Vec3d world = openvdb::Vec3d(c.x(), c.y(), c.z()) * h;
        const double value = g.density[i], next = density(g, c.offsetBy(1, 0, 0));
        EXPECT_NEAR(sampler.wsSample(world), value, tol) << c;
        EXPECT_NEAR(sampler.wsSample(world + openvdb::Vec3d(0.5 * h, 0, 0)), 0.5 * (value + next),
                    tol)
            << c;
    });
}

// ---------------------------------------------------------------------------
// Orientation and its second moment.

TEST(Splat, SingleFiberOrientationIsItsDirection) {
    const std::vector<Vec3d> directions = {{1, 0, 0},
                                           {0, 1, 0},
                                           {0, 0, 1},
                                           {-1, 0, 0},
                                           glm::normalize(Vec3d(1, 1, 1)),
                                           glm::normalize(Vec3d(-0.3, 0.8, -0.52))};
    for (const Vec3d& u : directions) {
        const Vec3f start(0.13f, -0.21f, 0.34f);
        const Vec3f end = start + Vec3f(2.7 * u);
        const FiberGrid g = splatStrands(groomOf({{start, end}}), withVoxelSize(0.23, true));
        SCOPED_TRACE(testing::Message() << "u = " << u);
        expectSingleDirection(g, glm::normalize(Vec3d(end) - Vec3d(start)));
    }
}

TEST(Splat, CrossingPerpendicularFibersAverage) {
    // Fibers along x and y crossing at voxel 0: there each brings length h,
    // so λ = 2/h², E[u] = (½, ½, 0) (|E[u]| = 0.707: coherence drops) and
    // E[u uᵀ] = diag(½, ½, 0). Voxels that only one fiber reaches keep it.
    constexpr double h = 0.25;
    const FiberGrid g = splatStrands(groomOf({{{-1.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}},
                                              {{0.0f, -1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}}}),
                                     withVoxelSize(h, true));
    const Coord o(0, 0, 0);
    EXPECT_NEAR(density(g, o), 2 / (h * h), 1e-6 / (h * h));
    expectVecNear(orientation(g, o), {0.5, 0.5, 0}, 1e-6, o);
    expectVecNear(at(g, g.tensorDiag, o), {0.5, 0.5, 0}, 1e-6, o);
    expectVecNear(at(g, g.tensorOffDiag, o), {0, 0, 0}, 1e-6, o);
    for (const Coord& c : {Coord(2, 0, 0), Coord(-3, 0, 0)})
        expectVecNear(orientation(g, c), {1, 0, 0}, 1e-6, c);
    expectVecNear(orientation(g, Coord(0, 3, 0)), {0, 1, 0}, 1e-6, Coord(0, 3, 0));
}

TEST(Splat, AntiparallelFibersCancelInTheMeanButNotInTheTensor) {
    // The root → tip sign is kept: opposite fibers cancel in E[u], while the
    // sign-free E[u uᵀ] still says "along x".
    constexpr double h = 0.25;
    const FiberGrid g = splatStrands(groomOf({{{-1.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}},
                                              {{1.0f, 0.0f, 0.0f}, {-1.0f, 0.0f, 0.0f}}}),
                                     withVoxelSize(h, true));
    const Coord o(0, 0, 0);
    EXPECT_NEAR(density(g, o), 2 / (h * h), 1e-6 / (h * h));
    expectVecNear(orientation(g, o), {0, 0, 0}, 1e-6, o);
    expectVecNear(at(g, g.tensorDiag, o), {1, 0, 0}, 1e-6, o);
}

TEST(Splat, StatisticsOfRealGroomsAreBounded) {
    // On wavy and curly grooms: λ > 0, |E[u]| ≤ 1, trace E[u uᵀ] = 1, and all
    // grids share one topology.
    for (GroomStyle style : {GroomStyle::Wavy, GroomStyle::Curly}) {
        ProceduralGroomParams p;
        p.style = style;
        p.strands = 400;
        const Groom groom = generateGroom(p);
        const FiberGrid g = splatStrands(groom, withVoxelSize(0, true));
        SCOPED_TRACE(toString(style));
        ASSERT_EQ(g.orientation.size(), g.density.size());
        ASSERT_EQ(g.tensorDiag.size(), g.density.size());
        ASSERT_EQ(g.tensorOffDiag.size(), g.density.size());
        double minCoherence = 1;
        g.forEachVoxel([&](std::size_t i, const Coord& c) {
            EXPECT_GT(g.density[i], 0.0f) << c;
            const double coherence = g.orientation[i].length();
            EXPECT_LE(coherence, 1 + 1e-5) << c;
            minCoherence = std::min(minCoherence, coherence);
            const openvdb::Vec3s diag = g.tensorDiag[i];
            EXPECT_NEAR(diag.x() + diag.y() + diag.z(), 1.0, 1e-5) << c;
        });
        EXPECT_LT(minCoherence, 0.9); // strands do cross somewhere
    }
}

TEST(Splat, NearlyLatticeAlignedFibersKeepBoundedStatistics) {
    // Fibers a hair's breadth from voxel planes give their far corners
    // rounding-sized weights; the orientation of such voxels must not be a
    // ratio of rounding errors.
    Pcg32 rng(7);
    constexpr double h = 0.25;
    Groom groom;
    for (int s = 0; s < 200; ++s) {
        // A lattice coordinate, or one float step beside it.
        const auto coordinate = [&] {
            const auto x = float(h * double(rng.nextU32() % 9));
            const std::uint32_t side = rng.nextU32() % 3;
            return side == 0 ? x : std::nextafter(x, side == 1 ? 1e9f : -1e9f);
        };
        const auto nearLattice = [&] {
            return Vec3f(coordinate(), coordinate(), coordinate());
        };
        const Vec3f a = nearLattice(), b = nearLattice();
        if (a != b)
            groom.addStrand(std::vector<Vec3f>{a, b});
    }
    const FiberGrid g = splatStrands(groom, withVoxelSize(h, true));
    EXPECT_NEAR(test::splattedLength(g) / test::exactLength(groom), 1.0, 1e-5);
    g.forEachVoxel([&](std::size_t i, const Coord& c) {
        EXPECT_LE(g.orientation[i].length(), 1 + 1e-5) << c << ", λ = " << g.density[i];
        const openvdb::Vec3s diag = g.tensorDiag[i];
        EXPECT_NEAR(diag.x() + diag.y() + diag.z(), 1.0, 1e-5) << c << ", λ = " << g.density[i];
        EXPECT_GE(diag.x(), -1e-5f) << c;
        EXPECT_GE(diag.y(), -1e-5f) << c;
        EXPECT_GE(diag.z(), -1e-5f) << c;
    });
}

// ---------------------------------------------------------------------------
// Length conservation.

/// Random walks with steps from 1/100 to 1.5 units in random directions.
Groom randomGroom(std::uint64_t seed, const Vec3f& offset) {
    Pcg32 rng(seed);
    Groom g;
    for (int s = 0; s < 20; ++s) {
        std::vector<Vec3f> pts{offset +
                               Vec3f(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2))};
        const int n = 2 + static_cast<int>(rng.nextU32() % 11);
        for (int k = 1; k < n; ++k) {
            const float cosTheta = rng.uniform(-1, 1), phi = rng.uniform(0, 6.2831853f);
            const float sinTheta = std::sqrt(1 - cosTheta * cosTheta);
            const float step = 0.01f * std::pow(150.0f, rng.uniformFloat());
            pts.push_back(pts.back() + step * Vec3f(sinTheta * std::cos(phi),
                                                    sinTheta * std::sin(phi), cosTheta));
        }
        g.addStrand(pts);
    }
    return g;
}

TEST(Splat, ConservesLengthForAnyVoxelSizeAndPlacement) {
    for (std::uint64_t seed = 1; seed <= 4; ++seed)
        for (double h : {0.023, 0.11, 0.5, 1.7, 6.0})
            for (const Vec3f& offset : {Vec3f(0.0f), Vec3f(0.5f, 0.25f, 0.125f) * float(h),
                                        Vec3f(1000.3f, -20.7f, 5.1f)}) {
                const Groom groom = randomGroom(seed, offset);
                const FiberGrid g = splatStrands(groom, withVoxelSize(h));
                const double exact = test::exactLength(groom);
                EXPECT_NEAR(test::splattedLength(g) / exact, 1.0, 1e-5)
                    << "seed " << seed << ", h " << h << ", offset " << offset;
            }
}

TEST(Splat, ConservesLengthOnVoxelBoundaries) {
    // h = 0.5 is exact in binary, so these segments lie exactly on voxel
    // planes, lines and vertices, and on the planes between 32³ bricks (16).
    constexpr double h = 0.5;
    const std::vector<std::vector<Vec3f>> cases = {
        {{0, 0, 0}, {2, 0, 0}},                         // along a line of voxels
        {{0.2f, 0.5f, 0.1f}, {1.7f, 0.5f, 1.3f}},       // in a voxel plane
        {{0, 0, 0}, {2, 2, 2}},                         // through voxel vertices
        {{-1.5f, -1, -0.5f}, {1.5f, 1, 0.5f}},          // through vertices, across 0
        {{0.1f, 0.1f, 0.1f}, {0.2f, 0.15f, 0.12f}},     // inside one cell
        {{0, 0, 0}, {0.5f, 0, 0}},                      // one cell edge exactly
        {{0.5f, 0.1f, 0.2f}, {1.0f, 0.3f, 0.4f}},       // face to face
        {{0.3f, 0.3f, 0.3f}, {0.3f, 0.3f, 0.3000001f}}, // very short
        {{16, 0.3f, 0.2f}, {16, 5, 3}},                 // in a brick boundary plane
        {{16, 16, -3}, {16, 16, 3}},                    // along a brick edge
        {{15.9f, 15.9f, 15.9f}, {16.1f, 16.1f, 16.1f}}, // through a brick corner
        {{-16, -16, -16}, {40, 33, 20}},                // across several bricks
    };
    for (const auto& c : cases) {
        const Groom groom = groomOf({c});
        const FiberGrid g = splatStrands(groom, withVoxelSize(h));
        EXPECT_NEAR(test::splattedLength(g) / test::exactLength(groom), 1.0, 1e-5)
            << c[0] << " -> " << c[1];
        g.forEachVoxel(
            [&](std::size_t i, const Coord& ijk) { EXPECT_GT(g.density[i], 0.0f) << ijk; });
    }
}

TEST(Splat, ConservesLengthOfProceduralGrooms) {
    for (GroomStyle style : {GroomStyle::Straight, GroomStyle::Wavy, GroomStyle::Curly}) {
        ProceduralGroomParams p;
        p.style = style;
        p.strands = 1000;
        const Groom groom = generateGroom(p);
        for (int across : {16, 256}) {
            const FiberGrid g = splatStrands(groom, withVoxelSize(defaultVoxelSize(groom, across)));
            EXPECT_NEAR(test::splattedLength(g) / test::exactLength(groom), 1.0, 1e-5)
                << toString(style) << ", " << across << " voxels across";
        }
    }
}

// ---------------------------------------------------------------------------
// Determinism, provenance, defaults.

TEST(Splat, BitIdenticalForAnyThreadCount) {
    for (GroomStyle style : {GroomStyle::Wavy, GroomStyle::Curly}) {
        ProceduralGroomParams p;
        p.style = style;
        p.strands = 3000;
        const Groom groom = generateGroom(p);
        SplatOptions options = withVoxelSize(0, true);
        const FiberGrid one = test::splatWithThreads(groom, options, 1);
        for (int threads : {2, 8})
            EXPECT_TRUE(test::sameFiberGrid(one, test::splatWithThreads(groom, options, threads)))
                << toString(style) << ", " << threads << " threads";
        options.threaded = false;
        EXPECT_TRUE(test::sameFiberGrid(one, splatStrands(groom, options))) << toString(style);
    }
}

TEST(Splat, RecordsWhatTheGridWasMadeFrom) {
    ProceduralGroomParams p;
    p.strands = 50;
    const Groom groom = generateGroom(p);
    SplatOptions options;
    options.fiberScale.diameter = 6e-5f;
    options.fiberScale.densityMultiplier = 3.0f;
    options.sourceFile = "head.hair";
    const FiberGrid g = splatStrands(groom, options);
    EXPECT_EQ(g.info.voxelSize, defaultVoxelSize(groom));
    EXPECT_EQ(g.info.fiberScale.diameter, 6e-5f);
    EXPECT_EQ(g.info.fiberScale.densityMultiplier, 3.0f);
    EXPECT_EQ(g.info.sourceFile, "head.hair");
    EXPECT_EQ(g.info.sourceHash, hexDigest(contentHash(groom)));
    EXPECT_EQ(g.info.strands, 50u);
    EXPECT_EQ(g.info.segments, groom.segmentCount());
    EXPECT_NEAR(g.info.totalLength, test::exactLength(groom), 1e-9 * g.info.totalLength);
    EXPECT_FALSE(g.info.version.empty());
    EXPECT_FALSE(g.hasTensor());
    EXPECT_TRUE(g.warnings.empty());
    // As OpenVDB grids (the .vdb file's form): named, classed, vertex-centred.
    const FiberVdbGrids vdb = toVdbGrids(g);
    EXPECT_EQ(vdb.density->getName(), "density");
    EXPECT_EQ(vdb.orientation->getName(), "orientation");
    EXPECT_EQ(vdb.density->getGridClass(), openvdb::GRID_FOG_VOLUME);
    EXPECT_EQ(vdb.density->transform(),
              *openvdb::math::Transform::createLinearTransform(g.info.voxelSize));
    EXPECT_EQ(vdb.density->activeVoxelCount(), g.activeVoxelCount());
    EXPECT_TRUE(vdb.density->tree().hasSameTopology(vdb.orientation->tree()));
    EXPECT_FALSE(vdb.tensorDiag);
}

TEST(Splat, DefaultVoxelSizeIsTheLongestSideOverAFixedCount) {
    const Groom groom = groomOf({{{0, 0, 0}, {1, 3, 2}}, {{-1, 0, 0}, {0, 0.5f, 0}}});
    EXPECT_DOUBLE_EQ(defaultVoxelSize(groom), 3.0 / kDefaultVoxelsAcross);
    EXPECT_DOUBLE_EQ(defaultVoxelSize(groom, 64), 3.0 / 64);
    EXPECT_EQ(defaultVoxelSize(Groom{}), 1.0);
    EXPECT_THROW(defaultVoxelSize(groom, 0), InputError);
}

// ---------------------------------------------------------------------------
// Bad input.

TEST(Splat, EmptyGroomGivesAnEmptyGridAndAWarning) {
    for (const Groom& groom : {Groom{}, groomOf({{{1, 2, 3}, {1, 2, 3}}})}) {
        const FiberGrid g = splatStrands(groom, SplatOptions{});
        EXPECT_TRUE(g.blocks.empty() && g.orientation.empty());
        EXPECT_EQ(g.activeVoxelCount(), 0u);
        EXPECT_EQ(g.warnings.size(), 1u);
        EXPECT_EQ(g.info.totalLength, 0.0);
    }
}

TEST(Splat, SkipsStrandsWithoutSegments) {
    // Only an unsanitized groom has them; they contribute nothing.
    Groom groom;
    groom.strandStart = {0, 0, 1, 3};
    groom.points = {{5, 5, 5}, {0, 0, 0}, {1, 0, 0}};
    const FiberGrid g = splatStrands(groom, withVoxelSize(0.25));
    EXPECT_NEAR(test::splattedLength(g), 1.0, 1e-6);
}

TEST(Splat, RefusesInvalidOptions) {
    const Groom groom = groomOf({{{0, 0, 0}, {1, 0, 0}}});
    for (double h : {-1.0, std::nan(""), HUGE_VAL})
        EXPECT_THROW(splatStrands(groom, withVoxelSize(h)), InputError) << h;
    SplatOptions o;
    o.fiberScale.diameter = 0;
    EXPECT_THROW(splatStrands(groom, o), InputError);
    o = SplatOptions{};
    o.fiberScale.densityMultiplier = -2;
    EXPECT_THROW(splatStrands(groom, o), InputError);
}

TEST(Splat, RefusesAVoxelSizeOverTheMemoryBudgetStatingTheEstimate) {
    ProceduralGroomParams p;
    p.strands = 200;
    const Groom groom = generateGroom(p);
    try {
        splatStrands(groom, withVoxelSize(1e-9));
        FAIL() << "voxel size 1e-9 was accepted";
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("GiB"), std::string::npos) << message;
        EXPECT_NE(message.find("budget"), std::string::npos) << message;
    }
    SplatOptions small;
    small.memoryBudgetBytes = 1 << 20;
    EXPECT_THROW(splatStrands(groom, small), InputError);
    small.memoryBudgetBytes = 1ull << 30;
    EXPECT_NO_THROW(splatStrands(groom, small));
}

TEST(Splat, AcceptsFineVoxelsThatFitTheBudget) {
    // At 700 voxels across, the bounding box's blocks, were they all full,
    // would need ~3 GiB; the hair of 1,000 strands needs far less and fits
    // 1 GiB.
    ProceduralGroomParams p;
    p.strands = 1000;
    const Groom groom = generateGroom(p);
    SplatOptions o = withVoxelSize(defaultVoxelSize(groom, 700));
    o.memoryBudgetBytes = 1ull << 30;
    const FiberGrid g = splatStrands(groom, o);
    EXPECT_LT(g.memoryBytes(), o.memoryBudgetBytes / 2);
    o.memoryBudgetBytes = g.memoryBytes() / 4;
    EXPECT_THROW(splatStrands(groom, o), InputError);
}

TEST(Splat, RefusesCoordinatesBeyondTheIndexSpace) {
    const Groom far = groomOf({{{1e6f, 0, 0}, {1e6f + 1, 0, 0}}});
    EXPECT_THROW(splatStrands(far, withVoxelSize(1e-4)), InputError);
}

TEST(Splat, RefusesVoxelsBelowOpenVdbsSmallestTransform) {
    // OpenVDB's linear transform needs h³ ≥ 3e-15: a groom small enough to
    // pass the memory check still cannot be voxelized at h = 1e-6.
    const Groom tiny = groomOf({{{0, 0, 0}, {1e-5f, 0, 0}}});
    EXPECT_THROW(splatStrands(tiny, withVoxelSize(1e-6)), InputError);
    EXPECT_THROW(splatStrands(Groom{}, withVoxelSize(1e-6)), InputError);
    EXPECT_NO_THROW(splatStrands(tiny, withVoxelSize(2e-5)));
}

TEST(Splat, StopsWhenInterrupted) {
    ProceduralGroomParams p;
    p.strands = 500;
    const Groom groom = generateGroom(p);
    requestInterrupt();
    EXPECT_THROW(splatStrands(groom, SplatOptions{}), Interrupted);
    clearInterrupt();
    EXPECT_NO_THROW(splatStrands(groom, SplatOptions{}));
}

TEST(Splat, RefusesNonFinitePoints) {
    Groom groom = groomOf({{{0, 0, 0}, {1, 0, 0}}, {{0, 1, 0}, {1, 1, 0}}});
    groom.points[3].y = std::nanf("");
    try {
        splatStrands(groom, SplatOptions{});
        FAIL() << "a NaN point was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("strand 1, point 1"), std::string::npos) << e.what();
    }
}

// ---------------------------------------------------------------------------
// Per-point diameters and fiber types (fiber_grid.h).

TEST(Splat, PerPointDiameterWeighsTheLengthDensityByDOverNominal) {
    const Groom plain = groomOf({{Vec3f(-0.31f, 0.02f, 0.0f), Vec3f(0.0f, 0.11f, 0.05f),
                                  Vec3f(0.29f, 0.0f, -0.04f)}});
    SplatOptions options = withVoxelSize(0.05);
    options.fiberScale.diameter = 1e-4f;
    const double length = test::exactLength(plain);
    // Twice the nominal diameter everywhere: twice the fibers.
    Groom thick = plain;
    thick.thickness.assign(3, 2e-4f);
    EXPECT_NEAR(test::splattedLength(splatStrands(thick, options)), 2 * length, 1e-5 * length);
    // Tapered 2D → D → 0: segment means 1.5 D and 0.5 D.
    Groom tapered = plain;
    tapered.thickness = {2e-4f, 1e-4f, 0.0f};
    const double l0 = glm::length(Vec3d(plain.points[1]) - Vec3d(plain.points[0]));
    const double l1 = glm::length(Vec3d(plain.points[2]) - Vec3d(plain.points[1]));
    EXPECT_NEAR(test::splattedLength(splatStrands(tapered, options)), 1.5 * l0 + 0.5 * l1,
                1e-5 * length);
    // The orientation is weighted the same way: D̄ = 0 on the second segment
    // leaves only the first one's direction.
    Groom firstOnly = plain;
    firstOnly.thickness = {1e-4f, 0.0f, 0.0f};
    const FiberGrid g = splatStrands(firstOnly, options);
    const Vec3d u0 = glm::normalize(Vec3d(plain.points[1]) - Vec3d(plain.points[0]));
    g.forEachVoxel(
        [&](std::size_t i, const Coord& c) { expectVecNear(g.orientation[i], u0, 1e-5, c); });
}

TEST(Splat, FiberTypesGetFractionsThatSumToOneAndSurviveTheVdbFile) {
    // Two crossing strands of types 0 and 2 (type 1 unused), and a strand
    // whose second segment changes type.
    Groom groom = groomOf({{Vec3f(-0.2f, 0.0f, 0.0f), Vec3f(0.2f, 0.0f, 0.0f)},
                           {Vec3f(0.0f, -0.2f, 0.01f), Vec3f(0.0f, 0.2f, 0.01f)},
                           {Vec3f(0.0f, 0.1f, -0.2f), Vec3f(0.0f, 0.1f, 0.0f),
                            Vec3f(0.0f, 0.1f, 0.2f)}});
    groom.fiberType = {0, 0, 2, 2, 0, 1, 1};
    const FiberGrid grid = splatStrands(groom, withVoxelSize(0.02));
    ASSERT_EQ(grid.fiberTypeCount(), 3u);
    double typeLength[3] = {0, 0, 0};
    const double h = grid.info.voxelSize;
    grid.forEachVoxel([&](std::size_t i, const Coord& c) {
        float sum = 0;
        for (std::size_t t = 0; t < 3; ++t) {
            const float f = grid.typeFraction[t][i];
            EXPECT_GE(f, 0.0f);
            sum += f;
            typeLength[t] += double(f) * double(grid.density[i]) * h * h * h;
        }
        EXPECT_NEAR(sum, 1.0f, 1e-5f) << c;
    });
    // Each type's splatted length is its segments' length.
    EXPECT_NEAR(typeLength[0], 0.4 + 0.2, 1e-4);
    EXPECT_NEAR(typeLength[1], 0.2, 1e-4);
    EXPECT_NEAR(typeLength[2], 0.4, 1e-4);
    // Untyped, the same groom has no fraction grids and the same density.
    Groom untyped = groom;
    untyped.fiberType.clear();
    const FiberGrid plain = splatStrands(untyped, withVoxelSize(0.02));
    EXPECT_TRUE(plain.typeFraction.empty());
    EXPECT_TRUE(test::sameBlocks(plain, grid));
    EXPECT_TRUE(test::sameBits(plain.density, grid.density));

    test::TempDir dir;
    writeFiberGrid(dir / "typed.vdb", grid);
    EXPECT_TRUE(test::sameFiberGrid(readFiberGrid(dir / "typed.vdb"), grid));
    // Deterministic for any thread count.
    EXPECT_TRUE(test::sameFiberGrid(test::splatWithThreads(groom, withVoxelSize(0.02), 1), grid));
}

} // namespace
} // namespace hairvox
