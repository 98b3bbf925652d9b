// hairvox voxelize: splatting strands into the fiber grid (conventions in fiber_grid.h).
//
// The work is organised so that every voxel's value is a sum in an order
// fixed by the groom alone, whatever the number of threads:
//  1. Scan (parallel over fixed chunks of strands): validate the points, the
//     bounds and the total length; estimate the memory and refuse a voxel
//     size over the budget before anything big is allocated.
//  2. Bucket (parallel over the same chunks): cut each strand into runs of
//     consecutive segments that reach one brick (a 32³-voxel block); a
//     serial counting sort in chunk order gives every brick its runs.
//  3. Splat (parallel over bricks, largest first): a brick owns its 32³
//     voxels and computes them alone, from every cell that touches them (its
//     own cells and a one-cell apron below, which a neighbour also visits
//     for its own voxels), in a dense double accumulator of the thread, then
//     emits its blocks of 8³ voxels with their active voxels' values packed.
//     No voxel is written by two bricks: no merge step.
//  4. The blocks are sorted by origin and their values gathered into the
//     grid's arrays (parallel over blocks; a copy of 16 bytes a voxel).
#include <hairvox/core/error.h>
#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/parallel.h>
#include <hairvox/core/progress.h>
#include <hairvox/core/version.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>
#include <unordered_map>

namespace hairvox {

namespace {

using Vec3i = glm::ivec3;
/// Two doubles in one SIMD register (GCC/Clang vector extension; plain
/// scalar code on targets without SIMD). The accumulator's channels are
/// updated in pairs: the hot loop is otherwise compiled to scalar code.
using Double2 = double __attribute__((vector_size(2 * sizeof(double))));

constexpr int kLeafDim = FiberBlock::kDim; // 8: OpenVDB's leaf
/// Brick side in voxels, a multiple of the leaf size. Measured on the 1.4M
/// segment wavy groom: 16 gives 2.4M (segment, brick) clips for 1.4M
/// segments and a slower bucketing, 32 gives 1.8M at the same splat speed,
/// with one accumulator of 34³ voxels × 4 doubles = 1.2 MiB per thread.
constexpr int kBrickLog2 = 5;
constexpr int kBrickSize = 1 << kBrickLog2;
constexpr int kLeavesPerBrickSide = kBrickSize / kLeafDim;
/// Accumulator side: voxels [brick origin − 1, brick origin + 32] hold the
/// corners of the cells [origin − 1, origin + 31] that touch the brick's voxels.
constexpr int kAccDim = kBrickSize + 2;
/// Strands are grouped into chunks of at least this many points for the
/// scan and the bucketing (fixed by the groom, never by the thread count).
constexpr std::size_t kChunkPoints = 16384;
/// Coordinates must stay well inside OpenVDB's int32 index space.
constexpr double kMaxIndex = 1 << 30;

double formatGiB(double bytes) {
    return bytes / double(1ull << 30);
}

// ---------------------------------------------------------------------------
// Running work in fixed chunks, in parallel or on the calling thread.

template <typename F>
void forEachIndex(std::size_t n, bool threaded, const F& f) {
    if (!threaded) {
        for (std::size_t i = 0; i < n; ++i)
            f(i);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i)
                              f(i);
                      });
}

/// f(0), f(1), ... f(n − 1), started in this order (on the calling thread,
/// or by all of TBB's threads taking the next index as they free up).
template <typename F>
void forEachIndexInOrder(std::size_t n, bool threaded, const F& f) {
    if (!threaded) {
        for (std::size_t i = 0; i < n; ++i)
            f(i);
        return;
    }
    std::atomic<std::size_t> next{0};
    tbb::parallel_for(0, tbb::this_task_arena::max_concurrency(), [&](int) {
        // Stop taking work once another thread threw (e.g. Interrupted).
        for (std::size_t i = next++; i < n && !tbb::is_current_task_group_canceling(); i = next++)
            f(i);
    });
}

struct StrandRange {
    std::size_t begin = 0, end = 0; ///< strands [begin, end)
};

std::vector<StrandRange> strandChunks(const Groom& groom) {
    std::vector<StrandRange> chunks;
    StrandRange current;
    std::size_t points = 0;
    for (std::size_t s = 0; s < groom.strandCount(); ++s) {
        points += groom.strand(s).size();
        if (points >= kChunkPoints) {
            current.end = s + 1;
            chunks.push_back(current);
            current.begin = s + 1;
            points = 0;
        }
    }
    if (current.begin < groom.strandCount()) {
        current.end = groom.strandCount();
        chunks.push_back(current);
    }
    return chunks;
}

/// A segment a + t·d, t ∈ [0, 1], in index space (core/grid_traversal.h).
using IndexSegment = GridLine<double>;

Vec3i floorToInt(const Vec3d& v) {
    return {hairvox::floorToInt(v.x), hairvox::floorToInt(v.y), hairvox::floorToInt(v.z)};
}

// ---------------------------------------------------------------------------
// Bricks and the bucketing of segments.

struct BrickKey {
    std::int32_t x = 0, y = 0, z = 0;
    bool operator==(const BrickKey&) const = default;
};

struct BrickKeyHash {
    std::size_t operator()(const BrickKey& k) const {
        std::uint64_t h = std::uint64_t(std::uint32_t(k.x)) * 0x9e3779b97f4a7c15ull;
        h ^= std::uint64_t(std::uint32_t(k.y)) * 0xc2b2ae3d27d4eb4full;
        h ^= std::uint64_t(std::uint32_t(k.z)) * 0x165667b19e3779f9ull;
        return h ^ (h >> 29);
    }
};

