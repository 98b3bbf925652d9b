#include "brick_volume.h"

#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/large_array.h>

#include <glm/common.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>
#include <new>
#include <limits>
#include <span>

namespace hairvox::detail {

namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

std::uint32_t hashBrick(const glm::ivec3& b) {
    return static_cast<std::uint32_t>(b.x) * 73856093u ^
           static_cast<std::uint32_t>(b.y) * 19349663u ^
           static_cast<std::uint32_t>(b.z) * 83492791u;
}

int valueIndex(int x, int y, int z) {
    return (x * BrickVolume::kSide + y) * BrickVolume::kSide + z;
}

/// Half of a Lanes value in a SIMD register (GCC's and Clang's vector
/// extension: SSE on x86-64's baseline, the same elementwise arithmetic in
/// the same order as on floats, so the same bits). Loops over the 8 floats
/// kept their sums in memory between corners.
using Half = float __attribute__((vector_size(16)));

inline Half loadHalf(const Lanes& v, int h) {
    Half r;
    std::memcpy(&r, v.v + 4 * h, sizeof(r));
    return r;
}

inline void storeHalf(Lanes& v, int h, const Half& r) {
    std::memcpy(v.v + 4 * h, &r, sizeof(r));
}

/// The trilinear weights of the 8 corners k = dx·4 + dy·2 + dz at fractions
/// f, each (wx·wy)·wz: all 8 in four vector products, where each corner's
/// own three loads and two products took more than its sums.
struct CornerWeights {
    alignas(16) float w[8];

