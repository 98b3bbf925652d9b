// hairvox voxelize: the fiber grid's packed storage (fiber_grid.h, "Storage").
#include <hairvox/voxelize/fiber_grid.h>

#include <algorithm>

namespace hairvox {

namespace {

template <typename T>
std::uint64_t bytesOf(const std::vector<T>& v) {
    return v.capacity() * sizeof(T);
}

} // namespace

std::uint64_t FiberGrid::memoryBytes() const {
    std::uint64_t bytes = bytesOf(blocks) + bytesOf(density) + bytesOf(orientation) +
                          bytesOf(tensorDiag) + bytesOf(tensorOffDiag);
    for (const auto& fraction : typeFraction)
        bytes += bytesOf(fraction);
    return bytes;
}

std::size_t FiberGrid::find(const openvdb::Coord& ijk) const {
    const openvdb::Coord origin = ijk & ~(FiberBlock::kDim - 1);
    const auto it = std::lower_bound(
        blocks.begin(), blocks.end(), origin,
        [](const FiberBlock& block, const openvdb::Coord& o) { return block.origin < o; });
    if (it == blocks.end() || it->origin != origin)
        return kInactive;
    const openvdb::Index offset = FiberBlock::Leaf::coordToOffset(ijk);
    if (!it->active.isOn(offset))
        return kInactive;
    // The rank of the offset among the block's active voxels: the bits set
    // in the mask's 64-bit words before it.
    using Word = openvdb::Index64;
    const openvdb::Index word = offset >> 6, bit = offset & 63;
    std::size_t rank = 0;
    for (openvdb::Index w = 0; w < word; ++w)
        rank += openvdb::util::CountOn(it->active.getWord<Word>(w));
    rank += openvdb::util::CountOn(it->active.getWord<Word>(word) & ((Word(1) << bit) - 1));
    return it->first + rank;
}

std::ostream& operator<<(std::ostream& os, const FiberGridInfo& info) {
    return os << "FiberGridInfo(voxelSize=" << info.voxelSize << ", " << info.fiberScale
              << ", sourceFile=\"" << info.sourceFile << "\", sourceHash=" << info.sourceHash
              << ", strands=" << info.strands << ", segments=" << info.segments
              << ", totalLength=" << info.totalLength << ", version=" << info.version << ")";
}

std::ostream& operator<<(std::ostream& os, const FiberGrid& grid) {
    return os << "FiberGrid(" << grid.info << ", activeVoxels=" << grid.activeVoxelCount()
              << ", tensor=" << (grid.hasTensor() ? "yes" : "no")
              << ", fiberTypes=" << grid.fiberTypeCount() << ")";
}

} // namespace hairvox
