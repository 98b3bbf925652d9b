#include "brick_volume.h"

#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/large_array.h>

#include <glm/common.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <span>

namespace hairvox::detail {

namespace {

std::uint32_t hashBrick(const glm::ivec3& b) {
    return static_cast<std::uint32_t>(b.x) * 73856093u ^
           static_cast<std::uint32_t>(b.y) * 19349663u ^
           static_cast<std::uint32_t>(b.z) * 83492791u;
}

/// Bit of cell c in a bitmap of the box [lo, hi] (x fastest).
std::size_t boxBit(const glm::ivec3& c, const glm::ivec3& lo, const glm::ivec3& hi) {
    const glm::ivec3 d = c - lo;
    const glm::ivec3 n = hi - lo + 1;
    return (std::size_t(d.z) * std::size_t(n.y) + std::size_t(d.y)) * std::size_t(n.x) +
           std::size_t(d.x);
}

/// A bitmap over the box [lo, hi], one bit per cell, all clear.
std::vector<std::uint64_t> boxBitmap(const glm::ivec3& lo, const glm::ivec3& hi) {
    return std::vector<std::uint64_t>(boxBit(hi, lo, hi) / 64 + 1, 0);
}

void setBoxBit(std::vector<std::uint64_t>& bits, const glm::ivec3& c, const glm::ivec3& lo,
               const glm::ivec3& hi) {
    const std::size_t bit = boxBit(c, lo, hi);
    bits[bit >> 6] |= std::uint64_t(1) << (bit & 63);
}

/// Whether cell c is set (false outside the box).
bool boxBitSet(const std::vector<std::uint64_t>& bits, const glm::ivec3& c, const glm::ivec3& lo,
               const glm::ivec3& hi) {
    if (glm::any(glm::lessThan(c, lo)) || glm::any(glm::greaterThan(c, hi)))
        return false;
    const std::size_t bit = boxBit(c, lo, hi);
    return (bits[bit >> 6] >> (bit & 63)) & 1u;
}

} // namespace

BrickVolume::BrickVolume(double voxelSize)
    : h_(voxelSize)
    , invH_(static_cast<float>(1.0 / voxelSize))
    , slots_(64, -1) {}

std::size_t BrickVolume::memoryBytes() const {
    return values_.size() * sizeof(Lanes) + present_.capacity() * sizeof(SlotBits) +
           valueBase_.capacity() * sizeof(std::size_t) +
           cellMask_.capacity() * sizeof(cellMask_[0]) +
           cellBoxes_.capacity() * sizeof(OctantBoxes) +
           (occupancy_.capacity() + superOccupancy_.capacity()) * sizeof(std::uint64_t) +
           brickCoord_.capacity() * sizeof(glm::ivec3) + slots_.capacity() * sizeof(std::int64_t);
}

BrickVolume::OctantBoxes BrickVolume::octantBoxes(const std::array<std::uint64_t, 8>& mask) {
    OctantBoxes boxes;
    for (std::size_t a = 0; a < 3; ++a) {
        boxes.lo[a].fill(8);
        boxes.hi[a].fill(0);
    }
    for (int x = 0; x < 8; ++x)
        for (std::uint64_t word = mask[std::size_t(x)]; word != 0; word &= word - 1) {
            const int bit = std::countr_zero(word);
            const std::array<int, 3> c{x, bit >> 3, bit & 7};
            const auto o = std::size_t(((c[0] >> 2) * 2 + (c[1] >> 2)) * 2 + (c[2] >> 2));
            for (std::size_t a = 0; a < 3; ++a) {
                boxes.lo[a][o] = std::min(boxes.lo[a][o], static_cast<std::uint8_t>(c[a]));
                boxes.hi[a][o] = std::max(boxes.hi[a][o], static_cast<std::uint8_t>(c[a]));
            }
        }
    boxes.whole = true;
    for (std::size_t o = 0; o < 8; ++o)
        for (std::size_t a = 0; a < 3; ++a) {
            const int lo = (o >> (2 - a) & 1) ? 4 : 0; // the octant's own cells
            boxes.whole = boxes.whole && boxes.lo[a][o] == lo && boxes.hi[a][o] == lo + 3;
        }
    return boxes;
}

std::int64_t BrickVolume::find(const glm::ivec3& b) const {
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = hashBrick(b) & mask;; i = (i + 1) & mask) {
        const std::int64_t slot = slots_[i];
        if (slot < 0 || brickCoord_[static_cast<std::size_t>(slot)] == b)
            return slot;
    }
}

