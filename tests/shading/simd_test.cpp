#include "test_util.h"

#include <hairvox/shading/simd.h>

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <hwy/targets.h>
#include <set>
#include <string>

namespace hairvox {
namespace {

/// The names of the targets this CPU supports, as Highway spells them.
std::set<std::string> supportedTargetNames() {
    std::set<std::string> names;
    for (std::int64_t bits = hwy::SupportedTargets(); bits != 0; bits &= bits - 1)
        names.insert(hwy::TargetName(bits & -bits));
    return names;
}

TEST(Simd, TargetIsOneHighwayKnowsAndThisCpuSupports) {
    const std::set<std::string> supported = supportedTargetNames();
    ASSERT_FALSE(supported.empty());
    const std::string target = simdTarget();
    EXPECT_TRUE(supported.count(target)) << target;
    // The best the CPU supports among the shading library's targets: nothing
    // it compiles (x86: AVX-512, AVX2, SSE4; NEON) above it is supported.
    for (const std::int64_t better : {HWY_AVX3, HWY_AVX2, HWY_SSE4}) {
        if (hwy::TargetName(better) == target)
            break;
        EXPECT_FALSE(hwy::SupportedTargets() & better)
            << target << " dispatched where " << hwy::TargetName(better) << " is supported";
    }
}

TEST(Simd, FmaPeakRunsOnTheKernelsTargetOnEveryTarget) {
    test::forEachSimdTarget([] {
        const SimdFmaPeak peak = simdFmaPeak();
        EXPECT_EQ(peak.target, simdTarget());
        EXPECT_TRUE(std::isfinite(peak.flopsPerSecond));
        EXPECT_GT(peak.flopsPerSecond, 1e7); // above 10 MFLOP/s even emulated and loaded
    });
}

} // namespace
} // namespace hairvox
