// hairvox volumetric: the cells the radiance cache and the surfaces'
// irradiance are kept in (radiance_cache.h, surface_irradiance.h).
//
// A cell is m × m × m voxels of the fiber grid (m = cellVoxels, voxel size
// h): cell C covers the voxels [m·C, m·C + m) on each axis, i.e. the world
// box [(m·C − ½)·h, (m·C + m − ½)·h), since a voxel's value holds in the box
// of one voxel around its vertex (fiber_medium.h). A dense index over a box
// of cells gives each present cell its slot (−1: absent). Values live at the
// cells' centres and are read trilinearly between the 8 centres around a
// point, absent cells left out and the weights renormalised.
#pragma once

#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/vecmath.h>

#include <bit>
#include <cstdint>
#include <vector>

namespace hairvox {

class CellGrid {
public:
    CellGrid() = default;
    /// The box of cells [cellMin, cellMin + dims), none present yet.
    CellGrid(float voxelSize, int cellVoxels, const glm::ivec3& cellMin, const glm::ivec3& dims)
        : h_(voxelSize)
        , m_(cellVoxels)
        , shift_(cellVoxels > 0 && std::has_single_bit(unsigned(cellVoxels))
                     ? std::countr_zero(unsigned(cellVoxels))
                     : -1)
        , min_(cellMin)
        , dims_(dims) {}

    float voxelSize() const { return h_; }
    int cellVoxels() const { return m_; }
    float cellSize() const { return float(m_) * h_; }
    const glm::ivec3& boxMin() const { return min_; }
    const glm::ivec3& boxDims() const { return dims_; }
    std::size_t boxCells() const {
        return std::size_t(dims_.x) * std::size_t(dims_.y) * std::size_t(dims_.z);
    }

    /// The cell holding world point x (inside the box or not).
    glm::ivec3 cellAt(const Vec3f& x) const {
        const Vec3f q = coordinates(x);
        return {floorToInt(q.x), floorToInt(q.y), floorToInt(q.z)};
    }
    /// The cell holding voxel v (index space).
    glm::ivec3 cellOfVoxel(const glm::ivec3& v) const {
        if (shift_ >= 0) // m = 2^shift: ⌊v/m⌋ is the arithmetic shift (C++20), no division
            return {v.x >> shift_, v.y >> shift_, v.z >> shift_};
        return {floorDiv(v.x, m_), floorDiv(v.y, m_), floorDiv(v.z, m_)};
    }
    /// The cell's place in the box's dense order (x slowest), or −1 outside.
    std::int64_t boxIndex(const glm::ivec3& cell) const {
        const glm::ivec3 r = cell - min_;
        if (r.x < 0 || r.y < 0 || r.z < 0 || r.x >= dims_.x || r.y >= dims_.y || r.z >= dims_.z)
            return -1;
        return std::int64_t((std::size_t(r.x) * std::size_t(dims_.y) + std::size_t(r.y)) *
                                std::size_t(dims_.z) +
                            std::size_t(r.z));
    }
    /// The cell at a place of the box's dense order.
    glm::ivec3 cellOfBoxIndex(std::size_t i) const {
        const auto z = std::size_t(dims_.z), y = std::size_t(dims_.y);
        return min_ + glm::ivec3(int(i / (z * y)), int((i / z) % y), int(i % z));
    }

    /// Makes the cells whose box index is marked present, slots given in box
    /// order; returns their box indices in slot order.
    std::vector<std::size_t> makePresent(const std::vector<std::uint8_t>& marked) {
        index_.assign(marked.size(), -1);
        std::vector<std::size_t> present;
        for (std::size_t i = 0; i < marked.size(); ++i)
            if (marked[i] != 0) {
                index_[i] = static_cast<std::int32_t>(present.size());
                present.push_back(i);
            }
        return present;
    }

    /// The slot of a present cell, or −1.
    std::int64_t slotOfCell(const glm::ivec3& cell) const {
        const std::int64_t i = boxIndex(cell);
        return i < 0 || index_.empty() ? -1 : index_[std::size_t(i)];
    }
    std::int64_t slotAt(const Vec3f& x) const { return slotOfCell(cellAt(x)); }
    /// The world position of a cell's centre.
    Vec3f centre(const glm::ivec3& cell) const { return (Vec3f(cell) + 0.5f) * cellSize() - 0.5f * h_; }

    /// Calls f(slot, w) for each present cell among the 8 whose centres
    /// surround x, w > 0 its trilinear weight; returns Σ w (0: none present).
    template <class F>
    float forEachAround(const Vec3f& x, F&& f) const {
        const Vec3f q = coordinates(x) - 0.5f;
        const glm::ivec3 base(floorToInt(q.x), floorToInt(q.y), floorToInt(q.z));
        const Vec3f t = q - Vec3f(base);
        float weights = 0;
        for (int corner = 0; corner < 8; ++corner) {
            const glm::ivec3 o((corner >> 2) & 1, (corner >> 1) & 1, corner & 1);
            const std::int64_t slot = slotOfCell(base + o);
            if (slot < 0)
                continue;
            const float w = (o.x ? t.x : 1.0f - t.x) * (o.y ? t.y : 1.0f - t.y) *
                            (o.z ? t.z : 1.0f - t.z);
            if (!(w > 0))
                continue;
            f(std::size_t(slot), w);
            weights += w;
        }
        return weights;
    }

    std::uint64_t memoryBytes() const { return index_.capacity() * sizeof(std::int32_t); }

    /// ⌊a / b⌋ for b > 0.
    static int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

private:
    /// Cell C spans [C, C + 1); its centre is at C + ½.
    Vec3f coordinates(const Vec3f& x) const { return (x / h_ + 0.5f) / float(m_); }

    float h_ = 1;
    int m_ = 1;
    int shift_ = 0; ///< log2 m if m is a power of two, else −1
    glm::ivec3 min_{0}, dims_{0};
    std::vector<std::int32_t> index_; ///< dense over the box: slot or −1
};

} // namespace hairvox
