#include <hairvox/core/hash.h>
#include <hairvox/core/math.h>
#include <hairvox/core/rgb.h>
#include <hairvox/core/rng.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

namespace hairvox {
namespace {

TEST(CoreMath, SafeFunctionsClampRoundingError) {
    EXPECT_EQ(safeSqrt(-1e-9), 0.0);
    EXPECT_DOUBLE_EQ(safeASin(1.0 + 1e-12), PiOver2);
    EXPECT_DOUBLE_EQ(safeACos(-1.0 - 1e-12), Pi);
    EXPECT_EQ(cosFromSin(1.0f), 0.0f);
    EXPECT_NEAR(cosFromSin(0.6), 0.8, 1e-15);
}

TEST(CoreMath, WrapAngleMapsIntoMinusPiPi) {
    for (double phi : {-100.0, -7.0, -Pi, -1.0, 0.0, 2.0, Pi, 4.0, 7.0, 100.0}) {
        const double w = wrapAngle(phi);
        EXPECT_GE(w, -Pi);
        EXPECT_LE(w, Pi);
        EXPECT_NEAR(std::remainder(w - phi, TwoPi), 0.0, 1e-12) << phi;
    }
}

TEST(CoreMath, GaussianIsNormalised) {
    const double sigma = 0.3;
    double integral = 0;
    const double dx = 1e-4;
    for (double x = -3.0; x <= 3.0; x += dx)
        integral += gaussian(x, sigma) * dx;
    EXPECT_NEAR(integral, 1.0, 1e-6);
}

TEST(CoreMath, SmoothStepEndsAndMonotone) {
    EXPECT_EQ(smoothStep(2.0, 3.0, 1.0), 0.0);
    EXPECT_EQ(smoothStep(2.0, 3.0, 4.0), 1.0);
    double previous = 0;
    for (double x = 2.0; x <= 3.0; x += 0.01) {
        const double s = smoothStep(2.0, 3.0, x);
        EXPECT_GE(s, previous);
        previous = s;
    }
}

TEST(CoreRgb, ArithmeticIsPerChannel) {
    const Rgb a(1, 2, 3), b(2, 4, 8);
    EXPECT_EQ(a + b, Rgb(3, 6, 11));
    EXPECT_EQ(a * b, Rgb(2, 8, 24));
    EXPECT_EQ(2.0f * a, Rgb(2, 4, 6));
    EXPECT_EQ(b / 2.0f, Rgb(1, 2, 4));
    EXPECT_FLOAT_EQ(exp(log(b)).b, 8.0f);
    EXPECT_FALSE(Rgb(1, std::numeric_limits<float>::quiet_NaN(), 0).isFinite());
}

TEST(CoreHash, SameInputSameDigestAndSplitInvariant) {
    const std::string text = "the quick brown fox jumps over the lazy dog";
    Hasher whole, pieces;
    whole.bytes(text.data(), text.size());
    pieces.bytes(text.data(), 5).bytes(text.data() + 5, 13).bytes(text.data() + 18, text.size() - 18);
    EXPECT_EQ(whole.digest(), pieces.digest());
    Hasher other;
    other.bytes(text.data(), text.size() - 1);
    EXPECT_NE(whole.digest(), other.digest());
    EXPECT_NE(Hasher().string("ab").string("c").digest(), Hasher().string("a").string("bc").digest());
    EXPECT_EQ(hexDigest(0x0123456789abcdefull), "0123456789abcdef");
}

TEST(CoreRng, DeterministicAndInRange) {
    Pcg32 a(42), b(42), c(43);
    std::set<std::uint32_t> seen;
    for (int i = 0; i < 1000; ++i) {
        const std::uint32_t x = a.nextU32();
        EXPECT_EQ(x, b.nextU32());
        seen.insert(x);
        const float u = c.uniformFloat();
        EXPECT_GE(u, 0.0f);
        EXPECT_LT(u, 1.0f);
    }
    EXPECT_GT(seen.size(), 990u);
}

} // namespace
} // namespace hairvox
