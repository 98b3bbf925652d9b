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
    for (auto it = grid.density->cbeginValueOn(); it; ++it)
        sum += double(*it);
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

/// Same topology and bitwise-identical voxel values.
template <typename GridT>
bool sameGrid(const GridT& a, const GridT& b) {
    using Leaf = typename GridT::TreeType::LeafNodeType;
    if (a.tree().leafCount() != b.tree().leafCount() ||
        a.tree().activeVoxelCount() != b.tree().activeVoxelCount())
        return false;
    for (auto it = a.tree().cbeginLeaf(); it; ++it) {
        const Leaf* other = b.tree().probeConstLeaf(it->origin());
        if (!other || other->getValueMask() != it->getValueMask() ||
            std::memcmp(it->buffer().data(), other->buffer().data(),
                        Leaf::SIZE * sizeof(typename GridT::ValueType)) != 0)
            return false;
    }
    return true;
}

inline bool sameFiberGrid(const FiberGrid& a, const FiberGrid& b) {
    if (!sameGrid(*a.density, *b.density) || !sameGrid(*a.orientation, *b.orientation) ||
        a.hasTensor() != b.hasTensor() || a.typeFraction.size() != b.typeFraction.size())
        return false;
    for (std::size_t t = 0; t < a.typeFraction.size(); ++t)
        if (!sameGrid(*a.typeFraction[t], *b.typeFraction[t]))
            return false;
    return !a.hasTensor() ||
           (sameGrid(*a.tensorDiag, *b.tensorDiag) && sameGrid(*a.tensorOffDiag, *b.tensorOffDiag));
}

/// splatStrands on exactly `threads` TBB threads.
inline FiberGrid splatWithThreads(const Groom& groom, const SplatOptions& options, int threads) {
    const ThreadLimit limit(threads);
    tbb::task_arena arena(threads);
    return arena.execute([&] { return splatStrands(groom, options); });
}

} // namespace hairvox::test