/// The bricks whose voxels the segment from a to b (index space) can reach,
/// appended to `out` without repeats. Brick B owns voxels [S·B, S·B + S − 1]
/// and needs the cells [S·B − 1, S·B + S − 1]: the bricks the segment passes
/// through plus, where it passes through a brick's last cell layer on some
/// axes, the neighbours above on those axes. A superset is harmless (the
/// brick clips the segment away).
void bricksOfSegment(const Vec3d& a, const Vec3d& b, std::vector<BrickKey>& out) {
    const auto add = [&](const BrickKey& key) {
        if (std::find(out.begin(), out.end(), key) == out.end())
            out.push_back(key);
    };
    // Fast path: the box of the cells the segment touches, widened to the
    // bricks that need them, holds at most two bricks.
    const Vec3i cellLo = floorToInt(glm::min(a, b)), cellHi = floorToInt(glm::max(a, b));
    const Vec3i brickLo = cellLo >> kBrickLog2, brickHi = (cellHi + 1) >> kBrickLog2;
    const Vec3i span = brickHi - brickLo + 1;
    if (span.x * span.y * span.z <= 2) {
        for (int x = brickLo.x; x <= brickHi.x; ++x)
            for (int y = brickLo.y; y <= brickHi.y; ++y)
                for (int z = brickLo.z; z <= brickHi.z; ++z)
                    add({x, y, z});
        return;
    }
    // Otherwise walk the bricks along the segment.
    constexpr double invBrick = 1.0 / kBrickSize;
    constexpr int big = std::numeric_limits<int>::max() / 2;
    const IndexSegment inBricks(a * invBrick, (b - a) * invBrick);
    traverseCells(
        inBricks, 0.0, 1.0, Vec3i(-big), Vec3i(big), [&](const Vec3i& brick, double tA, double tB) {
            // Does the piece reach the brick's last cell layer on each axis? (Voxel
            // units; the margin keeps the test conservative against rounding.)
            Vec3i up(0);
            for (int i = 0; i < 3; ++i) {
                const double hi = std::max(a[i] + tA * (b[i] - a[i]), a[i] + tB * (b[i] - a[i]));
                up[i] = hi >= double(brick[i] * kBrickSize + kBrickSize - 1) - 1e-6 ? 1 : 0;
            }
            for (int ex = 0; ex <= up.x; ++ex)
                for (int ey = 0; ey <= up.y; ++ey)
                    for (int ez = 0; ez <= up.z; ++ez)
                        add({brick.x + ex, brick.y + ey, brick.z + ez});
            return true;
        });
}

/// Consecutive segments of one strand that all reach one brick: points
/// [begin, end) of the groom, end − begin ≥ 2. Runs rather than single
/// segments keep the bucket lists short and the reads of the groom's points
/// sequential.
struct Run {
    std::uint32_t begin = 0, end = 0;
};

/// The runs of one chunk's strands, in a fixed order; bricks are numbered
/// locally, in order of first appearance.
struct ChunkRuns {
    struct Entry {
        std::uint32_t brick; ///< index into bricks
        Run run;
    };
    std::vector<BrickKey> bricks;
    std::vector<Entry> runs;
};

void runsOfChunk(const Groom& groom, const StrandRange& chunk, double invH, ChunkRuns& out) {
    std::unordered_map<BrickKey, std::uint32_t, BrickKeyHash> localIds;
    const auto localId = [&](const BrickKey& key) {
        const auto [it, inserted] = localIds.try_emplace(key, std::uint32_t(out.bricks.size()));
        if (inserted)
            out.bricks.push_back(key);
        return it->second;
    };
    struct Open {
        BrickKey brick;
        std::uint32_t begin;
    };
    std::vector<Open> open, stillOpen;
    std::vector<BrickKey> keys;
    for (std::size_t s = chunk.begin; s < chunk.end; ++s) {
        if (groom.strand(s).size() < 2)
            continue; // no segment (only an unsanitized groom has such strands)
        const std::uint32_t first = groom.strandStart[s], last = groom.strandStart[s + 1] - 1;
        for (std::uint32_t p = first; p < last; ++p) {
            const Vec3f& p0 = groom.points[p];
            const Vec3f& p1 = groom.points[p + 1];
            if (p0 == p1)
                continue; // no length: it neither starts nor ends a run
            keys.clear();
            bricksOfSegment(Vec3d(p0) * invH, Vec3d(p1) * invH, keys);
            stillOpen.clear();
            for (const Open& o : open) {
                if (std::find(keys.begin(), keys.end(), o.brick) != keys.end())
                    stillOpen.push_back(o);
                else
                    out.runs.push_back({localId(o.brick), {o.begin, p + 1}});
            }
            for (const BrickKey& k : keys)
                if (std::none_of(open.begin(), open.end(),
                                 [&](const Open& o) { return o.brick == k; }))
                    stillOpen.push_back({k, p});
            std::swap(open, stillOpen);
        }
        for (const Open& o : open)
            out.runs.push_back({localId(o.brick), {o.begin, last + 1}});
        open.clear();
    }
}

/// Runs grouped by brick, each brick's list in chunk order.
struct BrickBuckets {
    std::vector<BrickKey> bricks;
    std::vector<std::size_t> start; ///< runs of brick b: [start[b], start[b + 1])
    std::vector<Run> runs;
    /// Brick ids by decreasing number of segments: the order in which they are
    /// started, so that the longest do not end up last on one thread (load
    /// balance only; every brick's result is independent of it).
    std::vector<std::uint32_t> largestFirst;
};

