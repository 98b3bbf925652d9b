// The rate volume's line integrals (transmittance/src/brick_volume.h, internal
// to the transmittance stage) against a brute-force quadrature of its own
// trilinear field: the walk skips empty super-bricks, bricks and the bricks
// whose values' cells a line misses, and none of that may lose a value.
#include "../../transmittance/src/brick_volume.h"
#include "test_util.h"

#include <hairvox/core/rng.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <hwy/targets.h>
#include <vector>

namespace hairvox::detail {
namespace {

constexpr float kNeverOpaque = 1e30f;

/// Voxels scattered sparsely over 5³ bricks (h = 1: index space is world
/// space), each with its own positive channels: at this density most bricks a
/// line enters hold values it passes beside, as hair at fine voxels.
struct SparseVolume {
    BrickVolume volume{1.0};
    std::vector<glm::ivec3> voxels;

    SparseVolume() {
        Pcg32 rng(5);
        for (int i = 0; i < 300; ++i)
            voxels.emplace_back(static_cast<int>(rng.nextU32() % 40),
                                static_cast<int>(rng.nextU32() % 40),
                                static_cast<int>(rng.nextU32() % 40));
        const auto brickOf = [](const glm::ivec3& c) {
            return c >> 3;
        };
        const auto localOf = [&](const glm::ivec3& c) {
            return c - 8 * brickOf(c);
        };
        for (const glm::ivec3& c : voxels) {
            const glm::ivec3 l = localOf(c);
            volume.reserveBrick(brickOf(c),
                                (l.x == 0 ? 4 : 0) | (l.y == 0 ? 2 : 0) | (l.z == 0 ? 1 : 0));
        }
        volume.allocateSlots();
        for (const glm::ivec3& c : voxels)
            volume.reserveVoxel(volume.brickSet(brickOf(c)), localOf(c));
        volume.allocateValues();
        for (const glm::ivec3& c : voxels) {
            OpticalDepths d;
            d.n = rng.uniform(0.5f, 2.0f);
            d.tauP = Rgb(rng.uniform(0.1f, 1.0f), rng.uniform(0.1f, 1.0f), rng.uniform(0.1f, 1.0f));
            d.sumBeta2 =
                Rgb(rng.uniform(0.1f, 1.0f), rng.uniform(0.1f, 1.0f), rng.uniform(0.1f, 1.0f));
            volume.set(volume.brickSet(brickOf(c)), localOf(c), d);
        }
    }

