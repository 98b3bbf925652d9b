// Internal to hairvox transmittance: a sparse volume of optical-depth channels
// (rates per unit length, or accumulated depths), its trilinear reconstruction
// and its exact line integral.
//
// Values live at voxel vertices (the fiber grid's vertex-centred convention):
// voxel (i,j,k) sits at world position (i,j,k)·h and values between voxels are
// trilinear. Storage is a hash map of bricks of 8³ voxels (the fiber grid's
// leaf layout) with a one-voxel apron on the +x, +y, +z sides (9³ slots), so
// the 8 corners of every cell a brick owns are in that brick: one lookup per
// brick, none per corner. A value is 8 floats (7 channels and padding) so
// that the per-cell arithmetic vectorises.
//
// Only the slots that hold a value are stored: each brick has a bitmap of its
// 9³ slots with prefix counts (rank), which gives a present slot's place in
// the brick's own packed run of values (absent slots read zero). Memory
// therefore follows the active voxels, not the bricks' volume: at fine voxel
// sizes a strand crosses a brick alone and fills ~5% of it (Ratboy at 0.5 mm:
// 25 active voxels per 8³ brick), where dense 9³ bricks cost 0.9 KB per active
// voxel and grew as the square of the resolution, and a 16-bit index per slot
// still cost 1.46 KB a brick. A line passes a brick without walking its cells
// where it misses the boxes of the cells that hold a value in each of the
// brick's octants, and walks the others only across the boxes it meets. Which
// bricks a line visits: a march (integrate) walks every brick it passes,
// skipping empty space a super-brick (4³ bricks) at a time; the light cache's
// lattice lines (integrateCumulative) are given the bricks whose values can
// reach them, binned by brick rather than found by walking (at 0.5 mm on
// Ratboy a lattice line passed 3.4 bricks for each whose values it met).
#pragma once

#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/large_array.h>
#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>

#include <glm/vec3.hpp>

#include <array>
#include <bit>
#include <cstdint>
#include <span>
#include <vector>

namespace hairvox::detail {

/// The channels the global term accumulates along a shadow ray: depths when
/// integrated, rates (per unit length) when stored per voxel.
struct OpticalDepths {
    float n = 0;
    Rgb tauP;
    Rgb sumBeta2;

    OpticalDepths& operator+=(const OpticalDepths& o) {
        n += o.n;
        tauP += o.tauP;
        sumBeta2 += o.sumBeta2;
        return *this;
    }
    OpticalDepths operator*(float w) const { return {n * w, tauP * w, sumBeta2 * w}; }
    OpticalDepths operator+(const OpticalDepths& o) const { return OpticalDepths(*this) += o; }
};

/// The storage and arithmetic form of OpticalDepths: 8 lanes, the 8th unused.
struct alignas(32) Lanes {
    float v[8] = {};

    static Lanes from(const OpticalDepths& d) {
        return {
            {d.n, d.tauP.r, d.tauP.g, d.tauP.b, d.sumBeta2.r, d.sumBeta2.g, d.sumBeta2.b, 0.0f}};
    }
    bool opaque(float depth) const {
        return v[0] > depth && v[1] > depth && v[2] > depth && v[3] > depth;
    }
    OpticalDepths depths() const { return {v[0], Rgb(v[1], v[2], v[3]), Rgb(v[4], v[5], v[6])}; }
};

/// std::popcount inline: x86-64's baseline has no POPCNT instruction, and
/// there GCC calls libgcc's __popcountdi2 for std::popcount (2% of a fine-voxel
/// render's CPU samples, from the light cache's cell walk, valueAt()).
inline int popcount64(std::uint64_t x) {
#if defined(__POPCNT__)
    return std::popcount(x);
#else
    x -= (x >> 1) & 0x5555555555555555u;
    x = (x & 0x3333333333333333u) + ((x >> 2) & 0x3333333333333333u);
    x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0fu;
    return static_cast<int>((x * 0x0101010101010101u) >> 56);
#endif
}

/// The corners of a cell that hold a value: at fine voxels a strand crosses a
/// brick alone, and a cell a line walks has few of its 8 (the others read
/// zero and add nothing to an interpolation).
struct CellCorners {
    int count = 0;
    std::array<std::uint8_t, 8> k; ///< corner dx·4 + dy·2 + dz
    std::array<const Lanes*, 8> value;
};

/// The line integrals' code for one SIMD target (brick_march-inl.h, compiled
/// per target by brick_march.cpp).
template <typename Target>
struct BrickMarch;

class BrickVolume {
public:
    static constexpr int kBrick = 8;                           ///< voxels per brick side
    static constexpr int kSide = kBrick + 1;                   ///< with the apron
    static constexpr int kBrickValues = kSide * kSide * kSide; ///< 729

