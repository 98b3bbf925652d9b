// The .vdb files hairvox writes say what they hold: a user loading them in a
// VDB tool finds typed (numeric) metadata, units, grid classes, component
// orders and backgrounds that mean "nothing here" (issue 15 §3).
#include "test_util.h"

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <map>

namespace hairvox {
namespace {

using test::quoted;

namespace fs = std::filesystem;

std::map<std::string, openvdb::GridBase::Ptr> readAll(const fs::path& path) {
    openvdb::initialize();
    openvdb::io::File file(path.string());
    file.open();
    std::map<std::string, openvdb::GridBase::Ptr> grids;
    const openvdb::GridPtrVecPtr all = file.getGrids(); // keep the vector alive while iterating
    for (const openvdb::GridBase::Ptr& g : *all)
        grids[g->getName()] = g;
    file.close();
    return grids;
}

/// `hairvox voxelize` of Ratboy's groom to `vdb`, with `options`.
auto voxelizeRatboy(const fs::path& vdb, const std::string& options) {
    return test::runHairvox("voxelize " + quoted(test::dataDir() / "Ratboy_mohawk.tfx") + " " +
                            options + " -o " + quoted(vdb));
}

std::string stringMeta(const openvdb::GridBase& g, const char* name) {
    const auto m = g.getMetadata<openvdb::StringMetadata>(name);
    return m ? m->value() : std::string("<missing>");
}

TEST(VdbMetadata, LitGridIsSelfDescribing) {
    test::TempDir dir;
    const fs::path vdb = dir / "lit.vdb";
    const auto r =
        test::runHairvox("transmittance " + quoted(test::dataDir() / "Ratboy_mohawk.tfx") +
                         " --light-dir 0,1,0.5 --voxel-size 0.01 -o " + quoted(vdb));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const auto grids = readAll(vdb);
    for (const char* name : {"n", "V", "T_s", "sigma2_f"}) {
        SCOPED_TRACE(name);
        ASSERT_TRUE(grids.count(name));
        const openvdb::GridBase& g = *grids.at(name);
        EXPECT_EQ(g.getGridClass(), openvdb::GRID_UNKNOWN);
        EXPECT_NE(stringMeta(g, "units"), "<missing>");
        EXPECT_NE(stringMeta(g, "description"), "<missing>");
        // Numbers are numbers, not strings.
        const auto h = g.getMetadata<openvdb::DoubleMetadata>("voxel_size");
        ASSERT_TRUE(h);
        EXPECT_NEAR(h->value(), 0.01, 1e-9);
        EXPECT_EQ(stringMeta(g, "light_type"), "directional");
        const auto dirMeta = g.getMetadata<openvdb::Vec3SMetadata>("light_direction");
        ASSERT_TRUE(dirMeta);
        EXPECT_NEAR(dirMeta->value().y(), 1 / std::sqrt(1.25f), 1e-5);
        EXPECT_FALSE(g.getMetadata<openvdb::StringMetadata>("light"));
        for (const char* fiber : {"fiber_diameter", "density_multiplier", "eta", "beta_R_deg",
                                  "alpha_R_deg", "d_f", "d_b", "light_intensity"})
            EXPECT_TRUE(g.getMetadata<openvdb::FloatMetadata>(fiber)) << fiber;
        EXPECT_TRUE(g.getMetadata<openvdb::Vec3SMetadata>("sigma_a"));
        EXPECT_EQ(stringMeta(g, "mode"), "grid");
    }
    const auto V = openvdb::gridPtrCast<openvdb::FloatGrid>(grids.at("V"));
    const auto n = openvdb::gridPtrCast<openvdb::FloatGrid>(grids.at("n"));
    ASSERT_TRUE(V && n);
    EXPECT_EQ(V->background(), 1.0f) << "outside the hair nothing blocks the light";
    EXPECT_EQ(n->background(), 0.0f);
    EXPECT_EQ(V->tree().getValue(openvdb::Coord(100000, 0, 0)), 1.0f);
    EXPECT_GT(V->activeVoxelCount(), 0u);
    for (const char* name : {"T_s", "sigma2_f"}) {
        const auto g = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grids.at(name));
        ASSERT_TRUE(g) << name;
        EXPECT_EQ(g->background(), openvdb::Vec3s(0.0f)) << name;
        EXPECT_EQ(stringMeta(*g, "component_order"), "R,G,B") << name;
    }
}

TEST(VdbMetadata, FiberGridIsSelfDescribing) {
    test::TempDir dir;
    const fs::path vdb = dir / "fibers.vdb";
    const auto r = voxelizeRatboy(vdb, "--voxel-size 0.01 --orientation-tensor");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const auto grids = readAll(vdb);
    ASSERT_TRUE(grids.count("density") && grids.count("orientation"));
    const openvdb::GridBase& density = *grids.at("density");
    EXPECT_EQ(density.getGridClass(), openvdb::GRID_FOG_VOLUME);
    EXPECT_EQ(stringMeta(density, "units"), "1/length^2 (scene units)");
    EXPECT_TRUE(density.getMetadata<openvdb::DoubleMetadata>("voxel_size"));
    EXPECT_EQ(openvdb::gridPtrCast<openvdb::FloatGrid>(grids.at("density"))->background(), 0.0f);
    const std::map<std::string, std::string> order = {{"orientation", "x,y,z (world axes)"},
                                                      {"tensorDiag", "xx,yy,zz"},
                                                      {"tensorOffDiag", "xy,xz,yz"}};
    for (const auto& [name, components] : order) {
        SCOPED_TRACE(name);
        ASSERT_TRUE(grids.count(name));
        const openvdb::GridBase& g = *grids.at(name);
        EXPECT_EQ(g.getGridClass(), openvdb::GRID_UNKNOWN);
        EXPECT_EQ(stringMeta(g, "component_order"), components);
        EXPECT_NE(stringMeta(g, "units"), "<missing>");
        EXPECT_NE(stringMeta(g, "description"), "<missing>");
    }
}

TEST(VdbMetadata, VoxelizeRefusesAFileItsBudgetCannotBuild) {
    // At 1 mm Ratboy's packed grid (~20 MB) fits 0.1 GiB, the OpenVDB leaves
    // its file needs (~180 MB, dense 8³ each) do not: refused before the
    // splat, by its estimate of them, and no file is left.
    test::TempDir dir;
    const fs::path vdb = dir / "fibers.vdb";
    const auto r = voxelizeRatboy(vdb, "--voxel-size 0.001 --memory-budget 0.1");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("OpenVDB leaves"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("budget"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(vdb));
}

} // namespace
} // namespace hairvox
