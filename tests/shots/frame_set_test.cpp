// Frame lists as a wrangler writes them (shots/frame_set.h) and frame numbers
// in file names (shots/frame_pattern.h).
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/shots/frame_pattern.h>
#include <hairvox/shots/frame_set.h>

#include <gtest/gtest.h>

namespace hairvox::shots {
namespace {

std::string parseError(const std::string& text) {
    try {
        FrameSet::parse(text);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(ShotsFrameSet, ParsesRangesStepsSinglesAndLists) {
    EXPECT_EQ(FrameSet::parse("1-240").size(), 240u);
    EXPECT_EQ(FrameSet::parse("1-240").first(), 1);
    EXPECT_EQ(FrameSet::parse("1-240").last(), 240);
    EXPECT_EQ(FrameSet::parse("1-240x2").frames(), FrameSet::range(1, 239, 2).frames());
    EXPECT_EQ(FrameSet::parse("1-240x2").size(), 120u);
    EXPECT_EQ(FrameSet::parse("7").frames(), std::vector<int>{7});
    EXPECT_EQ(FrameSet::parse(" 1-3, 10 ,5-9x2").frames(),
              (std::vector<int>{1, 2, 3, 5, 7, 9, 10}));
    EXPECT_EQ(FrameSet::parse("3,1,3,2").frames(), (std::vector<int>{1, 2, 3})) << "sorted, unique";
    EXPECT_EQ(FrameSet::parse("-5--3").frames(), (std::vector<int>{-5, -4, -3}));
    EXPECT_EQ(FrameSet::parse("1001-1003").frames(), (std::vector<int>{1001, 1002, 1003}));
}

TEST(ShotsFrameSet, RefusesWhatIsNoFrameList) {
    for (const char* bad : {"", " ", "a", "1-", "-", "5-3", "1-10x0", "1-10x-2", "1,,2", "1-2y",
                            "1.5", "99999999", "1-9999999x1,0-999999"}) {
        const std::string e = parseError(bad);
        EXPECT_TRUE(test::contains(e, strCat("--frames ", bad))) << bad << ": " << e;
        EXPECT_TRUE(test::contains(e, "A-BxSTEP")) << bad << ": " << e;
    }
    EXPECT_TRUE(test::contains(parseError("5-3"), "'5-3' ends before it starts"));
    EXPECT_TRUE(test::contains(parseError("1-10x0"), "step below 1"));
    EXPECT_TRUE(test::contains(parseError("1-9999999x1,0-999999"), "more than 1000000 frames"));
}

TEST(ShotsFrameSet, PrintsWhatItParsesBackAndChunksInOrder) {
    for (const char* text : {"1-240", "1-239x2", "7", "1-3,6,9-21x4", "1,5", "-3-2", "1-2"}) {
        const FrameSet set = FrameSet::parse(text);
        EXPECT_EQ(set.toString(), text);
        EXPECT_EQ(FrameSet::parse(set.toString()), set);
    }
    EXPECT_EQ(FrameSet::of({1, 2, 3, 10, 20, 30, 31}).toString(), "1-3,10-30x10,31");
    const std::vector<FrameSet> chunks = FrameSet::parse("1-10").chunks(4);
    ASSERT_EQ(chunks.size(), 3u);
    EXPECT_EQ(chunks[0].toString(), "1-4");
    EXPECT_EQ(chunks[1].toString(), "5-8");
    EXPECT_EQ(chunks[2].toString(), "9-10");
    EXPECT_EQ(FrameSet::parse("1-10").intersect(FrameSet::parse("8-20")).toString(), "8-10");
    EXPECT_TRUE(FrameSet().chunks(3).empty());
}

TEST(ShotsFramePattern, WritesFrameNumbersAsPrintfAndAsNukeDo) {
    EXPECT_EQ(expandFramePattern("out/shot.%04d.exr", 7, "x"), "out/shot.0007.exr");
    EXPECT_EQ(expandFramePattern("out/shot.####.exr", 7, "x"), "out/shot.0007.exr");
    EXPECT_EQ(expandFramePattern("shot.%d.png", 12345, "x"), "shot.12345.png");
    EXPECT_EQ(expandFramePattern("shot.#.png", 12345, "x"), "shot.12345.png");
    EXPECT_EQ(expandFramePattern("shot.##.png", 12345, "x"), "shot.12345.png")
        << "padding, never truncation";
    EXPECT_EQ(expandFramePattern("a%%b.%03d", 5, "x"), "a%b.005");
    EXPECT_EQ(expandFramePattern("f.%04d.####", -5, "x"), "f.-005.-005");
    EXPECT_EQ(expandFramePattern("still.exr", 5, "x"), "still.exr");
    EXPECT_TRUE(hasFramePattern("a.%04d.exr"));
    EXPECT_TRUE(hasFramePattern("a.####.exr"));
    EXPECT_FALSE(hasFramePattern("a.exr"));
    EXPECT_FALSE(hasFramePattern("100%%.exr"));
    EXPECT_FALSE(hasFramePattern("a.%s.exr")) << "not a frame number";
    EXPECT_EQ(printfFramePattern("out/a.####.png", "x"), "out/a.%04d.png");
    EXPECT_EQ(printfFramePattern("out/%%a.%05d.png", "x"), "out/%%a.%05d.png");
    for (const char* bad : {"a.%s.exr", "a.%4d.exr", "a.%", "a.##########.exr"}) {
        try {
            expandFramePattern(bad, 1, "/output/exr");
            ADD_FAILURE() << bad << " accepted";
        } catch (const InputError& e) {
            EXPECT_TRUE(test::contains(e.what(), strCat("/output/exr: '", bad, "'"))) << e.what();
        }
    }
}

} // namespace
} // namespace hairvox::shots
