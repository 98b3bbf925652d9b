// What a new user trips over in `hairvox render` (issue 15 §3): outputs chosen
// by explicit flags and never sharing a file, warnings naming what a render
// silently ignored, a useless voxel size, a width alone, and a render too big
// for memory refused before allocating.
#include "test_util.h"

#include <hairvox/film/image_file.h>

#include <gtest/gtest.h>

#include <chrono>

namespace hairvox {
namespace {

using test::quoted;
using test::readBytes;
using test::contains;

namespace fs = std::filesystem;

bool isPng(const fs::path& p) {
    return readBytes(p).rfind("\x89PNG", 0) == 0;
}

bool isExr(const fs::path& p) {
    return readBytes(p).rfind("\x76\x2f\x31\x01", 0) == 0;
}

/// A small scene: 200 procedural strands on a head, 32 x 32 unless changed.
struct SmallScene {
    std::string lights = R"([{ "name": "key", "type": "directional", "direction": [0, 1, -1] }])";
    std::string camera = R"("position": [0, 0.05, -0.6], "look_at": [0, 0.05, 0], "fov": 40,
                            "resolution": [32, 32])";
    std::string output;
    std::string extra;

    std::string json() const {
        return R"({ "groom": { "procedural": { "style": "wavy", "strands": 200, "seed": 1 } },
                    "lights": )" +
               lights + R"(, "camera": { )" + camera + R"( },
                    "head": { "center": [0, 0, 0], "radius": 0.1 })" +
               (output.empty() ? "" : ", \"output\": " + output) + extra + "}";
    }
    fs::path write(const test::TempDir& dir, const std::string& name = "s.json") const {
        test::writeText(dir / name, json());
        return dir / name;
    }
};

std::string outputs(const fs::path& exr, const fs::path& png) {
    return R"({ "exr": ")" + exr.string() + R"(", "png": ")" + png.string() + R"(" })";
}

TEST(CliRenderOutputs, ExtensionOfOChoosesTheOutput) {
    test::TempDir dir;
    const fs::path scene = SmallScene{}.write(dir, "issue15_o_png.json");
    // The scene's own outputs would be out/issue15_o_png.{exr,png} in the working directory.
    const fs::path sceneExr = fs::current_path() / "out" / "issue15_o_png.exr";
    fs::remove(sceneExr);
    // -o x.png sets the PNG only: no EXR is written over it or anywhere else.
    auto r = test::runHairvox("render " + quoted(scene) + " --quiet -o " + quoted(dir / "x.png"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(isPng(dir / "x.png"));
    EXPECT_FALSE(fs::exists(dir / "x.exr"));
    EXPECT_FALSE(fs::exists(sceneExr)) << "the scene's own outputs were written too";
    // -o y.exr with --png: both, each what its name says.
    r = test::runHairvox("render " + quoted(scene) + " --quiet -o " + quoted(dir / "y.exr") +
                         " --png " + quoted(dir / "y.png"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(isExr(dir / "y.exr"));
    EXPECT_TRUE(isPng(dir / "y.png"));
    r = test::runHairvox("render " + quoted(scene) + " --quiet --exr " + quoted(dir / "z.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(isExr(dir / "z.exr"));
    EXPECT_FALSE(fs::exists(dir / "z.png"));
}

TEST(CliRenderOutputs, RefusesOutputsThatWouldLoseAFile) {
    test::TempDir dir;
    const fs::path scene = SmallScene{}.write(dir);
    test::writeText(dir / "keep.png", "the user's file");
    const auto refused = [&](const std::string& args, const std::string& part) {
        const auto r = test::runHairvox("render " + quoted(scene) + " --quiet " + args);
        EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, part)) << args << "\n" << r.output;
    };
    refused("-o " + quoted(dir / "a.tif"), "must be .exr or .png");
    refused("--exr " + quoted(dir / "keep.png") + " --png " + quoted(dir / "keep.png"),
            "--exr " + (dir / "keep.png").string() + " and --png " + (dir / "keep.png").string());
    refused("-o " + quoted(dir / "a.exr") + " --exr " + quoted(dir / "b.exr"), "both set the EXR");
    refused("--png " + quoted(scene), "is the scene file");
    EXPECT_EQ(readBytes(dir / "keep.png"), "the user's file");
    EXPECT_EQ(readBytes(scene), SmallScene{}.json());

    // The same file named twice in the scene itself.
    SmallScene same;
    same.output = outputs(dir / "same.png", dir / "same.png");
    const auto r = test::runHairvox("render " + quoted(same.write(dir, "same.json")) + " --quiet");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "output.exr and output.png")) << r.output;
    EXPECT_FALSE(fs::exists(dir / "same.png"));
}

TEST(CliRenderOutputs, NothingToWriteIsAnError) {
    test::TempDir dir;
    SmallScene scene;
    scene.output = R"({ "exr": null, "png": null })";
    const auto r = test::runHairvox("render " + quoted(scene.write(dir)) + " --quiet");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "nothing would be written")) << r.output;
}

