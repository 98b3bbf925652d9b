// Numerical stress of the shading stage: millions of evaluations of f_s (table
// and exact), the dual-scattering tables and the full shader over random and
// extreme inputs — every output finite and ≥ 0.
#include "shading_test_util.h"

#include <hairvox/core/rng.h>
#include <hairvox/shading/azimuthal.h>
#include <hairvox/shading/dual_scattering_shader.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace hairvox {
namespace {

bool finiteNonNegative(const Rgb& c) { return c.isFinite() && c.minComponent() >= 0.0f; }

bool finiteNonNegative(const ShadeResult& r) {
    return finiteNonNegative(r.directR) && finiteNonNegative(r.directTT) &&
           finiteNonNegative(r.directTRT) && finiteNonNegative(r.backDirect) &&
           finiteNonNegative(r.scatter) && finiteNonNegative(r.total());
}

/// Parameter sets at the corners of the valid ranges (not the full product:
/// each set builds its tables).
std::vector<FiberParams> extremeParams() {
    std::vector<FiberParams> sets;
    const float sigmas[] = {0.0f, 1e-8f, 50.0f};
    const float betas[] = {0.5f, 30.0f};
    int k = 0;
    for (float sigma : sigmas)
        for (float beta : betas) {
            FiberParams p;
            p.sigma_a = Rgb(sigma);
            p.beta_R = radians(beta);
            p.alpha_R = radians(k % 3 == 0 ? -20.0f : (k % 3 == 1 ? 0.0f : 20.0f));
            p.eta = k % 2 == 0 ? 1.1f : 2.5f;
            sets.push_back(p);
            ++k;
        }
    FiberParams mixed;
    mixed.sigma_a = Rgb(0.0f, 1e-8f, 50.0f);
    mixed.eccentricity = 0.5f;
    mixed.causticWidth = radians(1.0f);
    mixed.causticFade = 0.01f;
    mixed.causticGain = 10.0f;
    mixed.causticMaxWidth = 2.0f;
    sets.push_back(mixed);
    FiberParams wide;
    wide.beta_R = radians(45.0f);
    wide.causticWidth = radians(45.0f);
    wide.causticFade = 1.0f;
    wide.causticMaxWidth = 0.01f;
    wide.eccentricity = 0.85f;
    sets.push_back(wide);
    sets.push_back(FiberParams{});
    return sets;
}

/// Directions that hit the special cases: along ±u, in the normal plane, and
/// azimuths 0, ±π (exactly opposite or equal projections).
std::vector<Vec3f> extremeDirections(const Vec3f& u) {
    std::vector<Vec3f> d{u, -u};
    for (double theta : {-PiOver2, -1.5, -0.3, 0.0, 0.3, 1.5, PiOver2})
        for (double phi : {-Pi, -PiOver2, 0.0, PiOver2, Pi})
            d.push_back(test::fiberDirection(u, theta, phi));
    return d;
}

Vec3f randomDirection(Pcg32& rng) {
    const float z = rng.uniform(-1, 1), a = rng.uniform(0, float(TwoPi));
    const float r = std::sqrt(std::max(0.0f, 1 - z * z));
    return {r * std::cos(a), r * std::sin(a), z};
}

GlobalTerm randomGlobalTerm(Pcg32& rng, const DualScatteringTables& t, float theta) {
    GlobalTerm g;
    // n over [0, 1e4], log-uniform, with exact zeros.
    const float u = rng.uniformFloat();
    g.n = u < 0.1f ? 0.0f : std::pow(10.0f, rng.uniform(-8, 4));
    g.V = std::exp(-g.n);
    const Rgb aBar_f = clamp(t.aBar_f(theta), 1e-30f, 1.0f);
    // Poisson or the paper's ā_f^n, products in log space.
    g.P = rng.uniformFloat() < 0.5f ? exp(-g.n * (Rgb(1.0f) - aBar_f)) : exp(g.n * log(aBar_f));
    g.T_s = 0.7f * max(g.P - Rgb(g.V), Rgb(0.0f));
    g.sigma2_f = Rgb(rng.uniform(0, 10), rng.uniform(0, 10), rng.uniform(0, 10));
    if (rng.uniformFloat() < 0.1f)
        g.sigma2_f = Rgb(0.0f);
    return g;
}

TEST(ShadingStressSlow, EveryOutputFiniteAndNonNegative) {
    Pcg32 rng(2024);
    long fsEvaluations = 0, exactEvaluations = 0, tableLookups = 0, shades = 0;
    for (const FiberParams& params : extremeParams()) {
        SCOPED_TRACE(::testing::Message() << params);
        const MarschnerBcsdf bcsdf(params);
        const DualScatteringTables tables = DualScatteringTables::build(params);
        const DualScatteringShader shader(bcsdf, tables, DualScatteringParams{});

        // Tables: random θ, the ends, beyond them and NaN.
        std::vector<float> thetas{-float(PiOver2), float(PiOver2), -10.0f, 10.0f,
                                  std::numeric_limits<float>::quiet_NaN()};
        for (int k = 0; k < 130000; ++k)
            thetas.push_back(rng.uniform(-1.6f, 1.6f));
        for (float theta : thetas) {
            const DualScatteringTables::Sample s = tables.lookup(theta);
            ASSERT_TRUE(finiteNonNegative(s.aBar_f) && finiteNonNegative(s.aBar_b) &&
                        finiteNonNegative(s.ABar_b) && finiteNonNegative(s.sigma2Bar_b) &&
                        finiteNonNegative(s.beta2Bar_f) &&
                        finiteNonNegative(tables.NG(theta, 3.0f * theta).sum()))
                << s;
            ASSERT_TRUE(s.DeltaBar_b.isFinite() && s.alphaBar_f.isFinite()) << s;
            ASSERT_TRUE(finiteNonNegative(tables.aBar_f(theta)) && finiteNonNegative(tables.beta2Bar_f(theta)));
            tableLookups += 3;
        }

        // f_s and the shader at the extreme directions, for several tangents.
        for (const Vec3f& u : {Vec3f(0, 0, 1), Vec3f(0, 1, 0), glm::normalize(Vec3f(1, -2, 3))}) {
            const std::vector<Vec3f> dirs = extremeDirections(u);
            for (const Vec3f& wi : dirs)
                for (const Vec3f& wo : dirs) {
                    const FiberAngles a = FiberAngles::fromDirections(wi, wo, u);
                    ASSERT_TRUE(finiteNonNegative(bcsdf.eval(a).sum())) << a;
                    ASSERT_TRUE(finiteNonNegative(bcsdf.evalExact(a).sum())) << a;
                    for (float n : {0.0f, 1e-7f, 1.0f, 1e4f}) {
                        GlobalTerm g;
                        g.n = n;
                        g.V = std::exp(-n);
                        g.P = exp(n * log(clamp(tables.aBar_f(a.theta_i), 1e-30f, 1.0f)));
                        g.T_s = 0.7f * max(g.P - Rgb(g.V), Rgb(0.0f));
                        for (float s2 : {0.0f, 10.0f}) {
                            g.sigma2_f = Rgb(s2);
                            ASSERT_TRUE(finiteNonNegative(shader.shade(a, g))) << a << " " << g;
                            ++shades;
                        }
                    }
                    fsEvaluations += 1;
                    exactEvaluations += 1;
                }
        }

        // Random directions: tabulated f_s and the full shader.
        for (int k = 0; k < 110000; ++k) {
            const Vec3f u = randomDirection(rng), wi = randomDirection(rng), wo = randomDirection(rng);
            const FiberAngles a = FiberAngles::fromDirections(wi, wo, u);
            const LobeValues f = bcsdf.eval(a);
            ASSERT_TRUE(finiteNonNegative(f.R) && finiteNonNegative(f.TT) && finiteNonNegative(f.TRT)) << a;
            const GlobalTerm g = randomGlobalTerm(rng, tables, a.theta_i);
            ASSERT_GE(g.T_s.minComponent(), 0.0f);
            ASSERT_TRUE(finiteNonNegative(shader.shade(wi, wo, u, g))) << a << " " << g;
            ++fsEvaluations;
            ++shades;
        }

        // Exact azimuthal functions: random angles, φ ∈ {0, ±π}, h → ±1 (R at
        // |φ| → π, TT at its azimuthal edge), and η' = 2 ± 1e-7 for TRT.
        std::vector<double> phis{0.0, Pi, -Pi, Pi - 1e-12, -Pi + 1e-12, 1e-12};
        const double edgeTT = 2 * std::asin(1 / double(params.eta)); // TT exit at h = ±1, θ_d = 0
        for (double e : {0.0, 1e-9, 1e-6})
            phis.push_back(edgeTT + e);
        std::vector<double> thetaDs{0.0, PiOver2, -PiOver2, 1.0};
        if (params.eta < 2.0f)
            for (double d : {-1e-7, 0.0, 1e-7}) {
                const double eta = params.eta, etaPrime = 2.0 + d;
                thetaDs.push_back(std::acos(std::sqrt((eta * eta - 1) / (etaPrime * etaPrime - 1))));
            }
        for (double theta_d : thetaDs)
            for (double phi : phis)
                for (double c2 : {-1.0, 0.0, 1.0}) {
                    const LobeValues n = bcsdf.NExact(theta_d, phi, c2);
                    ASSERT_TRUE(finiteNonNegative(n.sum())) << theta_d << " " << phi;
                    ASSERT_TRUE(finiteNonNegative(bcsdf.N(float(theta_d), float(phi), float(c2)).sum()));
                    ++exactEvaluations;
                }
        for (int k = 0; k < 8000; ++k) {
            const FiberAngles a = FiberAngles::fromAngles(rng.uniform(-1.571f, 1.571f),
                                                          rng.uniform(-1.571f, 1.571f),
                                                          rng.uniform(-3.2f, 3.2f), rng.uniform(-3.2f, 3.2f));
            ASSERT_TRUE(finiteNonNegative(bcsdf.evalExact(a).sum())) << a;
            ++exactEvaluations;
        }
    }
    RecordProperty("fs_evaluations", std::to_string(fsEvaluations));
    RecordProperty("exact_evaluations", std::to_string(exactEvaluations));
    RecordProperty("table_lookups", std::to_string(tableLookups));
    RecordProperty("shades", std::to_string(shades));
    EXPECT_GE(fsEvaluations, 1000000);
    EXPECT_GE(tableLookups, 1000000);
    EXPECT_GE(shades, 1000000);
    EXPECT_GE(exactEvaluations, 50000);
}

} // namespace
} // namespace hairvox
