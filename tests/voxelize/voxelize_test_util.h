// hairvox tests: helpers shared by the voxelize tests.
#pragma once

#include <hairvox/core/parallel.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <tbb/task_arena.h>

#include <cstring>

namespace hairvox::test {

/// Σ_v λ_v h³: the fiber length the density grid holds.
inline double splattedLength(const FiberGrid& grid) {
    double sum = 0;
    for (const float lambda : grid.density)
        sum += double(lambda);
    const double h = grid.info.voxelSize;
    return sum * h * h * h;
}

/// Σ |p_{k+1} − p_k| in double: the exact length of the groom's polylines.
inline double exactLength(const Groom& groom) {
    double sum = 0;
    for (std::size_t s = 0; s < groom.strandCount(); ++s) {
        const auto pts = groom.strand(s);
        for (std::size_t k = 1; k < pts.size(); ++k)
            sum += glm::length(Vec3d(pts[k]) - Vec3d(pts[k - 1]));
    }
    return sum;
}

/// The same values, bit for bit.
template <typename T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
    // An empty vector's data() may be null, which memcmp may not be given.
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

/// Same blocks: origins, active voxels, value offsets.
inline bool sameBlocks(const FiberGrid& a, const FiberGrid& b) {
    if (a.blocks.size() != b.blocks.size())
        return false;
    for (std::size_t k = 0; k < a.blocks.size(); ++k)
        if (a.blocks[k].origin != b.blocks[k].origin || a.blocks[k].first != b.blocks[k].first ||
            a.blocks[k].active != b.blocks[k].active)
            return false;
    return true;
}

/// Same blocks and bitwise-identical values.
inline bool sameFiberGrid(const FiberGrid& a, const FiberGrid& b) {
    if (!sameBlocks(a, b) || a.hasTensor() != b.hasTensor() ||
        a.typeFraction.size() != b.typeFraction.size())
        return false;
    for (std::size_t t = 0; t < a.typeFraction.size(); ++t)
        if (!sameBits(a.typeFraction[t], b.typeFraction[t]))
            return false;
    return sameBits(a.density, b.density) && sameBits(a.orientation, b.orientation) &&
           sameBits(a.tensorDiag, b.tensorDiag) && sameBits(a.tensorOffDiag, b.tensorOffDiag);
}

/// splatStrands on exactly `threads` TBB threads.
inline FiberGrid splatWithThreads(const Groom& groom, const SplatOptions& options, int threads) {
    const ThreadLimit limit(threads);
    tbb::task_arena arena(threads);
    return arena.execute([&] { return splatStrands(groom, options); });
}

} // namespace hairvox::test
