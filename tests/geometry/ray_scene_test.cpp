// The Embree scene of the strands (geometry/ray_scene.h): fiber crossings
// along a ray and the strand a point lies on.
#include <hairvox/geometry/ray_scene.h>

#include <gtest/gtest.h>

namespace hairvox {
namespace {

constexpr float kDiameter = 5e-5f;

TEST(RayScene, JointOfTwoSegmentsIsOneCrossingAndCurlsCountTwice) {
    Groom groom;
    // A strand with a vertex exactly on the ray.
    const Vec3f bent[3] = {{-0.01f, 0.005f, 0}, {0, 0.005f, 0}, {0.01f, 0.006f, 0}};
    groom.addStrand(bent);
    const RayScene caster(groom, FiberScale{kDiameter, 1.0f});
    std::vector<FiberCrossing> hits;
    caster.crossings(Vec3f(0, 0, 0), Vec3f(0, 1, 0), 1.0f, hits);
    ASSERT_EQ(hits.size(), 1u);
    EXPECT_NEAR(hits[0].t, 0.005f, 1e-4f);
    // A curl that loops back across the ray counts each time it crosses.
    Groom loop;
    const Vec3f curl[5] = {{-0.01f, 0.002f, 0},
                           {0.01f, 0.002f, 0},
                           {0.01f, 0.004f, 0.0005f},
                           {-0.01f, 0.004f, -0.0005f},
                           {-0.01f, 0.006f, 0.001f}};
    loop.addStrand(curl);
    RayScene(loop, FiberScale{kDiameter, 1.0f})
        .crossings(Vec3f(0, 0, 0), Vec3f(0, 1, 0), 1.0f, hits);
    ASSERT_EQ(hits.size(), 2u);
    EXPECT_NEAR(hits[1].arcLength - hits[0].arcLength, 0.02206f, 1e-4f); // half + turn + half
    const RayScene loopCaster(loop, FiberScale{kDiameter, 1.0f});
    const auto on = loopCaster.locate(Vec3f(0.005f, 0.002f, 0));
    ASSERT_TRUE(on.has_value());
    EXPECT_EQ(on->segment, 0u);
    EXPECT_NEAR(on->arcLength, 0.015f, 1e-5f);
    EXPECT_EQ(loopCaster.locate(Vec3f(0.005f, 0.002f, 0), 0)->segment, 0u); // with a strand hint
    EXPECT_FALSE(loopCaster.locate(Vec3f(0, 0.5f, 0)).has_value());
}

/// Whether a ray along +y from (x, 0, z) meets a fiber of `scene`: by
/// crossings(), intersect() and occluded() alike.
bool hitAt(const RayScene& scene, float x, float z) {
    const Vec3f origin(x, 0, z), dir(0, 1, 0);
    std::vector<FiberCrossing> hits;
    scene.crossings(origin, dir, 1.0f, hits);
    const bool any = !hits.empty();
    EXPECT_EQ(scene.intersect(origin, dir, 1.0f).has_value(), any) << x << ", " << z;
    EXPECT_EQ(scene.occluded(origin, dir, 1.0f), any) << x << ", " << z;
    return any;
}

/// A strand along x at y = 0.005 from x = −0.01 to 0.01 in `segments`
/// segments, with per-point diameters from `thickness` (empty: none).
Groom strandAlongX(int segments, const std::vector<float>& thickness) {
    Groom groom;
    std::vector<Vec3f> points;
    for (int k = 0; k <= segments; ++k)
        points.emplace_back(-0.01f + 0.02f * float(k) / float(segments), 0.005f, 0.0f);
    groom.addStrand(points);
    groom.thickness = thickness;
    return groom;
}

TEST(RayScene, PerPointDiameterSetsTheRibbonWidth) {
    // A ray along y meets the ribbon (in the plane y = 0.005, across z) when
    // its offset |z| is below half the width k·D_i.
    const FiberScale scale{kDiameter, 1.0f};
    const RayScene plain(strandAlongX(2, {}), scale);
    const RayScene twice(strandAlongX(2, std::vector<float>(3, 2 * kDiameter)), scale);
    const RayScene twiceK(strandAlongX(2, std::vector<float>(3, 2 * kDiameter)),
                          FiberScale{kDiameter, 1.5f});
    EXPECT_EQ(plain.ribbonWidth(), kDiameter);
    EXPECT_EQ(twice.ribbonWidth(), 2 * kDiameter);
    EXPECT_FLOAT_EQ(twiceK.ribbonWidth(), 3 * kDiameter);
    for (const float x : {-0.0063f, 0.0031f}) {
        SCOPED_TRACE(x);
        EXPECT_TRUE(hitAt(plain, x, 0.45f * kDiameter));
        EXPECT_FALSE(hitAt(plain, x, 0.55f * kDiameter));
        EXPECT_TRUE(hitAt(twice, x, -0.95f * kDiameter));
        EXPECT_FALSE(hitAt(twice, x, -1.05f * kDiameter));
        EXPECT_TRUE(hitAt(twiceK, x, 1.45f * kDiameter));
        EXPECT_FALSE(hitAt(twiceK, x, 1.55f * kDiameter));
    }
    // locate() searches as far as the widest ribbon reaches.
    EXPECT_TRUE(twiceK.locate(Vec3f(0.001f, 0.005f, 2.9f * kDiameter)).has_value());
    EXPECT_FALSE(twiceK.locate(Vec3f(0.001f, 0.005f, 3.1f * kDiameter)).has_value());
    EXPECT_TRUE(plain.locate(Vec3f(0.001f, 0.005f, 0.9f * kDiameter)).has_value());
    EXPECT_FALSE(plain.locate(Vec3f(0.001f, 0.005f, 1.1f * kDiameter)).has_value());
}

TEST(RayScene, TaperedStrandIsHitWithinItsLocalWidth) {
    // D at the root, D/2 at the middle, 0 at the tip: the width is linear
    // along each segment, w(x) = D·(1 − (x + 0.01)/0.02) here.
    const RayScene tapered(strandAlongX(2, {kDiameter, 0.5f * kDiameter, 0.0f}),
                           FiberScale{kDiameter, 1.0f});
    EXPECT_EQ(tapered.ribbonWidth(), kDiameter);
    for (const float x : {-0.0093f, -0.0063f, 0.0031f, 0.0087f, 0.0099f}) {
        SCOPED_TRACE(x);
        const float halfWidth = 0.5f * kDiameter * (1.0f - (x + 0.01f) / 0.02f);
        EXPECT_TRUE(hitAt(tapered, x, 0.9f * halfWidth));
        EXPECT_FALSE(hitAt(tapered, x, 1.1f * halfWidth));
        EXPECT_TRUE(hitAt(tapered, x, 0.0f));
    }
    EXPECT_FALSE(hitAt(tapered, 0.0101f, 0.0f)); // beyond the tip
    // A strand of width 0 is never hit, not even through its centreline.
    const RayScene bare(strandAlongX(2, std::vector<float>(3, 0.0f)), FiberScale{kDiameter, 1.0f});
    EXPECT_EQ(bare.ribbonWidth(), 0.0f);
    for (const float x : {-0.01f, -0.0063f, -0.005f, 0.0f, 0.0031f, 0.01f})
        EXPECT_FALSE(hitAt(bare, x, 0.0f)) << x;
}

} // namespace
} // namespace hairvox
