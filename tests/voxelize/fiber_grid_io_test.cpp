#include "test_util.h"
#include "voxelize/voxelize_test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>
#include <openvdb/io/File.h>

#include <cstdio>
#include <cstdlib>
#include <utility>

namespace hairvox {
namespace {

FiberGrid smallGrid(bool tensor) {
    ProceduralGroomParams p;
    p.style = GroomStyle::Curly;
    p.strands = 200;
    SplatOptions o;
    o.storeOrientationTensor = tensor;
    o.fiberScale.diameter = 7e-5f;
    o.fiberScale.densityMultiplier = 2.5f;
    o.sourceFile = "curly test groom.hair";
    return splatStrands(generateGroom(p), o);
}

void expectSameInfo(const FiberGridInfo& a, const FiberGridInfo& b) {
    EXPECT_EQ(a.voxelSize, b.voxelSize);
    EXPECT_EQ(a.fiberScale.diameter, b.fiberScale.diameter);
    EXPECT_EQ(a.fiberScale.densityMultiplier, b.fiberScale.densityMultiplier);
    EXPECT_EQ(a.sourceFile, b.sourceFile);
    EXPECT_EQ(a.sourceHash, b.sourceHash);
    EXPECT_EQ(a.strands, b.strands);
    EXPECT_EQ(a.segments, b.segments);
    EXPECT_EQ(a.totalLength, b.totalLength);
    EXPECT_EQ(a.version, b.version);
}

/// Writes `grids` as a plain .vdb (not through writeFiberGrid).
void writeRawVdb(const std::filesystem::path& path, const openvdb::GridPtrVec& grids) {
    openvdb::initialize();
    openvdb::io::File(path.string()).write(grids);
}

/// Runs a shell command; returns its exit status and output.
std::pair<int, std::string> run(const std::string& command) {
    FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (!pipe)
        return {-1, "popen failed"};
    std::string output;
    char buffer[4096];
    std::size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0)
        output.append(buffer, n);
    return {::pclose(pipe), output};
}

std::string readFiberGridError(const std::filesystem::path& path) {
    try {
        readFiberGrid(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(FiberGridIo, RoundTripKeepsValuesAndMetadata) {
    test::TempDir dir;
    for (bool tensor : {false, true}) {
        const FiberGrid grid = smallGrid(tensor);
        const auto path = dir / (tensor ? "tensor.vdb" : "plain.vdb");
        writeFiberGrid(path, grid);
        const FiberGrid back = readFiberGrid(path);
        SCOPED_TRACE(tensor ? "with tensor" : "without tensor");
        EXPECT_TRUE(test::sameFiberGrid(grid, back));
        EXPECT_EQ(back.hasTensor(), tensor);
        expectSameInfo(grid.info, back.info);
        // The file holds OpenVDB grids of the packed voxels, one leaf per block.
        openvdb::io::File file(path.string());
        file.open();
        const auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("density"));
        ASSERT_TRUE(density);
        EXPECT_EQ(density->getGridClass(), openvdb::GRID_FOG_VOLUME);
        EXPECT_EQ(density->transform(),
                  *openvdb::math::Transform::createLinearTransform(grid.info.voxelSize));
        EXPECT_TRUE(density->getMetadata<openvdb::DoubleMetadata>("voxel_size"));
        EXPECT_EQ(density->tree().leafCount(), grid.blocks.size());
        EXPECT_EQ(density->activeVoxelCount(), grid.activeVoxelCount());
        grid.forEachVoxel([&](std::size_t i, const openvdb::Coord& c) {
            EXPECT_EQ(density->tree().getValue(c), grid.density[i]) << c;
        });
        EXPECT_EQ(file.hasGrid("tensorDiag"), tensor);
    }
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 2)
        << "temporary files were left behind";
}

TEST(FiberGridIo, EmptyGridRoundTrips) {
    test::TempDir dir;
    const FiberGrid grid = splatStrands(Groom{}, SplatOptions{});
    writeFiberGrid(dir / "empty.vdb", grid);
    const FiberGrid back = readFiberGrid(dir / "empty.vdb");
    EXPECT_EQ(back.activeVoxelCount(), 0u);
    expectSameInfo(grid.info, back.info);
}

TEST(FiberGridIo, BadFilesAreInputErrorsNamingTheFile) {
    test::TempDir dir;
    const auto missing = dir / "missing.vdb";
    EXPECT_NE(readFiberGridError(missing).find("missing.vdb"), std::string::npos);

    test::writeText(dir / "text.vdb", "not a vdb file at all");
    EXPECT_NE(readFiberGridError(dir / "text.vdb").find("text.vdb"), std::string::npos);

    // A valid .vdb, but not a fiber grid.
    auto foo = openvdb::FloatGrid::create();
    foo->setName("foo");
    writeRawVdb(dir / "foo.vdb", {foo});
    EXPECT_NE(readFiberGridError(dir / "foo.vdb").find("'density'"), std::string::npos);

    // The right grids without hairvox metadata.
    const FiberVdbGrids grid = toVdbGrids(smallGrid(false));
    for (const auto& g : grid.all())
        g->removeMeta("voxel_size");
    writeRawVdb(dir / "nometa.vdb", grid.all());
    const std::string noMeta = readFiberGridError(dir / "nometa.vdb");
    EXPECT_NE(noMeta.find("nometa.vdb"), std::string::npos) << noMeta;
    EXPECT_NE(noMeta.find("metadata"), std::string::npos) << noMeta;

    // A density grid of the wrong type.
    auto wrongType = openvdb::DoubleGrid::create();
    wrongType->setName("density");
    writeRawVdb(dir / "double.vdb", {wrongType, grid.orientation});
    EXPECT_NE(readFiberGridError(dir / "double.vdb").find("type"), std::string::npos);
}

TEST(FiberGridIo, RefusesOtherTransformsAndBadValues) {
    test::TempDir dir;
    const FiberGrid grid = smallGrid(false);

    // A cell-centred (offset) transform would silently shift every sample.
    FiberVdbGrids shifted = toVdbGrids(grid);
    shifted.density->transform().postTranslate(openvdb::Vec3d(0.5 * grid.info.voxelSize));
    writeVdbFile(dir / "shifted.vdb", shifted.all());
    EXPECT_NE(readFiberGridError(dir / "shifted.vdb").find("transform"), std::string::npos);

    FiberVdbGrids negative = toVdbGrids(grid);
    negative.density->tree().setValueOn(openvdb::Coord(0, 0, 0), -1.0f);
    writeVdbFile(dir / "negative.vdb", negative.all());
    EXPECT_NE(readFiberGridError(dir / "negative.vdb").find(">= 0"), std::string::npos);

    FiberVdbGrids oneTensor = toVdbGrids(smallGrid(true));
    oneTensor.tensorOffDiag = nullptr;
    writeVdbFile(dir / "onetensor.vdb", oneTensor.all());
    EXPECT_NE(readFiberGridError(dir / "onetensor.vdb").find("tensor"), std::string::npos);

    // An active tile of 128³ voxels: a grid of the user's, not a splat; its
    // voxels would otherwise be dropped unseen.
    FiberVdbGrids tiled = toVdbGrids(grid);
    tiled.density->tree().addTile(2, openvdb::Coord(1 << 12), 1.0f, true);
    writeVdbFile(dir / "tiled.vdb", tiled.all());
    const std::string tiles = readFiberGridError(dir / "tiled.vdb");
    EXPECT_NE(tiles.find("active tiles"), std::string::npos) << tiles;
}

TEST(FiberGridIo, ReadsOtherGridsAtTheDensitysVoxels) {
    // A foreign file whose orientation grid lacks a voxel the density has:
    // that voxel reads the orientation's background, and a value where the
    // density has none is not a voxel.
    test::TempDir dir;
    const FiberGrid grid = smallGrid(false);
    ASSERT_GT(grid.activeVoxelCount(), 2u);
    FiberVdbGrids vdb = toVdbGrids(grid);
    const openvdb::Coord first =
        grid.blocks.front().voxel(grid.blocks.front().active.findFirstOn());
    vdb.orientation->tree().setValueOff(first, openvdb::Vec3s(0.0f));
    vdb.orientation->tree().setValueOn(openvdb::Coord(-(1 << 12)), openvdb::Vec3s(1, 0, 0));
    writeVdbFile(dir / "foreign.vdb", vdb.all());
    const FiberGrid back = readFiberGrid(dir / "foreign.vdb");
    EXPECT_TRUE(test::sameBits(back.density, grid.density));
    ASSERT_EQ(back.orientation.size(), grid.orientation.size());
    EXPECT_EQ(back.orientation[0], openvdb::Vec3s(0.0f));
    EXPECT_EQ(back.find(openvdb::Coord(-(1 << 12))), FiberGrid::kInactive);
    for (std::size_t i = 1; i < back.orientation.size(); ++i)
        EXPECT_EQ(back.orientation[i], grid.orientation[i]) << i;
}

TEST(FiberGridIo, UnwritablePathIsAnInputError) {
    EXPECT_THROW(writeFiberGrid("/proc/hairvox/grid.vdb", smallGrid(false)), InputError);
}

TEST(FiberGridIo, VdbPrintListsGridsAndMetadata) {
    if (std::system("command -v vdb_print > /dev/null 2>&1") != 0)
        GTEST_SKIP() << "vdb_print (package libopenvdb-tools) is not installed";
    test::TempDir dir;
    writeFiberGrid(dir / "grid.vdb", smallGrid(true));
    const auto [status, output] = run("vdb_print -l '" + (dir / "grid.vdb").string() + "'");
    ASSERT_EQ(status, 0) << output;
    for (const char* expected :
         {"density", "orientation", "tensorDiag", "tensorOffDiag", "voxel_size", "fiber_diameter",
          "density_multiplier", "source_file", "source_hash", "segments", "total_length",
          "hairvox_version"})
        EXPECT_NE(output.find(expected), std::string::npos) << expected << " in\n" << output;
}

TEST(FiberGridIo, PyopenvdbReadsGridsAndMetadata) {
    // Only the system python has the Debian pyopenvdb module.
    if (std::system("/usr/bin/python3 -c 'import pyopenvdb' > /dev/null 2>&1") != 0)
        GTEST_SKIP() << "pyopenvdb (package python3-openvdb) is not available to /usr/bin/python3";
    test::TempDir dir;
    const FiberGrid grid = smallGrid(false);
    writeFiberGrid(dir / "grid.vdb", grid);
    const std::string script =
        "import pyopenvdb as vdb, sys\n"
        "grids, meta = vdb.readAll(sys.argv[1])\n"
        "for g in grids:\n"
        "    print(g.name, g.activeVoxelCount(), g['fiber_diameter'], g['segments'],"
        " g['source_hash'])\n";
    test::writeText(dir / "read.py", script);
    const auto [status, output] = run("/usr/bin/python3 '" + (dir / "read.py").string() + "' '" +
                                      (dir / "grid.vdb").string() + "'");
    ASSERT_EQ(status, 0) << output;
    const std::string voxels = std::to_string(grid.activeVoxelCount());
    EXPECT_NE(output.find("density " + voxels), std::string::npos) << output;
    EXPECT_NE(output.find("orientation " + voxels), std::string::npos) << output;
    EXPECT_NE(output.find(std::to_string(grid.info.segments) + " " + grid.info.sourceHash),
              std::string::npos)
        << output;
}

} // namespace
} // namespace hairvox