void BrickVolume::grow() {
    std::vector<std::int64_t> slots(slots_.size() * 2, -1);
    const std::size_t mask = slots.size() - 1;
    for (std::size_t brick = 0; brick < brickCount_; ++brick) {
        const glm::ivec3& b = brickCoord_[brick];
        std::size_t i = hashBrick(b) & mask;
        while (slots[i] >= 0)
            i = (i + 1) & mask;
        slots[i] = static_cast<std::int64_t>(brick);
    }
    slots_.swap(slots);
}

std::int64_t BrickVolume::insert(const glm::ivec3& b) {
    if (const std::int64_t found = find(b); found >= 0)
        return found;
    if (2 * (brickCount_ + 1) > slots_.size())
        grow();
    const std::size_t mask = slots_.size() - 1;
    std::size_t i = hashBrick(b) & mask;
    while (slots_[i] >= 0)
        i = (i + 1) & mask;
    slots_[i] = static_cast<std::int64_t>(brickCount_);
    brickCoord_.push_back(b);
    if (brickCount_ == 0) {
        brickMin_ = brickMax_ = b;
    } else {
        brickMin_ = glm::min(brickMin_, b);
        brickMax_ = glm::max(brickMax_, b);
    }
    return static_cast<std::int64_t>(brickCount_++);
}

void BrickVolume::reserveBrick(const glm::ivec3& b, int lowFaces) {
    for (int mask = 0; mask < 8; ++mask)
        if ((mask & lowFaces) == mask)
            insert(b - glm::ivec3((mask >> 2) & 1, (mask >> 1) & 1, mask & 1));
}

bool BrickVolume::occupied(const glm::ivec3& b) const {
    return boxBitSet(occupancy_, b, brickMin_, brickMax_);
}

bool BrickVolume::superOccupied(const glm::ivec3& sb) const {
    return boxBitSet(superOccupancy_, sb, superMin_, superMax_);
}

void BrickVolume::allocateSlots() {
    if (brickCount_ > 0) {
        // Floor division by kSuper (C++20: arithmetic shift).
        superMin_ = brickMin_ >> kSuperShift;
        superMax_ = brickMax_ >> kSuperShift;
        occupancy_ = boxBitmap(brickMin_, brickMax_);
        superOccupancy_ = boxBitmap(superMin_, superMax_);
        for (const glm::ivec3& b : brickCoord_) {
            setBoxBit(occupancy_, b, brickMin_, brickMax_);
            setBoxBit(superOccupancy_, b >> kSuperShift, superMin_, superMax_);
        }
    }
    present_.assign(brickCount_, SlotBits{});
}

void BrickVolume::allocateValues() {
    // Each brick numbers its reserved slots in slot order (deterministic for
    // any thread count), then the bricks' runs are laid end to end.
    std::vector<std::size_t> counts(brickCount_);
    cellMask_.assign(brickCount_, {});
    cellBoxes_.resize(brickCount_);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, brickCount_, 64), [&](const auto& r) {
        for (std::size_t brick = r.begin(); brick != r.end(); ++brick) {
            SlotBits& slots = present_[brick];
            std::uint16_t next = 0;
            for (std::size_t w = 0; w < kSlotWords; ++w) {
                slots.rank[w] = next;
                for (std::uint64_t word = slots.bits[w]; word != 0; word &= word - 1) {
                    ++next;
                    const int slot = int(w) * 64 + std::countr_zero(word);
                    const int x = slot / (kSide * kSide), y = slot / kSide % kSide,
                              z = slot % kSide;
                    // The value is a corner of the cells (x − 1 .. x, y − 1 .. y,
                    // z − 1 .. z) within the brick: their (y, z) bits at once,
                    // bit cy·8 + cz, as the bytes cy of their z bits.
                    const auto within = [](int c) { // bits c − 1 and c of 0 .. 7
                        return ((std::uint64_t(1) << c) | (std::uint64_t(1) << c >> 1)) & 0xFFu;
                    };
                    const std::uint64_t cz = within(z), cy = within(y);
                    const std::uint64_t cells =
                        (((cy & 1u) | (cy & 2u) << 7 | (cy & 4u) << 14 | (cy & 8u) << 21 |
                          (cy & 16u) << 28 | (cy & 32u) << 35 | (cy & 64u) << 42 |
                          (cy & 128u) << 49) *
                         cz);
                    for (int cx = std::max(x - 1, 0); cx <= std::min(x, kBrick - 1); ++cx)
                        cellMask_[brick][std::size_t(cx)] |= cells;
                }
            }
            counts[brick] = next;
            cellBoxes_[brick] = octantBoxes(cellMask_[brick]);
        }
    });
    valueBase_.resize(brickCount_);
    std::size_t valueCount = 0;
    for (std::size_t brick = 0; brick < brickCount_; ++brick) {
        valueBase_[brick] = valueCount;
        valueCount += counts[brick];
    }
    // Zeroed brick by brick on the threads (the apron slots no voxel sets stay zero).
    values_ = LargeBuffer<Lanes>(valueCount);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, brickCount_, 64), [&](const auto& r) {
        std::uninitialized_value_construct(values_.begin() + valueBase_[r.begin()],
                                           values_.begin() + valueBase_[r.end() - 1] +
                                               counts[r.end() - 1]);
    });
}

