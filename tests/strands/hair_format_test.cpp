#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

namespace hairvox {
namespace {

constexpr std::uint32_t kSegments = 1, kPoints = 2, kThickness = 4, kColors = 16;

/// A .hair header with the given counts and array bits (data appended by the caller).
test::ByteWriter hairHeader(std::uint32_t strands, std::uint32_t points, std::uint32_t arrays,
                            std::uint32_t defaultSegments = 0, const char* magic = "HAIR") {
    test::ByteWriter w;
    w.putBytes(magic, 4).put(strands).put(points).put(arrays).put(defaultSegments);
    w.put(0.1f).put(0.0f).put(1.0f).put(1.0f).put(1.0f).zeros(88);
    return w;
}

void putPoints(test::ByteWriter& w, std::initializer_list<float> xyz) {
    for (float v : xyz)
        w.put(v);
}

std::string readError(const std::filesystem::path& path) {
    try {
        readHairFile(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(HairFormat, GeneratedGroomRoundTripsExactly) {
    test::TempDir dir;
    for (GroomStyle style : {GroomStyle::Straight, GroomStyle::Wavy, GroomStyle::Curly}) {
        ProceduralGroomParams params;
        params.style = style;
        params.strands = 300;
        params.seed = 7;
        const Groom groom = generateGroom(params);
        const auto path = dir / (std::string(toString(style)) + ".hair");
        writeHairFile(path, groom);
        const LoadedGroom back = readHairFile(path);
        EXPECT_EQ(back.sanitized.droppedSegments, 0u);
        ASSERT_EQ(back.groom.strandStart, groom.strandStart);
        ASSERT_EQ(back.groom.points.size(), groom.points.size());
        EXPECT_EQ(std::memcmp(back.groom.points.data(), groom.points.data(),
                              groom.points.size() * sizeof(Vec3f)),
                  0)
            << "points differ after a .hair round trip (" << toString(style) << ")";
    }
}

TEST(HairFormat, VariableSegmentsAndOptionalArraysRoundTrip) {
    Groom groom;
    const std::vector<Vec3f> a{{0, 0, 0}, {0, 1, 0}}, b{{1, 0, 0}, {1, 1, 0}, {1, 2, 0.5f}};
    groom.addStrand(a);
    groom.addStrand(b);
    groom.thickness = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f};
    groom.transparency = {0, 0.1f, 0.2f, 0.3f, 0.4f};
    groom.color = {Rgb(1, 0, 0), Rgb(0, 1, 0), Rgb(0, 0, 1), Rgb(1, 1, 0), Rgb(0, 1, 1)};
    test::TempDir dir;
    writeHairFile(dir / "g.hair", groom);
    const LoadedGroom back = readHairFile(dir / "g.hair");
    EXPECT_EQ(back.groom.strandStart, groom.strandStart);
    EXPECT_EQ(back.groom.points, groom.points);
    EXPECT_EQ(back.groom.thickness, groom.thickness);
    EXPECT_EQ(back.groom.transparency, groom.transparency);
    EXPECT_EQ(back.groom.color, groom.color);
}

TEST(HairFormat, WrongMagic) {
    test::TempDir dir;
    auto w = hairHeader(1, 2, kPoints, 1, "HAIX");
    putPoints(w, {0, 0, 0, 0, 1, 0});
    w.writeTo(dir / "f.hair");
    EXPECT_NE(readError(dir / "f.hair").find("wrong magic"), std::string::npos);
}

TEST(HairFormat, TruncatedHeader) {
    test::TempDir dir;
    test::ByteWriter w;
    w.putBytes("HAIR", 4).zeros(20);
    w.writeTo(dir / "f.hair");
    EXPECT_NE(readError(dir / "f.hair").find("truncated header"), std::string::npos);
}

TEST(HairFormat, TruncatedPointsArray) {
    test::TempDir dir;
    auto w = hairHeader(2, 4, kPoints, 1);
    putPoints(w, {0, 0, 0, 0, 1, 0, 1, 0, 0}); // 3 of 4 points
    w.writeTo(dir / "f.hair");
    const std::string err = readError(dir / "f.hair");
    EXPECT_NE(err.find("truncated"), std::string::npos) << err;
    EXPECT_NE(err.find("f.hair"), std::string::npos) << err;
}

TEST(HairFormat, TrailingBytesDisagreeWithCounts) {
    test::TempDir dir;
    auto w = hairHeader(1, 2, kPoints, 1);
    putPoints(w, {0, 0, 0, 0, 1, 0, 7});
    w.writeTo(dir / "f.hair");
    EXPECT_NE(readError(dir / "f.hair").find("which need"), std::string::npos);
}

TEST(HairFormat, AbsurdCountsRefusedBeforeAllocating) {
    test::TempDir dir;
    auto w = hairHeader(0xffffffffu, 0xfffffff0u, kPoints | kSegments | kColors, 1);
    w.writeTo(dir / "f.hair");
    const std::string err = readError(dir / "f.hair");
    EXPECT_FALSE(err.empty());
    // Many strands, few points: must not reserve one offset per declared strand.
    auto v = hairHeader(0xffffffffu, 2, kPoints, 1);
    putPoints(v, {0, 0, 0, 0, 1, 0});
    v.writeTo(dir / "g.hair");
    EXPECT_NE(readError(dir / "g.hair").find("strands but only"), std::string::npos);
}

TEST(HairFormat, SegmentCountsDisagreeWithPointCount) {
    test::TempDir dir;
    auto w = hairHeader(2, 4, kPoints | kSegments);
    w.put(std::uint16_t(1)).put(std::uint16_t(2)); // needs 5 points
    putPoints(w, {0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0});
    w.writeTo(dir / "f.hair");
    EXPECT_NE(readError(dir / "f.hair").find("segment counts"), std::string::npos);
}

TEST(HairFormat, NaNCoordinate) {
    test::TempDir dir;
    auto w = hairHeader(1, 2, kPoints, 1);
    putPoints(w, {0, 0, 0, 0, std::numeric_limits<float>::quiet_NaN(), 0});
    w.writeTo(dir / "f.hair");
    const std::string err = readError(dir / "f.hair");
    EXPECT_NE(err.find("non-finite"), std::string::npos) << err;
    EXPECT_NE(err.find("strand 0, point 1"), std::string::npos) << err;
}

TEST(HairFormat, InfiniteCoordinate) {
    test::TempDir dir;
    auto w = hairHeader(1, 2, kPoints, 1);
    putPoints(w, {0, 0, 0, std::numeric_limits<float>::infinity(), 0, 0});
    w.writeTo(dir / "f.hair");
    EXPECT_NE(readError(dir / "f.hair").find("non-finite"), std::string::npos);
}

TEST(HairFormat, StrandWithOnePoint) {
    test::TempDir dir;
    auto w = hairHeader(2, 3, kPoints | kSegments);
    w.put(std::uint16_t(1)).put(std::uint16_t(0));
    putPoints(w, {0, 0, 0, 0, 1, 0, 5, 5, 5});
    w.writeTo(dir / "f.hair");
    EXPECT_NE(readError(dir / "f.hair").find("strand 1 has 1 point"), std::string::npos);
}

TEST(HairFormat, ZeroLengthSegmentsDroppedWithCount) {
    test::TempDir dir;
    auto w = hairHeader(2, 6, kPoints | kSegments | kThickness);
    w.put(std::uint16_t(3)).put(std::uint16_t(1));
    putPoints(w, {0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 2, 0,  // one repeated point
                  3, 3, 3, 3, 3, 3});                 // a strand of coincident points
    for (float t : {1.f, 2.f, 3.f, 4.f, 5.f, 6.f})
        w.put(t);
    w.writeTo(dir / "f.hair");
    const LoadedGroom g = readHairFile(dir / "f.hair");
    EXPECT_EQ(g.sanitized.droppedSegments, 2u);
    EXPECT_EQ(g.sanitized.droppedStrands, 1u);
    ASSERT_EQ(g.groom.strandCount(), 1u);
    EXPECT_EQ(g.groom.pointCount(), 3u);
    EXPECT_EQ(g.groom.thickness, (std::vector<float>{1.f, 2.f, 4.f}));
    EXPECT_DOUBLE_EQ(g.groom.totalLength(), 2.0);
}

TEST(HairFormat, UnknownArrayBitsAndMissingPoints) {
    test::TempDir dir;
    hairHeader(0, 0, kPoints | 64).writeTo(dir / "a.hair");
    EXPECT_NE(readError(dir / "a.hair").find("unknown array bits"), std::string::npos);
    hairHeader(0, 0, kSegments).writeTo(dir / "b.hair");
    EXPECT_NE(readError(dir / "b.hair").find("no points array"), std::string::npos);
}

TEST(HairFormat, EmptyGroomIsValid) {
    test::TempDir dir;
    hairHeader(0, 0, kPoints).writeTo(dir / "e.hair");
    const LoadedGroom g = readHairFile(dir / "e.hair");
    EXPECT_TRUE(g.groom.empty());
    EXPECT_EQ(g.groom.totalLength(), 0.0);
}

TEST(HairFormat, WriterRefusesTooManySegments) {
    Groom groom;
    std::vector<Vec3f> pts(70000);
    for (std::size_t i = 0; i < pts.size(); ++i)
        pts[i] = Vec3f(0, static_cast<float>(i), 0);
    groom.addStrand(pts);
    test::TempDir dir;
    EXPECT_THROW(writeHairFile(dir / "big.hair", groom), InputError);
    EXPECT_FALSE(std::filesystem::exists(dir / "big.hair"));
}

} // namespace
} // namespace hairvox
