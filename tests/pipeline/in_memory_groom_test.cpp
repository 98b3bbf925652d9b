// A groom given in memory (GroomSource::inMemory, pipeline/scene.h — what the
// Python module's hairvox.Groom becomes in a scene) renders as the same groom
// read from a file, is sanitized like a file's, is counted by the memory
// estimate, keys FrameReuse by its content and is never changed by a render.
#include "film/film_bytes.h"
#include "scene_test_util.h"
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>

namespace hairvox {
namespace {

/// The default scene's groom, small (400 strands), with per-point diameters
/// and two colours, so that both attributes go through the pipeline.
Groom attributedGroom() {
    ProceduralGroomParams params = defaultScene().groom.procedural;
    params.strands = 400;
    Groom groom = generateGroom(params);
    groom.thickness.assign(groom.pointCount(), 0.0f);
    groom.color.assign(groom.pointCount(), Rgb(0.0f));
    for (std::size_t s = 0; s < groom.strandCount(); ++s)
        for (std::uint32_t i = groom.strandStart[s]; i < groom.strandStart[s + 1]; ++i) {
            groom.thickness[i] = 70e-6f + 10e-6f * float(s % 3);
            groom.color[i] = s % 2 ? Rgb(0.6f, 0.45f, 0.3f) : Rgb(0.1f, 0.06f, 0.04f);
        }
    return groom;
}

/// The default scene at 64², its head a sphere instead of the mannequin mesh.
Scene smallScene(const std::string& name) {
    Scene scene = test::keyBackScene();
    scene.name = name;
    scene.meshes.clear();
    scene.head = Head{};
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

TEST(InMemoryGroom, RendersAsTheSameGroomReadFromAFile) {
    test::TempDir dir;
    const Groom groom = attributedGroom();
    Scene fromFile = smallScene("groom");
    fromFile.groom.file = dir / "groom.hair";
    writeHairFile(fromFile.groom.file, groom);
    Scene inMemory = smallScene("groom");
    inMemory.groom.inMemory = std::make_shared<const Groom>(groom);
    EXPECT_FALSE(inMemory.groom.isProcedural());

    for (const Integrator integrator : {Integrator::DualScattering, Integrator::Path}) {
        fromFile.integrator = inMemory.integrator = integrator;
        fromFile.pathTrace.spp = inMemory.pathTrace.spp = 2;
        const SceneRender a = renderScene(fromFile, options(dir), false);
        const SceneRender b = renderScene(inMemory, options(dir), false);
        ASSERT_GT(a.film.layers().size(), 2u);
        EXPECT_TRUE(test::filmBytes(a.film) == test::filmBytes(b.film)) << toString(integrator);
        EXPECT_EQ(a.fiberTypes, 2u);
        EXPECT_EQ(b.fiberTypes, 2u);
        // What the outputs would record: the same voxel size, or the same path-trace hash.
        EXPECT_EQ(a.outputAttributes, b.outputAttributes) << toString(integrator);
        EXPECT_FALSE(b.outputAttributes.empty());
    }
}

TEST(InMemoryGroom, RenderLeavesTheCallersGroomUnchanged) {
    test::TempDir dir;
    auto groom = std::make_shared<const Groom>(attributedGroom());
    Scene scene = smallScene("groom");
    scene.groom.inMemory = groom;
    scene.groom.thickness = GroomThickness::Scale; // resolved into diameters in loadGroom's copy
    const SceneGroom loaded = loadGroom(scene);
    EXPECT_EQ(groom->thickness, attributedGroom().thickness);
    EXPECT_TRUE(groom->fiberType.empty());
    EXPECT_FLOAT_EQ(loaded.groom.thickness[0], groom->thickness[0] * scene.fiberScale.diameter);
    EXPECT_EQ(loaded.palette.size(), 2u);
}

TEST(InMemoryGroom, IsSanitizedLikeAFile) {
    Groom groom;
    groom.points = {Vec3f(0.0f), Vec3f(0.0f), Vec3f(0.0f, 0.01f, 0.0f), // a repeated point
                    Vec3f(0.02f, 0.0f, 0.0f), Vec3f(0.02f, 0.02f, 0.0f)};
    groom.strandStart = {0, 3, 5};
    Scene scene = smallScene("groom");
    scene.groom.inMemory = std::make_shared<const Groom>(groom);
    const SceneGroom loaded = loadGroom(scene);
    EXPECT_EQ(loaded.groom.pointCount(), 4u);
    ASSERT_EQ(loaded.warnings.size(), 1u);
    EXPECT_EQ(loaded.warnings[0], "dropped 1 zero-length segment(s)");

    groom.points[3].x = std::nanf("");
    scene.groom.inMemory = std::make_shared<const Groom>(groom);
    try {
        loadGroom(scene);
        ADD_FAILURE() << "a non-finite point was accepted";
    } catch (const InputError& e) {
        EXPECT_TRUE(test::contains(e.what(), "in-memory groom: strand 1, point 0")) << e.what();
    }
}

TEST(InMemoryGroom, IsNamedAndCountedByTheMemoryEstimate) {
    const Groom groom = attributedGroom();
    Scene scene = smallScene("groom");
    scene.groom.inMemory = std::make_shared<const Groom>(groom);
    scene.validate();
    EXPECT_EQ(scene.groom.sourceName(), "in-memory groom");
    std::ostringstream text;
    text << scene;
    EXPECT_TRUE(test::contains(text.str(), "groom=in-memory groom")) << text.str();

    Scene empty = scene;
    empty.groom.inMemory = std::make_shared<const Groom>();
    const std::uint64_t perPoint =
        (estimateRenderMemory(scene).groom - estimateRenderMemory(empty).groom) /
        groom.pointCount();
    EXPECT_GT(perPoint, 12u); // at least the points themselves, and their render buffers
}

TEST(InMemoryGroom, FrameReuseKeysOnItsContent) {
    test::TempDir dir;
    Groom groom = attributedGroom();
    Scene scene = smallScene("frame");
    scene.groom.inMemory = std::make_shared<const Groom>(groom);
    FrameReuse reuse;
    EXPECT_FALSE(renderScene(scene, options(dir), false, &reuse).gridReused);
    // A new object with the same content: the same grid.
    scene.groom.inMemory = std::make_shared<const Groom>(groom);
    EXPECT_TRUE(renderScene(scene, options(dir), false, &reuse).gridReused);
    // The same name ("in-memory groom"), other points: splatted again.
    for (Vec3f& p : groom.points)
        p.y += 0.01f;
    scene.groom.inMemory = std::make_shared<const Groom>(groom);
    const SceneRender moved = renderScene(scene, options(dir), false, &reuse);
    EXPECT_FALSE(moved.gridReused);
    EXPECT_TRUE(test::filmBytes(moved.film) ==
                test::filmBytes(renderScene(scene, options(dir), false).film));
}

} // namespace
} // namespace hairvox
