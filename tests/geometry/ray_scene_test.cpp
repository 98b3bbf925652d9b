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

} // namespace
} // namespace hairvox
