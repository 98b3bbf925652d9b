// The shot commands (docs/farm.md): render --frames (a line per frame and
// the total; a run again renders nothing), status, submit --dry-run (the
// sbatch script of the frames not done), sheet (ffmpeg's movie, contact
// sheet and GIF); bad input exits 2 naming what is wrong.
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/film/image_file.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace hairvox {
namespace {

namespace fs = std::filesystem;
using test::contains;
using test::quoted;

/// A 4-frame turntable at 24², its outputs in dir/out.
fs::path writeShot(const test::TempDir& dir, const std::string& extra = "") {
    const fs::path path = dir / "turn.json";
    test::writeText(path, R"({
      "frames": { "start": 1, "end": 4 },
      "groom": { "procedural": { "style": "wavy", "strands": 100, "seed": 2 } },
      "lights": [ { "name": "key", "type": "directional", "direction": [0, 1, -1] } ],
      "camera": { "position": [0, 0.05, -0.6], "look_at": [0, -0.05, 0], "fov": 40,
                  "resolution": [24, 24], "orbit": { "degrees_per_frame": 90 } },
      "head": { "center": [0, 0, 0], "radius": 0.1 },)" +
                              extra + R"(
      "output": { "exr": ")" + (dir / "out/turn.%04d.exr").string() +
                              R"(", "png": ")" + (dir / "out/turn.####.png").string() + R"(" }
    })");
    return path;
}

std::string cacheEnv(const test::TempDir& dir) {
    return "HAIRVOX_CACHE_DIR=" + quoted(dir / "tables") + " ";
}

TEST(CliShots, RenderFramesSaysWhatBecameOfEachAndSkipsWhatIsDone) {
    test::TempDir dir;
    const fs::path shot = writeShot(dir);
    const auto first =
        test::runShell(cacheEnv(dir) + quoted(HAIRVOX_BINARY) + " render " + quoted(shot) +
                       " --frames 1-3 --quiet --cache " + quoted(dir / "cache") + " 2>&1");
    ASSERT_EQ(first.exitCode, 0) << first.output;
    EXPECT_TRUE(contains(first.output, "3 frame(s) 1-3 of 1-4")) << first.output;
    EXPECT_TRUE(contains(first.output, "frame 1 (1 of 3): rendered")) << first.output;
    EXPECT_TRUE(contains(first.output, "frame 2 (2 of 3): rendered")) << first.output;
    EXPECT_TRUE(contains(first.output, "the frame before's grid and 1 light(s)")) << first.output;
    EXPECT_TRUE(contains(first.output, "3 of 3 frames rendered, 0 up to date, 0 failed"))
        << first.output;
    EXPECT_TRUE(fs::exists(dir / "out/turn.0003.png"));
    EXPECT_FALSE(fs::exists(dir / "out/turn.0004.exr"));

    // All frames (the default): only frame 4 is rendered.
    const auto all = test::runShell(cacheEnv(dir) + quoted(HAIRVOX_BINARY) + " render " +
                                    quoted(shot) + " --quiet 2>&1");
    ASSERT_EQ(all.exitCode, 0) << all.output;
    EXPECT_TRUE(contains(all.output, "frame 2 (2 of 4): up to date")) << all.output;
    EXPECT_TRUE(contains(all.output, "1 of 4 frames rendered, 3 up to date")) << all.output;
    const auto forced = test::runShell(cacheEnv(dir) + quoted(HAIRVOX_BINARY) + " render " +
                                       quoted(shot) + " --frames 2 --force --quiet 2>&1");
    EXPECT_TRUE(contains(forced.output, "1 of 1 frames rendered")) << forced.output;
    // An override is part of the frame: at another width frame 4 is rendered again.
    const auto wider = test::runShell(cacheEnv(dir) + quoted(HAIRVOX_BINARY) + " render " +
                                      quoted(shot) + " --frames 4 --width 32 --quiet 2>&1");
    EXPECT_TRUE(contains(wider.output, "1 of 1 frames rendered")) << wider.output;
    EXPECT_EQ(readExrInfo(dir / "out/turn.0004.exr").width, 32);
}

