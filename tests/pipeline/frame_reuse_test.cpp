// Frames of a sequence sharing what does not change (pipeline/pipeline.h,
// FrameReuse): what is reused follows what changed between the frames, and
// every frame is the same bytes as rendered alone.
#include "film/film_bytes.h"
#include "scene_test_util.h"
#include "test_util.h"

#include <hairvox/pipeline/pipeline.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hairvox {
namespace {

/// The default scene, small (600 strands at 64²), its groom in a file of `dir`.
Scene fileScene(const test::TempDir& dir) {
    Scene scene = test::keyBackScene();
    scene.name = "frame";
    scene.groom.procedural.strands = 600;
    scene.groom.file = dir / "groom.hair";
    writeHairFile(scene.groom.file, generateGroom(scene.groom.procedural));
    scene.camera.width = scene.camera.height = 64;
    scene.output.exr.clear();
    scene.output.png.clear();
    return scene;
}

PipelineOptions options(const test::TempDir& dir) {
    PipelineOptions o;
    o.tableCacheDir = dir / "cache";
    return o;
}

struct Reused {
    bool grid = false;
    std::vector<bool> lights;
    bool operator==(const Reused&) const = default;
};

/// Renders `scene` as the next frame of `reuse` and alone; expects the same
/// film, and says what the frame took from the one before.
Reused renderNext(const Scene& scene, const test::TempDir& dir, FrameReuse& reuse) {
    const SceneRender next = renderScene(scene, options(dir), false, &reuse);
    const SceneRender alone = renderScene(scene, options(dir), false);
    EXPECT_TRUE(test::filmBytes(next.film) == test::filmBytes(alone.film))
        << "a frame rendered after another differs from the same frame alone";
    Reused r;
    r.grid = next.gridReused;
    for (const LightReport& l : next.lights)
        r.lights.push_back(l.reused);
    EXPECT_EQ(next.activeVoxels, alone.activeVoxels);
    return r;
}

TEST(FrameReuse, WhatIsReusedFollowsWhatChanged) {
    test::TempDir dir;
    const Scene first = fileScene(dir);
    ASSERT_EQ(first.lights.size(), 2u);
    FrameReuse reuse;
    EXPECT_EQ(renderNext(first, dir, reuse), (Reused{false, {false, false}}));

    // The camera moves (a turntable): the grid and both lights are kept.
    Scene moved = first;
    moved.camera.position = Vec3f(0.35f, 0.05f, 0.6f);
    EXPECT_EQ(renderNext(moved, dir, reuse), (Reused{true, {true, true}}));

    // One light moves: only that light is prepared again.
    Scene relit = moved;
    relit.lights[1].direction = normalize(Vec3f(-0.3f, 0.5f, -0.8f));
    EXPECT_EQ(renderNext(relit, dir, reuse), (Reused{true, {true, false}}));
    EXPECT_EQ(renderNext(relit, dir, reuse), (Reused{true, {true, true}}));

    // A new colour: the same grid, every light prepared for the new fibers.
    Scene recoloured = relit;
    recoloured.fiber.sigma_a = recoloured.fiber.sigma_a * 2.0f;
    EXPECT_EQ(renderNext(recoloured, dir, reuse), (Reused{true, {false, false}}));

    // Another voxel size: nothing is kept.
    Scene finer = recoloured;
    finer.voxelSize = 0.004f;
    EXPECT_EQ(renderNext(finer, dir, reuse), (Reused{false, {false, false}}));

    // The groom file rewritten under the same name: splatted again.
    EXPECT_EQ(renderNext(finer, dir, reuse), (Reused{true, {true, true}}));
    ProceduralGroomParams other = finer.groom.procedural;
    other.seed += 1;
    writeHairFile(finer.groom.file, generateGroom(other));
    EXPECT_EQ(renderNext(finer, dir, reuse), (Reused{false, {false, false}}));
}

TEST(FrameReuse, ExactModeKeepsItsLightsAndAPathTraceBetweenFramesChangesNothing) {
    test::TempDir dir;
    Scene exact = fileScene(dir);
    exact.globalTermMode = GlobalTermMode::Exact;
    exact.exact.rays = 2;
    exact.exact.radius = 0.004f;
    FrameReuse reuse;
    EXPECT_EQ(renderNext(exact, dir, reuse), (Reused{false, {false, false}}));
    Scene traced = exact;
    traced.integrator = Integrator::Path;
    traced.pathTrace.spp = 1;
    traced.camera.width = traced.camera.height = 16;
    (void)renderScene(traced, options(dir), false, &reuse);
    exact.camera.position = Vec3f(0.35f, 0.05f, 0.6f);
    EXPECT_EQ(renderNext(exact, dir, reuse), (Reused{false, {true, true}}));
}

} // namespace
} // namespace hairvox
