#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/strands/groom_io.h>

#include <gtest/gtest.h>

#include <limits>

namespace hairvox {
namespace {

struct TfxLayout {
    float version = 4.0f;
    std::uint32_t strands = 1, perStrand = 2;
    std::uint32_t offsetPositions = 160, offsetStrandUV = 0, offsetVertexUV = 0,
                  offsetThickness = 0, offsetColor = 0;
};

test::ByteWriter tfxHeader(const TfxLayout& l) {
    test::ByteWriter w;
    w.put(l.version).put(l.strands).put(l.perStrand).put(l.offsetPositions).put(l.offsetStrandUV)
        .put(l.offsetVertexUV).put(l.offsetThickness).put(l.offsetColor).zeros(128);
    return w;
}

void putVertex(test::ByteWriter& w, float x, float y, float z) { w.put(x).put(y).put(z).put(1.0f); }

std::string readError(const std::filesystem::path& path) {
    try {
        readTfxFile(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(TfxFormat, RatboyMohawkFigures) {
    const LoadedGroom g = readGroom(test::dataDir() / "Ratboy_mohawk.tfx");
    EXPECT_EQ(g.format, GroomFormat::Tfx);
    EXPECT_EQ(g.groom.strandCount(), 2228u);
    EXPECT_EQ(g.groom.pointCount(), 71296u);
    EXPECT_EQ(g.groom.segmentCount(), 69068u);
    EXPECT_NEAR(g.groom.totalLength(), 230.2, 230.2 * 1e-3);
    const Vec3f size = g.groom.bounds().extent();
    EXPECT_NEAR(size.x, 0.21, 0.01);
    EXPECT_NEAR(size.y, 0.90, 0.01);
    EXPECT_NEAR(size.z, 0.61, 0.01);
}

TEST(TfxFormat, BearFigures) {
    // A TressFX 3 file with zero offsets (data/README.md).
    const LoadedGroom g = readGroom(test::dataDir() / "bear.tfx");
    EXPECT_EQ(g.groom.strandCount(), 48113u);
    EXPECT_EQ(g.groom.segmentCount(), 144339u);
    EXPECT_NEAR(g.groom.totalLength(), 207300.0, 207300.0 * 1e-3);
    const Vec3f size = g.groom.bounds().extent();
    EXPECT_NEAR(size.z, 199.37, 0.01);
}

TEST(TfxFormat, SmallFileWithThicknessAndColour) {
    test::TempDir dir;
    TfxLayout l;
    l.strands = 2;
    l.perStrand = 3;
    l.offsetThickness = 160 + 6 * 16;
    l.offsetColor = l.offsetThickness + 2 * 4;
    auto w = tfxHeader(l);
    for (int s = 0; s < 2; ++s)
        for (int k = 0; k < 3; ++k)
            putVertex(w, float(s), float(k), 0);
    w.put(0.5f).put(0.25f);
    for (int i = 0; i < 6; ++i)
        w.put(0.1f * float(i)).put(0.2f).put(0.3f).put(1.0f);
    w.writeTo(dir / "t.tfx");
    const LoadedGroom g = readTfxFile(dir / "t.tfx");
    EXPECT_EQ(g.groom.strandCount(), 2u);
    EXPECT_EQ(g.groom.points[4], Vec3f(1, 1, 0));
    EXPECT_EQ(g.groom.thickness, (std::vector<float>{0.5f, 0.5f, 0.5f, 0.25f, 0.25f, 0.25f}));
    EXPECT_FLOAT_EQ(g.groom.color[5].r, 0.5f);
}

/// A TressFX 3 file: the 296-byte header, then float3 positions at
/// `offsetPositions` (0: right after the header, as AMD's viewer samples have it).
test::ByteWriter tfx3File(std::uint32_t strands, std::uint32_t perStrand,
                          std::uint32_t offsetPositions, std::uint32_t offsetThickness) {
    test::ByteWriter w;
    w.put(3.0f).put(strands).put(perStrand).put(std::uint32_t(0)).put(std::uint32_t(0));
    w.zeros(31 * 4);
    w.put(offsetPositions).put(offsetThickness).zeros(4 * 4).zeros(32 * 4);
    for (std::uint32_t s = 0; s < strands; ++s)
        for (std::uint32_t k = 0; k < perStrand; ++k)
            w.put(float(s)).put(float(k)).put(0.5f);
    return w;
}

TEST(TfxFormat, Version3WithZeroOffsetsHasPositionsAfterTheHeader) {
    test::TempDir dir;
    tfx3File(3, 4, 0, 0).writeTo(dir / "t3.tfx");
    const LoadedGroom g = readGroom(dir / "t3.tfx");
    EXPECT_EQ(g.groom.strandCount(), 3u);
    EXPECT_EQ(g.groom.pointCount(), 12u);
    EXPECT_EQ(g.groom.points[6], Vec3f(1, 2, 0.5f));
    EXPECT_TRUE(g.groom.thickness.empty());
}

TEST(TfxFormat, Version3WithOffsetsAndThickness) {
    test::TempDir dir;
    auto w = tfx3File(2, 2, 296, 296 + 4 * 12);
    w.put(0.5f).put(2.0f);
    w.writeTo(dir / "t3.tfx");
    const LoadedGroom g = readTfxFile(dir / "t3.tfx");
    EXPECT_EQ(g.groom.points[3], Vec3f(1, 1, 0.5f));
    EXPECT_EQ(g.groom.thickness, (std::vector<float>{0.5f, 0.5f, 2.0f, 2.0f}));
}

TEST(TfxFormat, Version3TruncatedOrInsideTheHeader) {
    test::TempDir dir;
    test::ByteWriter shortHeader;
    shortHeader.put(3.0f).zeros(200);
    shortHeader.writeTo(dir / "a.tfx");
    EXPECT_NE(readError(dir / "a.tfx").find("a TressFX 3 header is 296"), std::string::npos);
    tfx3File(2, 4, 100, 0).writeTo(dir / "b.tfx");
    EXPECT_NE(readError(dir / "b.tfx").find("lies inside the header"), std::string::npos);
    auto c = tfx3File(2, 4, 0, 0);
    c.writeTo(dir / "c.tfx");
    std::filesystem::resize_file(dir / "c.tfx", 296 + 5 * 12);
    EXPECT_NE(readError(dir / "c.tfx").find("vertex positions"), std::string::npos);
}

TEST(TfxFormat, TruncatedHeader) {
    test::TempDir dir;
    test::ByteWriter w;
    w.put(4.0f).zeros(40);
    w.writeTo(dir / "t.tfx");
    EXPECT_NE(readError(dir / "t.tfx").find("truncated header"), std::string::npos);
}

TEST(TfxFormat, WrongVersionIsWrongMagic) {
    test::TempDir dir;
    TfxLayout l;
    l.version = 1234.0f;
    auto w = tfxHeader(l);
    putVertex(w, 0, 0, 0);
    putVertex(w, 0, 1, 0);
    w.writeTo(dir / "t.tfx");
    EXPECT_NE(readError(dir / "t.tfx").find("not a TressFX 3 or 4 file"), std::string::npos);
}

TEST(TfxFormat, PositionsPastEndOfFile) {
    test::TempDir dir;
    TfxLayout l;
    l.strands = 10;
    auto w = tfxHeader(l);
    putVertex(w, 0, 0, 0);
    w.writeTo(dir / "t.tfx");
    const std::string err = readError(dir / "t.tfx");
    EXPECT_NE(err.find("vertex positions"), std::string::npos) << err;
    EXPECT_NE(err.find("truncated"), std::string::npos) << err;
}

TEST(TfxFormat, AbsurdCountsRefusedBeforeAllocating) {
    test::TempDir dir;
    TfxLayout l;
    l.strands = 0xffffffffu;
    l.perStrand = 0xffffffffu;
    tfxHeader(l).writeTo(dir / "t.tfx");
    EXPECT_NE(readError(dir / "t.tfx").find("limit"), std::string::npos);
    l.strands = 1u << 20;
    l.perStrand = 64;
    tfxHeader(l).writeTo(dir / "u.tfx");
    EXPECT_NE(readError(dir / "u.tfx").find("truncated"), std::string::npos);
}

TEST(TfxFormat, OptionalArrayPastEndOfFile) {
    test::TempDir dir;
    TfxLayout l;
    l.offsetColor = 160 + 2 * 16;
    auto w = tfxHeader(l);
    putVertex(w, 0, 0, 0);
    putVertex(w, 0, 1, 0);
    w.writeTo(dir / "t.tfx");
    EXPECT_NE(readError(dir / "t.tfx").find("vertex colours"), std::string::npos);
}

TEST(TfxFormat, OneVertexPerStrand) {
    test::TempDir dir;
    TfxLayout l;
    l.perStrand = 1;
    auto w = tfxHeader(l);
    putVertex(w, 0, 0, 0);
    w.writeTo(dir / "t.tfx");
    EXPECT_NE(readError(dir / "t.tfx").find("at least 2"), std::string::npos);
}

TEST(TfxFormat, PositionOffsetInsideHeader) {
    test::TempDir dir;
    TfxLayout l;
    l.offsetPositions = 4;
    auto w = tfxHeader(l);
    putVertex(w, 0, 0, 0);
    putVertex(w, 0, 1, 0);
    w.writeTo(dir / "t.tfx");
    EXPECT_NE(readError(dir / "t.tfx").find("inside the header"), std::string::npos);
}

TEST(TfxFormat, NaNCoordinate) {
    test::TempDir dir;
    auto w = tfxHeader(TfxLayout{});
    putVertex(w, 0, 0, 0);
    putVertex(w, std::numeric_limits<float>::quiet_NaN(), 1, 0);
    w.writeTo(dir / "t.tfx");
    EXPECT_NE(readError(dir / "t.tfx").find("non-finite"), std::string::npos);
}

} // namespace
} // namespace hairvox