    /// ∫ of sample() along origin + t·dir over [t0, t1], by Simpson's rule
    /// on steps much finer than a cell (the field is a cubic within a cell,
    /// continuous across faces).
    OpticalDepths quadrature(const Vec3f& origin, const Vec3f& dir, float t0, float t1) const {
        constexpr int kSteps = 16384; // even
        const double dt = double(t1 - t0) / kSteps;
        double sum[7] = {};
        for (int k = 0; k <= kSteps; ++k) {
            const double w = (k == 0 || k == kSteps) ? 1 : (k % 2 ? 4 : 2);
            const OpticalDepths d =
                volume.sample(origin + static_cast<float>(double(t0) + k * dt) * dir);
            const float v[7] = {d.n,          d.tauP.r,     d.tauP.g,    d.tauP.b,
                                d.sumBeta2.r, d.sumBeta2.g, d.sumBeta2.b};
            for (int c = 0; c < 7; ++c)
                sum[c] += w * double(v[c]);
        }
        for (double& s : sum)
            s *= dt / 3;
        return {float(sum[0]), Rgb(float(sum[1]), float(sum[2]), float(sum[3])),
                Rgb(float(sum[4]), float(sum[5]), float(sum[6]))};
    }
};

void expectNear(const OpticalDepths& a, const OpticalDepths& ref, const char* what, int line) {
    const float got[7] = {a.n,          a.tauP.r,     a.tauP.g,    a.tauP.b,
                          a.sumBeta2.r, a.sumBeta2.g, a.sumBeta2.b};
    const float want[7] = {ref.n,          ref.tauP.r,     ref.tauP.g,    ref.tauP.b,
                           ref.sumBeta2.r, ref.sumBeta2.g, ref.sumBeta2.b};
    for (int c = 0; c < 7; ++c)
        ASSERT_NEAR(got[c], want[c], 1e-3f * want[c] + 1e-4f)
            << what << ", line " << line << ", channel " << c;
}

/// Lines through the volume: random ones, and ones along the cells' faces and
/// edges next to values (where a walk's cell and a box test could disagree by
/// a rounding).
std::vector<std::pair<Vec3f, Vec3f>> testLines(const SparseVolume& v) {
    std::vector<std::pair<Vec3f, Vec3f>> lines;
    Pcg32 rng(9);
    for (int i = 0; i < 300; ++i) {
        const Vec3f target(rng.uniform(0, 40), rng.uniform(0, 40), rng.uniform(0, 40));
        Vec3f dir(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        dir = glm::normalize(dir + Vec3f(0, 0, 1e-3f));
        lines.emplace_back(target - 60.0f * dir, dir);
    }
    for (std::size_t i = 0; i < 60; ++i) {
        const Vec3f c(v.voxels[i]);
        const int axis = static_cast<int>(i % 3);
        Vec3f dir(0.0f);
        dir[axis] = i % 2 ? 1.0f : -1.0f;
        Vec3f origin = c + Vec3f(i % 4 == 0 ? 0.0f : 0.5f); // on an edge, or through the cell
        origin[axis] = dir[axis] > 0 ? -10.0f : 50.0f;
        lines.emplace_back(origin, dir);
        // Nearly along a face, drifting across it.
        Vec3f slant = dir;
        slant[(axis + 1) % 3] = 1e-4f;
        lines.emplace_back(origin, glm::normalize(slant));
    }
    return lines;
}

TEST(BrickVolume, LineIntegralsMatchAQuadratureOfTheField) {
    const SparseVolume v;
    int hits = 0;
    const auto lines = testLines(v);
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const auto& [origin, dir] = lines[i];
        bool touched = false;
        const OpticalDepths ref = v.quadrature(origin, dir, 0.0f, 120.0f);
        expectNear(v.volume.integrate(origin, dir, 0.0f, 120.0f, kNeverOpaque, touched), ref,
                   "integrate", int(i));
        hits += ref.n > 0;
    }
    EXPECT_GT(hits, 150) << "too few lines meet a value to test anything";
}

TEST(BrickVolume, CumulativeSamplesMatchTheIntegralsUpToThem) {
    // What the light-space cache stores: the samples recorded, each the
    // integral up to its position, and an unrecorded one the value of the
    // last recorded before it.
    const SparseVolume v;
    const auto lines = testLines(v);
    constexpr float kStep = 0.75f;
    constexpr std::size_t kCount = 160;
    // Every brick a candidate, in reverse order: the line finds its own and orders them.
    std::vector<std::uint32_t> bricks(v.volume.brickCount());
    for (std::size_t b = 0; b < bricks.size(); ++b)
        bricks[b] = static_cast<std::uint32_t>(bricks.size() - 1 - b);
    std::vector<BrickVolume::BrickCrossing> crossings;
    std::vector<BrickVolume::CumulativeSample> recorded;
    for (std::size_t i = 0; i < lines.size(); i += 3) {
        const auto& [origin, dir] = lines[i];
        v.volume.integrateCumulative(origin, dir, 0.0f, kStep, kCount, kNeverOpaque, bricks,
                                     crossings, recorded);
        std::size_t r = 0;
        OpticalDepths held; // the value an unrecorded sample holds
        for (std::size_t k = 0; k < kCount; k += 7) {
            while (r < recorded.size() && recorded[r].k <= k)
                held = recorded[r++].value.depths();
            expectNear(held, v.quadrature(origin, dir, 0.0f, float(k) * kStep), "cumulative",
                       int(i));
        }
    }
}

TEST(BrickVolume, EverySimdTargetIntegratesToTheSameBits) {
    // The line integrals are compiled once per SIMD target (brick_march.cpp)
    // and must not depend on the host's: the same sums in the same order at
    // every vector width, and no a·b + c contracted into an FMA.
    const SparseVolume v;
    const auto lines = testLines(v);
    std::vector<std::uint32_t> bricks(v.volume.brickCount());
    for (std::size_t b = 0; b < bricks.size(); ++b)
        bricks[b] = static_cast<std::uint32_t>(b);
    const auto integrals = [&] {
        std::vector<float> out;
        std::vector<BrickVolume::BrickCrossing> crossings;
        std::vector<BrickVolume::CumulativeSample> recorded;
        for (std::size_t i = 0; i < lines.size(); ++i) {
            const auto& [origin, dir] = lines[i];
            bool touched = false;
            const OpticalDepths d =
                v.volume.integrate(origin, dir, 0.0f, 120.0f, kNeverOpaque, touched);
            out.insert(out.end(), {d.n, d.tauP.r, d.tauP.g, d.tauP.b, d.sumBeta2.r, d.sumBeta2.g,
                                   d.sumBeta2.b});
            v.volume.integrateCumulative(origin, dir, 0.0f, 0.75f, 160, kNeverOpaque, bricks,
                                         crossings, recorded);
            for (const auto& sample : recorded)
                out.insert(out.end(), std::begin(sample.value.v), std::end(sample.value.v));
            const OpticalDepths s = v.volume.sample(origin + 60.0f * dir);
            out.insert(out.end(), {s.n, s.tauP.r, s.sumBeta2.b});
        }
        return out;
    };
    // The baseline (the last target: Highway lists the best first).
    std::vector<float> reference;
    std::vector<std::int64_t> targets;
    for (const std::int64_t target : hwy::SupportedAndGeneratedTargets())
        targets.push_back(target);
    ASSERT_GE(targets.size(), 2u) << "one SIMD target only: nothing to compare";
    hwy::SetSupportedTargetsForTest(targets.back());
    reference = integrals();
    hwy::SetSupportedTargetsForTest(0);
    ASSERT_GT(reference.size(), 3000u);
    test::forEachSimdTarget([&] {
        const std::vector<float> got = integrals();
        ASSERT_EQ(got.size(), reference.size());
        EXPECT_EQ(std::memcmp(got.data(), reference.data(), got.size() * sizeof(float)), 0);
    });
}

} // namespace
} // namespace hairvox::detail