BrickBuckets bucketSegments(const Groom& groom, const std::vector<StrandRange>& chunks, double invH,
                            bool threaded) {
    std::vector<ChunkRuns> chunkRuns(chunks.size());
    forEachIndex(chunks.size(), threaded, [&](std::size_t c) {
        throwIfInterrupted();
        runsOfChunk(groom, chunks[c], invH, chunkRuns[c]);
    });

    // Global brick ids in order of first appearance, chunk by chunk.
    BrickBuckets buckets;
    std::unordered_map<BrickKey, std::uint32_t, BrickKeyHash> ids;
    std::vector<std::vector<std::uint32_t>> globalId(chunks.size());
    for (std::size_t c = 0; c < chunks.size(); ++c)
        for (const BrickKey& key : chunkRuns[c].bricks) {
            const auto [it, inserted] = ids.try_emplace(key, std::uint32_t(buckets.bricks.size()));
            if (inserted)
                buckets.bricks.push_back(key);
            globalId[c].push_back(it->second);
        }
    // Counting sort of the runs by brick, in chunk order.
    std::vector<std::size_t> counts(buckets.bricks.size(), 0), segments(buckets.bricks.size(), 0);
    for (std::size_t c = 0; c < chunks.size(); ++c)
        for (const ChunkRuns::Entry& e : chunkRuns[c].runs) {
            const std::uint32_t b = globalId[c][e.brick];
            ++counts[b];
            segments[b] += e.run.end - e.run.begin - 1;
        }
    buckets.start.assign(buckets.bricks.size() + 1, 0);
    for (std::size_t b = 0; b < counts.size(); ++b)
        buckets.start[b + 1] = buckets.start[b] + counts[b];
    std::vector<std::size_t> cursor(buckets.start.begin(), buckets.start.end() - 1);
    buckets.runs.resize(buckets.start.back());
    for (std::size_t c = 0; c < chunks.size(); ++c)
        for (const ChunkRuns::Entry& e : chunkRuns[c].runs)
            buckets.runs[cursor[globalId[c][e.brick]]++] = e.run;

    buckets.largestFirst.resize(buckets.bricks.size());
    std::iota(buckets.largestFirst.begin(), buckets.largestFirst.end(), 0u);
    std::stable_sort(buckets.largestFirst.begin(), buckets.largestFirst.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return segments[a] > segments[b]; });
    return buckets;
}

// ---------------------------------------------------------------------------
// The per-brick accumulator.

/// Channels per voxel: ∫w ds, ∫w u ds (3), with the tensor ∫w u uᵀ ds (6),
/// and for a typed groom ∫w [type = t] ds for each fiber type t.
template <bool Tensor, bool Typed>
struct Channels {
    static constexpr std::size_t kTensorDiag = 4, kTensorOffDiag = 7;
    static constexpr std::size_t kType = Tensor ? 10 : 4;
    static constexpr std::size_t C = kType + (Typed ? kMaxFiberTypes : 0);

    /// The per-segment values splatted with the weights: 1, u, u uᵀ, and the
    /// one-hot fiber type.
    static std::array<double, C> values(const Vec3d& u, std::uint8_t type) {
        std::array<double, C> v{};
        v[0] = 1;
        v[1] = u.x;
        v[2] = u.y;
        v[3] = u.z;
        if constexpr (Tensor) {
            v[kTensorDiag] = u.x * u.x;
            v[kTensorDiag + 1] = u.y * u.y;
            v[kTensorDiag + 2] = u.z * u.z;
            v[kTensorOffDiag] = u.x * u.y;
            v[kTensorOffDiag + 1] = u.x * u.z;
            v[kTensorOffDiag + 2] = u.y * u.z;
        }
        if constexpr (Typed)
            v[kType + type] = 1;
        return v;
    }
};

/// The blocks and values one brick produces, laid out as in FiberGrid (a
/// block's `first` counts from the brick's first value).
struct BrickVoxels {
    std::vector<FiberBlock> blocks;
    std::vector<float> density;
    std::vector<openvdb::Vec3s> orientation, tensorDiag, tensorOffDiag;
    std::array<std::vector<float>, kMaxFiberTypes> typeFraction;
};

/// Dense double sums over one brick and its apron, z fastest (OpenVDB's leaf
/// order). Coordinates are local: local 0 is voxel (brick origin − 1).
template <bool Tensor, bool Typed>
class BrickAccumulator {
public:
    using Ch = Channels<Tensor, Typed>;
    static constexpr std::size_t C = Ch::C;
    static_assert(C % 2 == 0, "channels are updated in pairs");
    static_assert(kLeavesPerBrickSide * kLeavesPerBrickSide * kLeavesPerBrickSide <= 64,
                  "touchedLeaves_ has one bit per leaf");
    static constexpr std::size_t kVoxels = std::size_t(kAccDim) * kAccDim * kAccDim;

    /// `fiberTypes`: how many type fractions to emit (Typed only).
    explicit BrickAccumulator(std::size_t fiberTypes)
        : sums_(kVoxels * C, 0.0)
        , touchedCells_((kVoxels + 63) / 64, 0)
        , touchedVoxels_((kVoxels + 63) / 64, 0)
        , fiberTypes_(fiberTypes) {}

    /// Adds segment s (in local index space) of weighted world length
    /// `length`, unit tangent u and fiber type `type`, clipped to the cells
    /// that touch the brick's voxels: local cells [0, 32], i.e. the box [0, 33]³.
    void addSegment(const IndexSegment& s, double length, const Vec3d& u, std::uint8_t type) {
        double t0 = 0, t1 = 1;
        for (int i = 0; i < 3; ++i) {
            constexpr double lo = 0, hi = kBrickSize + 1;
            if (s.invDir[i] == 0.0) {
                if (s.origin[i] < lo || s.origin[i] > hi)
                    return;
                continue;
            }
            double ta = (lo - s.origin[i]) * s.invDir[i], tb = (hi - s.origin[i]) * s.invDir[i];
            if (ta > tb)
                std::swap(ta, tb);
            t0 = std::max(t0, ta);
            t1 = std::min(t1, tb);
        }
        if (!(t0 < t1))
            return;

        const std::array<double, C> values = Ch::values(u, type);
        std::array<Double2, C / 2> channel;
        for (std::size_t j = 0; j < C / 2; ++j)
            channel[j] = Double2{values[2 * j], values[2 * j + 1]};

        const Vec3i cellMin(0), cellMax(kBrickSize);
        // The fractions inside the current cell are carried from piece to
        // piece: they advance by (tB − tA)·d, and an axis whose cell boundary
        // was crossed restarts exactly at 0 (stepping up) or 1 (down), so
        // they stay in [0, 1] up to rounding without clamping.
        Vec3i previous = floorToInt(s.at(t0));
        Vec3d f = s.at(t0) - Vec3d(previous);
        traverseCells(s, t0, t1, cellMin, cellMax, [&](const Vec3i& cell, double tA, double tB) {
            for (int i = 0; i < 3; ++i)
                if (cell[i] != previous[i])
                    f[i] = cell[i] > previous[i] ? 0.0 : 1.0;
            previous = cell;
            const Vec3d delta = (tB - tA) * s.dir;
            splatPiece(cell, f, delta, length * (tB - tA), channel);
            f += delta;
            return true;
        });
    }

