// The fiber grid as bytes for the shared disk cache (voxelize/fiber_grid.h):
// read back it is the same grid, bit for bit; bytes that are not such a grid
// — cut short, blocks out of order or off the lattice, counts that disagree
// with the masks, values no fiber grid holds — are refused by name.
#include "test_util.h"
#include "voxelize/voxelize_test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

namespace hairvox {
namespace {

FiberGrid splatted(bool tensor, bool types) {
    ProceduralGroomParams p;
    p.style = GroomStyle::Curly;
    p.strands = 150;
    Groom groom = generateGroom(p);
    if (types) { // three fiber types
        groom.fiberType.resize(groom.pointCount());
        for (std::size_t i = 0; i < groom.fiberType.size(); ++i)
            groom.fiberType[i] = static_cast<std::uint8_t>((i / 64) % 3);
    }
    SplatOptions o;
    o.storeOrientationTensor = tensor;
    o.fiberScale.densityMultiplier = 2.5f;
    o.sourceFile = "curly.hair";
    return splatStrands(groom, o);
}

void expectSameGrid(const FiberGrid& a, const FiberGrid& b) {
    EXPECT_TRUE(test::sameFiberGrid(a, b));
    EXPECT_EQ(a.hasTensor(), b.hasTensor());
    EXPECT_EQ(a.info.voxelSize, b.info.voxelSize);
    EXPECT_EQ(a.info.fiberScale.densityMultiplier, b.info.fiberScale.densityMultiplier);
    EXPECT_EQ(a.info.sourceFile, b.info.sourceFile);
    EXPECT_EQ(a.info.sourceHash, b.info.sourceHash);
    EXPECT_EQ(a.info.strands, b.info.strands);
    EXPECT_EQ(a.info.segments, b.info.segments);
    EXPECT_EQ(a.info.totalLength, b.info.totalLength);
    EXPECT_EQ(a.info.version, b.info.version);
}

TEST(FiberGridBytes, ReadBackIsTheSameGrid) {
    for (const bool tensor : {false, true})
        for (const bool types : {false, true}) {
            SCOPED_TRACE(testing::Message() << "tensor " << tensor << ", types " << types);
            const FiberGrid grid = splatted(tensor, types);
            ASSERT_GT(grid.activeVoxelCount(), 1000u);
            EXPECT_EQ(grid.typeFraction.size(), types ? 3u : 0u);
            const std::vector<std::byte> bytes = fiberGridBytes(grid);
            expectSameGrid(fiberGridFromBytes(bytes, "entry"), grid);
        }
    // An empty grid too.
    const FiberGrid empty = splatStrands(Groom{}, SplatOptions{});
    expectSameGrid(fiberGridFromBytes(fiberGridBytes(empty), "entry"), empty);
}

/// The message fiberGridFromBytes gives for `bytes` ("" if it accepts them).
std::string refusal(const std::vector<std::byte>& bytes) {
    try {
        fiberGridFromBytes(bytes, "cache/grid/x.bin");
    } catch (const InputError& e) {
        EXPECT_TRUE(test::contains(e.what(), "cache/grid/x.bin: not a hairvox fiber grid"))
            << e.what();
        return e.what();
    }
    return "";
}

TEST(FiberGridBytes, RefusesWhatIsNotAFiberGrid) {
    const FiberGrid grid = splatted(false, false);
    const std::vector<std::byte> good = fiberGridBytes(grid);
    ASSERT_EQ(refusal(good), "");
    // Cut short anywhere, or with bytes after it.
    for (const std::size_t keep :
         {std::size_t(0), std::size_t(5), std::size_t(40), good.size() / 2, good.size() - 1})
        EXPECT_NE(refusal(std::vector<std::byte>(good.begin(),
                                                 good.begin() + static_cast<std::ptrdiff_t>(keep))),
                  "")
            << keep;
    std::vector<std::byte> longer = good;
    longer.push_back(std::byte{0});
    EXPECT_TRUE(test::contains(refusal(longer), "bytes after the grid"));

    // Values a grid cannot hold, and blocks that do not fit their masks.
    FiberGrid bad = grid;
    bad.density[10] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(test::contains(refusal(fiberGridBytes(bad)), "density"));
    bad = grid;
    bad.density[3] = -1.0f;
    EXPECT_TRUE(test::contains(refusal(fiberGridBytes(bad)), "density -1"));
    bad = grid;
    bad.orientation[7] = openvdb::Vec3s(std::numeric_limits<float>::infinity(), 0, 0);
    EXPECT_TRUE(test::contains(refusal(fiberGridBytes(bad)), "orientation"));
    bad = grid;
    std::swap(bad.blocks[0].origin, bad.blocks[1].origin);
    EXPECT_TRUE(test::contains(refusal(fiberGridBytes(bad)), "out of order"));
    bad = grid;
    bad.blocks[0].origin = bad.blocks[0].origin - openvdb::Coord(3, 0, 0);
    EXPECT_TRUE(test::contains(refusal(fiberGridBytes(bad)), "off the lattice"));
    bad = grid;
    bad.blocks[1].first += 1;
    EXPECT_TRUE(test::contains(refusal(fiberGridBytes(bad)), "starts at value"));
    bad = grid;
    bad.density.pop_back();
    EXPECT_TRUE(test::contains(refusal(fiberGridBytes(bad)), "not one value per active voxel"));
    bad = grid;
    bad.typeFraction.assign(1, std::vector<float>(grid.activeVoxelCount(), 1.0f));
    EXPECT_TRUE(test::contains(refusal(fiberGridBytes(bad)), "fiber-type fractions"));
    bad = grid;
    bad.info.voxelSize = 0;
    EXPECT_TRUE(test::contains(refusal(fiberGridBytes(bad)), "voxel size"));
}

} // namespace
} // namespace hairvox
