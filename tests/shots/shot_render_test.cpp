// A shot's frames rendered in one process (shots/shot_render.h) and their
// status (shots/frame_status.h): each EXR records its digest; a run again
// renders only what is not done; an edit of the shot or an input makes
// frames stale; a damaged or half-present output is stale; a frame whose
// input is missing is blocked (and fails alone); each frame is the same
// image in any run.
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/film/image_file.h>
#include <hairvox/shots/frame_status.h>
#include <hairvox/shots/shot_render.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

namespace hairvox::shots {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// A 3-frame turntable at 32², outputs under `dir` (absolute).
json turntable(const test::TempDir& dir) {
    json doc = json::parse(R"({
      "frames": { "start": 1, "end": 3 },
      "groom": { "procedural": { "style": "wavy", "strands": 120, "seed": 4 } },
      "lights": [ { "name": "key", "type": "directional", "direction": [0, 1, -1] } ],
      "camera": { "position": [0, 0.05, -0.6], "look_at": [0, -0.05, 0], "fov": 40,
                  "resolution": [32, 32], "orbit": { "degrees_per_frame": 30 } },
      "head": { "center": [0, 0, 0], "radius": 0.1 }
    })");
    doc["output"] = {{"exr", (dir / "out/t.%04d.exr").string()},
                     {"png", (dir / "out/t.####.png").string()}};
    return doc;
}

Shot write(const test::TempDir& dir, const json& doc) {
    test::writeText(dir / "t.json", doc.dump(2));
    return Shot::load(dir / "t.json");
}

ShotRenderOptions options(const test::TempDir& dir) {
    ShotRenderOptions o;
    o.pipeline.tableCacheDir = dir / "tables";
    return o;
}

std::vector<FrameState> states(const Shot& shot) {
    std::vector<FrameState> out;
    for (const FrameStatus& s : shotStatus(shot, shot.frames()))
        out.push_back(s.state);
    return out;
}

TEST(ShotsRender, FramesRecordTheirDigestAndARunAgainRendersNothing) {
    test::TempDir dir;
    const Shot shot = write(dir, turntable(dir));
    EXPECT_EQ(states(shot), std::vector<FrameState>(3, FrameState::Missing));
    std::vector<int> seen;
    const ShotRenderSummary first =
        renderShot(shot, shot.frames(), options(dir), [&](const FrameReport& r) {
            seen.push_back(r.frame);
            EXPECT_EQ(r.outcome, FrameReport::Outcome::Rendered) << r.error;
            EXPECT_EQ(r.count, 3u);
            ASSERT_NE(r.render, nullptr);
            // A turntable splats and prepares its light once.
            EXPECT_EQ(r.render->gridReused, r.frame > 1);
            EXPECT_EQ(r.render->lights[0].reused, r.frame > 1);
        });
    EXPECT_EQ(seen, (std::vector<int>{1, 2, 3}));
    EXPECT_EQ(first.rendered, 3u);
    EXPECT_TRUE(first.failed.empty());
    const ExrInfo info = readExrInfo(dir / "out/t.0002.exr");
    EXPECT_TRUE(info.complete);
    EXPECT_EQ(info.attributes.at(kFrameAttribute), "2");
    EXPECT_EQ(info.attributes.at(kShotAttribute), (dir / "t.json").string());
    const std::vector<FrameStatus> status = shotStatus(shot, shot.frames());
    EXPECT_EQ(info.attributes.at(kFrameHashAttribute), status[1].hash);
    EXPECT_EQ(states(shot), std::vector<FrameState>(3, FrameState::Done));
    // The frames differ (the camera turns).
    EXPECT_NE(test::readBytes(dir / "out/t.0001.png"), test::readBytes(dir / "out/t.0002.png"));

    const auto written = fs::last_write_time(dir / "out/t.0002.exr");
    const ShotRenderSummary again = renderShot(shot, shot.frames(), options(dir));
    EXPECT_EQ(again.rendered, 0u);
    EXPECT_EQ(again.upToDate, 3u);
    EXPECT_EQ(fs::last_write_time(dir / "out/t.0002.exr"), written) << "a done frame rewritten";

    ShotRenderOptions forced = options(dir);
    forced.force = true;
    EXPECT_EQ(renderShot(shot, FrameSet::parse("2"), forced).rendered, 1u);
}

TEST(ShotsRender, AFrameIsTheSameImageInAnyRun) {
    test::TempDir dir;
    const Shot shot = write(dir, turntable(dir));
    renderShot(shot, shot.frames(), options(dir));
    const std::string exr = test::readBytes(dir / "out/t.0003.exr");
    const std::string png = test::readBytes(dir / "out/t.0003.png");
    // Frame 3 alone, without the frames before it to share a grid with.
    fs::remove(dir / "out/t.0003.exr");
    fs::remove(dir / "out/t.0003.png");
    EXPECT_EQ(renderShot(shot, FrameSet::parse("3"), options(dir)).rendered, 1u);
    EXPECT_TRUE(test::readBytes(dir / "out/t.0003.exr") == exr);
    EXPECT_TRUE(test::readBytes(dir / "out/t.0003.png") == png);
}

