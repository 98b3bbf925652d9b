// core/distribution.h: sampling by inversion never lands on an interval of
// weight 0, whatever the cumulative sum rounds to; densities integrate to one.
#include <hairvox/core/distribution.h>
#include <hairvox/core/rng.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace hairvox {
namespace {

TEST(PiecewiseConstant1D, NeverSamplesAnIntervalOfWeightZero) {
    // Weights whose normalised sum rounds below 1 before the trailing zeros
    // (the case a compiler's contraction turned into a sample of density 0).
    const std::vector<float> f = {0.1f, 0.7f, 0.3f, 0.0f, 0.0f, 0.9f, 0.0f, 0.0f};
    const PiecewiseConstant1D d(f);
    Pcg32 rng(3);
    for (int k = 0; k < 100000; ++k) {
        const float u = k < 2 ? (k == 0 ? 0.0f : std::nextafter(1.0f, 0.0f)) : rng.uniformFloat();
        const PiecewiseConstant1D::Sample s = d.sample(u);
        ASSERT_GT(f[s.index], 0.0f) << "u = " << u;
        ASSERT_GT(s.pdf, 0.0f);
        ASSERT_EQ(s.pdf, d.pdf(s.index));
        ASSERT_GE(s.x, float(s.index) / float(f.size()));
        ASSERT_LT(s.x, float(s.index + 1) / float(f.size()));
    }
    double integral = 0;
    for (std::size_t i = 0; i < f.size(); ++i)
        integral += double(d.pdf(i)) / double(f.size());
    EXPECT_NEAR(integral, 1.0, 1e-6);
}

TEST(PiecewiseConstant1D, AZeroFunctionIsUniform) {
    const std::vector<float> f(5, 0.0f);
    const PiecewiseConstant1D d(f);
    EXPECT_EQ(d.integral(), 0.0);
    for (const float u : {0.0f, 0.3f, std::nextafter(1.0f, 0.0f)}) {
        const PiecewiseConstant1D::Sample s = d.sample(u);
        EXPECT_FLOAT_EQ(s.pdf, 1.0f);
        EXPECT_NEAR(s.x, u, 1e-6f);
    }
}

} // namespace
} // namespace hairvox