    /// Emits the blocks of the brick's own voxels (local [1, 32]) that hold
    /// fiber, and clears what was touched for the next brick. Its work is
    /// per voxel touched, not per block: at fine voxels a block a strand
    /// passes holds a few dozen of its 512 voxels.
    void extract(const openvdb::Coord& brickOrigin, double invVoxelVolume, BrickVoxels& out) {
        // The voxels the touched cells' corners are (every value was added
        // there), and of them the brick's own, by leaf.
        constexpr std::size_t dz = 1, dy = kAccDim, dx = dy * kAccDim;
        forEachBit(touchedCells_, [&](std::size_t cell) {
            for (const std::size_t corner :
                 {std::size_t(0), dz, dy, dy + dz, dx, dx + dz, dx + dy, dx + dy + dz})
                touchedVoxels_[(cell + corner) >> 6] |= std::uint64_t(1) << ((cell + corner) & 63);
        });
        forEachBit(touchedVoxels_, [&](std::size_t voxel) {
            // Local voxel (x, y, z) − 1 in the brick's own [0, 31]³, or outside it (the apron).
            const auto x = int(voxel / dx) - 1, y = int(voxel / dy % kAccDim) - 1,
                       z = int(voxel % kAccDim) - 1;
            if (std::min({x, y, z}) < 0 || std::max({x, y, z}) >= kBrickSize)
                return;
            const int leaf = leafBit(x / kLeafDim, y / kLeafDim, z / kLeafDim);
            touchedLeaves_ |= std::uint64_t(1) << leaf;
            leafVoxels_[std::size_t(leaf)].setOn(
                FiberBlock::Leaf::coordToOffset(openvdb::Coord(x, y, z)));
        });
        forEachTouchedLeaf([&](const Vec3i& lo) {
            auto& voxels = leafVoxels_[std::size_t(
                leafBit(lo.x / kLeafDim, lo.y / kLeafDim, lo.z / kLeafDim))];
            extractBlock(lo, voxels, brickOrigin + openvdb::Coord(lo.x - 1, lo.y - 1, lo.z - 1),
                         invVoxelVolume, out);
            voxels.setOff();
        });
        forEachBit(touchedVoxels_,
                   [&](std::size_t voxel) { std::fill_n(&sums_[voxel * C], C, 0.0); });
        std::fill(touchedCells_.begin(), touchedCells_.end(), 0);
        std::fill(touchedVoxels_.begin(), touchedVoxels_.end(), 0);
        touchedLeaves_ = 0;
    }

private:
    /// Voxel (x, y, z)'s place among the accumulator's kVoxels, z fastest.
    static std::size_t voxelIndex(int x, int y, int z) {
        return (std::size_t(x) * kAccDim + std::size_t(y)) * kAccDim + std::size_t(z);
    }
    /// Its first channel in sums_.
    static std::size_t index(int x, int y, int z) { return voxelIndex(x, y, z) * C; }

    /// Adds ∫ w_v ds · channel, exactly, to the 8 corners of `cell` for a
    /// piece of length `pieceLength` whose fractions in the cell go from f to
    /// f + δ. With τ ∈ [0, 1] along the piece, f_i(τ) = f_i + δ_i τ, and a
    /// corner's weight is X·Y·Z with X ∈ {1 − f_x, f_x}, ... For each (Y, Z)
    /// pair the quadratic YZ has moments Q0 = ∫YZ dτ, Q1 = ∫τ YZ dτ, and then
    /// ∫ f_x YZ = f_x Q0 + δ_x Q1, ∫ (1 − f_x) YZ = Q0 − ∫ f_x YZ.
    void splatPiece(const Vec3i& cell, const Vec3d& f, const Vec3d& delta, double pieceLength,
                    const std::array<Double2, C / 2>& channel) {
        // Moments of Y1 = f_y, Z1 = f_z and of their product P = Y1·Z1.
        constexpr double third = 1.0 / 3.0;
        const double y0 = f.y + 0.5 * delta.y, y1 = 0.5 * f.y + third * delta.y;
        const double z0 = f.z + 0.5 * delta.z, z1 = 0.5 * f.z + third * delta.z;
        const double p0 = f.y * f.z, p1 = f.y * delta.z + delta.y * f.z, p2 = delta.y * delta.z;
        const double pq0 = p0 + 0.5 * p1 + third * p2, pq1 = 0.5 * p0 + third * p1 + 0.25 * p2;
        // (Q0, Q1) of the (Y, Z) pairs (0,0), (0,1), (1,0), (1,1).
        const double q0[4] = {1 - y0 - z0 + pq0, z0 - pq0, y0 - pq0, pq0};
        const double q1[4] = {0.5 - y1 - z1 + pq1, z1 - pq1, y1 - pq1, pq1};
        const std::size_t cellIndex = voxelIndex(cell.x, cell.y, cell.z);
        touchedCells_[cellIndex >> 6] |= std::uint64_t(1) << (cellIndex & 63);
        double* base = &sums_[cellIndex * C];
        constexpr std::size_t dz = C, dy = std::size_t(kAccDim) * C, dx = dy * kAccDim;
        constexpr std::size_t yzOffset[4] = {0, dz, dy, dy + dz};
        // Weights that are 0 in exact arithmetic can come out as ±1e-16: they
        // are clamped to 0, so every voxel's statistics stay convex
        // combinations (|E[u]| ≤ 1, E[u uᵀ] positive semidefinite) however
        // little length it receives.
#pragma GCC unroll 4
        for (std::size_t k = 0; k < 4; ++k) {
            const double w1 = f.x * q0[k] + delta.x * q1[k];
            const double w0 = q0[k] - w1;
            addChannels(base + yzOffset[k], std::max(w0, 0.0) * pieceLength, channel);
            addChannels(base + yzOffset[k] + dx, std::max(w1, 0.0) * pieceLength, channel);
        }
    }