    explicit BrickVolume(double voxelSize);

    double voxelSize() const { return h_; }
    bool empty() const { return brickCount_ == 0; }
    std::size_t brickCount() const { return brickCount_; }
    std::size_t memoryBytes() const;

    /// The bricks a voxel of brick b is stored in: b itself (index 0) and the
    /// bricks below it whose +side apron holds b's low faces (index = bit mask
    /// of the axes shifted: 4 x, 2 y, 1 z). −1 where absent.
    struct BrickSet {
        std::int64_t brick[8];
    };

    /// Building takes five steps, in this order:
    ///  1. reserveBrick() for every brick (serial): registers brick b and, for
    ///     each bit of `lowFaces` (4 x, 2 y, 1 z: b has values on that low
    ///     face), the bricks whose aprons hold them;
    ///  2. allocateSlots(): the slot bitmaps of every brick, all absent;
    ///  3. reserveVoxel() for every voxel that will hold a value (thread-safe
    ///     for distinct voxels);
    ///  4. allocateValues(): packs each brick's reserved slots and allocates
    ///     every value at once, zeroed in parallel (pages first touched by
    ///     the threads that fill them, not faulted in by a growing vector);
    ///  5. set() for the reserved voxels (thread-safe for distinct voxels).
    void reserveBrick(const glm::ivec3& b, int lowFaces);
    void allocateSlots();
    BrickSet brickSet(const glm::ivec3& b) const;
    /// Reserves the slots of the voxel at `local` ∈ [0, 8)³ of the brick
    /// set's brick: in its brick and in the aprons below.
    void reserveVoxel(const BrickSet& bricks, const glm::ivec3& local);
    void allocateValues();
    /// Stores the value of a reserved voxel in its brick and the aprons below.
    void set(const BrickSet& bricks, const glm::ivec3& local, const OpticalDepths& value);

    /// ∫_{tStart}^{tEnd} of the trilinear field along origin + t·dir (dir unit,
    /// world units), exact. Stops early once n and every channel of tauP
    /// exceed `opaqueDepth`. `touched` reports whether any brick was entered.
    OpticalDepths integrate(const Vec3f& origin, const Vec3f& dir, float tStart, float tEnd,
                            float opaqueDepth, bool& touched) const;

    /// One sample of a cumulative integral: ∫_{tStart}^{t_k} at t_k = tStart + k·step.
    struct CumulativeSample {
        std::size_t k;
        Lanes value;
    };
    /// Where a line crosses a brick (index space: s = t / voxel size).
    struct BrickCrossing {
        float sEnter, sExit;
        std::uint32_t brick;
    };
    /// World-space box of the cells of brick `brick` that a value is a corner
    /// of (empty where it has none): a line that misses it adds nothing there.
    Bounds3f valueBounds(std::size_t brick) const;
    /// Cumulative integrals along origin + t·dir at t_k = tStart + k·step,
    /// k = 0 .. count − 1, recorded sparsely: `out` gets, in increasing k, the
    /// samples from the last one before the line enters a brick whose values
    /// it meets to the last one before it leaves it. A sample not recorded holds the value of the
    /// one recorded before it (the integral does not change outside bricks),
    /// and 0 before the first. Stops once n and every channel of tauP exceed
    /// `opaqueDepth` (later samples would only grow).
    ///
    /// The line visits only `candidates`, in any order: they must include
    /// every brick whose valueBounds() it meets (others are passed at the cost
    /// of a slab test). A caller that bins the bricks by the lines their
    /// values reach — the light cache — makes the work follow the hair the
    /// line crosses, not the bricks it passes on the way; `crossings` is the
    /// caller's scratch.
    void integrateCumulative(const Vec3f& origin, const Vec3f& dir, float tStart, float step,
                             std::size_t count, float opaqueDepth,
                             std::span<const std::uint32_t> candidates,
                             std::vector<BrickCrossing>& crossings,
                             std::vector<CumulativeSample>& out) const;

