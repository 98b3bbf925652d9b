// The global term sampled along the fibers (alongFibers()): what a query gets
// is the linear interpolation of the two samples around it on its segment,
// whatever batch it comes in; queries without a segment are evaluated as
// they are; and on a real grid the interpolation stays within the grid's own
// resolution of evaluating every point.
#include "slab.h"

#include <hairvox/core/rng.h>
#include <hairvox/transmittance/grid_global_term.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>

namespace hairvox {
namespace {

/// A global term that is a smooth function of the position (so that the
/// interpolation is visible), counting what it evaluates.
class FieldGlobalTerm final : public LightGlobalTerm {
public:
    GlobalTermStats evaluate(std::span<const GlobalTermQuery> queries,
                             std::span<GlobalTerm> out) const override {
        for (std::size_t i = 0; i < queries.size(); ++i) {
            const Vec3f& p = queries[i].position;
            GlobalTerm& g = out[i];
            g.n = 2.0f + std::sin(40.0f * p.x) + p.y * p.y;
            g.V = std::exp(-g.n);
            g.P = Rgb(std::exp(-0.3f * g.n));
            g.T_s = g.P - Rgb(g.V);
            g.sigma2_f = Rgb(0.01f + 0.001f * p.z);
        }
        evaluated += queries.size();
        GlobalTermStats stats;
        stats.queries = stats.evaluated = queries.size();
        return stats;
    }
    mutable std::size_t evaluated = 0;
};

/// Two strands of long segments along x, and queries on them at random t.
struct Fixture {
    Fixture() {
        const Vec3f a[3] = {{0, 0, 0}, {0.1f, 0, 0}, {0.2f, 0.01f, 0}};
        const Vec3f b[2] = {{0, 0.05f, 0.02f},
                            {0.003f, 0.05f, 0.02f}}; // shorter than a sample spacing
        groom.addStrand(a);
        groom.addStrand(b);
        Pcg32 rng(3);
        for (std::uint32_t segment : {0u, 1u, 3u})
            for (int k = 0; k < 40; ++k) {
                const float t = rng.uniformFloat();
                const Vec3f p0 = groom.points[segment], p1 = groom.points[segment + 1];
                queries.push_back({p0 + t * (p1 - p0), glm::normalize(p1 - p0),
                                   segment == 3 ? 1u : 0u, true, 0, segment});
            }
    }
    Groom groom;
    std::vector<GlobalTermQuery> queries;
};

std::uint32_t bitsOf(float x) {
    return std::bit_cast<std::uint32_t>(x);
}

TEST(AlongFibers, InterpolatesBetweenSamplesOnTheSegment) {
    const Fixture f;
    constexpr float spacing = 0.01f; // 10 samples along the 0.1 segments, one on the short one
    auto inner = std::make_unique<FieldGlobalTerm>();
    const FieldGlobalTerm& field = *inner;
    const auto sampled = alongFibers(std::move(inner), f.groom, spacing);
    std::vector<GlobalTerm> out(f.queries.size());
    const GlobalTermStats stats = sampled->evaluate(f.queries, out);
    EXPECT_EQ(stats.queries, f.queries.size());
    EXPECT_EQ(stats.evaluated, field.evaluated);
    EXPECT_LT(field.evaluated, f.queries.size() / 2) << "dense runs share their samples";

    const FieldGlobalTerm reference;
    for (std::size_t i = 0; i < f.queries.size(); ++i) {
        const GlobalTermQuery& q = f.queries[i];
        const Vec3f p0 = f.groom.points[q.segment], d = f.groom.points[q.segment + 1] - p0;
        const int m = std::max(1, int(std::ceil(glm::length(d) / spacing)));
        const float x = glm::dot(q.position - p0, d) / glm::dot(d, d) * float(m);
        const int k = std::min(int(x), m - 1);
        GlobalTermQuery s0 = q, s1 = q;
        s0.position = p0 + (float(k) / float(m)) * d;
        s1.position = p0 + (float(k + 1) / float(m)) * d;
        GlobalTerm g0, g1;
        reference.evaluate({&s0, 1}, {&g0, 1});
        reference.evaluate({&s1, 1}, {&g1, 1});
        const float w = x - float(k);
        EXPECT_NEAR(out[i].n, g0.n + w * (g1.n - g0.n), 1e-5f) << "query " << i;
        EXPECT_NEAR(out[i].V, g0.V + w * (g1.V - g0.V), 1e-6f) << "query " << i;
        EXPECT_NEAR(out[i].T_s.g, g0.T_s.g + w * (g1.T_s.g - g0.T_s.g), 1e-6f) << "query " << i;
        EXPECT_NEAR(out[i].sigma2_f.b, g0.sigma2_f.b + w * (g1.sigma2_f.b - g0.sigma2_f.b), 1e-8f);
    }
}

TEST(AlongFibers, AQueryGetsTheSameBitsInAnyBatch) {
    // Dense runs, sparse runs (a query alone on its segment), shuffled order
    // (runs broken up), batches of one: the interpolation uses the same two
    // samples every time.
    const Fixture f;
    const auto sampled = alongFibers(std::make_unique<FieldGlobalTerm>(), f.groom, 0.01f);
    std::vector<GlobalTerm> whole(f.queries.size());
    sampled->evaluate(f.queries, whole);

    std::vector<std::size_t> order(f.queries.size());
    std::iota(order.begin(), order.end(), 0);
    Pcg32 rng(9);
    for (std::size_t i = order.size(); i > 1; --i)
        std::swap(order[i - 1], order[std::min(i - 1, std::size_t(rng.uniformFloat() * float(i)))]);
    std::vector<GlobalTermQuery> shuffled;
    for (std::size_t i : order)
        shuffled.push_back(f.queries[i]);
    std::vector<GlobalTerm> out(shuffled.size());
    sampled->evaluate(shuffled, out);
    for (std::size_t j = 0; j < order.size(); ++j) {
        GlobalTerm alone;
        sampled->evaluate({&f.queries[order[j]], 1}, {&alone, 1});
        for (const GlobalTerm* g : {&out[j], &alone}) {
            EXPECT_EQ(bitsOf(g->n), bitsOf(whole[order[j]].n)) << "query " << order[j];
            EXPECT_EQ(bitsOf(g->V), bitsOf(whole[order[j]].V)) << "query " << order[j];
            EXPECT_EQ(bitsOf(g->T_s.r), bitsOf(whole[order[j]].T_s.r)) << "query " << order[j];
        }
    }
}

TEST(AlongFibers, ConsecutiveSegmentsShareTheirVertexWithTheSameBits) {
    // Queries along segments 0 and 1 of a strand, in order, then segment 3
    // of the other strand: with shared vertices the sample at point 1 (the
    // end of segment 0's run, the start of segment 1's) is evaluated once,
    // and every query gets the same bits as without sharing, since the
    // samples at t = 0 and 1 are the vertices themselves.
    Fixture f; // its queries come segment by segment
    // A query at each end of both long segments, so that the runs meet at
    // the vertex between them.
    for (std::uint32_t segment : {0u, 1u})
        for (float t : {0.0f, 1.0f}) {
            const Vec3f p0 = f.groom.points[segment], p1 = f.groom.points[segment + 1];
            GlobalTermQuery q{t == 1.0f ? p1 : p0, glm::normalize(p1 - p0), 0u, true, 0, segment};
            const auto at =
                std::find_if(f.queries.begin(), f.queries.end(),
                             [&](const GlobalTermQuery& o) { return o.segment > segment; });
            f.queries.insert(at, q);
        }
    auto separateInner = std::make_unique<FieldGlobalTerm>();
    auto sharedInner = std::make_unique<FieldGlobalTerm>();
    const FieldGlobalTerm& separateField = *separateInner;
    const FieldGlobalTerm& sharedField = *sharedInner;
    const auto separate = alongFibers(std::move(separateInner), f.groom, 0.01f, false);
    const auto shared = alongFibers(std::move(sharedInner), f.groom, 0.01f, true);
    std::vector<GlobalTerm> a(f.queries.size()), b(f.queries.size());
    separate->evaluate(f.queries, a);
    shared->evaluate(f.queries, b);
    EXPECT_EQ(sharedField.evaluated + 1, separateField.evaluated);
    for (std::size_t i = 0; i < f.queries.size(); ++i) {
        EXPECT_EQ(bitsOf(a[i].n), bitsOf(b[i].n)) << "query " << i;
        EXPECT_EQ(bitsOf(a[i].V), bitsOf(b[i].V)) << "query " << i;
        EXPECT_EQ(bitsOf(a[i].sigma2_f.g), bitsOf(b[i].sigma2_f.g)) << "query " << i;
    }
}

TEST(AlongFibers, PointsOffTheFibersAreEvaluatedAsTheyAre) {
    const Fixture f;
    const auto sampled = alongFibers(std::make_unique<FieldGlobalTerm>(), f.groom, 0.01f);
    const FieldGlobalTerm reference;
    std::vector<GlobalTermQuery> queries = f.queries;
    queries[3].segment = kUnknownSegment; // a point the caller did not place on a segment
    queries[4].onFiber = false;           // a point on a surface
    queries[5].segment = 1000;            // not a segment of this groom
    std::vector<GlobalTerm> out(queries.size());
    sampled->evaluate(queries, out);
    for (std::size_t i : {3u, 4u, 5u}) {
        GlobalTerm g;
        reference.evaluate({&queries[i], 1}, {&g, 1});
        EXPECT_EQ(bitsOf(out[i].n), bitsOf(g.n)) << "query " << i;
    }
    // Spacing 0 is no sampling at all.
    const auto unsampled = alongFibers(std::make_unique<FieldGlobalTerm>(), f.groom, 0.0f);
    EXPECT_NE(dynamic_cast<const FieldGlobalTerm*>(unsampled.get()), nullptr);
}

TEST(AlongFibers, GridSampledAVoxelApartMatchesEveryPoint) {
    // Fibers of a slab seen by a light across them: the grid's global term at
    // points along the fibers, sampled a voxel apart and interpolated, against
    // evaluating every point. The difference is far below the grid's own
    // error against exact mode (MAE(V) ~0.01, README).
    const test::Slab slab;
    const Groom groom = slab.groom();
    SplatOptions splat;
    splat.voxelSize = 0.002;
    const FiberGrid grid = splatStrands(groom, splat);
    GlobalTermSettings settings = test::slabSettings();
    settings.groom = &groom;
    GridOptions every, sampled;
    every.fiberSampleSpacing = 0;
    sampled.fiberSampleSpacing = 1;
    const Light light = Light::directional(glm::normalize(Vec3f(0.3f, 1, 0.2f)));
    const auto everyModel =
        makeGridModel(grid, {test::constantTable(0.6f, 0.02f)}, settings, every);
    const auto sampledModel =
        makeGridModel(grid, {test::constantTable(0.6f, 0.02f)}, settings, sampled);
    const auto a = everyModel->forLight(light);
    const auto b = sampledModel->forLight(light);
    // Runs of points along 200 fibers, as a rasterizer hands them over.
    std::vector<GlobalTermQuery> queries;
    for (std::uint32_t s = 0; s < 200; ++s) {
        const std::uint32_t k = groom.strandStart[s * 40];
        const Vec3f p0 = groom.points[k], p1 = groom.points[k + 1];
        for (int j = 0; j < 200; ++j)
            queries.push_back({p0 + (float(j) / 200.0f) * (p1 - p0), glm::normalize(p1 - p0),
                               s * 40, true, 0, k});
    }
    std::vector<GlobalTerm> exact(queries.size()), interpolated(queries.size());
    a->evaluate(queries, exact);
    const GlobalTermStats stats = b->evaluate(queries, interpolated);
    EXPECT_LT(stats.evaluated * 3, stats.queries);
    double meanAbsV = 0, meanV = 0;
    for (std::size_t i = 0; i < queries.size(); ++i) {
        meanAbsV +=
            std::abs(double(exact[i].V) - double(interpolated[i].V)) / double(queries.size());
        meanV += double(exact[i].V) / double(queries.size());
    }
    EXPECT_GT(meanV, 0.05);
    EXPECT_LT(meanAbsV, 0.003) << "mean V " << meanV;
}

} // namespace
} // namespace hairvox
