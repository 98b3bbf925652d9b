#include <hairvox/core/math.h>
#include <hairvox/transmittance/crossing_table.h>

#include <gtest/gtest.h>

namespace hairvox {
namespace {

TEST(CrossingTable, RatesAndIsotropicAverages) {
    // ā_f = 0.6 and β̄_f² = 0.01 everywhere: every rate is cos θ times a constant.
    const CrossingTable table = CrossingTable::build([](float) { return Rgb(0.6f); },
                                                     [](float) { return Rgb(0.01f); });
    for (float s : {-1.0f, -0.7f, 0.0f, 0.3f, 0.999f, 1.0f}) {
        const CrossingTable::Rates r = table.rates(s);
        EXPECT_NEAR(r.cosTheta, std::sqrt(1 - s * s), 1e-6f);
        EXPECT_NEAR(r.wAbsorb.g, 0.4f * r.cosTheta, 1e-6f);
        EXPECT_NEAR(r.wLogA.b, -std::log(0.6f) * r.cosTheta, 1e-6f);
        EXPECT_NEAR(r.wBeta2.r, 0.01f * r.cosTheta, 1e-7f);
        EXPECT_NEAR(table.crossing(s).logABar_f.r, std::log(0.6f), 1e-6f);
    }
    // ½∫_{−1}^{1} sqrt(1 − s²) ds = π/4.
    EXPECT_NEAR(table.isotropicRates().cosTheta, Pi / 4, 1e-4);
    EXPECT_NEAR(table.isotropicRates().wAbsorb.r, 0.4 * Pi / 4, 1e-4);
}

TEST(CrossingTable, InterpolatesAngleDependenceAndClampsOpaqueFibers) {
    const CrossingTable table = CrossingTable::build(
        [](float theta) { return Rgb(0.5f + 0.4f * std::cos(theta), 0.0f, 1.0f); },
        [](float theta) { return Rgb(theta * theta); });
    for (float s = -1.0f; s <= 1.0f; s += 0.01f) {
        const float theta = std::asin(std::clamp(s, -1.0f, 1.0f));
        const CrossingTable::Values v = table.crossing(s);
        EXPECT_NEAR(v.logABar_f.r, std::log(0.5f + 0.4f * std::cos(theta)), 1e-5f) << s;
        EXPECT_TRUE(std::isfinite(v.logABar_f.g)) << "ā_f = 0 must stay finite in log space";
        EXPECT_LT(v.logABar_f.g, -60.0f);
        EXPECT_EQ(v.logABar_f.b, 0.0f);
        EXPECT_NEAR(v.beta2Bar_f.r, theta * theta, 1e-5f + 1e-5f * theta * theta) << s;
    }
}

} // namespace
} // namespace hairvox
