// What a frame's digest covers (shots/frame_hash.h): every setting of its
// scene, the contents of its input files, the frame and the version — not
// the scene's name, where its outputs go or where its inputs are.
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/shots/frame_hash.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>

#include <functional>

namespace hairvox::shots {
namespace {

namespace fs = std::filesystem;

TEST(ShotsFrameHash, FollowsWhatTheImagesAreMadeOf) {
    // The two-light look with its outputs (which outputs are part of a frame).
    const Scene base = loadScene(test::dataDir() / "scenes" / "key_back.json");
    FileDigests files;
    const std::string h = frameHash(base, 1, files);
    EXPECT_EQ(h.size(), 16u);
    EXPECT_EQ(frameHash(base, 1, files), h);
    EXPECT_NE(frameHash(base, 2, files), h) << "the frame number";

    const auto changes = [&](const char* what, const std::function<void(Scene&)>& edit) {
        Scene s = base;
        edit(s);
        EXPECT_NE(frameHash(s, 1, files), h) << what << " does not change the digest";
    };
    changes("camera", [](Scene& s) { s.camera.position.x += 1e-4f; });
    changes("resolution", [](Scene& s) { s.camera.width = 512; });
    changes("a light", [](Scene& s) { s.lights[0].intensity *= 2; });
    changes("a light's name (its EXR layers)", [](Scene& s) { s.lights[0].name = "other"; });
    changes("a fiber", [](Scene& s) { s.fiber.sigma_a = s.fiber.sigma_a * 1.01f; });
    changes("the groom", [](Scene& s) { s.groom.procedural.seed = 2; });
    changes("the density", [](Scene& s) { s.fiberScale.densityMultiplier = 2; });
    changes("the mode", [](Scene& s) { s.globalTermMode = GlobalTermMode::Approx; });
    changes("the voxel size", [](Scene& s) { s.voxelSize = 0.003f; });
    changes("a mesh transform", [](Scene& s) { s.meshes[0].transform.translate.y = 0.01f; });
    changes("the tone map", [](Scene& s) { s.output.toneMap = ToneMap::Clamp; });
    changes("the EXR's layers", [](Scene& s) { s.output.layers.emplace(); });
    changes("no PNG", [](Scene& s) { s.output.png.clear(); });
    changes("the compression", [](Scene& s) { s.output.exrCompression = ExrCompression::Zips; });
    changes("the integrator", [](Scene& s) { s.integrator = Integrator::Path; });
    changes("an environment", [](Scene& s) { s.environment = defaultScene().environment; });

    // The default scene's built-in map: which one, and how it is turned.
    const Scene lit = defaultScene();
    const std::string studio = frameHash(lit, 1, files);
    Scene sky = lit;
    sky.environment->builtin = "sky";
    EXPECT_NE(frameHash(sky, 1, files), studio) << "the built-in map";
    Scene turned = lit;
    turned.environment->rotation += 1;
    EXPECT_NE(frameHash(turned, 1, files), studio) << "the map's rotation";

    const auto keeps = [&](const char* what, const std::function<void(Scene&)>& edit) {
        Scene s = base;
        edit(s);
        EXPECT_EQ(frameHash(s, 1, files), h) << what << " changes the digest";
    };
    keeps("the scene's name", [](Scene& s) { s.name = "elsewhere.json frame 1"; });
    keeps("the output paths", [](Scene& s) {
        s.output.exr = "/elsewhere/a.exr";
        s.output.png = "/elsewhere/a.png";
    });
}

TEST(ShotsFrameHash, FilesCountByContentNotByNameOrPlace) {
    test::TempDir dir;
    ProceduralGroomParams p;
    p.strands = 50;
    writeHairFile(dir / "a.hair", generateGroom(p));
    fs::create_directories(dir / "copy");
    fs::copy_file(dir / "a.hair", dir / "copy" / "b.hair");
    Scene scene = defaultScene();
    scene.groom.file = dir / "a.hair";
    FileDigests files;
    const std::string h = frameHash(scene, 1, files);
    scene.groom.file = dir / "copy" / "b.hair";
    EXPECT_EQ(frameHash(scene, 1, files), h) << "the same strands elsewhere";
    // Rewritten with other strands (a simulation cache written again).
    p.seed = 7;
    writeHairFile(dir / "copy" / "b.hair", generateGroom(p));
    FileDigests fresh;
    EXPECT_NE(frameHash(scene, 1, fresh), h);
    EXPECT_NE(frameHash(scene, 1, files), h) << "a rewritten file is read again";
    scene.groom.file = dir / "absent.hair";
    EXPECT_THROW(frameHash(scene, 1, files), InputError);
}

// The digest lists the scene's fields one by one (hashSceneInto): a field
// added to one of these structs must be added there too, or frames rendered
// with another value of it would pass for done. So this test fails when one
// of them changes size (x86-64, GCC): add the field to hashSceneInto
// (shots/src/frame_hash.cpp), then the new size here.
TEST(ShotsFrameHash, CoversEveryFieldOfTheScene) {
    EXPECT_EQ(sizeof(Scene), 816u);
    EXPECT_EQ(sizeof(GroomSource), 160u);
    EXPECT_EQ(sizeof(ProceduralGroomParams), 96u);
    EXPECT_EQ(sizeof(CameraParams), 48u);
    EXPECT_EQ(sizeof(Head), 28u);
    EXPECT_EQ(sizeof(MeshSource), 112u);
    EXPECT_EQ(sizeof(MeshTransform), 36u);
    EXPECT_EQ(sizeof(ExactSettings), 16u);
    EXPECT_EQ(sizeof(PathTraceSettings), 40u);
    EXPECT_EQ(sizeof(OutputSettings), 128u);
    EXPECT_EQ(sizeof(EnvironmentLight), 128u);
    EXPECT_EQ(sizeof(VolumetricSettings), 56u); // (VolumetricSettings::hashInto)
}

} // namespace
} // namespace hairvox::shots
