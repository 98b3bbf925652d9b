// Issue 8: outputs are written atomically. A render killed with SIGKILL at any
// moment — while computing, while writing the EXR or the PNG, while writing the
// table cache — leaves under each final name either the previous file or the
// complete new one (byte-identical to an uninterrupted render: renders are
// deterministic), never a partial file. Hidden temporaries (".NAME.tmp-HOST-PID-N")
// may remain after SIGKILL; they are not outputs.
#include "render_run.h"

#include <hairvox/core/error.h>

#include <gtest/gtest.h>

#include <cstdio>

namespace hairvox {
namespace {

namespace fs = std::filesystem;

constexpr double kRenderTimeLimit = 300;
const std::string kOldExr = "previous EXR bytes";
const std::string kOldPng = "previous PNG bytes";

struct Reference {
    std::string exr, png;
    double seconds = 0;
};

class KillSlow : public ::testing::Test {
protected:
    void SetUp() override {
        scene_ = dir_ / "scene.json";
        test::writeText(scene_, test::smallRenderScene());
        const test::ChildResult r =
            test::runChild(test::renderOptions(scene_, dir_ / "ref", cache_), kRenderTimeLimit);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        ref_ = {test::readBytes(dir_ / "ref" / "out.exr"), test::readBytes(dir_ / "ref" / "out.png"),
                r.seconds};
        ASSERT_GT(ref_.exr.size(), 10000u);
        ASSERT_GT(ref_.png.size(), 1000u);
    }

    /// A work directory holding the previous outputs.
    fs::path runDir(const std::string& name) const {
        const fs::path d = dir_ / name;
        fs::create_directories(d);
        test::writeText(d / "out.exr", kOldExr);
        test::writeText(d / "out.png", kOldPng);
        return d;
    }

    /// Each final name holds the old bytes or the complete new file.
    void expectOldOrComplete(const fs::path& d, const std::string& when) const {
        const std::string exr = test::readBytes(d / "out.exr"), png = test::readBytes(d / "out.png");
        EXPECT_TRUE(exr == kOldExr || exr == ref_.exr)
            << when << ": out.exr is neither the old file nor the complete render (" << exr.size()
            << " bytes)";
        EXPECT_TRUE(png == kOldPng || png == ref_.png)
            << when << ": out.png is neither the old file nor the complete render (" << png.size()
            << " bytes)";
    }

    test::TempDir dir_;
    fs::path scene_;
    fs::path cache_ = dir_ / "cache";
    Reference ref_;
};

TEST_F(KillSlow, AtAnyMomentTheOutputsAreOldOrComplete) {
    for (double fraction : {0.05, 0.25, 0.5, 0.75, 0.9}) {
        const fs::path d = runDir(strCat("at", fraction));
        test::Child child(test::renderOptions(scene_, d, cache_));
        const double at = fraction * ref_.seconds;
        test::waitFor(child, [&] { return child.secondsRunning() >= at; }, kRenderTimeLimit);
        child.signal(SIGKILL);
        const test::ChildResult r = child.wait(kRenderTimeLimit);
        expectOldOrComplete(d, strCat("killed at ", at, " s"));
        std::printf("killed at %.2f s of %.2f s: %s\n", at, ref_.seconds,
                    r.signal == SIGKILL ? "killed" : "had already finished");
    }
}

TEST_F(KillSlow, DuringTheWriteTheOutputsAreOldOrComplete) {
    // Kill the moment the EXR's (then the PNG's) temporary is created; retry if
    // the write was over before the signal landed. Both go through
    // writeFileAtomically(); the EXR (2 MB) must be caught mid-write. The PNG
    // (60 KB) is written, flushed and renamed within a kill's latency on most
    // attempts, so for it only "old or complete" is required of every attempt.
    for (const std::string name : {"out.exr", "out.png"}) {
        bool killedMidWrite = false;
        for (int attempt = 0; attempt < 5 && !killedMidWrite; ++attempt) {
            const fs::path d = runDir(strCat("write-", name, attempt));
            test::Child child(test::renderOptions(scene_, d, cache_));
            const bool writing = test::waitForTemporaryOf(child, d, name, kRenderTimeLimit);
            child.signal(SIGKILL);
            child.wait(kRenderTimeLimit);
            ASSERT_TRUE(writing) << "the render ended before writing " << name;
            expectOldOrComplete(d, "killed while writing " + name);
            killedMidWrite = test::hasTemporaryOf(d, name);
            if (killedMidWrite) {
                EXPECT_EQ(test::readBytes(d / name), name == "out.exr" ? kOldExr : kOldPng);
            }
        }
        if (name == "out.exr") {
            EXPECT_TRUE(killedMidWrite) << "never caught the process while writing " << name;
        }
        std::printf("%s: %s\n", name.c_str(),
                    killedMidWrite ? "killed mid-write" : "the write was over before the kill");
    }
    // A later render in the same directory replaces the outputs; the stale
    // temporaries of the killed runs do not get in its way.
    const fs::path d = dir_ / "write-out.exr0";
    const test::ChildResult r =
        test::runChild(test::renderOptions(scene_, d, cache_), kRenderTimeLimit);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(test::readBytes(d / "out.exr"), ref_.exr);
    EXPECT_EQ(test::readBytes(d / "out.png"), ref_.png);
}

TEST_F(KillSlow, DuringTheTableCacheWriteTheCacheStaysUsable) {
    // A fresh cache: the render builds the dual-scattering tables and writes
    // them (a small file: the kill may land just before or after the write).
    const fs::path cache = dir_ / "fresh-cache";
    const fs::path d = runDir("cache-kill");
    fs::create_directories(cache); // empty: watched for the tables' temporary
    {
        test::Child child(test::renderOptions(scene_, d, cache));
        // inotify, not polling: the small write can be over between two polls.
        const bool writing =
            test::waitForTemporaryOf(child, cache, "dual-scattering-", kRenderTimeLimit);
        child.signal(SIGKILL);
        child.wait(kRenderTimeLimit);
        ASSERT_TRUE(writing) << "the render ended before writing its table cache";
        std::printf("killed %s the table cache write\n",
                    test::temporaries(cache).empty() ? "just after" : "during");
    }
    // Whatever was left, the next render works and gives the same image.
    test::ChildResult r = test::runChild(test::renderOptions(scene_, d, cache), kRenderTimeLimit);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
    EXPECT_EQ(test::readBytes(d / "out.exr"), ref_.exr);

    // A cache file cut short (a disk problem, not hairvox: writes are atomic)
    // is rebuilt, not trusted.
    for (const auto& e : fs::directory_iterator(cache))
        if (e.path().extension() == ".bin")
            fs::resize_file(e.path(), fs::file_size(e.path()) / 2);
    fs::remove(d / "out.exr");
    r = test::runChild(test::renderOptions(scene_, d, cache), kRenderTimeLimit);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(test::readBytes(d / "out.exr"), ref_.exr);
}

} // namespace
} // namespace hairvox