    /// The trilinear value at a world position (zero outside every brick).
    OpticalDepths sample(const Vec3f& position) const;
    /// World-space bounds of every brick.
    Bounds3f bounds() const;

private:
    template <typename Target>
    friend struct BrickMarch;
    /// Slot of the voxel at (x, y, z) ∈ [0, kSide)³ of a brick.
    static int valueIndex(int x, int y, int z) { return (x * kSide + y) * kSide + z; }
    /// Index of the brick at brick coordinate b, or −1.
    std::int64_t find(const glm::ivec3& b) const;
    /// Whether brick b exists, from the occupancy bits (no hashing): what a
    /// line's walk asks of every brick position it crosses.
    bool occupied(const glm::ivec3& b) const;
    /// Whether any brick of super-brick sb (kSuper³ bricks) exists.
    bool superOccupied(const glm::ivec3& sb) const;
    std::int64_t insert(const glm::ivec3& b);
    void grow();
    /// Calls f(brick, slot) for the slots that hold the voxel at `local` of
    /// the brick set's brick: its own and those in the aprons below.
    template <typename F>
    static void forEachCopy(const BrickSet& bricks, const glm::ivec3& local, F&& f);
    /// Where slot `slot` of brick `brick` is in values_, or kNoValue.
    std::size_t valueAt(std::size_t brick, int slot) const {
        const auto w = static_cast<std::size_t>(slot >> 6);
        const std::uint64_t bit = std::uint64_t(1) << (slot & 63);
        const std::uint64_t word = present_[brick].bits[w];
        return (word & bit) ? valueBase_[brick] + present_[brick].rank[w] +
                                  std::size_t(popcount64(word & (bit - 1)))
                            : kNoValue;
    }
    static constexpr std::size_t kNoValue = ~std::size_t(0);

    /// 64-bit words of a brick's slot bitmap.
    static constexpr int kSlotWords = (kBrickValues + 63) / 64;
    /// Which of a brick's kBrickValues slots hold a value, and the values
    /// before each word (prefix popcounts): slot s is value
    /// rank[s / 64] + popcount(bits[s / 64] below s) of the brick's packed run.
    /// 120 bytes a brick, where a 16-bit index per slot took 1.46 KB: at fine
    /// voxels a brick holds few values (Ratboy at 0.5 mm: ~25), and the slot
    /// tables were most of the volume's memory and of its zeroing.
    struct SlotBits {
        std::array<std::uint64_t, kSlotWords> bits{};
        std::array<std::uint16_t, kSlotWords> rank{};
    };

    double h_;
    float invH_;
    std::vector<std::int64_t> slots_; ///< open addressing: brick index per slot, −1 if free
    std::size_t brickCount_ = 0;
    std::vector<glm::ivec3> brickCoord_; ///< per brick
    std::vector<SlotBits> present_;      ///< per brick
    std::vector<std::size_t> valueBase_; ///< per brick, its first value in values_
    /// Per brick, one bit per cell (x·64 + y·8 + z) set where a corner of the
    /// cell holds a value: a line's walk skips the other cells on one test.
    std::vector<std::array<std::uint64_t, 8>> cellMask_;
    /// Per brick and octant of 4³ cells, the box of those cells: local cell
    /// coordinates lo[axis][octant]..hi[axis][octant] (lo > hi where the
    /// octant has none), an axis's 8 octants side by side for the SIMD
    /// targets' slab tests (brick_march-inl.h, valueSpan).
    struct OctantBoxes {
        std::array<std::array<std::uint8_t, 8>, 3> lo, hi;
        /// Every box is its whole octant (a dense brick): any line through
        /// the brick meets one, and the test is skipped.
        bool whole = false;
    };
    std::vector<OctantBoxes> cellBoxes_;
    /// The boxes of the set cells of a cell mask (bit x·64 + y·8 + z) in each
    /// of its octants (octant ((x/4)·2 + y/4)·2 + z/4).
    static OctantBoxes octantBoxes(const std::array<std::uint64_t, 8>& cellMask);
    /// The packed values of every brick, once allocateValues() has run.
    LargeBuffer<Lanes> values_;
    glm::ivec3 brickMin_{0}, brickMax_{-1};
    /// One bit per brick position of [brickMin_, brickMax_] (x fastest), set
    /// where a brick exists; built by allocateSlots().
    std::vector<std::uint64_t> occupancy_;
    /// The same one level up, per super-brick of kSuper³ bricks: a march's
    /// walk crosses empty space a super-brick at a time. At fine voxels the
    /// bricks are sparse (Ratboy at 0.5 mm: 95% of the brick positions a line
    /// crosses are empty), and walking them one by one grew faster than the hair.
    static constexpr int kSuperShift = 2;
    static constexpr int kSuper = 1 << kSuperShift;
    glm::ivec3 superMin_{0}, superMax_{-1};
    std::vector<std::uint64_t> superOccupancy_;
};

} // namespace hairvox::detail