    /// v[c] += w · channel[c] for the C channels of one voxel.
    static void addChannels(double* v, double w, const std::array<Double2, C / 2>& channel) {
        const Double2 w2{w, w};
#pragma GCC unroll 5
        for (std::size_t j = 0; j < C / 2; ++j) {
            Double2 sum;
            std::memcpy(&sum, v + 2 * j, sizeof sum);
            sum += w2 * channel[j];
            std::memcpy(v + 2 * j, &sum, sizeof sum);
        }
    }

    /// The block at `origin` (local voxel `lo`) of the `touched` voxels
    /// whose λ is at least FLT_MIN, their values appended to `out`.
    void extractBlock(const Vec3i& lo, const openvdb::util::NodeMask<3>& touched,
                      const openvdb::Coord& origin, double invVoxelVolume, BrickVoxels& out) {
        FiberBlock block{origin, static_cast<std::uint32_t>(out.density.size()), {}};
        for (auto it = touched.beginOn(); it; ++it) {
            const openvdb::Index offset = it.pos();
            const openvdb::Coord l = FiberBlock::Leaf::offsetToLocalCoord(offset);
            const double* v = &sums_[index(lo.x + l.x(), lo.y + l.y(), lo.z + l.z())];
            const auto lambda = static_cast<float>(v[0] * invVoxelVolume);
            // Below FLT_MIN λ is physically nothing, and the ratios
            // below would lose their precision in denormals.
            if (!(lambda >= FLT_MIN))
                continue;
            block.active.setOn(offset);
            const double inv = 1.0 / v[0];
            const auto mean = [&](std::size_t ch) {
                return openvdb::Vec3s(static_cast<float>(v[ch] * inv),
                                      static_cast<float>(v[ch + 1] * inv),
                                      static_cast<float>(v[ch + 2] * inv));
            };
            out.density.push_back(lambda);
            out.orientation.push_back(mean(1));
            if constexpr (Tensor) {
                out.tensorDiag.push_back(mean(Ch::kTensorDiag));
                out.tensorOffDiag.push_back(mean(Ch::kTensorOffDiag));
            }
            if constexpr (Typed)
                for (std::size_t t = 0; t < fiberTypes_; ++t)
                    out.typeFraction[t].push_back(static_cast<float>(v[Ch::kType + t] * inv));
        }
        if (!block.active.isOff())
            out.blocks.push_back(block);
    }

    static int leafBit(int x, int y, int z) {
        return (x * kLeavesPerBrickSide + y) * kLeavesPerBrickSide + z;
    }

    /// f(i) for every bit i set in `bits`, in increasing order.
    template <typename F>
    static void forEachBit(const std::vector<std::uint64_t>& bits, const F& f) {
        for (std::size_t w = 0; w < bits.size(); ++w)
            for (std::uint64_t word = bits[w]; word != 0; word &= word - 1)
                f(w * 64 + std::size_t(__builtin_ctzll(word)));
    }

    /// f(first local voxel of the leaf) for every marked leaf.
    template <typename F>
    void forEachTouchedLeaf(const F& f) const {
        for (int x = 0; x < kLeavesPerBrickSide; ++x)
            for (int y = 0; y < kLeavesPerBrickSide; ++y)
                for (int z = 0; z < kLeavesPerBrickSide; ++z)
                    if (touchedLeaves_ >> leafBit(x, y, z) & 1)
                        f(Vec3i(x, y, z) * kLeafDim + 1);
    }

    std::vector<double> sums_;
    /// Cells that received a piece since the last extract, a bit each by the
    /// index of their lowest corner; the voxels they reach, found by extract.
    std::vector<std::uint64_t> touchedCells_, touchedVoxels_;
    /// The brick's own touched voxels by leaf (leafBit()), found by extract.
    std::array<openvdb::util::NodeMask<3>, 64> leafVoxels_{};
    std::size_t fiberTypes_;
    std::uint64_t touchedLeaves_ = 0; ///< leaves with touched own voxels (extract), by leafBit()
};

template <bool Tensor, bool Typed>
std::vector<BrickVoxels> splatBricks(const Groom& groom, const BrickBuckets& buckets, double h,
                                     const FiberScale& scale, std::size_t fiberTypes, bool threaded,
                                     ProgressReporter& progress) {
    const double invH = 1.0 / h, invVoxelVolume = 1.0 / (h * h * h);
    const bool perPointDiameter = !groom.thickness.empty();
    const double invWidth = 1.0 / double(scale.ribbonWidth());
    std::vector<BrickVoxels> voxels(buckets.bricks.size());
    tbb::enumerable_thread_specific<std::unique_ptr<BrickAccumulator<Tensor, Typed>>> accumulators;
    forEachIndexInOrder(buckets.bricks.size(), threaded, [&](std::size_t k) {
        throwIfInterrupted();
        const std::uint32_t b = buckets.largestFirst[k];
        auto& acc = accumulators.local();
        if (!acc)
            acc = std::make_unique<BrickAccumulator<Tensor, Typed>>(fiberTypes);
        const BrickKey& key = buckets.bricks[b];
        const openvdb::Coord origin(key.x * kBrickSize, key.y * kBrickSize, key.z * kBrickSize);
        const Vec3d base = Vec3d(origin.x(), origin.y(), origin.z()) - 1.0;
        for (std::size_t r = buckets.start[b]; r < buckets.start[b + 1]; ++r) {
            const Run run = buckets.runs[r];
            // Runs jump around the groom: fetch the next one while this one is splatted.
            if (r + 1 < buckets.start[b + 1])
                __builtin_prefetch(&groom.points[buckets.runs[r + 1].begin]);
            Vec3d p1(groom.points[run.begin]);
            for (std::uint32_t p = run.begin + 1; p < run.end; ++p) {
                const Vec3d p0 = p1;
                p1 = Vec3d(groom.points[p]);
                const Vec3d delta = p1 - p0;
                const double length = glm::length(delta);
                // A segment of mean diameter D̄ counts as D̄/D fibers of diameter D
                // (its width is linear between its points: ribbonWidthAt()).
                const double weight =
                    perPointDiameter ? 0.5 * invWidth *
                                           (double(ribbonWidthAt(groom, scale, p - 1)) +
                                            double(ribbonWidthAt(groom, scale, p)))
                                     : 1.0;
                if (length > 0 && weight > 0)
                    acc->addSegment(IndexSegment(p0 * invH - base, delta * invH), length * weight,
                                    delta * (1.0 / length), fiberTypeAt(groom, p - 1));
            }
        }
        acc->extract(origin, invVoxelVolume, voxels[b]);
        progress.update();
    });
    return voxels;
}

