// Issue 8: a render interrupted with Ctrl-C (SIGINT) or by a farm scheduler
// (SIGTERM) stops promptly, says so, exits with 130 and leaves no output and
// no temporary behind: every long loop polls throwIfInterrupted() and the
// writers remove their temporaries while unwinding.
#include "render_run.h"

#include <hairvox/core/error.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <thread>

namespace hairvox {
namespace {

namespace fs = std::filesystem;

constexpr double kRenderTimeLimit = 300;
/// From the signal to the process's exit (the stages poll between chunks of
/// well under a second of work on one core).
constexpr double kMaxStopSeconds = 1.5;

class InterruptSlow : public ::testing::Test {
protected:
    void SetUp() override {
        scene_ = dir_ / "scene.json";
        test::writeText(scene_, test::smallRenderScene());
        const test::ChildResult r =
            test::runChild(test::renderOptions(scene_, dir_ / "ref", dir_ / "cache-ref"),
                           kRenderTimeLimit);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        seconds_ = r.seconds;
    }

    /// Sends `sig` once `ready()` holds; checks the stop and returns its latency
    /// (negative if the render finished first).
    template <typename Ready>
    double interrupt(const std::string& name, int sig, Ready ready) {
        const fs::path d = dir_ / name;
        // A fresh table cache per run, so that early signals land in the table build.
        test::Child child(test::renderOptions(scene_, d, d / "cache"));
        if (!test::waitFor(child, [&] { return ready(child, d); }, kRenderTimeLimit)) {
            const test::ChildResult r = child.wait(kRenderTimeLimit);
            EXPECT_EQ(r.exitCode, 0) << r.output;
            return -1;
        }
        const auto sent = test::Clock::now();
        child.signal(sig);
        const test::ChildResult r = child.wait(kRenderTimeLimit);
        const double latency = std::chrono::duration<double>(test::Clock::now() - sent).count();
        SCOPED_TRACE(name + ": " + r.output);
        if (r.exitCode == 0) // finished before the signal was seen
            return -1;
        if (r.signal == sig) {
            // Signalled while the process was still starting, before main()
            // installed the handler: the default action ended it at once.
            EXPECT_LT(latency, kMaxStopSeconds);
            EXPECT_FALSE(fs::exists(d / "out.exr"));
            return latency;
        }
        EXPECT_EQ(r.exitCode, 130);
        EXPECT_NE(r.output.find("hairvox: interrupted"), std::string::npos);
        EXPECT_LT(latency, kMaxStopSeconds) << "stopped " << latency << " s after the signal";
        EXPECT_FALSE(fs::exists(d / "out.exr"));
        EXPECT_FALSE(fs::exists(d / "out.png"));
        EXPECT_TRUE(test::temporaries(d).empty()) << "a temporary was left behind";
        EXPECT_TRUE(test::temporaries(d / "cache").empty()) << "a cache temporary was left behind";
        return latency;
    }

    test::TempDir dir_;
    fs::path scene_;
    double seconds_ = 0;
};

TEST_F(InterruptSlow, CtrlCStopsPromptlyAtAnyMoment) {
    double worst = 0;
    int stopped = 0;
    for (double fraction : {0.02, 0.1, 0.2, 0.3, 0.45, 0.6, 0.75, 0.9}) {
        const double at = fraction * seconds_;
        const double latency = interrupt(strCat("at", fraction), SIGINT, [&](test::Child& c, auto&) {
            return c.secondsRunning() >= at;
        });
        std::printf("SIGINT at %.2f s of %.2f s: %s %.3f s\n", at, seconds_,
                    latency < 0 ? "finished first" : "stopped after", latency);
        worst = std::max(worst, latency);
        stopped += latency >= 0 ? 1 : 0;
    }
    EXPECT_GE(stopped, 6);
    std::printf("worst stop latency %.3f s (bound %.1f s)\n", worst, kMaxStopSeconds);
}

TEST_F(InterruptSlow, CtrlCWhileWritingTheExrLeavesNothing) {
    const double latency = interrupt("exr", SIGINT, [](test::Child&, const fs::path& d) {
        return test::hasTemporaryOf(d, "out.exr");
    });
    std::printf("SIGINT during the EXR write: %s %.3f s\n",
                latency < 0 ? "finished first" : "stopped after", latency);
}

TEST_F(InterruptSlow, SigtermStopsLikeCtrlC) {
    const double latency = interrupt("term", SIGTERM, [&](test::Child& c, auto&) {
        return c.secondsRunning() >= 0.5 * seconds_;
    });
    EXPECT_GE(latency, 0) << "the render finished before SIGTERM";
}

TEST_F(InterruptSlow, SecondCtrlCEndsTheProcessAtOnce) {
    const fs::path d = dir_ / "twice";
    test::Child child(test::renderOptions(scene_, d, dir_ / "cache-ref"));
    test::waitFor(child, [&] { return child.secondsRunning() >= 0.3 * seconds_; }, kRenderTimeLimit);
    child.signal(SIGINT);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const auto sent = test::Clock::now();
    child.signal(SIGINT);
    const test::ChildResult r = child.wait(kRenderTimeLimit);
    const double latency = std::chrono::duration<double>(test::Clock::now() - sent).count();
    if (r.exited) { // the first Ctrl-C was fast enough to end the render on its own
        EXPECT_EQ(r.exitCode, 130) << r.output;
    } else {
        EXPECT_EQ(r.signal, SIGINT) << r.output;
    }
    EXPECT_LT(latency, 0.5);
    EXPECT_FALSE(fs::exists(d / "out.exr"));
    EXPECT_FALSE(fs::exists(d / "out.png"));
}

} // namespace
} // namespace hairvox
