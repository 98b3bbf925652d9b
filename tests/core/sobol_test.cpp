// The Owen-scrambled Sobol (0,2)-sequence (core/sobol.h): every aligned block
// of 2^m points is a (0,m,2)-net for any seed, each point is uniform over the
// seeds, and different seeds (the sampler's pairs of dimensions) are
// independent.
#include <hairvox/core/sobol.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace hairvox {
namespace {

// Points [first, first + 2^m) hold one point in every elementary interval of
// 2^p × 2^(m−p) cells, p = 0..m.
::testing::AssertionResult isNet(std::uint32_t first, unsigned m, std::uint64_t seed) {
    const std::uint32_t n = 1u << m;
    std::vector<std::array<std::uint32_t, 2>> points;
    for (std::uint32_t i = first; i < first + n; ++i)
        points.push_back(seed == 0 ? sobol2D(i) : scrambledSobol2DBits(i, seed));
    for (unsigned p = 0; p <= m; ++p) {
        std::vector<int> count(n, 0);
        for (const auto& q : points) {
            const std::uint32_t cx = p == 0 ? 0 : q[0] >> (32 - p);
            const std::uint32_t cy = p == m ? 0 : q[1] >> (32 - (m - p));
            ++count[(cx << (m - p)) | cy];
        }
        for (std::uint32_t c = 0; c < n; ++c)
            if (count[c] != 1)
                return ::testing::AssertionFailure()
                       << "points " << first << ".." << first + n - 1 << ", seed " << seed << ": "
                       << count[c] << " points in cell " << c << " of 2^" << p << " x 2^" << m - p;
    }
    return ::testing::AssertionSuccess();
}

TEST(Sobol, FirstPointsAreSobolsSequence) {
    // Dimension 0: van der Corput; dimension 1: polynomial x + 1.
    const double x[] = {0, 0.5, 0.25, 0.75, 0.125, 0.625};
    const double y[] = {0, 0.5, 0.75, 0.25, 0.625, 0.125};
    for (std::uint32_t i = 0; i < 6; ++i) {
        EXPECT_EQ(double(sobol2D(i)[0]) * 0x1p-32, x[i]) << i;
        EXPECT_EQ(double(sobol2D(i)[1]) * 0x1p-32, y[i]) << i;
    }
}

TEST(Sobol, EveryAlignedBlockIsANetForAnySeed) {
    for (const std::uint64_t seed : {0ull, 1ull, 2ull, 0x1234'5678'9abc'def0ull, ~0ull})
        for (unsigned m = 1; m <= 10; ++m)
            for (const std::uint32_t block : {0u, 1u, 5u, 1000u})
                EXPECT_TRUE(isNet(block << m, m, seed));
    // An unaligned block of a scrambled sequence is not (the test can fail).
    EXPECT_FALSE(isNet(3, 6, 7));
}

TEST(Sobol, SamplerIsStratifiedInEveryPairAndEveryOneDimension) {
    constexpr std::uint32_t n = 64;
    for (int d = 0; d < 5; ++d) {
        std::vector<int> cells(n, 0), strata(n, 0);
        for (std::uint32_t i = 0; i < n; ++i) {
            SobolSampler s(42, i);
            for (int k = 0; k < d; ++k)
                s.next2D(); // the pairs before
            const Vec2f u = s.next2D();
            const float v = s.next1D();
            ++cells[std::size_t(u.x * 8) * 8 + std::size_t(u.y * 8)];
            ++strata[std::size_t(v * n)];
        }
        for (std::uint32_t c = 0; c < n; ++c) {
            EXPECT_EQ(cells[c], 1) << "pair " << d << ", cell " << c;
            EXPECT_EQ(strata[c], 1) << "1D after pair " << d << ", stratum " << c;
        }
    }
}

// Over seeds, a point is uniform on [0, 1)² (the estimator is unbiased) and
// two pairs of one sample are uncorrelated (the padding).
TEST(Sobol, PointsAreUniformAndPairsIndependentOverSeeds) {
    constexpr int seeds = 1 << 14, bins = 8;
    for (const std::uint32_t index : {0u, 3u, 1000u}) {
        std::vector<int> hist(bins * bins, 0);
        double sxy = 0, sx = 0, sy = 0, sxx = 0, syy = 0;
        for (int k = 0; k < seeds; ++k) {
            SobolSampler s(std::uint64_t(k) * std::uint64_t{0x9e3779b97f4a7c15u}, index);
            const Vec2f a = s.next2D(), b = s.next2D();
            ++hist[std::size_t(a.x * bins) * bins + std::size_t(a.y * bins)];
            const double x = double(a.x), y = double(b.x);
            sx += x;
            sy += y;
            sxy += x * y;
            sxx += x * x;
            syy += y * y;
        }
        double chi2 = 0;
        const double expected = double(seeds) / (bins * bins);
        for (const int h : hist)
            chi2 += (h - expected) * (h - expected) / expected;
        // 63 degrees of freedom: P(χ² > 110) ≈ 2e-4.
        EXPECT_LT(chi2, 110.0) << "index " << index;
        const double n = seeds;
        const double cov = sxy / n - (sx / n) * (sy / n);
        const double corr =
            cov / std::sqrt((sxx / n - sx * sx / n / n) * (syy / n - sy * sy / n / n));
        EXPECT_LT(std::abs(corr), 4.0 / std::sqrt(n)) << "index " << index; // 4σ
    }
}

} // namespace
} // namespace hairvox