// ---------------------------------------------------------------------------
// Validation and the memory estimate.

/// One parallel pass over the groom: what validation, the default voxel size
/// and the memory estimate need.
struct GroomScan {
    Bounds3f bounds;
    double totalLength = 0;
    Vec3d sumAbsDelta{0.0};                         ///< Σ over segments of |Δx|, |Δy|, |Δz|
    std::size_t badStrand = SIZE_MAX, badPoint = 0; ///< first non-finite point
    double maxWidthRatio = 1; ///< largest D_i/D (per-point diameters)
    std::size_t fiberTypes = 1; ///< 1 + the largest fiber type
};

GroomScan scanGroom(const Groom& groom, const std::vector<StrandRange>& chunks,
                    const FiberScale& scale, bool threaded) {
    std::vector<GroomScan> perChunk(chunks.size());
    forEachIndex(chunks.size(), threaded, [&](std::size_t c) {
        GroomScan& scan = perChunk[c];
        for (std::size_t s = chunks[c].begin; s < chunks[c].end && scan.badStrand == SIZE_MAX;
             ++s) {
            const auto pts = groom.strand(s);
            for (std::size_t k = 0; k < pts.size(); ++k) {
                if (!isFinite(pts[k])) {
                    scan.badStrand = s;
                    scan.badPoint = k;
                    break;
                }
                scan.bounds.extend(pts[k]);
                if (!groom.thickness.empty())
                    scan.maxWidthRatio = std::max(
                        scan.maxWidthRatio,
                        double(ribbonWidthAt(groom, scale, groom.strandStart[s] + k)) /
                            double(scale.ribbonWidth()));
                if (k > 0) {
                    const Vec3d delta = Vec3d(pts[k]) - Vec3d(pts[k - 1]);
                    scan.totalLength += glm::length(delta);
                    scan.sumAbsDelta += glm::abs(delta);
                }
            }
        }
    });
    GroomScan total;
    for (const GroomScan& s : perChunk) {
        if (s.badStrand != SIZE_MAX)
            throw InputError(strCat("voxelize: strand ", s.badStrand, ", point ", s.badPoint,
                                    " has a non-finite coordinate ",
                                    groom.strand(s.badStrand)[s.badPoint]));
        total.bounds.extend(s.bounds);
        total.totalLength += s.totalLength;
        total.sumAbsDelta += s.sumAbsDelta;
        total.maxWidthRatio = std::max(total.maxWidthRatio, s.maxWidthRatio);
    }
    total.fiberTypes = fiberTypeCount(groom);
    if (total.fiberTypes > kMaxFiberTypes)
        throw InputError(strCat("voxelize: the groom has fiber type ", total.fiberTypes - 1,
                                "; at most ", kMaxFiberTypes, " types (0 to ",
                                kMaxFiberTypes - 1, ") are supported"));
    return total;
}

double voxelSizeFromBounds(const Bounds3f& bounds, int voxelsAcross) {
    if (voxelsAcross < 1)
        throw InputError(strCat("voxelize: voxels across = ", voxelsAcross, " should be >= 1"));
    const Vec3f extent = bounds.extent();
    const auto longest = static_cast<double>(std::max({extent.x, extent.y, extent.z}));
    return longest > 0 ? longest / voxelsAcross : 1.0;
}

/// A bound on the active voxels: those of `leaves` blocks, or, if fewer, the
/// 8 corners of each strand's first cell and 4 more for each cell boundary a
/// segment crosses (at most Σ|Δ|₁/h plus 3 a segment).
double voxelBound(double leaves, const Groom& groom, const GroomScan& scan, double h) {
    const double l1 = scan.sumAbsDelta.x + scan.sumAbsDelta.y + scan.sumAbsDelta.z;
    return std::min(leaves * kLeafDim * kLeafDim * kLeafDim,
                    8.0 * double(groom.strandCount()) +
                        4.0 * (l1 / h + 3.0 * double(groom.segmentCount())));
}

/// Bytes splatStrands needs for `leaves` blocks: their active voxels' values
/// (voxelBound()) three times — each brick's arrays with their growth's
/// slack, then the grid's — and the blocks, plus the runs of the bucketing
/// (about one per strand and brick crossing, doubled for the bricks above
/// that need a brick's last layer) and the accumulators; with `vdbFile`,
/// also the leaves of the grid's .vdb (toVdbGrids).
double memoryForLeaves(double leaves, const Groom& groom, const GroomScan& scan, double h,
                       bool tensor, bool threaded, bool vdbFile) {
    const bool typed = scan.fiberTypes > 1;
    const double voxelBytes = double(sizeof(float)) * double(1 + (typed ? scan.fiberTypes : 0)) +
                              double(sizeof(openvdb::Vec3s)) * (tensor ? 3 : 1);
    const double l1 = scan.sumAbsDelta.x + scan.sumAbsDelta.y + scan.sumAbsDelta.z;
    const double runs = 2.0 * (double(groom.strandCount()) + l1 / (h * kBrickSize));
    const double channels = double(tensor ? Channels<true, false>::C : Channels<false, false>::C) +
                            (typed ? double(kMaxFiberTypes) : 0.0);
    const double accumulatorBytes = double(kAccDim) * kAccDim * kAccDim * channels * 8;
    const double threads = threaded ? std::max(1, activeThreadCount()) : 1;
    const double vdbBytes =
        vdbFile ? double(vdbBlockBytes(tensor, typed ? scan.fiberTypes : 0)) * leaves : 0.0;
    return 3.0 * (voxelBound(leaves, groom, scan, h) * voxelBytes +
                  leaves * double(sizeof(FiberBlock))) +
           runs * double(sizeof(ChunkRuns::Entry) + sizeof(Run)) + threads * accumulatorBytes +
           vdbBytes;
}