TEST(CliShots, BadFramesAndShotsExitTwoNamingTheProblem) {
    test::TempDir dir;
    const fs::path shot = writeShot(dir);
    const auto outside = test::runHairvox("render " + quoted(shot) + " --frames 3-9");
    EXPECT_EQ(outside.exitCode, 2);
    EXPECT_TRUE(contains(outside.output, "frame 5 is not one of")) << outside.output;
    const auto garbled = test::runHairvox("status " + quoted(shot) + " --frames 1-x");
    EXPECT_EQ(garbled.exitCode, 2);
    EXPECT_TRUE(contains(garbled.output, "--frames 1-x")) << garbled.output;
    test::writeText(dir / "scene.json", R"({ "groom": { "procedural": {} },
        "lights": [], "camera": { "position": [0, 0, -1], "look_at": [0, 0, 0] } })");
    const auto notShot = test::runHairvox("render " + quoted(dir / "scene.json") + " --frames 1");
    EXPECT_EQ(notShot.exitCode, 2);
    EXPECT_TRUE(contains(notShot.output, "/frames: missing")) << notShot.output;
    const auto oneFile =
        test::runHairvox("render " + quoted(shot) + " -o " + quoted(dir / "a.exr"));
    EXPECT_EQ(oneFile.exitCode, 2);
    EXPECT_TRUE(contains(oneFile.output, "--exr, --png and -o name one file")) << oneFile.output;
}

TEST(CliShots, StatusListsDoneMissingAndStaleFrames) {
    test::TempDir dir;
    const fs::path shot = writeShot(dir);
    ASSERT_EQ(test::runShell(cacheEnv(dir) + quoted(HAIRVOX_BINARY) + " render " + quoted(shot) +
                             " --frames 1-2 --quiet")
                  .exitCode,
              0);
    fs::remove(dir / "out/turn.0002.png");
    const auto status = test::runHairvox("status " + quoted(shot));
    ASSERT_EQ(status.exitCode, 0) << status.output;
    EXPECT_TRUE(contains(status.output, "1 done, 2 missing, 1 stale, 0 blocked")) << status.output;
    EXPECT_TRUE(contains(status.output, "missing  3-4")) << status.output;
    EXPECT_TRUE(contains(status.output, "2 stale:")) << status.output;
    EXPECT_TRUE(contains(status.output, "to render: 2-4")) << status.output;
    const auto todo = test::runHairvox("status " + quoted(shot) + " --todo");
    EXPECT_EQ(todo.output, "2-4\n");
    const auto json = test::runHairvox("status " + quoted(shot) + " --json");
    const nlohmann::json parsed = nlohmann::json::parse(json.output);
    EXPECT_EQ(parsed["done"], "1");
    EXPECT_EQ(parsed["missing"], "3-4");
    EXPECT_EQ(parsed["detail"][1]["state"], "stale");
    // A temporary a killed render left is listed (and is not an output).
    test::writeText(dir / "out/.turn.0003.exr.tmp-node7-4242-0", "half");
    const auto leftovers = test::runHairvox("status " + quoted(shot));
    EXPECT_TRUE(contains(leftovers.output, "1 temporary file(s) of renders killed outright"))
        << leftovers.output;
    EXPECT_TRUE(contains(leftovers.output, "missing  3-4")) << leftovers.output;
}

