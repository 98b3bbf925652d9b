// The global term at the fiber grid's active voxels (transmittance/lit_grid.h):
// packed in the grid's value order, and the same values in the lit OpenVDB grids.
#include "slab.h"

#include <hairvox/transmittance/grid_global_term.h>
#include <hairvox/transmittance/lit_grid.h>

#include <gtest/gtest.h>

#include <stdexcept>

namespace hairvox {
namespace {

TEST(LitGrid, PackedValuesAreTheGridsValuesInTheFiberGridsOrder) {
    test::Slab slab;
    slab.fibers = 500;
    SplatOptions splat;
    splat.voxelSize = 0.002;
    const FiberGrid grid = splatStrands(slab.groom(), splat);
    const auto model =
        makeGridModel(grid, {test::constantTable(0.5f, 0.01f)}, test::slabSettings(), {});
    const auto light = model->forLight(Light::directional(Vec3f(0.0f, 1.0f, 0.0f)));
    const VoxelGlobalTerms values = evaluateAtActiveVoxels(grid, *light);
    ASSERT_EQ(values.terms.size(), grid.activeVoxelCount());
    EXPECT_EQ(values.stats.queries, grid.activeVoxelCount());

    const LitGrid lit = toLitGrid(grid, values);
    auto n = lit.n->getConstAccessor();
    auto V = lit.V->getConstAccessor();
    auto T_s = lit.T_s->getConstAccessor();
    double nLow = 0, nHigh = 0, low = 0, high = 0; // near the slab's bottom and its top
    grid.forEachVoxel([&](std::size_t i, const openvdb::Coord& ijk) {
        const GlobalTerm& g = values.terms[i];
        EXPECT_EQ(n.getValue(ijk), g.n);
        EXPECT_EQ(V.getValue(ijk), g.V);
        EXPECT_EQ(T_s.getValue(ijk), openvdb::Vec3s(g.T_s.r, g.T_s.g, g.T_s.b));
        const double y = ijk.y() * splat.voxelSize;
        if (y < 0.3 * double(slab.thicknessY))
            nLow += double(g.n), low += 1;
        else if (y > 0.7 * double(slab.thicknessY))
            nHigh += double(g.n), high += 1;
    });
    // The light is above: more fibers lie toward it from the slab's bottom.
    ASSERT_GT(low, 0);
    ASSERT_GT(high, 0);
    EXPECT_GT(nLow / low, 2 * nHigh / high);
    EXPECT_EQ(lit.n->activeVoxelCount(), grid.activeVoxelCount());

    VoxelGlobalTerms truncated = values;
    truncated.terms.pop_back();
    EXPECT_THROW(toLitGrid(grid, truncated), std::invalid_argument);
}

} // namespace
} // namespace hairvox