/// Trilinear corners spill into the next leaf on each axis for 1 cell in 8.
constexpr double kLeafSpill = (9.0 / 8.0) * (9.0 / 8.0) * (9.0 / 8.0);

/// A quick bound on the leaves the grids will hold: the leaves of the
/// bounding box, or, if fewer, one per strand plus one per leaf boundary
/// crossed (Σ|Δ|₁ / 8h) with spill. Both ignore that hair is a shell and
/// that strands share leaves, so it can be several times too high.
double leafBound(const Groom& groom, const GroomScan& scan, double h) {
    double boxLeaves = 1;
    for (int i = 0; i < 3; ++i) {
        const double leafSize = h * kLeafDim;
        boxLeaves *= std::floor(double(scan.bounds.max[i]) / leafSize) -
                     std::floor(double(scan.bounds.min[i]) / leafSize) + 2;
    }
    const double l1 = scan.sumAbsDelta.x + scan.sumAbsDelta.y + scan.sumAbsDelta.z;
    return std::min(boxLeaves, (double(groom.strandCount()) + l1 / (h * kLeafDim)) * kLeafSpill);
}

/// A closer estimate of the leaves, for when leafBound() is over the budget:
/// the distinct leaves of points sampled along every segment at most one leaf
/// apart per axis, with spill. Costs one sort of the samples.
double sampledLeafCount(const Groom& groom, const std::vector<StrandRange>& chunks, double h,
                        bool threaded) {
    const double invLeaf = 1.0 / (h * kLeafDim);
    const BrickKeyHash hash; // of leaf coordinates here; a collision only lowers the count
    std::vector<std::vector<std::uint64_t>> perChunk(chunks.size());
    forEachIndex(chunks.size(), threaded, [&](std::size_t c) {
        throwIfInterrupted();
        std::vector<std::uint64_t>& keys = perChunk[c];
        for (std::size_t s = chunks[c].begin; s < chunks[c].end; ++s)
            for (std::uint32_t p = groom.strandStart[s]; p + 1 < groom.strandStart[s + 1]; ++p) {
                const Vec3d a = Vec3d(groom.points[p]) * invLeaf;
                const Vec3d d = Vec3d(groom.points[p + 1]) * invLeaf - a;
                const double longest = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
                const int steps = std::max(1, static_cast<int>(std::ceil(longest)));
                for (int k = 0; k <= steps; ++k) {
                    const Vec3i leaf = floorToInt(a + (double(k) / steps) * d);
                    keys.push_back(hash({leaf.x, leaf.y, leaf.z}));
                }
            }
        std::sort(keys.begin(), keys.end());
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    });
    std::vector<std::uint64_t> all;
    for (auto& keys : perChunk) {
        all.insert(all.end(), keys.begin(), keys.end());
        std::vector<std::uint64_t>().swap(keys);
    }
    std::sort(all.begin(), all.end());
    return double(std::unique(all.begin(), all.end()) - all.begin()) * kLeafSpill;
}

void validateOptions(const SplatOptions& o) {
    if (!(std::isfinite(o.voxelSize) && o.voxelSize >= 0))
        throw InputError(strCat("voxelize: voxel size = ", o.voxelSize,
                                " should be > 0 (or 0 for the groom's default)"));
    o.fiberScale.validate();
}

/// Refuses, before anything is allocated, a voxel size that the groom's
/// coordinates, the float density or the memory budget cannot take.
void checkVoxelSizeForGroom(const Groom& groom, const std::vector<StrandRange>& chunks,
                            const GroomScan& scan, double h, double defaultH,
                            const SplatOptions& options) {
    const Vec3f lo = glm::abs(scan.bounds.min), hi = glm::abs(scan.bounds.max);
    const auto reach = static_cast<double>(std::max({lo.x, lo.y, lo.z, hi.x, hi.y, hi.z}));
    if (reach / h >= kMaxIndex)
        throw InputError(strCat("voxelize: voxel size ", h, " puts coordinates up to ", reach,
                                " at voxel index ", reach / h,
                                ", beyond OpenVDB's 32-bit index space (limit ", kMaxIndex,
                                "); use a larger voxel size"));
    // λ ≤ total length · max D_i/D / h³ anywhere; it must fit a float.
    if (!(scan.totalLength * scan.maxWidthRatio / (h * h * h) < double(FLT_MAX)))
        throw InputError(strCat("voxelize: voxel size ", h,
                                " is too small: the length density would overflow a float"));

    const auto budget = double(options.memoryBudgetBytes);
    const auto bytesFor = [&](double leaves) {
        return memoryForLeaves(leaves, groom, scan, h, options.storeOrientationTensor,
                               options.threaded, options.forVdbFile);
    };
    double leaves = leafBound(groom, scan, h);
    // Within 16× of the budget the bound may just be loose: count instead.
    if (bytesFor(leaves) > budget && bytesFor(leaves) <= 16 * budget)
        leaves = std::min(leaves, sampledLeafCount(groom, chunks, h, options.threaded));
    const double bytes = bytesFor(leaves);
    if (bytes > budget) {
        std::ostringstream os;
        os << std::setprecision(3) << "voxelize: voxel size " << h << " would need about "
           << formatGiB(bytes) << " GiB (estimate: " << leaves << " blocks of 8³ voxels, "
           << voxelBound(leaves, groom, scan, h) << " active voxels at most"
           << (options.forVdbFile ? ", and the .vdb's OpenVDB leaves" : "")
           << "), over the memory budget of " << formatGiB(budget)
           << " GiB; use a larger voxel size (this groom's default is " << defaultH << ")";
        throw InputError(os.str());
    }
}

