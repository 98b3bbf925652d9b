#include "slab.h"

#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/transmittance/exact_global_term.h>
#include <hairvox/transmittance/grid_global_term.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <span>

namespace hairvox {
namespace {

using test::constantTable;
using test::slabSettings;
constexpr float kDiameter = test::kSlabDiameter;

FiberGrid splat(const Groom& groom, double voxelSize) {
    SplatOptions options;
    options.voxelSize = voxelSize;
    options.storeOrientationTensor = true;
    return splatStrands(groom, options);
}

/// Compares a light's cached global term with its march at 50 random points
/// at each of `heights` in a slab's plane (x in ±1 cm, z in ±3 cm): n within
/// relative·n + absolute per point, each row's mean within 2%. Returns the
/// march's values.
std::vector<GlobalTerm> expectCacheMatchesMarch(const LightGlobalTerm& cached,
                                                const LightGlobalTerm& marched,
                                                std::span<const float> heights, std::uint64_t seed,
                                                float relative, float absolute,
                                                const std::string& what) {
    std::vector<GlobalTermQuery> queries;
    Pcg32 rng(seed);
    for (const float y : heights)
        for (int i = 0; i < 50; ++i)
            queries.push_back({Vec3f(rng.uniform(-0.01f, 0.01f), y, rng.uniform(-0.03f, 0.03f)),
                               Vec3f(1, 0, 0)});
    std::vector<GlobalTerm> a(queries.size()), b(queries.size());
    cached.evaluate(queries, a);
    marched.evaluate(queries, b);
    for (std::size_t row = 0; row < heights.size(); ++row) {
        double meanA = 0, meanB = 0;
        for (std::size_t i = 50 * row; i < 50 * (row + 1); ++i) {
            EXPECT_NEAR(a[i].n, b[i].n, relative * b[i].n + absolute)
                << what << " at " << queries[i].position;
            meanA += double(a[i].n) / 50;
            meanB += double(b[i].n) / 50;
        }
        EXPECT_NEAR(meanA, meanB, 0.02 * meanB + 0.01) << what << " row " << row;
    }
    return b;
}

TEST(GridGlobalTerm, SlabMatchesClosedForms) {
    const test::Slab slab;
    const FiberGrid grid = splat(slab.groom(), 0.002);
    const float aBar = 0.55f;
    for (const OrientationModel model :
         {OrientationModel::MeanTangent, OrientationModel::CoherenceBlend,
          OrientationModel::Tensor}) {
        GridOptions options;
        options.orientation = model;
        options.startOffset = 0;
        const auto gridModel =
            makeGridModel(grid, {constantTable(aBar, 0.02f)}, slabSettings(), options);
        for (const Vec3f dir : {Vec3f(0, 1, 0), Vec3f(0.5f, 1, 0), Vec3f(0, 1, 0.6f),
                                Vec3f(-0.4f, 1, 0.4f), Vec3f(0.8f, 1, -0.2f)}) {
            const Vec3f omega = glm::normalize(dir);
            const auto light = gridModel->forLight(Light::directional(omega));
            std::vector<GlobalTermQuery> queries;
            Pcg32 rng(5);
            for (int i = 0; i < 200; ++i)
                queries.push_back(
                    {Vec3f(rng.uniform(-0.015f, 0.015f), -0.005f, rng.uniform(-0.08f, 0.08f)),
                     Vec3f(1, 0, 0)});
            std::vector<GlobalTerm> out(queries.size());
            light->evaluate(queries, out);
            double n = 0, V = 0, P = 0;
            for (const GlobalTerm& g : out) {
                n += double(g.n) / double(out.size());
                V += double(g.V) / double(out.size());
                P += double(g.P.r) / double(out.size());
            }
            const double nExpected = slab.expectedN(omega, kDiameter);
            // The grid integrates the local density, so only the fiber
            // realization's density fluctuation (~1/sqrt(fibers per 2 mm)) remains.
            EXPECT_NEAR(n, nExpected, 0.02 * nExpected) << toString(model) << " " << omega;
            EXPECT_NEAR(V, std::exp(-nExpected), 0.01) << toString(model) << " " << omega;
            EXPECT_NEAR(P, std::exp(-nExpected * (1 - double(aBar))), 0.01)
                << toString(model) << " " << omega;
        }
    }
}

TEST(GridGlobalTerm, EmptySpaceIsExactlyUnoccluded) {
    const test::Slab slab;
    const FiberGrid grid = splat(slab.groom(), 0.002);
    for (const auto make : {&makeGridModel, &makeApproxModel}) {
        const auto model = make(grid, {constantTable(0.5f, 0.01f)}, slabSettings(), {});
        for (const auto& [p, dir] : {std::pair{Vec3f(0, 0.05f, 0), Vec3f(0, 1, 0)},
                                     std::pair{Vec3f(0, 0.005f, 0.2f), Vec3f(0, 0, 1)},
                                     std::pair{Vec3f(5, 5, 5), Vec3f(1, 1, 1)}}) {
            GlobalTerm g;
            const GlobalTermQuery q{p, Vec3f(1, 0, 0)};
            const GlobalTermStats stats =
                model->forLight(Light::directional(dir))->evaluate({&q, 1}, {&g, 1});
            EXPECT_EQ(g.n, 0.0f);
            EXPECT_EQ(g.V, 1.0f);
            EXPECT_EQ(g.P, Rgb(1.0f));
            EXPECT_EQ(g.T_s, Rgb(0.0f));
            EXPECT_EQ(g.sigma2_f, Rgb(0.0f));
            EXPECT_EQ(stats.emptyPaths, 1u) << "a path through empty space must not march";
        }
    }
}

TEST(GridGlobalTerm, CrossingCountIsSymmetric) {
    // From a below the slab toward b above it, and back: beyond both points
    // there is only empty space, so n(a → ω) = n(b → −ω).
    const test::Slab slab;
    const FiberGrid grid = splat(slab.groom(), 0.002);
    GridOptions options;
    options.evaluation = GridEvaluation::March; // the integrator itself, no cache interpolation
    const auto model = makeGridModel(grid, {constantTable(0.5f, 0.01f)}, slabSettings(), options);
    Pcg32 rng(9);
    for (int i = 0; i < 16; ++i) {
        const Vec3f a(rng.uniform(-0.01f, 0.01f), -0.004f, rng.uniform(-0.05f, 0.05f));
        const Vec3f b(rng.uniform(-0.01f, 0.01f), 0.014f, rng.uniform(-0.05f, 0.05f));
        const Vec3f omega = glm::normalize(b - a);
        GlobalTerm up, down;
        const GlobalTermQuery qa{a, Vec3f(1, 0, 0)}, qb{b, Vec3f(1, 0, 0)};
        model->forLight(Light::directional(omega))->evaluate({&qa, 1}, {&up, 1});
        model->forLight(Light::directional(-omega))->evaluate({&qb, 1}, {&down, 1});
        EXPECT_GT(up.n, 0.5f);
        EXPECT_NEAR(up.n, down.n, 1e-5f * up.n) << a << " " << b;
    }
}

TEST(GridGlobalTerm, CacheStoresNothingAcrossEmptySpaceAndAgreesWithTheMarch) {
    // Two slabs, one `gap` above the other, lit from above at a slant. The
    // light-space cache's lines change only inside the slabs: what it holds
    // must not grow with the empty space between them (dense lines did, as the
    // inside of a head at fine voxel sizes), and its lookups below, inside and
    // between the slabs must agree with the exact march.
    const test::Slab slab;
    const Vec3f omega = glm::normalize(Vec3f(0.1f, 1, 0.1f));
    std::size_t held[2] = {};
    for (int g = 0; g < 2; ++g) {
        const float gap = g == 0 ? 0.02f : 0.3f;
        const Groom lower = slab.groom();
        Groom groom = lower;
        for (std::size_t s = 0; s < lower.strandCount(); ++s) {
            const auto points = lower.strand(s);
            const Vec3f line[2] = {points[0] + Vec3f(0, gap, 0), points[1] + Vec3f(0, gap, 0)};
            groom.addStrand(line);
        }
        const FiberGrid grid = splat(groom, 0.002);
        GridOptions march;
        march.evaluation = GridEvaluation::March;
        const CrossingTable table = constantTable(0.5f, 0.01f);
        const auto cacheModel = makeGridModel(grid, {table}, slabSettings(), {});
        const auto marchModel = makeGridModel(grid, {table}, slabSettings(), march);
        const auto cached = cacheModel->forLight(Light::directional(omega));
        const auto marched = marchModel->forLight(Light::directional(omega));
        held[g] = cached->memoryBytes();
        // Per point, the lattice's interpolation of a noisy density (~16
        // fibers per voxel column) differs from the march by up to ~15% (a
        // slab missed would be 50%); over 50 points at one height it averages
        // out. The paths stay inside the slabs' sides.
        const float heights[] = {-0.004f, 0.005f, 0.01f + 0.5f * gap, gap + 0.005f};
        const std::vector<GlobalTerm> b = expectCacheMatchesMarch(
            *cached, *marched, heights, 3, 0.2f, 0.03f, strCat("gap ", gap));
        EXPECT_GT(b.front().n, 3.0f) << "below both slabs: both are crossed";
    }
    EXPECT_GT(held[0], 0u);
    EXPECT_LT(double(held[1]), 1.3 * double(held[0]))
        << "the cache grew with the empty space between the slabs: " << held[0] << " -> "
        << held[1] << " bytes";
}

TEST(GridGlobalTerm, CacheAgreesWithTheMarchUnderAPointLightAndAnAxisAlignedOne) {
    // The cache's lines are given the bricks whose values can reach them
    // (LightSpaceCache::build bins each brick's value box by the lattice's
    // lines): a brick left out is a shadow missed. A point light's lines
    // radiate from it (a perspective lattice); a light along an axis puts
    // lines on brick faces. Both must find what the march finds.
    const test::Slab slab;
    const FiberGrid grid = splat(slab.groom(), 0.002);
    GridOptions march;
    march.evaluation = GridEvaluation::March;
    const CrossingTable table = constantTable(0.5f, 0.01f);
    const auto cacheModel = makeGridModel(grid, {table}, slabSettings(), {});
    const auto marchModel = makeGridModel(grid, {table}, slabSettings(), march);
    for (const Light& light : {Light::point(Vec3f(0.004f, 0.4f, -0.01f)),
                               Light::directional(Vec3f(0, 1, 0))}) {
        // Per point the lattice's interpolation differs from the march by up
        // to a third near the slab's top face, where n is small (a brick left
        // out loses its whole 8-voxel span of the slab); over a row it averages out.
        const float heights[] = {-0.004f, 0.003f, 0.007f};
        const std::vector<GlobalTerm> b =
            expectCacheMatchesMarch(*cacheModel->forLight(light), *marchModel->forLight(light),
                                    heights, 5, 0.35f, 0.05f, strCat(light));
        EXPECT_GT(b.front().n, 1.5f) << light << ": below the slab, the slab is crossed";
    }
}

TEST(GridGlobalTerm, AQueryDoesNotDependOnItsBatch) {
    // The cache's lookups go in batches that prefetch together
    // (LightSpaceCache::lookup): a query's value must be the one it gets
    // alone, to the bit, wherever it falls in a batch (200 queries span
    // several, the last one partial), and whether or not its light is
    // nearer than the start offset (a point light among the fibers).
    const test::Slab slab;
    const FiberGrid grid = splat(slab.groom(), 0.002);
    const auto model = makeGridModel(grid, {constantTable(0.5f, 0.01f)}, slabSettings(), {});
    std::vector<GlobalTermQuery> queries;
    Pcg32 rng(11);
    for (int i = 0; i < 203; ++i)
        queries.push_back({Vec3f(rng.uniform(-0.01f, 0.01f), rng.uniform(-0.004f, 0.012f),
                                 rng.uniform(-0.03f, 0.03f)),
                           Vec3f(1, 0, 0)});
    for (const Light& light : {Light::directional(glm::normalize(Vec3f(0.2f, 1, 0.1f))),
                               Light::point(queries[7].position)}) {
        const auto term = model->forLight(light);
        std::vector<GlobalTerm> together(queries.size());
        term->evaluate(queries, together);
        for (std::size_t i = 0; i < queries.size(); ++i) {
            GlobalTerm alone;
            term->evaluate(std::span(queries).subspan(i, 1), std::span(&alone, 1));
            ASSERT_EQ(std::bit_cast<std::uint32_t>(alone.n), std::bit_cast<std::uint32_t>(together[i].n))
                << "query " << i << " at " << queries[i].position;
            for (int c = 0; c < 3; ++c)
                ASSERT_EQ(std::bit_cast<std::uint32_t>(alone.P[c]),
                          std::bit_cast<std::uint32_t>(together[i].P[c]))
                    << "query " << i << " channel " << c;
        }
    }
}

TEST(GridGlobalTerm, LightsSharingAWorkspaceAreThoseOfLightsPreparedAlone) {
    // A workspace hands one light's rates volume to the next, refilled: every
    // query of every light must get the bits it gets from a light prepared
    // alone — cache and march, grid and approx, directional and point lights
    // (a point light among the fibers: the march), in any order.
    const test::Slab slab;
    const FiberGrid grid = splat(slab.groom(), 0.002);
    std::vector<GlobalTermQuery> queries;
    Pcg32 rng(13);
    for (int i = 0; i < 150; ++i)
        queries.push_back({Vec3f(rng.uniform(-0.01f, 0.01f), rng.uniform(-0.004f, 0.012f),
                                 rng.uniform(-0.03f, 0.03f)),
                           Vec3f(1, 0, 0)});
    const Light lights[] = {Light::directional(glm::normalize(Vec3f(0.2f, 1, 0.1f))),
                            Light::point(queries[3].position),
                            Light::directional(glm::normalize(Vec3f(-0.6f, -1, 0.3f))),
                            Light::point(Vec3f(0.05f, 0.2f, -0.1f))};
    const auto bits = [](const GlobalTerm& g) {
        return std::array{
            std::bit_cast<std::uint32_t>(g.n),         std::bit_cast<std::uint32_t>(g.V),
            std::bit_cast<std::uint32_t>(g.P.r),       std::bit_cast<std::uint32_t>(g.P.g),
            std::bit_cast<std::uint32_t>(g.P.b),       std::bit_cast<std::uint32_t>(g.T_s.r),
            std::bit_cast<std::uint32_t>(g.sigma2_f.b)};
    };
    GridOptions march;
    march.evaluation = GridEvaluation::March;
    const CrossingTable table = constantTable(0.5f, 0.01f);
    for (const auto& model : {makeGridModel(grid, {table}, slabSettings(), {}),
                              makeGridModel(grid, {table}, slabSettings(), march),
                              makeApproxModel(grid, {table}, slabSettings(), {})}) {
        const std::unique_ptr<LightWorkspace> workspace = model->makeWorkspace();
        ASSERT_NE(workspace, nullptr);
        for (const Light& light : lights) {
            const auto shared = model->forLight(light, workspace.get());
            const auto alone = model->forLight(light);
            std::vector<GlobalTerm> a(queries.size()), b(queries.size());
            shared->evaluate(queries, a);
            alone->evaluate(queries, b);
            for (std::size_t i = 0; i < queries.size(); ++i)
                ASSERT_EQ(bits(a[i]), bits(b[i]))
                    << "query " << i << ": " << a[i] << " against " << b[i];
        }
    }
    // A workspace is its model's.
    const auto one = makeGridModel(grid, {table}, slabSettings(), {});
    const auto other = makeGridModel(grid, {table}, slabSettings(), {});
    const std::unique_ptr<LightWorkspace> workspace = one->makeWorkspace();
    EXPECT_THROW(static_cast<void>(other->forLight(lights[0], workspace.get())),
                 std::invalid_argument);
}

TEST(GridGlobalTerm, PoissonKeepsTransmittanceNonNegativeWhereGeometricCannot) {
    // Dark hair (ā_f < 1/e): the paper's ā_f^n drops below V = e^{−n}.
    const test::Slab slab;
    const FiberGrid grid = splat(slab.groom(), 0.002);
    GlobalTerm poisson, geometric;
    const GlobalTermQuery q{Vec3f(0, -0.005f, 0), Vec3f(1, 0, 0)};
    GridOptions options;
    options.estimator = AttenuationEstimator::Poisson;
    makeGridModel(grid, {constantTable(0.2f, 0.01f)}, slabSettings(), options)
        ->forLight(Light::directional(Vec3f(0, 1, 0)))
        ->evaluate({&q, 1}, {&poisson, 1});
    options.estimator = AttenuationEstimator::Geometric;
    makeGridModel(grid, {constantTable(0.2f, 0.01f)}, slabSettings(), options)
        ->forLight(Light::directional(Vec3f(0, 1, 0)))
        ->evaluate({&q, 1}, {&geometric, 1});
    EXPECT_GT(poisson.T_s.r, 0.0f);
    EXPECT_GT(poisson.P.r, poisson.V);
    EXPECT_LT(geometric.P.r, geometric.V); // the raw geometric form would make T_s negative
    EXPECT_EQ(geometric.T_s.r, 0.0f);      // and is clamped
}

/// Mean P (red) of the global term straight up, from 400 points below the slab.
double meanPBelowSlab(const GlobalTermModel& model) {
    const auto light = model.forLight(Light::directional(Vec3f(0, 1, 0)));
    std::vector<GlobalTermQuery> queries;
    Pcg32 rng(5);
    for (int i = 0; i < 400; ++i)
        queries.push_back({Vec3f(rng.uniform(-0.015f, 0.015f), -0.005f, rng.uniform(-0.08f, 0.08f)),
                           Vec3f(1, 0, 0)});
    std::vector<GlobalTerm> out(queries.size());
    light->evaluate(queries, out);
    double P = 0;
    for (const GlobalTerm& g : out)
        P += double(g.P.r) / double(out.size());
    return P;
}

// Two fiber types in one slab: crossings are Poisson with each type half the
// time, so E[∏ā_f] = exp(−n·(1 − (ā_0 + ā_1)/2)). Exact mode attenuates each
// crossing by its own type, the grid mixes the types' rates by the splatted
// fractions; both must find the mixture, and a slab of type 1 only must find
// ā_1 alone (the type is read, not assumed).
TEST(GridGlobalTerm, FiberTypesMixTheirRatesAsExactModeFindsThem) {
    const test::Slab slab;
    const float a0 = 0.9f, a1 = 0.2f;
    const CrossingTables tables{constantTable(a0, 0.01f), constantTable(a1, 0.01f)};
    const double n = slab.expectedN(Vec3f(0, 1, 0), kDiameter);
    Groom mixed = slab.groom();
    mixed.fiberType.resize(mixed.pointCount());
    for (std::size_t i = 0; i < mixed.pointCount(); ++i)
        mixed.fiberType[i] = static_cast<std::uint8_t>((i / 2) % 2); // strand by strand
    Groom allType1 = slab.groom();
    allType1.fiberType.assign(allType1.pointCount(), 1);
    // allType1: type 0 is declared (two tables) but no fiber has it.
    for (const auto& [groom, aMean] :
         {std::pair<const Groom&, double>{mixed, 0.5 * (double(a0) + double(a1))},
          std::pair<const Groom&, double>{allType1, double(a1)}}) {
        const double expected = std::exp(-n * (1.0 - aMean));
        const FiberGrid grid = splat(groom, 0.002);
        ASSERT_EQ(grid.fiberTypeCount(), 2u);
        GridOptions options;
        options.startOffset = 0;
        EXPECT_NEAR(meanPBelowSlab(*makeGridModel(grid, tables, slabSettings(), options)),
                    expected, 0.01)
            << "grid, mean a_f " << aMean;
        ExactOptions exact;
        exact.rays = 64;
        exact.radius = 0.004f;
        EXPECT_NEAR(meanPBelowSlab(*makeExactModel(groom, tables, slabSettings(), exact)),
                    expected, 0.02)
            << "exact, mean a_f " << aMean;
    }
    // One table for a two-type groom is refused.
    EXPECT_THROW(makeExactModel(mixed, {constantTable(a0, 0.01f)}, slabSettings(), {}),
                 InputError);
}

} // namespace
} // namespace hairvox