TEST(CliRenderWarnings, LightInsideTheHeadIsNamed) {
    test::TempDir dir;
    SmallScene scene;
    scene.lights = R"([{ "name": "key", "type": "directional", "direction": [0, 1, -1] },
                       { "name": "buried", "type": "point", "position": [0, 0.01, 0] }])";
    scene.output = outputs(dir / "o.exr", dir / "o.png");
    const auto r = test::runHairvox("render " + quoted(scene.write(dir)) + " --quiet");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "warning: light 'buried'")) << r.output;
    EXPECT_TRUE(contains(r.output, "inside the head")) << r.output;
    EXPECT_FALSE(contains(r.output, "light 'key'")) << r.output;
}

TEST(CliRenderWarnings, CameraThatSeesNoHair) {
    test::TempDir dir;
    SmallScene scene;
    scene.camera =
        R"("position": [0, 0.05, -0.6], "look_at": [0, 0.05, -2], "resolution": [32, 32])";
    scene.output = outputs(dir / "o.exr", dir / "o.png");
    auto r = test::runHairvox("render " + quoted(scene.write(dir)) + " --quiet");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "warning: the camera sees no hair")) << r.output;
    // The small scene as it is sees hair: no such warning.
    SmallScene seen;
    seen.output = scene.output;
    r = test::runHairvox("render " + quoted(seen.write(dir)) + " --quiet");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_FALSE(contains(r.output, "warning")) << r.output;
}

TEST(CliRenderWarnings, VoxelSizeLargerThanTheGroom) {
    test::TempDir dir;
    SmallScene scene;
    scene.output = outputs(dir / "o.exr", dir / "o.png");
    const auto r =
        test::runHairvox("render " + quoted(scene.write(dir)) + " --quiet --voxel-size 0.5");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "grid.voxel_size = 0.5 is too large")) << r.output;
    EXPECT_TRUE(contains(r.output, "bounding box is")) << r.output;
    EXPECT_FALSE(fs::exists(dir / "o.exr"));
}

TEST(CliRenderWarnings, WidthAloneKeepsTheCameraAspect) {
    test::TempDir dir;
    SmallScene scene;
    scene.camera =
        R"("position": [0, 0.05, -0.6], "look_at": [0, 0.05, 0], "resolution": [200, 100])";
    scene.output = outputs(dir / "o.exr", dir / "o.png");
    const fs::path file = scene.write(dir);
    auto r = test::runHairvox("render " + quoted(file) + " --width 64");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "64x32")) << r.output;
    r = test::runHairvox("render " + quoted(file) + " --height 20");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "40x20")) << r.output;
}

TEST(CliRenderOptions, ShadingRateIsChosenOnTheCommandLine) {
    test::TempDir dir;
    SmallScene scene;
    scene.output = outputs(dir / "r.exr", dir / "r.png");
    const fs::path file = scene.write(dir);
    auto r = test::runHairvox("render " + quoted(file) + " --shading-rate vertex");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "(vertex rate)")) << r.output;
    r = test::runHairvox("render " + quoted(file) + " --shading-rate pixel");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_TRUE(contains(r.output, "--shading-rate")) << r.output;
    // The adaptive rate's report says what it interpolated instead of shading.
    r = test::runHairvox("render " + quoted(file) +
                         " --shading-rate adaptive --shading-tolerance 0.1");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "(adaptive rate, tolerance 0.1: ")) << r.output;
    EXPECT_TRUE(contains(r.output, "probed segment-tiles smooth")) << r.output;
    r = test::runHairvox("render " + quoted(file) + " --shading-tolerance 0.1");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_TRUE(contains(r.output, "--shading-tolerance applies to the adaptive")) << r.output;
    // The tail: reported when it interpolates anything, refused at the vertex rate.
    r = test::runHairvox("render " + quoted(file) + " --tail-transmittance 0.5");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "seen through transmittance < 0.5 interpolated from"))
        << r.output;
    r = test::runHairvox("render " + quoted(file) + " --shading-rate vertex --tail-transmittance 0.1");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_TRUE(contains(r.output, "--tail-transmittance applies to the fragment and adaptive"))
        << r.output;
    r = test::runHairvox("render " + quoted(file) + " --tail-transmittance 2");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_TRUE(contains(r.output, "--tail-transmittance")) << r.output;
}