/// Gathers the bricks' blocks into the grid, in lexicographic order of their
/// origins (a brick's blocks are in that order already, and bricks own
/// disjoint voxels, so no origin repeats), and frees the bricks' arrays.
void assembleBricks(std::vector<BrickVoxels>& bricks, std::size_t fiberTypes, bool threaded,
                    FiberGrid& grid) {
    struct BlockRef {
        openvdb::Coord origin;
        std::uint32_t brick, block;
    };
    std::vector<BlockRef> refs;
    std::uint64_t voxels = 0;
    for (std::size_t b = 0; b < bricks.size(); ++b) {
        for (std::size_t k = 0; k < bricks[b].blocks.size(); ++k)
            refs.push_back({bricks[b].blocks[k].origin, std::uint32_t(b), std::uint32_t(k)});
        voxels += bricks[b].density.size();
    }
    if (voxels > std::numeric_limits<std::uint32_t>::max())
        throw InputError(strCat("voxelize: ", voxels,
                                " active voxels; the fiber grid holds up to 2^32 - 1; use a "
                                "larger voxel size"));
    std::sort(refs.begin(), refs.end(),
              [](const BlockRef& a, const BlockRef& b) { return a.origin < b.origin; });
    grid.blocks.resize(refs.size());
    std::uint32_t first = 0;
    for (std::size_t k = 0; k < refs.size(); ++k) {
        grid.blocks[k] = bricks[refs[k].brick].blocks[refs[k].block];
        grid.blocks[k].first = first;
        first += grid.blocks[k].active.countOn();
    }
    grid.density.resize(voxels);
    grid.orientation.resize(voxels);
    if (grid.tensorStored) {
        grid.tensorDiag.resize(voxels);
        grid.tensorOffDiag.resize(voxels);
    }
    grid.typeFraction.assign(fiberTypes > 1 ? fiberTypes : 0, std::vector<float>(voxels));
    forEachIndex(refs.size(), threaded, [&](std::size_t k) {
        const BrickVoxels& brick = bricks[refs[k].brick];
        const std::size_t from = brick.blocks[refs[k].block].first, to = grid.blocks[k].first,
                          n = grid.blocks[k].active.countOn();
        const auto copy = [&](const auto& source, auto& target) {
            std::copy_n(source.begin() + std::ptrdiff_t(from), n,
                        target.begin() + std::ptrdiff_t(to));
        };
        copy(brick.density, grid.density);
        copy(brick.orientation, grid.orientation);
        if (grid.tensorStored) {
            copy(brick.tensorDiag, grid.tensorDiag);
            copy(brick.tensorOffDiag, grid.tensorOffDiag);
        }
        for (std::size_t t = 0; t < grid.typeFraction.size(); ++t)
            copy(brick.typeFraction[t], grid.typeFraction[t]);
    });
    std::vector<BrickVoxels>().swap(bricks);
}

} // namespace

double defaultVoxelSize(const Groom& groom, int voxelsAcross) {
    return voxelSizeFromBounds(groom.bounds(), voxelsAcross);
}

FiberGrid splatStrands(const Groom& groom, const SplatOptions& options) {
    validateOptions(options);
    const std::vector<StrandRange> chunks = strandChunks(groom);
    // The content hash is serial: it runs beside the parallel scan.
    std::uint64_t hash = 0;
    tbb::task_group hashing;
    if (options.threaded)
        hashing.run([&] { hash = contentHash(groom); });
    else
        hash = contentHash(groom);
    const GroomScan scan = scanGroom(groom, chunks, options.fiberScale, options.threaded);
    hashing.wait();
    const double defaultH = voxelSizeFromBounds(scan.bounds, kDefaultVoxelsAcross);
    const double h = options.voxelSize > 0 ? options.voxelSize : defaultH;
    const bool tensor = options.storeOrientationTensor;
    const bool hasLength = scan.totalLength > 0;
    if (hasLength)
        checkVoxelSizeForGroom(groom, chunks, scan, h, defaultH, options);
    // OpenVDB refuses linear transforms whose determinant h³ is below 3e-15.
    const double minVoxelSize = std::cbrt(3 * openvdb::math::Tolerance<double>::value());
    if (h < minVoxelSize)
        throw InputError(strCat("voxelize: voxel size ", h, " is below ", minVoxelSize,
                                ", the smallest voxel OpenVDB's linear transform allows; "
                                "express the groom in smaller units"));

    FiberGrid grid;
    grid.info.voxelSize = h;
    grid.info.fiberScale = options.fiberScale;
    grid.info.sourceFile = options.sourceFile;
    grid.info.sourceHash = hexDigest(hash);
    grid.info.strands = groom.strandCount();
    grid.info.segments = groom.segmentCount();
    grid.info.totalLength = scan.totalLength;
    grid.info.version = version();
    grid.tensorStored = tensor;
    const bool typed = scan.fiberTypes > 1;
    if (typed)
        grid.typeFraction.resize(scan.fiberTypes);
    if (!hasLength) {
        grid.warnings.emplace_back(groom.empty()
                                       ? "the groom is empty; the fiber grid is empty"
                                       : "the groom has no fiber length; the fiber grid is empty");
        return grid;
    }

    const double invH = 1.0 / h;
    const BrickBuckets buckets = bucketSegments(groom, chunks, invH, options.threaded);
    ProgressReporter progress("voxelize", buckets.bricks.size(), options.showProgress);
    const auto splat = [&]<bool Tensor, bool Typed>() {
        return splatBricks<Tensor, Typed>(groom, buckets, h, options.fiberScale, scan.fiberTypes,
                                          options.threaded, progress);
    };
    std::vector<BrickVoxels> bricks =
        tensor ? (typed ? splat.operator()<true, true>() : splat.operator()<true, false>())
               : (typed ? splat.operator()<false, true>() : splat.operator()<false, false>());
    progress.finish();
    assembleBricks(bricks, scan.fiberTypes, options.threaded, grid);
    return grid;
}

std::ostream& operator<<(std::ostream& os, const SplatOptions& o) {
    return os << "SplatOptions(voxelSize=" << o.voxelSize << ", " << o.fiberScale
              << ", storeOrientationTensor=" << o.storeOrientationTensor
              << ", threaded=" << o.threaded << ", memoryBudgetBytes=" << o.memoryBudgetBytes
              << ", forVdbFile=" << o.forVdbFile << ", sourceFile=\"" << o.sourceFile
              << "\", showProgress=" << o.showProgress << ")";
}

} // namespace hairvox
