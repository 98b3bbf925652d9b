// globalTermFromDepths (transmittance/global_term_model.h): the global term
// from expected optical depths under a Poisson model of crossings
// (docs/DESIGN.md §5), tested directly against its closed forms and limits.
#include <hairvox/core/rng.h>
#include <hairvox/transmittance/global_term_model.h>

#include <gtest/gtest.h>

#include <cmath>

namespace hairvox {
namespace {

TEST(GlobalTermFromDepths, PoissonClosedForms) {
    // n crossings on average, each attenuating by ā_f = 0.6 with variance β̄² = 0.01.
    const float n = 2.0f, aBar = 0.6f, beta2 = 0.01f, d_f = 0.7f;
    const GlobalTerm g = globalTermFromDepths(n, Rgb(n * (1 - aBar)), Rgb(n * beta2), d_f);
    EXPECT_FLOAT_EQ(g.n, n);
    EXPECT_NEAR(g.V, std::exp(-2.0f), 1e-7f);
    EXPECT_NEAR(g.P.g, std::exp(-0.8f), 1e-7f); // E[ā_f^m], m ~ Poisson(n)
    EXPECT_NEAR(g.T_s.b, d_f * (std::exp(-0.8f) - std::exp(-2.0f)), 1e-7f);
    EXPECT_NEAR(g.sigma2_f.r, n * beta2 / (1 - std::exp(-n)), 1e-7f); // conditioned on m ≥ 1
}

TEST(GlobalTermFromDepths, NothingInFrontIsUnoccluded) {
    const GlobalTerm g = globalTermFromDepths(0.0f, Rgb(0.0f), Rgb(0.0f), 0.7f);
    EXPECT_EQ(g.V, 1.0f);
    EXPECT_EQ(g.P, Rgb(1.0f));
    EXPECT_EQ(g.T_s, Rgb(0.0f));
    EXPECT_EQ(g.sigma2_f, Rgb(0.0f));
}

TEST(GlobalTermFromDepths, ContinuousAsNGoesToZero) {
    // T_s → 0 and σ_f² → the mean β̄² of the fibers in front as n → 0 (no jump).
    const float beta2 = 0.02f, aBar = 0.5f;
    for (const float n : {1e-2f, 1e-4f, 1e-6f, 1e-8f}) {
        const GlobalTerm g = globalTermFromDepths(n, Rgb(n * (1 - aBar)), Rgb(n * beta2), 0.7f);
        EXPECT_LE(g.T_s.r, 0.7f * n);
        EXPECT_NEAR(g.sigma2_f.g, beta2, 0.6f * beta2 * n + 1e-6f) << n;
        EXPECT_TRUE(g.sigma2_f.isFinite());
    }
}

TEST(GlobalTermFromDepths, TransmittanceIsNeverNegativeNorAboveDf) {
    Pcg32 rng(17);
    for (int i = 0; i < 10000; ++i) {
        const float n = 50.0f * rng.uniformFloat() * rng.uniformFloat();
        // Any tauP in [0, n]: per crossing the attenuation depth is 1 − ā_f ∈ [0, 1].
        const Rgb tauP(n * rng.uniformFloat(), n * rng.uniformFloat(), n * rng.uniformFloat());
        const float d_f = rng.uniformFloat();
        const GlobalTerm g = globalTermFromDepths(n, tauP, Rgb(0.01f * n), d_f);
        for (int c = 0; c < 3; ++c) {
            ASSERT_GE(g.T_s[c], 0.0f);
            ASSERT_LE(g.T_s[c], d_f);
            ASSERT_GE(g.P[c], g.V - 1e-7f); // P ≥ V: ā_f ≤ 1 per crossing
        }
        ASSERT_TRUE(g.sigma2_f.isFinite());
    }
}

TEST(GlobalTermFromDepths, DeepHairUnderflowsToBlackNotNaN) {
    const GlobalTerm g = globalTermFromDepths(1e4f, Rgb(5e3f), Rgb(1e2f), 0.7f);
    EXPECT_EQ(g.V, 0.0f);
    EXPECT_EQ(g.T_s, Rgb(0.0f));
    EXPECT_NEAR(g.sigma2_f.r, 100.0f, 1e-3f); // Σβ̄² over 10⁴ crossings of 0.01 rad²
}

} // namespace
} // namespace hairvox