TEST(CliRenderOptions, ExrCompressionIsChosenOnTheCommandLine) {
    test::TempDir dir;
    SmallScene scene;
    scene.output = outputs(dir / "zips.exr", dir / "r.png");
    const fs::path file = scene.write(dir);
    auto r = test::runHairvox("render " + quoted(file));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    r = test::runHairvox("render " + quoted(file) + " --exr " + quoted(dir / "none.exr") +
                         " --exr-compression none");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_GT(fs::file_size(dir / "none.exr"), 2 * fs::file_size(dir / "zips.exr"));
    EXPECT_EQ(readExr(dir / "none.exr").channels, readExr(dir / "zips.exr").channels)
        << "compression changed pixel values";
    r = test::runHairvox("render " + quoted(file) + " --exr-compression lzma");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_TRUE(contains(r.output, "--exr-compression")) << r.output;
}

TEST(CliRenderOptions, LayersAreChosenOnTheCommandLine) {
    test::TempDir dir;
    SmallScene scene;
    scene.output = outputs(dir / "all.exr", dir / "r.png");
    const fs::path file = scene.write(dir);
    auto r = test::runHairvox("render " + quoted(file) + " --quiet");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    r = test::runHairvox("render " + quoted(file) + " --exr " + quoted(dir / "none.exr") +
                         " --layers none");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "4 of 35 channels (output.layers)")) << r.output;
    const ExrImage all = readExr(dir / "all.exr"), none = readExr(dir / "none.exr");
    ASSERT_EQ(none.channels.size(), 4u);
    for (const char* c : {"R", "G", "B", "A"})
        EXPECT_EQ(none.channels.at(c), all.channels.at(c)) << c << " changed";
    // compare: without the hair alpha, the mask it reads by default is named
    // with what to do; the beauty under A compares.
    r = test::runHairvox("compare " + quoted(dir / "none.exr") + " " + quoted(dir / "all.exr"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "--what beauty --mask A")) << r.output;
    r = test::runHairvox("compare " + quoted(dir / "none.exr") + " " + quoted(dir / "all.exr") +
                         " --what beauty --mask A");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "relative L1:     0.0000")) << r.output;
    r = test::runHairvox("render " + quoted(file) + " --quiet --exr " +
                         quoted(dir / "some.exr") + " --layers Z,key.V");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(readExr(dir / "some.exr").channels.size(), 6u);
    r = test::runHairvox("render " + quoted(file) + " --quiet --exr " + quoted(dir / "x.exr") +
                         " --layers Z,key.v");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "output.layers[1] \"key.v\": not a layer")) << r.output;
    EXPECT_FALSE(fs::exists(dir / "x.exr"));
}

TEST(CliRenderMemory, AbsurdSizeFailsFastWithTheEstimate) {
    test::TempDir dir;
    const auto start = std::chrono::steady_clock::now();
    const auto r = test::runHairvox("render --width 8000 --height 8000 --max-memory 1 --exr " +
                                    quoted(dir / "big.exr") + " --png " + quoted(dir / "big.png"));
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "8000 x 8000 render would need about")) << r.output;
    EXPECT_TRUE(contains(r.output, "over the memory limit of 1.0 GiB")) << r.output;
    EXPECT_TRUE(contains(r.output, "--max-memory")) << r.output;
    EXPECT_FALSE(fs::exists(dir / "big.exr"));
    EXPECT_FALSE(fs::exists(dir / "big.png"));
    EXPECT_LT(seconds, 10.0) << "refused only after work";
    // Within the limit the same command renders.
    const auto ok = test::runHairvox("render --width 24 --height 24 --max-memory 1 --quiet --png " +
                                     quoted(dir / "small.png"));
    EXPECT_EQ(ok.exitCode, 0) << ok.output;
    EXPECT_TRUE(isPng(dir / "small.png"));
}

} // namespace
} // namespace hairvox
