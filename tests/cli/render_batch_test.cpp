// `hairvox render A.json B.json ...`: the frames of a sequence rendered one
// after another in one process, sharing what does not change between them
// (tests/pipeline/frame_reuse_test.cpp). Each scene writes the bytes it writes alone;
// every scene and every output is checked before the first render; a scene
// that fails while rendering does not stop the others, and the exit code
// says it failed.
#include "test_util.h"

#include <gtest/gtest.h>


namespace hairvox {
namespace {

using test::quoted;
using test::readBytes;
using test::contains;

namespace fs = std::filesystem;

/// A 24 × 24 frame of 150 procedural strands, seen from `cameraX`, written
/// to the outputs it names (`groom` replaces the procedural groom).
fs::path writeFrame(const test::TempDir& dir, const std::string& name, float cameraX,
                    const fs::path& exr, const fs::path& png,
                    const std::string& groom =
                        R"({ "procedural": { "style": "wavy", "strands": 150, "seed": 3 } })") {
    const fs::path path = dir / (name + ".json");
    test::writeText(path, R"({ "groom": )" + groom + R"(,
        "lights": [{ "name": "key", "type": "directional", "direction": [0, 1, -1] }],
        "camera": { "position": [)" +
                              std::to_string(cameraX) +
                              R"(, 0.05, -0.6], "look_at": [0, 0.05, 0], "fov": 40,
                    "resolution": [24, 24] },
        "head": { "center": [0, 0, 0], "radius": 0.1 },
        "output": { "exr": ")" +
                              exr.string() + R"(", "png": ")" + png.string() + R"(" } })");
    return path;
}

TEST(CliRenderBatch, EachSceneWritesWhatItWritesAlone) {
    test::TempDir dir;
    const fs::path a = writeFrame(dir, "a", -0.1f, dir / "a.exr", dir / "a.png");
    const fs::path b = writeFrame(dir, "b", 0.1f, dir / "b.exr", dir / "b.png");
    const auto batch = test::runHairvox("render " + quoted(a) + " " + quoted(b));
    ASSERT_EQ(batch.exitCode, 0) << batch.output;
    EXPECT_TRUE(contains(batch.output, "2 of 2 scenes rendered")) << batch.output;
    // Only the camera moved: the second frame takes the first's grid and light.
    EXPECT_TRUE(contains(batch.output, "the frame before's grid")) << batch.output;
    EXPECT_TRUE(contains(batch.output, "key the frame before's")) << batch.output;
    for (const char* frame : {"a", "b"}) {
        const fs::path alone = dir / (std::string(frame) + "_alone.exr");
        const auto r = test::runHairvox("render " + quoted(dir / (std::string(frame) + ".json")) +
                                        " --quiet -o " + quoted(alone));
        ASSERT_EQ(r.exitCode, 0) << r.output;
        const std::string inBatch = readBytes(dir / (std::string(frame) + ".exr"));
        EXPECT_FALSE(inBatch.empty()) << frame;
        EXPECT_TRUE(inBatch == readBytes(alone)) << frame << ": the batch's EXR differs";
        EXPECT_TRUE(fs::exists(dir / (std::string(frame) + ".png"))) << frame;
    }
    // Two frames from different places are different images.
    EXPECT_NE(readBytes(dir / "a.exr"), readBytes(dir / "b.exr"));
}

TEST(CliRenderBatch, EverySceneIsCheckedBeforeTheFirstRender) {
    test::TempDir dir;
    const fs::path a = writeFrame(dir, "a", 0.0f, dir / "a.exr", dir / "a.png");
    test::writeText(dir / "typo.json", R"({ "groom": { "procedural": { "strands": "many" } } })");
    const auto r =
        test::runHairvox("render " + quoted(a) + " " + quoted(dir / "typo.json") + " --quiet");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "1 of 2 scenes cannot be rendered; nothing was rendered"))
        << r.output;
    EXPECT_TRUE(contains(r.output, (dir / "typo.json").string())) << r.output;
    EXPECT_FALSE(fs::exists(dir / "a.exr")) << "the good scene was rendered anyway";
}

TEST(CliRenderBatch, RefusesOutputsThatWouldLoseAFile) {
    test::TempDir dir;
    const auto refused = [&](const std::vector<fs::path>& scenes, const std::string& args,
                             const std::string& part) {
        std::string line = "render --quiet " + args;
        for (const fs::path& s : scenes)
            line += " " + quoted(s);
        const auto r = test::runHairvox(line);
        EXPECT_EQ(r.exitCode, 2) << line << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, part)) << line << "\n" << r.output;
    };
    const fs::path a = writeFrame(dir, "a", 0.0f, dir / "a.exr", dir / "a.png");
    // Command-line outputs name one file: refused for several scenes.
    const fs::path b = writeFrame(dir, "b", 0.1f, dir / "b.exr", dir / "b.png");
    refused({a, b}, "-o " + quoted(dir / "x.exr"), "with several scenes each writes");
    // Two scenes writing one file, spelt differently.
    const fs::path same =
        writeFrame(dir, "same", 0.1f, dir / "sub" / ".." / "a.exr", dir / "same.png");
    fs::create_directories(dir / "sub");
    refused({a, same}, "", "are the same file");
    // One scene's output over another's scene file or groom file.
    test::writeText(dir / "keep.hair", "the user's groom");
    const fs::path usesGroom =
        writeFrame(dir, "groom", 0.0f, dir / "g.exr", dir / "g.png",
                   R"({ "file": ")" + (dir / "keep.hair").string() + R"(" })");
    const fs::path overGroom = writeFrame(dir, "over", 0.0f, dir / "keep.hair", dir / "o.png");
    refused({usesGroom, overGroom}, "", "groom file");
    const fs::path overScene = writeFrame(dir, "overScene", 0.0f, dir / "o.exr", a);
    refused({a, overScene}, "", "is the scene file " + a.string());
    EXPECT_EQ(readBytes(dir / "keep.hair"), "the user's groom");
    EXPECT_FALSE(fs::exists(dir / "a.exr"));
    EXPECT_FALSE(fs::exists(dir / "b.exr"));
}

TEST(CliRenderBatch, AFailedSceneDoesNotStopTheOthers) {
    test::TempDir dir;
    // A groom file that exists but is not a groom: found only when loaded.
    test::writeText(dir / "broken.hair", "HAIR but not really");
    const fs::path a = writeFrame(dir, "a", 0.0f, dir / "a.exr", dir / "a.png");
    const fs::path broken =
        writeFrame(dir, "broken", 0.0f, dir / "broken.exr", dir / "broken.png",
                   R"({ "file": ")" + (dir / "broken.hair").string() + R"(" })");
    const fs::path c = writeFrame(dir, "c", 0.1f, dir / "c.exr", dir / "c.png");
    const auto r = test::runHairvox("render " + quoted(a) + " " + quoted(broken) + " " + quoted(c));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "hairvox: error: " + broken.string() + ": ")) << r.output;
    EXPECT_TRUE(contains(r.output, "2 of 3 scenes rendered")) << r.output;
    EXPECT_TRUE(contains(r.output, "1 of 3 scenes failed: " + broken.string())) << r.output;
    EXPECT_TRUE(fs::exists(dir / "a.exr"));
    EXPECT_TRUE(fs::exists(dir / "c.exr")) << "the scene after the failed one was not rendered";
    EXPECT_FALSE(fs::exists(dir / "broken.exr"));
}

} // namespace
} // namespace hairvox