BrickVolume::BrickSet BrickVolume::brickSet(const glm::ivec3& b) const {
    BrickSet set;
    for (int mask = 0; mask < 8; ++mask)
        set.brick[mask] = find(b - glm::ivec3((mask >> 2) & 1, (mask >> 1) & 1, mask & 1));
    return set;
}

template <typename F>
void BrickVolume::forEachCopy(const BrickSet& bricks, const glm::ivec3& local, F&& f) {
    // The voxel's own brick, and the aprons below for each axis where it is on the low face.
    // (The submasks of onLowFace, from it down to 0: one for a voxel off the
    // low faces, as most are, where testing all 8 cost more than the copy.)
    const int onLowFace = (local.x == 0 ? 4 : 0) | (local.y == 0 ? 2 : 0) | (local.z == 0 ? 1 : 0);
    for (int mask = onLowFace;; mask = (mask - 1) & onLowFace) {
        if (bricks.brick[mask] >= 0) {
            const glm::ivec3 l =
                local + kBrick * glm::ivec3((mask >> 2) & 1, (mask >> 1) & 1, mask & 1);
            f(static_cast<std::size_t>(bricks.brick[mask]), valueIndex(l.x, l.y, l.z));
        }
        if (mask == 0)
            break;
    }
}

void BrickVolume::reserveVoxel(const BrickSet& bricks, const glm::ivec3& local) {
    // Voxels of neighbouring leaves share the aprons' words: set bits atomically.
    forEachCopy(bricks, local, [&](std::size_t brick, int slot) {
        std::atomic_ref(present_[brick].bits[static_cast<std::size_t>(slot >> 6)])
            .fetch_or(std::uint64_t(1) << (slot & 63), std::memory_order_relaxed);
    });
}

void BrickVolume::set(const BrickSet& bricks, const glm::ivec3& local, const OpticalDepths& value) {
    forEachCopy(bricks, local, [&](std::size_t brick, int slot) {
        values_[valueAt(brick, slot)] = Lanes::from(value);
    });
}

Bounds3f BrickVolume::valueBounds(std::size_t brick) const {
    Bounds3f bounds;
    const glm::ivec3 base = kBrick * brickCoord_[brick];
    const float h = static_cast<float>(h_);
    const OctantBoxes& boxes = cellBoxes_[brick];
    for (std::size_t o = 0; o < 8; ++o) {
        if (boxes.lo[0][o] > boxes.hi[0][o])
            continue; // an octant without such cells
        bounds.extend(Vec3f(base + glm::ivec3(boxes.lo[0][o], boxes.lo[1][o], boxes.lo[2][o])) * h);
        bounds.extend(Vec3f(base + glm::ivec3(boxes.hi[0][o], boxes.hi[1][o], boxes.hi[2][o]) + 1) *
                      h);
    }
    return bounds;
}

Bounds3f BrickVolume::bounds() const {
    Bounds3f b;
    if (!empty()) {
        b.extend(Vec3f(kBrick * brickMin_) * static_cast<float>(h_));
        b.extend(Vec3f(kBrick * (brickMax_ + 1)) * static_cast<float>(h_));
    }
    return b;
}

} // namespace hairvox::detail
