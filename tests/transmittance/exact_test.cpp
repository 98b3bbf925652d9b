#include "slab.h"

#include <hairvox/core/math.h>
#include <hairvox/transmittance/exact_global_term.h>

#include <gtest/gtest.h>

#include <cmath>

namespace hairvox {
namespace {

using test::constantTable;
using test::slabSettings;
constexpr float kDiameter = test::kSlabDiameter;

GlobalTerm evaluateAt(const GlobalTermModel& model, const Light& light, const Vec3f& p,
                      const Vec3f& tangent = Vec3f(1, 0, 0)) {
    GlobalTerm out;
    const GlobalTermQuery q{p, tangent};
    model.forLight(light)->evaluate({&q, 1}, {&out, 1});
    return out;
}

/// The slab seen by exact mode with density multiplier k: k·λ hairs per unit
/// volume at independent positions, so n, V, P and σ_f² take the Poisson
/// closed forms of k·n₁ crossings (issue 5's analytic slab).
void expectSlabMatchesPoissonClosedForms(float densityMultiplier) {
    const test::Slab slab;
    const Groom groom = slab.groom();
    const float aBar = 0.55f;
    ExactOptions options;
    options.rays = 64;
    options.radius = 0.004f;
    GlobalTermSettings s = slabSettings();
    s.fiberScale.densityMultiplier = densityMultiplier;
    const auto model = makeExactModel(groom, {constantTable(aBar, 0.02f)}, s, options);

    for (const Vec3f dir : {Vec3f(0, 1, 0), Vec3f(0.5f, 1, 0), Vec3f(0, 1, 0.6f),
                            Vec3f(-0.4f, 1, 0.4f), Vec3f(0.8f, 1, -0.2f)}) {
        const Vec3f omega = glm::normalize(dir);
        const auto light = model->forLight(Light::directional(omega));
        // Random points 5 mm below the slab (so that the tilted disk of ray
        // origins stays below it), far enough from the edges that no ray
        // leaves the slab sideways.
        std::vector<GlobalTermQuery> queries;
        Pcg32 rng(5);
        for (int i = 0; i < 400; ++i)
            queries.push_back(
                {Vec3f(rng.uniform(-0.015f, 0.015f), -0.005f, rng.uniform(-0.08f, 0.08f)),
                 Vec3f(1, 0, 0)});
        std::vector<GlobalTerm> out(queries.size());
        light->evaluate(queries, out);
        double n = 0, V = 0, P = 0, sigma2 = 0;
        for (const GlobalTerm& g : out) {
            n += double(g.n) / double(out.size());
            V += double(g.V) / double(out.size());
            P += double(g.P.r) / double(out.size());
            sigma2 += double(g.sigma2_f.r) / double(out.size());
        }
        const double nExpected = double(densityMultiplier) * slab.expectedN(omega, kDiameter);
        EXPECT_NEAR(n, nExpected, 0.03 * nExpected) << omega;
        EXPECT_NEAR(V, std::exp(-nExpected), 0.02) << omega;
        EXPECT_NEAR(P, std::exp(-nExpected * (1 - double(aBar))), 0.02) << omega;
        // Σβ̄² over the rays that crossed something: 0.02·n / (1 − e^{−n}).
        EXPECT_NEAR(sigma2, 0.02 * nExpected / -std::expm1(-nExpected), 0.04 * 0.02 * nExpected)
            << omega;
    }
}

TEST(ExactGlobalTerm, SlabMatchesPoissonClosedForms) {
    expectSlabMatchesPoissonClosedForms(1.0f);
}

// A modeled strand standing for k hairs is k hairs side by side (a ribbon k·D
// wide), not k hairs stacked on one spot: V falls as e^{−k·n₁}, as the grid
// and the rasterizer assume, instead of staying at e^{−n₁}.
TEST(ExactGlobalTerm, DensityMultiplierAddsIndependentHairs) {
    expectSlabMatchesPoissonClosedForms(2.0f);
    expectSlabMatchesPoissonClosedForms(0.5f);
}

TEST(ExactGlobalTerm, EmptySpaceIsExactlyUnoccluded) {
    const test::Slab slab;
    const auto model =
        makeExactModel(slab.groom(), {constantTable(0.5f, 0.01f)}, slabSettings(), {});
    // Above the slab looking up, and beside it looking sideways: nothing in front.
    for (const auto& [p, dir] : {std::pair{Vec3f(0, 0.05f, 0), Vec3f(0, 1, 0)},
                                 std::pair{Vec3f(0, 0.005f, 0.2f), Vec3f(0, 0, 1)}}) {
        const GlobalTerm g = evaluateAt(*model, Light::directional(dir), p);
        EXPECT_EQ(g.n, 0.0f);
        EXPECT_EQ(g.V, 1.0f);
        EXPECT_EQ(g.P, Rgb(1.0f));
        EXPECT_EQ(g.T_s, Rgb(0.0f));
        EXPECT_EQ(g.sigma2_f, Rgb(0.0f));
    }
}

TEST(ExactGlobalTerm, OwnFiberDoesNotShadowItself) {
    Groom groom;
    const Vec3f line[4] = {{0, 0, 0}, {0.01f, 0.002f, 0}, {0.02f, 0.001f, 0.003f}, {0.03f, 0, 0}};
    groom.addStrand(line);
    ExactOptions options;
    options.rays = 32;
    options.radius = 0.0005f;
    const auto model = makeExactModel(groom, {constantTable(0.5f, 0.01f)}, slabSettings(), options);
    for (float t : {0.1f, 0.5f, 0.99f}) {
        const Vec3f p = lerp(t, line[1], line[2]);
        for (const Vec3f dir :
             {Vec3f(0, 1, 0), Vec3f(1, 0.1f, 0), Vec3f(0.3f, -1, 0.2f), Vec3f(-1, -0.05f, 0)}) {
            const GlobalTerm g =
                evaluateAt(*model, Light::directional(dir), p, glm::normalize(line[2] - line[1]));
            EXPECT_EQ(g.n, 0.0f) << "t=" << t << " dir=" << dir;
        }
    }
}

TEST(ExactGlobalTerm, CurlComingBackCounts) {
    // A loop: the strand leaves the point along +x, turns, and crosses back
    // 2 mm above it; a light straight up sees that crossing, not its own fiber.
    Groom groom;
    const Vec3f curl[5] = {{-0.01f, 0, 0},
                           {0.01f, 0, 0},
                           {0.01f, 0.002f, 0.0005f},
                           {-0.01f, 0.002f, -0.0005f},
                           {-0.01f, 0.004f, 0}};
    groom.addStrand(curl);
    const auto model = makeExactModel(groom, {constantTable(0.5f, 0.01f)}, slabSettings(), {});
    for (const std::uint32_t hint : {kUnknownStrand, 0u}) {
        GlobalTerm g;
        const GlobalTermQuery q{Vec3f(0, 0, 0), Vec3f(1, 0, 0), hint};
        model->forLight(Light::directional(Vec3f(0, 1, 0)))->evaluate({&q, 1}, {&g, 1});
        EXPECT_EQ(g.n, 1.0f);
        EXPECT_NEAR(g.P.r, 0.5f, 1e-5f);
    }
}

TEST(ExactGlobalTerm, OccluderBlocksLight) {
    const test::Slab slab;
    GlobalTermSettings s = slabSettings();
    s.surfaces = std::make_shared<const SurfaceScene>(std::vector<Sphere>{{Vec3f(0, 0.05f, 0), 0.01f}},
                                                     std::vector<TriangleMesh>{});
    const auto model = makeExactModel(slab.groom(), {constantTable(0.5f, 0.01f)}, s, {});
    const auto light = model->forLight(Light::point(Vec3f(0, 0.1f, 0)));
    const GlobalTermQuery queries[2] = {{Vec3f(0, -0.001f, 0), Vec3f(1, 0, 0)},
                                        {Vec3f(0.04f, -0.001f, 0), Vec3f(1, 0, 0)}};
    GlobalTerm out[2];
    const GlobalTermStats stats = light->evaluate(queries, out);
    EXPECT_EQ(out[0].V, 0.0f);
    EXPECT_EQ(out[0].T_s, Rgb(0.0f));
    EXPECT_GT(out[1].n, 0.0f);
    EXPECT_EQ(stats.blockedBySurface, 1u);
}

TEST(ExactGlobalTerm, IndependentOfBatchingAndOrder) {
    const test::Slab slab;
    ExactOptions options;
    options.rays = 8;
    options.radius = 0.002f;
    const auto model =
        makeExactModel(slab.groom(), {constantTable(0.5f, 0.01f)}, slabSettings(), options);
    const auto light = model->forLight(Light::directional(Vec3f(0.3f, 1, 0.1f)));
    std::vector<GlobalTermQuery> queries;
    for (int i = 0; i < 50; ++i)
        queries.push_back({Vec3f(0.001f * float(i), 0.003f, 0.0f), Vec3f(1, 0, 0)});
    std::vector<GlobalTerm> all(queries.size());
    light->evaluate(queries, all);
    for (std::size_t i = 0; i < queries.size(); ++i) {
        GlobalTerm one;
        light->evaluate({&queries[queries.size() - 1 - i], 1}, {&one, 1});
        EXPECT_EQ(one.n, all[queries.size() - 1 - i].n);
        EXPECT_EQ(one.P, all[queries.size() - 1 - i].P);
    }
}

} // namespace
} // namespace hairvox

namespace hairvox {
namespace {

TEST(GlobalTermOccluder, PointLightInsideTheHeadReachesNothing) {
    const test::Slab slab;
    GlobalTermSettings s = slabSettings();
    s.surfaces = std::make_shared<const SurfaceScene>(std::vector<Sphere>{{Vec3f(0, 0.05f, 0), 0.01f}},
                                                     std::vector<TriangleMesh>{});
    const auto model = makeExactModel(slab.groom(), {constantTable(0.5f, 0.01f)}, s, {});
    EXPECT_TRUE(model->forLight(Light::point(Vec3f(0, 0.052f, 0)))->blocksEverything());
    EXPECT_FALSE(model->forLight(Light::point(Vec3f(0, 0.1f, 0)))->blocksEverything());
    EXPECT_FALSE(model->forLight(Light::directional(Vec3f(0, 1, 0)))->blocksEverything());
    s.surfaces.reset();
    EXPECT_FALSE(makeExactModel(slab.groom(), {constantTable(0.5f, 0.01f)}, s, {})
                     ->forLight(Light::point(Vec3f(0, 0.052f, 0)))
                     ->blocksEverything());
}

} // namespace
} // namespace hairvox
