#include "test_util.h"

#include <hairvox/strands/groom_io.h>
#include <hairvox/strands/procedural.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <gtest/gtest.h>

namespace hairvox {
namespace {

using test::quoted;

/// A small wavy groom written as .hair; returns its path.
std::filesystem::path writeGroom(const test::TempDir& dir) {
    ProceduralGroomParams p;
    p.strands = 300;
    const auto path = dir / "wavy.hair";
    writeHairFile(path, generateGroom(p));
    return path;
}

TEST(VoxelizeCli, WritesAGridAndReportsIt) {
    test::TempDir dir;
    const auto hair = writeGroom(dir);
    const auto vdb = dir / "out" / "grid.vdb";
    const auto r = test::runHairvox("voxelize " + quoted(hair) + " -o " + quoted(vdb) +
                                    " --voxels-across 64 --diameter 6e-5 --density-multiplier 2"
                                    " --orientation-tensor --threads 1");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (const char* expected : {"active voxels:", "memory:", "MiB", "time:", "voxelize"})
        EXPECT_NE(r.output.find(expected), std::string::npos) << expected << " in\n" << r.output;
    const FiberGrid grid = readFiberGrid(vdb);
    const Groom groom = readGroom(hair).groom;
    EXPECT_DOUBLE_EQ(grid.info.voxelSize, defaultVoxelSize(groom, 64));
    EXPECT_EQ(grid.info.fiberScale.diameter, 6e-5f);
    EXPECT_EQ(grid.info.fiberScale.densityMultiplier, 2.0f);
    EXPECT_EQ(grid.info.sourceFile, hair.string());
    EXPECT_TRUE(grid.hasTensor());
    EXPECT_NE(r.output.find(std::to_string(grid.activeVoxelCount() % 1000)), std::string::npos);
}

TEST(VoxelizeCli, ExplicitVoxelSize) {
    test::TempDir dir;
    const auto hair = writeGroom(dir);
    const auto r = test::runHairvox("voxelize " + quoted(hair) + " -o " + quoted(dir / "g.vdb") +
                                    " --voxel-size 0.004");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(readFiberGrid(dir / "g.vdb").info.voxelSize, 0.004);
}

TEST(VoxelizeCli, BadInputExitsWith2) {
    test::TempDir dir;
    const auto hair = writeGroom(dir);
    const std::string out = " -o " + quoted(dir / "g.vdb");
    for (const std::string& args :
         {"voxelize " + quoted(dir / "missing.hair") + out, "voxelize " + quoted(hair),
          "voxelize " + quoted(hair) + out + " --voxel-size -1",
          "voxelize " + quoted(hair) + out + " --voxel-size 0.01 --voxels-across 10",
          "voxelize " + quoted(hair) + out + " --voxels-across 0",
          "voxelize " + quoted(hair) + out + " --diameter 0",
          "voxelize " + quoted(hair) + " -o /proc/hairvox/g.vdb"}) {
        const auto r = test::runHairvox(args);
        EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "g.vdb"));
}

TEST(VoxelizeCli, AbsurdVoxelSizeIsRefusedWithTheEstimate) {
    test::TempDir dir;
    const auto hair = writeGroom(dir);
    const auto r = test::runHairvox("voxelize " + quoted(hair) + " -o " + quoted(dir / "g.vdb") +
                                    " --voxel-size 1e-9");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("GiB"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "g.vdb"));
}

TEST(VoxelizeCli, EmptyGroomWarnsAndWritesAnEmptyGrid) {
    test::TempDir dir;
    writeHairFile(dir / "empty.hair", Groom{});
    const auto r =
        test::runHairvox("voxelize " + quoted(dir / "empty.hair") + " -o " + quoted(dir / "g.vdb"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("warning"), std::string::npos) << r.output;
    EXPECT_EQ(readFiberGrid(dir / "g.vdb").activeVoxelCount(), 0u);
}

TEST(VoxelizeCli, Help) {
    const auto r = test::runHairvox("voxelize --help");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("--voxels-across"), std::string::npos) << r.output;
}

} // namespace
} // namespace hairvox
