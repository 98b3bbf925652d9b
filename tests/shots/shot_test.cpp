// A shot file (shots/shot.h): frames, camera and light orbits, per-frame
// files; frame `start` is the scene as written, each frame is a scene the
// scene parser accepts; errors name the file and the JSON path.
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/shots/shot.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

namespace hairvox::shots {
namespace {

using nlohmann::json;

json turntable() {
    return json::parse(R"({
      "frames": { "start": 1, "end": 8 },
      "groom": { "procedural": { "style": "straight", "strands": 100 } },
      "lights": [
        { "name": "key", "type": "directional", "direction": [0, 1, 1] },
        { "name": "rim", "type": "point", "position": [0.5, 0.2, 0],
          "orbit": { "center": [0, 0.2, 0], "degrees_per_frame": -90 } }
      ],
      "camera": { "position": [0, 0.1, -0.8], "look_at": [0, 0, 0], "resolution": [32, 32],
                  "orbit": { "axis": [0, 1, 0], "degrees_per_frame": 45 } },
      "output": { "exr": "out/turn.%04d.exr", "png": "out/turn.####.png" }
    })");
}

std::string shotError(const json& document) {
    try {
        Shot::parse(document, "turn.json", "");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

void expectNear(const Vec3f& a, const Vec3f& b, float tolerance = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, tolerance) << a << " vs " << b;
    EXPECT_NEAR(a.y, b.y, tolerance) << a << " vs " << b;
    EXPECT_NEAR(a.z, b.z, tolerance) << a << " vs " << b;
}

TEST(ShotsShot, FrameStartIsTheSceneAsWrittenAndOrbitsTurnTheRig) {
    const Shot shot = Shot::parse(turntable(), "turn.json", "");
    EXPECT_EQ(shot.start(), 1);
    EXPECT_EQ(shot.end(), 8);
    EXPECT_EQ(shot.frames().size(), 8u);
    ASSERT_TRUE(shot.cameraOrbit().has_value());
    expectNear(shot.cameraOrbit()->center, Vec3f(0.0f)); // the camera's look_at

    const Scene first = shot.frame(1);
    EXPECT_EQ(first.name, "turn.json frame 1");
    EXPECT_EQ(first.camera.position, Vec3f(0, 0.1f, -0.8f)) << "exactly as written";
    EXPECT_EQ(first.lights[1].position, Vec3f(0.5f, 0.2f, 0));
    EXPECT_EQ(first.output.exr, "out/turn.0001.exr");
    EXPECT_EQ(first.output.png, "out/turn.0001.png");

    // Frame 3: the camera 90° about +y (right-handed: -z goes to -x), the
    // rim light −180° about its centre's vertical.
    const Scene third = shot.frame(3);
    expectNear(third.camera.position, Vec3f(-0.8f, 0.1f, 0));
    expectNear(third.camera.lookAt, Vec3f(0.0f));
    expectNear(third.camera.up, Vec3f(0, 1, 0));
    expectNear(third.lights[1].position, Vec3f(-0.5f, 0.2f, 0));
    EXPECT_EQ(third.lights[0].direction, first.lights[0].direction) << "the key light stays";
    EXPECT_EQ(third.output.exr, "out/turn.0003.exr");
    // A whole turn is the frame as written, to the bit.
    EXPECT_EQ(shot.frame(9).camera.position, first.camera.position);
    EXPECT_EQ(shot.frame(5).lights[1].position, first.lights[1].position);
    EXPECT_FALSE(shot.groomVaries());
}

TEST(ShotsShot, ADirectionalLightTurnsAndStaysAUnitVector) {
    json doc = turntable();
    doc["lights"][0]["orbit"] = {{"axis", {0, 0, 1}}, {"degrees_per_frame", 30}};
    const Shot shot = Shot::parse(doc, "turn.json", "");
    const Scene s = shot.frame(4); // 90° about +z
    const Vec3f d0 = normalize(Vec3f(0, 1, 1));
    expectNear(s.lights[0].direction, Vec3f(-d0.y, d0.x, d0.z));
    EXPECT_NEAR(glm::length(s.lights[0].direction), 1.0f, 1e-6f);
}

TEST(ShotsShot, PerFrameFilesAndDefaultOutputs) {
    json doc = turntable();
    doc["groom"] = {{"file", "sim/groom.%04d.hair"}};
    doc.erase("output");
    const Shot shot = Shot::parse(doc, "shots/turn.json", "shots");
    EXPECT_TRUE(shot.groomVaries());
    const Scene s = shot.frame(12);
    EXPECT_EQ(s.groom.file, std::filesystem::path("shots/sim/groom.0012.hair"));
    EXPECT_EQ(s.output.exr, "out/turn.0012.exr");
    EXPECT_EQ(s.output.png, "out/turn.0012.png");
    // One frame needs no pattern; a null output stays null.
    doc["frames"] = {{"start", 5}, {"end", 5}};
    doc["output"] = {{"exr", "still.exr"}, {"png", nullptr}};
    const Scene still = Shot::parse(doc, "turn.json", "").frame(5);
    EXPECT_EQ(still.output.exr, "still.exr");
    EXPECT_TRUE(still.output.png.empty());
}

TEST(ShotsShot, ErrorsNameTheFileAndTheJsonPath) {
    const auto expectError = [](json doc, const std::string& part) {
        const std::string e = shotError(doc);
        EXPECT_TRUE(test::contains(e, "turn.json: ")) << e;
        EXPECT_TRUE(test::contains(e, part)) << "expected '" << part << "' in: " << e;
    };
    json doc = turntable();
    doc.erase("frames");
    expectError(doc, "/frames: missing");
    doc = turntable();
    doc["frames"]["end"] = 0;
    expectError(doc, "/frames/end: 0 is before /frames/start 1");
    doc = turntable();
    doc["frames"]["end"] = "ten";
    expectError(doc, "/frames/end: expected a whole frame number");
    doc = turntable();
    doc["frames"]["end"] = 2.5;
    expectError(doc, "/frames/end: expected a whole frame number");
    doc = turntable();
    doc["frames"]["step"] = 2;
    expectError(doc, "/frames/step: unknown key (valid keys in /frames: start, end)");
    doc = turntable();
    doc["camera"]["orbit"]["axis"] = {0, 0, 0};
    expectError(doc, "/camera/orbit/axis: expected a non-zero vector");
    doc = turntable();
    doc["camera"]["orbit"]["axis"] = {0, 1};
    expectError(doc, "/camera/orbit/axis: expected an array of 3 numbers");
    doc = turntable();
    doc["camera"]["orbit"]["speed"] = 1;
    expectError(doc, "/camera/orbit/speed: unknown key");
    doc = turntable();
    doc["camera"]["orbit"].erase("degrees_per_frame");
    expectError(doc, "/camera/orbit/degrees_per_frame: missing");
    doc = turntable();
    doc["lights"][1]["orbit"]["degrees_per_frame"] = 1e9;
    expectError(doc, "/lights/1/orbit/degrees_per_frame: expected a number in [-3600, 3600]");
    doc = turntable();
    doc["output"]["exr"] = "out/turn.exr";
    expectError(doc, "/output/exr: \"out/turn.exr\" has no frame number, so every frame of 1-8");
    doc = turntable();
    doc["output"]["png"] = "out/turn.%s.png";
    expectError(doc, "/output/png: 'out/turn.%s.png': a '%' at character");
    // Scene keys are the scene parser's, with its messages.
    doc = turntable();
    doc["camera"]["fovy"] = 30;
    expectError(doc, "/camera/fovy: unknown key");
    doc = turntable();
    doc["lights"][0]["intensity"] = "bright";
    expectError(doc, "/lights/0/intensity: expected a number");
}

TEST(ShotsShot, AFrameTheOrbitSpoilsIsNamed) {
    // The camera circles the head's edge: at frame 3 it is inside the head.
    json doc = turntable();
    doc["head"] = {{"center", {0.8, 0.1, 0}}, {"radius", 0.1}};
    const Shot shot = Shot::parse(doc, "turn.json", "");
    EXPECT_NO_THROW(shot.frame(2));
    try {
        shot.frame(7);
        ADD_FAILURE() << "frame 7 puts the camera inside the head";
    } catch (const InputError& e) {
        EXPECT_TRUE(test::contains(e.what(), "turn.json frame 7: ")) << e.what();
        EXPECT_TRUE(test::contains(e.what(), "inside the head")) << e.what();
    }
    EXPECT_THROW(shot.select(FrameSet::parse("7-9")), InputError);
    EXPECT_EQ(shot.select(FrameSet::parse("2-4")).size(), 3u);
}

TEST(ShotsShot, IsShotFileTellsShotsFromScenes) {
    test::TempDir dir;
    test::writeText(dir / "shot.json", turntable().dump());
    json scene = turntable();
    scene.erase("frames");
    test::writeText(dir / "scene.json", scene.dump());
    test::writeText(dir / "broken.json", "{ not json");
    EXPECT_TRUE(isShotFile(dir / "shot.json"));
    EXPECT_FALSE(isShotFile(dir / "scene.json"));
    EXPECT_FALSE(isShotFile(dir / "broken.json"));
    EXPECT_THROW(isShotFile(dir / "absent.json"), InputError);
    EXPECT_EQ(Shot::load(dir / "shot.json").name(), (dir / "shot.json").string());
}

TEST(ShotsShot, ExampleShotsParse) {
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(test::dataDir() / "shots")) {
        SCOPED_TRACE(entry.path().string());
        const Shot shot = Shot::load(entry.path());
        EXPECT_NO_THROW(shot.frame(shot.end()));
        ++count;
    }
    EXPECT_GE(count, 1);
}

} // namespace
} // namespace hairvox::shots
