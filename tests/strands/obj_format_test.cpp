#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/strands/groom_io.h>

#include <gtest/gtest.h>

namespace hairvox {
namespace {

std::string readError(const std::filesystem::path& path) {
    try {
        readObjFile(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(ObjFormat, PolylinesEdgeChainsAndNegativeIndices) {
    test::TempDir dir;
    test::writeText(dir / "h.obj", "# two strands\n"
                                   "o hair\n"
                                   "v 0 0 0\nv 0 1 0\nv 0 2 0\n"
                                   "l 1 2 3\n"
                                   "v 1 0 0\nv 1 1 0\nv 1 2 0\n"
                                   "l 4 5\nl 5 6\n" // Blender-style edges, joined
                                   "v 2 0 0\nv 2 1 0\n"
                                   "l -2/1 -1/2\r\n"
                                   "f 1 2 3\n");
    const LoadedGroom g = readObjFile(dir / "h.obj");
    ASSERT_EQ(g.groom.strandCount(), 3u);
    EXPECT_EQ(g.groom.strand(1).size(), 3u);
    EXPECT_EQ(g.groom.strand(2)[1], Vec3f(2, 1, 0));
    ASSERT_EQ(g.warnings.size(), 1u);
    EXPECT_NE(g.warnings[0].find("face"), std::string::npos);
}

TEST(ObjFormat, IndexOutOfRangeNamesLine) {
    test::TempDir dir;
    test::writeText(dir / "h.obj", "v 0 0 0\nv 0 1 0\nl 1 3\n");
    const std::string err = readError(dir / "h.obj");
    EXPECT_NE(err.find("h.obj:3:"), std::string::npos) << err;
    EXPECT_NE(err.find("out of range"), std::string::npos) << err;
}

TEST(ObjFormat, BadNumberAndMissingCoordinate) {
    test::TempDir dir;
    test::writeText(dir / "a.obj", "v 0 zero 0\n");
    EXPECT_NE(readError(dir / "a.obj").find("not a number"), std::string::npos);
    test::writeText(dir / "b.obj", "v 0 0\n");
    EXPECT_NE(readError(dir / "b.obj").find("3 coordinates"), std::string::npos);
    test::writeText(dir / "c.obj", "v 0 0 0\nl 1\n");
    EXPECT_NE(readError(dir / "c.obj").find("at least 2"), std::string::npos);
}

TEST(ObjFormat, NoPolylinesAndBinaryGarbage) {
    test::TempDir dir;
    test::writeText(dir / "a.obj", "v 0 0 0\nv 1 1 1\nv 1 0 1\nf 1 2 3\n");
    EXPECT_NE(readError(dir / "a.obj").find("no polylines"), std::string::npos);
    test::ByteWriter w;
    w.putBytes("v 0 \0 0", 7);
    w.writeTo(dir / "b.obj");
    EXPECT_NE(readError(dir / "b.obj").find("NUL"), std::string::npos);
}

TEST(ObjFormat, NonFiniteCoordinate) {
    test::TempDir dir;
    test::writeText(dir / "a.obj", "v 0 0 0\nv inf 1 0\nl 1 2\n");
    EXPECT_NE(readError(dir / "a.obj").find("non-finite"), std::string::npos);
}

TEST(GroomIo, DispatchByMagicAndExtension) {
    test::TempDir dir;
    test::writeText(dir / "x.unknown", "hello");
    EXPECT_THROW(readGroom(dir / "x.unknown"), InputError);
    EXPECT_THROW(readGroom(dir / "missing.hair"), InputError);
    test::writeText(dir / "y.obj", "v 0 0 0\nv 0 1 0\nl 1 2\n");
    EXPECT_EQ(readGroom(dir / "y.obj").format, GroomFormat::Obj);
}

} // namespace
} // namespace hairvox