TEST(ShotsRender, EditsMakeFramesStaleAndDamagedOutputsAreNotDone) {
    test::TempDir dir;
    json doc = turntable(dir);
    Shot shot = write(dir, doc);
    renderShot(shot, shot.frames(), options(dir));
    ASSERT_EQ(states(shot), std::vector<FrameState>(3, FrameState::Done));

    // A PNG gone, an EXR cut short.
    fs::remove(dir / "out/t.0001.png");
    const std::string exr = test::readBytes(dir / "out/t.0002.exr");
    test::writeText(dir / "out/t.0002.exr", exr.substr(0, exr.size() / 2));
    const std::vector<FrameStatus> damaged = shotStatus(shot, shot.frames());
    EXPECT_EQ(damaged[0].state, FrameState::Stale);
    EXPECT_TRUE(test::contains(damaged[0].reason, "without")) << damaged[0].reason;
    EXPECT_EQ(damaged[1].state, FrameState::Stale);
    EXPECT_FALSE(damaged[1].reason.empty());
    EXPECT_EQ(damaged[2].state, FrameState::Done);
    const ShotRenderSummary repaired = renderShot(shot, shot.frames(), options(dir));
    EXPECT_EQ(repaired.rendered, 2u);
    EXPECT_EQ(repaired.upToDate, 1u);

    // The shot edited: every frame stale, and rendered again.
    doc["camera"]["fov"] = 35;
    shot = write(dir, doc);
    const std::vector<FrameStatus> edited = shotStatus(shot, shot.frames());
    for (const FrameStatus& s : edited) {
        EXPECT_EQ(s.state, FrameState::Stale);
        EXPECT_TRUE(test::contains(s.reason, "rendered from another scene")) << s.reason;
    }
    EXPECT_EQ(renderShot(shot, shot.frames(), options(dir)).rendered, 3u);
    // A command-line override is part of what a frame is made of.
    ShotRenderOptions wider = options(dir);
    wider.adjust = [](Scene& s) {
        s.camera.width = 48;
    };
    EXPECT_EQ(shotStatus(shot, shot.frames(), wider.adjust)[0].state, FrameState::Stale);
}

TEST(ShotsRender, AFrameWithoutItsGroomIsBlockedAndFailsAlone) {
    test::TempDir dir;
    ProceduralGroomParams p;
    p.strands = 100;
    fs::create_directories(dir / "sim");
    for (const int f : {1, 3}) {
        p.seed = std::uint64_t(f);
        writeHairFile(dir / strCat("sim/g.000", f, ".hair"), generateGroom(p));
    }
    json doc = turntable(dir);
    doc["groom"] = {{"file", "sim/g.%04d.hair"}};
    const Shot shot = write(dir, doc);
    EXPECT_TRUE(shot.groomVaries());
    const std::vector<FrameStatus> before = shotStatus(shot, shot.frames());
    EXPECT_EQ(before[1].state, FrameState::Blocked);
    EXPECT_TRUE(test::contains(before[1].reason, "g.0002.hair")) << before[1].reason;
    std::vector<FrameReport::Outcome> outcomes;
    const ShotRenderSummary summary =
        renderShot(shot, shot.frames(), options(dir),
                   [&](const FrameReport& r) { outcomes.push_back(r.outcome); });
    EXPECT_EQ(summary.rendered, 2u);
    EXPECT_EQ(summary.failed.toString(), "2");
    EXPECT_FALSE(summary.internalError);
    EXPECT_EQ(outcomes[1], FrameReport::Outcome::Failed);
    EXPECT_FALSE(fs::exists(dir / "out/t.0002.exr"));
}

TEST(ShotsRender, OutputsThatWouldOverwriteAnInputAreRefusedBeforeAnyRender) {
    test::TempDir dir;
    ProceduralGroomParams p;
    p.strands = 50;
    writeHairFile(dir / "g.0001.hair", generateGroom(p));
    json doc = turntable(dir);
    doc["groom"] = {{"file", "g.%04d.hair"}};
    doc["output"]["png"] = (dir / "g.%04d.hair").string();
    const Shot shot = write(dir, doc);
    try {
        renderShot(shot, shot.frames(), options(dir));
        ADD_FAILURE() << "a groom file would have been overwritten";
    } catch (const InputError& e) {
        EXPECT_TRUE(test::contains(e.what(), "groom file")) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "out/t.0001.exr")) << "rendered before the check";
}

} // namespace
} // namespace hairvox::shots
