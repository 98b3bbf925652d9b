// currentProgress() (core/progress.h): the live reporter as a caller that
// polls sees it (the Python module's progress callback), drawn or not.
#include <hairvox/core/progress.h>

#include <gtest/gtest.h>

#include <thread>

namespace hairvox {
namespace {

TEST(Progress, CurrentProgressIsTheNewestLiveReporter) {
    EXPECT_FALSE(currentProgress().has_value());
    std::uint64_t outerSerial = 0;
    {
        ProgressReporter outer("voxelize", 10, false);
        outer.update(3);
        const auto a = currentProgress();
        ASSERT_TRUE(a.has_value());
        EXPECT_EQ(a->title, "voxelize");
        EXPECT_EQ(a->done, 3u);
        EXPECT_EQ(a->total, 10u);
        outerSerial = a->serial;
        {
            ProgressReporter inner("render", 4, false);
            // Updated from another thread, read from this one.
            std::thread([&] { inner.update(9); }).join();
            const auto b = currentProgress();
            ASSERT_TRUE(b.has_value());
            EXPECT_EQ(b->title, "render");
            EXPECT_EQ(b->done, 4u); // at most the total
            EXPECT_NE(b->serial, outerSerial);
            inner.finish();
            EXPECT_EQ(currentProgress()->title, "voxelize");
        }
        EXPECT_EQ(currentProgress()->serial, outerSerial);
    }
    EXPECT_FALSE(currentProgress().has_value());
}

} // namespace
} // namespace hairvox