    explicit CornerWeights(const Vec3f& f) {
        const float x0 = 1.0f - f.x, y0 = 1.0f - f.y, z0 = 1.0f - f.z;
        const Half xy = Half{x0, x0, f.x, f.x} * Half{y0, f.y, y0, f.y};
        const Half z = {z0, f.z, z0, f.z};
        const Half low = Half{xy[0], xy[0], xy[1], xy[1]} * z;  // dx = 0
        const Half high = Half{xy[2], xy[2], xy[3], xy[3]} * z; // dx = 1
        std::memcpy(w, &low, sizeof(low));
        std::memcpy(w + 4, &high, sizeof(high));
    }
};

/// Trilinear interpolation of a cell's corners at fractions f. The corners
/// left out are zero, so the sum is the 8-corner sum, bit for bit (adding
/// w·0 to a non-negative sum leaves it as it is).
inline Lanes trilinear(const CellCorners& c, const Vec3f& f) {
    const CornerWeights weights(f);
    Half r0 = {}, r1 = {};
    for (int i = 0; i < c.count; ++i) {
        const float w = weights.w[c.k[std::size_t(i)]];
        const Lanes& v = *c.value[std::size_t(i)];
        r0 += w * loadHalf(v, 0);
        r1 += w * loadHalf(v, 1);
    }
    Lanes r;
    storeHalf(r, 0, r0);
    storeHalf(r, 1, r1);
    return r;
}

/// trilinear() at fractions f and g together (a piece's middle and end): the
/// same sums in the same order, as two independent chains of additions
/// where one evaluation after the other waited on each add's latency.
inline void trilinear2(const CellCorners& c, const Vec3f& f, const Vec3f& g, Lanes& atF,
                       Lanes& atG) {
    const CornerWeights weightsF(f), weightsG(g);
    Half f0 = {}, f1 = {}, g0 = {}, g1 = {};
    for (int i = 0; i < c.count; ++i) {
        const std::size_t k = c.k[std::size_t(i)];
        const float wf = weightsF.w[k], wg = weightsG.w[k];
        const Lanes& v = *c.value[std::size_t(i)];
        const Half v0 = loadHalf(v, 0), v1 = loadHalf(v, 1);
        f0 += wf * v0;
        f1 += wf * v1;
        g0 += wg * v0;
        g1 += wg * v1;
    }
    storeHalf(atF, 0, f0);
    storeHalf(atF, 1, f1);
    storeHalf(atG, 0, g0);
    storeHalf(atG, 1, g1);
}

/// a += w·(f0 + 4 fm + f1), lane by lane.
inline void addSimpson(Lanes& a, const Lanes& f0, const Lanes& fm, const Lanes& f1, float w) {
    for (int h = 0; h < 2; ++h)
        storeHalf(a, h,
                  loadHalf(a, h) +
                      w * (loadHalf(f0, h) + 4.0f * loadHalf(fm, h) + loadHalf(f1, h)));
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
    OctantBoxes result;
    auto& boxes = result.box;
    boxes.fill({{8, 8, 8}, {0, 0, 0}});
    for (int x = 0; x < 8; ++x)
        for (std::uint64_t word = mask[std::size_t(x)]; word != 0; word &= word - 1) {
            const int bit = std::countr_zero(word);
            const std::array<int, 3> c{x, bit >> 3, bit & 7};
            auto& box = boxes[std::size_t(((c[0] >> 2) * 2 + (c[1] >> 2)) * 2 + (c[2] >> 2))];
            for (std::size_t a = 0; a < 3; ++a) {
                box.lo[a] = std::min(box.lo[a], static_cast<std::uint8_t>(c[a]));
                box.hi[a] = std::max(box.hi[a], static_cast<std::uint8_t>(c[a]));
            }
        }
    result.whole = true;
    for (std::size_t o = 0; o < 8; ++o)
        for (std::size_t a = 0; a < 3; ++a) {
            const int lo = (o >> (2 - a) & 1) ? 4 : 0; // the octant's own cells
            result.whole = result.whole && boxes[o].lo[a] == lo && boxes[o].hi[a] == lo + 3;
        }
    return result;
}

bool BrickVolume::valueSpan(std::size_t brick, const glm::ivec3& b, const GridLine<float>& line,
                            float s0, float s1, float& spanBegin, float& spanEnd) const {
    const OctantBoxes& boxes = cellBoxes_[brick];
    spanBegin = s0;
    spanEnd = s1;
    if (boxes.whole)
        return true;
    spanBegin = kInfinity;
    spanEnd = -kInfinity;
    const glm::ivec3 base = kBrick * b;
    // The walk's crossings are exact to a few ulps of the index coordinates:
    // 1/64 of a cell, more where the coordinates are large.
    const int magnitude = std::max({std::abs(base.x), std::abs(base.y), std::abs(base.z)}) + kBrick;
    const float margin = 1.0f / 64.0f + 64.0f * std::numeric_limits<float>::epsilon() *
                                            static_cast<float>(magnitude);
    for (const CellBox& box : boxes.box) {
        if (box.lo[0] > box.hi[0])
            continue; // an octant without such cells
        float sa = s0, sb = s1;
        for (std::size_t a = 0; a < 3 && sa <= sb; ++a) {
            const int i = static_cast<int>(a);
            const float lo = static_cast<float>(base[i] + box.lo[a]) - margin;
            const float hi = static_cast<float>(base[i] + box.hi[a] + 1) + margin;
            if (line.invDir[i] == 0.0f) { // the walk does not move along a
                const float x = line.origin[i] + s0 * line.dir[i];
                if (x < lo || x > hi)
                    sb = -kInfinity;
                continue;
            }
            const float ta = (lo - line.origin[i]) * line.invDir[i];
            const float tb = (hi - line.origin[i]) * line.invDir[i];
            sa = std::max(sa, std::min(ta, tb));
            sb = std::min(sb, std::max(ta, tb));
        }
        if (sa <= sb) {
            spanBegin = std::min(spanBegin, sa);
            spanEnd = std::max(spanEnd, sb);
        }
    }
    return spanBegin <= spanEnd;
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

CellCorners BrickVolume::cornersOf(std::size_t brick, const glm::ivec3& cell) const {
    CellCorners corners;
    const SlotBits& present = present_[brick];
    const Lanes* values = values_.data() + valueBase_[brick];
    const int first = valueIndex(cell.x, cell.y, cell.z);
    // Corner k = dx·4 + dy·2 + dz: each (dx, dy) has its dz = 0 and 1 on
    // adjacent slots, so one rank (valueAt()'s) serves both.
    for (int pair = 0; pair < 4; ++pair) {
        const int slot = first + (pair >> 1) * kSide * kSide + (pair & 1) * kSide;
        const auto w = static_cast<std::size_t>(slot >> 6);
        const int bit = slot & 63;
        const std::uint64_t word = present.bits[w];
        std::size_t rank =
            present.rank[w] + std::size_t(popcount64(word & ((std::uint64_t(1) << bit) - 1)));
        // (The dz = 1 slot is the next bit, in the next word after bit 63;
        // slots end at 728, so that word exists.)
        const std::uint64_t high = bit < 63 ? word >> (bit + 1) : present.bits[w + 1];
        if ((word >> bit) & 1u) {
            const auto n = std::size_t(corners.count++);
            corners.k[n] = static_cast<std::uint8_t>(2 * pair);
            corners.value[n] = values + rank++;
        }
        if (high & 1u) {
            const auto n = std::size_t(corners.count++);
            corners.k[n] = static_cast<std::uint8_t>(2 * pair + 1);
            corners.value[n] = values + rank;
        }
    }
    return corners;
}

template <typename F>
void BrickVolume::walkBricks(const Vec3f& O, const Vec3f& dir, float s0, float s1,
                             F&& visit) const {
    if (empty())
        return;
    const Vec3f lo = Vec3f(kBrick * brickMin_), hi = Vec3f(kBrick * (brickMax_ + 1));
    for (int a = 0; a < 3; ++a) { // clip to the bricks' bounding box
        if (dir[a] == 0.0f) {
            if (O[a] < lo[a] || O[a] > hi[a])
                return;
            continue;
        }
        const float ta = (lo[a] - O[a]) / dir[a], tb = (hi[a] - O[a]) / dir[a];
        s0 = std::max(s0, std::min(ta, tb));
        s1 = std::min(s1, std::max(ta, tb));
    }
    if (!(s0 < s1))
        return;
    // Bricks are cells 8 index units wide, super-bricks 8·kSuper: traverse
    // the line scaled by 1/(8·kSuper), then by 1/8 within the occupied ones.
    const GridLine<float> inSupers(O / float(kBrick * kSuper), dir / float(kBrick * kSuper));
    const GridLine<float> inBricks(O / float(kBrick), dir / float(kBrick));
    traverseCells(
        inSupers, s0, s1, superMin_, superMax_,
        [&](const glm::ivec3& sb, float sEnterSuper, float sExitSuper) {
            if (!superOccupied(sb))
                return true;
            return traverseCells(inBricks, sEnterSuper, sExitSuper,
                                 glm::max(sb * kSuper, brickMin_),
                                 glm::min(sb * kSuper + (kSuper - 1), brickMax_),
                                 [&](const glm::ivec3& b, float sEnter, float sExit) {
                                     if (!occupied(b))
                                         return true;
                                     return visit(static_cast<std::size_t>(find(b)), b, sEnter,
                                                  sExit);
                                 });
        });
}

template <typename NextSplit, typename OnPiece>
void BrickVolume::forEachPiece(std::size_t brick, const glm::ivec3& b, const GridLine<float>& line,
                               float sa, float sb, NextSplit&& nextSplit, OnPiece&& onPiece) const {
    const glm::ivec3 base = kBrick * b;
    // The field is continuous: a piece's end value is the next piece's start value.
    Lanes fStart;
    bool haveStart = false;
    traverseCells(line, sa, sb, base, base + (kBrick - 1),
                  [&](const glm::ivec3& cell, float s, float sEnd) {
                      const glm::ivec3 l = cell - base;
                      if (!((cellMask_[brick][std::size_t(l.x)] >> (l.y * 8 + l.z)) & 1u)) {
                          fStart = Lanes{}; // no corner holds a value
                          haveStart = true;
                          return true;
                      }
                      const CellCorners corners = cornersOf(brick, l);
                      bool any = false;
                      for (int i = 0; i < corners.count; ++i)
                          any = any || corners.value[std::size_t(i)]->v[0] != 0.0f;
                      if (!any) {
                          fStart = Lanes{};
                          haveStart = true;
                          return true;
                      }
                      const Vec3f cf(cell);
                      const auto at = [&](float t) {
                          return trilinear(corners, line.at(t) - cf);
                      };
                      if (!haveStart)
                          fStart = at(s);
                      haveStart = true;
                      for (float a = s; a < sEnd;) {
                          const float e = std::min(nextSplit(a), sEnd);
                          Lanes fMid, fEnd;
                          trilinear2(corners, line.at(0.5f * (a + e)) - cf, line.at(e) - cf, fMid,
                                     fEnd);
                          onPiece(a, e, fStart, fMid, fEnd);
                          fStart = fEnd;
                          a = e;
                      }
                      return true;
                  });
}

OpticalDepths BrickVolume::integrate(const Vec3f& origin, const Vec3f& dir, float tStart,
                                     float tEnd, float opaqueDepth, bool& touched) const {
    // Index space: p(s) = O + s·dir with s = t/h; the sum is scaled by h at the end.
    // Simpson's rule per cell piece is exact: the trilinear field is a cubic along a line.
    const Vec3f O = origin * invH_;
    const float opaqueSum = opaqueDepth * invH_;
    Lanes sum;
    touched = false;
    const GridLine<float> line(O, dir);
    walkBricks(O, dir, tStart * invH_, std::isinf(tEnd) ? kInfinity : tEnd * invH_,
               [&](std::size_t brick, const glm::ivec3& b, float s, float sExit) {
                   touched = true;
                   float sa, sb;
                   if (!valueSpan(brick, b, line, s, sExit, sa, sb))
                       return true;
                   forEachPiece(
                       brick, b, line, sa, sb, [](float) { return kInfinity; },
                       [&](float s0, float s1, const Lanes& f0, const Lanes& fm, const Lanes& f1) {
                           addSimpson(sum, f0, fm, f1, (s1 - s0) / 6.0f);
                       });
                   return !sum.opaque(opaqueSum);
               });
    return sum.depths() * static_cast<float>(h_);
}

void BrickVolume::integrateCumulative(const Vec3f& origin, const Vec3f& dir, float tStart,
                                      float step, std::size_t count, float opaqueDepth,
                                      std::span<const std::uint32_t> candidates,
                                      std::vector<BrickCrossing>& crossings,
                                      std::vector<CumulativeSample>& out) const {
    out.clear();
    if (count == 0)
        return;
    const Vec3f O = origin * invH_;
    const float opaqueSum = opaqueDepth * invH_;
    const float sStart = tStart * invH_, sStep = step * invH_;
    const auto position = [&](std::size_t k) { return sStart + static_cast<float>(k) * sStep; };
    Lanes sum;
    std::size_t next = 0;       // the next sample to record
    float nextAt = position(0); // its position; +∞ once every sample is recorded
    const auto setNext = [&](std::size_t k) {
        next = k;
        nextAt = k < count ? position(k) : kInfinity;
    };
    // Records sample `next` with the running sum (in world units).
    const auto recordNext = [&] {
        out.push_back({next, sum});
        for (float& lane : out.back().value.v)
            lane *= static_cast<float>(h_);
        setNext(next + 1);
    };
    // Records every sample from `next` to the last at or before s.
    const auto recordUpTo = [&](float s) {
        while (nextAt <= s)
            recordNext();
    };
    // Entering a brick at s: the samples since the last brick hold the
    // current sum. The first of them (which the last brick's exit changed)
    // and the last (which the brick's first piece interpolates from) are
    // recorded; those between are skipped.
    const auto skipTo = [&](float s) {
        if (nextAt <= s)
            recordNext();
        const float local = std::floor((s - sStart) / sStep);
        std::size_t k = local > 0 ? std::min(static_cast<std::size_t>(local), count - 1) : 0;
        while (k > 0 && position(k) > s) // float rounding either side of a sample
            --k;
        while (k + 1 < count && position(k + 1) <= s)
            ++k;
        if (k > next)
            setNext(k);
    };
    // The candidates the line crosses over [sStart, position(count − 1)], in
    // order along it (bricks are disjoint: their crossings do not overlap).
    const GridLine<float> line(O, dir);
    crossings.clear();
    for (const std::uint32_t brick : candidates) {
        const Vec3f lo(kBrick * brickCoord_[brick]), hi = lo + float(kBrick);
        float s0 = sStart, s1 = position(count - 1);
        for (int a = 0; a < 3; ++a) {
            if (line.invDir[a] == 0.0f) {
                // Parallel to the slab: inside it or not at all. On a face
                // between two bricks, in the upper one only (⌊x⌋, as a
                // walk through the cells takes it).
                if (O[a] < lo[a] || O[a] >= hi[a])
                    s1 = -kInfinity;
                continue;
            }
            const float ta = (lo[a] - O[a]) * line.invDir[a], tb = (hi[a] - O[a]) * line.invDir[a];
            s0 = std::max(s0, std::min(ta, tb));
            s1 = std::min(s1, std::max(ta, tb));
        }
        if (s0 < s1)
            crossings.push_back({s0, s1, brick});
    }
    std::sort(crossings.begin(), crossings.end(), [](const BrickCrossing& x, const BrickCrossing& y) {
        return x.sEnter < y.sEnter || (x.sEnter == y.sEnter && x.brick < y.brick);
    });
    for (const BrickCrossing& crossing : crossings) {
        // A brick the line crosses no value's cell of leaves the sum and
        // what is recorded as they were (the samples it would record repeat
        // the last value; the next brick's skipTo records the same ones
        // either side of a change).
        const glm::ivec3& b = brickCoord_[crossing.brick];
        float sa, sb;
        if (!valueSpan(crossing.brick, b, line, crossing.sEnter, crossing.sExit, sa, sb))
            continue;
        skipTo(sa);
        recordUpTo(sa);
        // Pieces end at sample positions, where the running sum is recorded.
        forEachPiece(
            crossing.brick, b, line, sa, sb,
            [&](float t) {
                // (floorToInt: std::floor is a long sequence on x86-64's
                // baseline; t lies within the line's samples, whose count is
                // far below 2^31, where both give the same float.)
                const float k = static_cast<float>(floorToInt((t - sStart) / sStep)) + 1.0f;
                const float split = sStart + k * sStep;
                return split > t ? split : split + sStep; // rounding at a sample
            },
            [&](float s0, float s1, const Lanes& f0, const Lanes& fm, const Lanes& f1) {
                // The samples up to the piece hold the sum before it:
                // those between the brick's entry and its first cell
                // with values are recorded here, not after it.
                recordUpTo(s0);
                addSimpson(sum, f0, fm, f1, (s1 - s0) / 6.0f);
                recordUpTo(s1);
            });
        if (sum.opaque(opaqueSum))
            return; // later samples would only grow
    }
    if (next < count)
        recordNext(); // the first sample after the last brick: the final value
}

Bounds3f BrickVolume::valueBounds(std::size_t brick) const {
    Bounds3f bounds;
    const glm::ivec3 base = kBrick * brickCoord_[brick];
    const float h = static_cast<float>(h_);
    for (const CellBox& box : cellBoxes_[brick].box) {
        if (box.lo[0] > box.hi[0])
            continue; // an octant without such cells
        bounds.extend(Vec3f(base + glm::ivec3(box.lo[0], box.lo[1], box.lo[2])) * h);
        bounds.extend(Vec3f(base + glm::ivec3(box.hi[0], box.hi[1], box.hi[2]) + 1) * h);
    }
    return bounds;
}

OpticalDepths BrickVolume::sample(const Vec3f& position) const {
    const Vec3f q = position * invH_;
    const glm::ivec3 c(glm::floor(q));
    const glm::ivec3 b = c >> 3; // floor division by the brick size (C++20: arithmetic shift)
    const std::int64_t brick = find(b);
    if (brick < 0)
        return {};
    const glm::ivec3 l = c - kBrick * b;
    return trilinear(cornersOf(static_cast<std::size_t>(brick), l), q - Vec3f(c)).depths();
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