TEST(CliShots, SubmitDryRunWritesTheScriptOfTheFramesNotDone) {
    test::TempDir dir;
    const fs::path shot = writeShot(dir);
    ASSERT_EQ(test::runShell(cacheEnv(dir) + quoted(HAIRVOX_BINARY) + " render " + quoted(shot) +
                             " --frames 2 --quiet")
                  .exitCode,
              0);
    const auto dry = test::runHairvox("submit " + quoted(shot) +
                                      " --per-task 2 --cpus 3 --partition gpu_a --time 1:00:00 "
                                      "--mem 4G --max-running 5 --sbatch=--account=show "
                                      "--sbatch=--qos=low --sheet --dry-run");
    ASSERT_EQ(dry.exitCode, 0) << dry.output;
    EXPECT_TRUE(contains(dry.output, "dry run, nothing submitted: frames 1,3-4")) << dry.output;
    const std::string script = test::readBytes(dir / "turn.farm/turn.sbatch");
    EXPECT_TRUE(contains(dry.output, script));
    EXPECT_TRUE(contains(script, "#SBATCH --array=0-1%5\n")) << script;
    EXPECT_TRUE(contains(script, "#SBATCH --account=show\n#SBATCH --qos=low\n")) << script;
    EXPECT_TRUE(contains(script, "#SBATCH --cpus-per-task=3\n")) << script;
    EXPECT_TRUE(contains(script, "#SBATCH --partition=gpu_a\n")) << script;
    EXPECT_TRUE(contains(script, "#SBATCH --time=1:00:00\n")) << script;
    EXPECT_TRUE(contains(script, "#SBATCH --mem=4G\n")) << script;
    EXPECT_TRUE(contains(script, strCat("#SBATCH --chdir=", fs::current_path().string())))
        << script;
    EXPECT_TRUE(contains(script, (dir / "turn.farm/logs/turn-%A_%a.out").string())) << script;
    EXPECT_TRUE(contains(script, "chunks=(\n  '1,3'\n  '4'\n)")) << script;
    EXPECT_TRUE(contains(script, " render " + quoted(shot) + " --frames \"$frames\" --threads"))
        << script;
    EXPECT_TRUE(contains(script, "--cache " + quoted(dir / "turn.farm/cache"))) << script;
    EXPECT_TRUE(fs::exists(dir / "turn.farm/logs"));
    const std::string sheet = test::readBytes(dir / "turn.farm/turn.sheet.sbatch");
    EXPECT_TRUE(contains(sheet, " sheet " + quoted(shot) + " --frames '1-4'")) << sheet;

    // Refused options; no sbatch on the PATH.
    const auto badTime = test::runHairvox("submit " + quoted(shot) + " --time soon --dry-run");
    EXPECT_EQ(badTime.exitCode, 2);
    EXPECT_TRUE(contains(badTime.output, "--time soon")) << badTime.output;
    const auto badOption =
        test::runHairvox("submit " + quoted(shot) + " --sbatch=account --dry-run");
    EXPECT_EQ(badOption.exitCode, 2);
    EXPECT_TRUE(contains(badOption.output, "expected one sbatch option")) << badOption.output;
    const auto noSbatch = test::runShell("PATH=/nonexistent " + quoted(HAIRVOX_BINARY) +
                                         " submit " + quoted(shot) + " 2>&1");
    EXPECT_EQ(noSbatch.exitCode, 2) << noSbatch.output;
    EXPECT_TRUE(contains(noSbatch.output, "sbatch is not on the PATH")) << noSbatch.output;
}

TEST(CliShots, SheetMakesAMovieAContactSheetAndAGif) {
    test::TempDir dir;
    const fs::path shot = writeShot(dir);
    const auto missing = test::runHairvox("sheet " + quoted(shot));
    EXPECT_EQ(missing.exitCode, 2);
    EXPECT_TRUE(contains(missing.output, "4 of 4 frames have no PNG (1-4)")) << missing.output;
    ASSERT_EQ(test::runShell(cacheEnv(dir) + quoted(HAIRVOX_BINARY) + " render " + quoted(shot) +
                             " --quiet")
                  .exitCode,
              0);
    const auto made = test::runHairvox("sheet " + quoted(shot) + " --gif " +
                                       quoted(dir / "turn.gif") + " --columns 2 --fps 12");
    ASSERT_EQ(made.exitCode, 0) << made.output;
    for (const char* file : {"out/turn.mp4", "out/turn.sheet.png", "turn.gif"})
        EXPECT_TRUE(contains(made.output, "wrote " + (dir / file).string())) << made.output;
    // What ffprobe (Debian's ffmpeg) reads in them: 4 frames of H.264, a
    // 2 × 2 sheet of 192-pixel thumbnails, a 4-frame GIF.
    const auto probe = [&](const fs::path& file, const std::string& entries) {
        return test::runShell("ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                              "stream=" +
                              entries + " -of csv=p=0 " + quoted(file) + " 2>&1")
            .output;
    };
    EXPECT_EQ(probe(dir / "out/turn.mp4", "codec_name,nb_read_frames"), "h264,4\n");
    EXPECT_EQ(probe(dir / "out/turn.sheet.png", "width,height"), "396,396\n");
    EXPECT_EQ(probe(dir / "turn.gif", "codec_name,nb_read_frames"), "gif,4\n");
}

} // namespace
} // namespace hairvox
