// hairvox volumetric: the fiber grid as an anisotropic participating medium
// (docs/DESIGN.md §9; Jakob et al. 2010, "A radiative transfer framework for
// rendering materials with anisotropic structure"; Moon, Walter & Marschner
// 2008 trace their light paths through such a volume of hair).
//
// Extinction. A ray of direction ω through fibers of diameter D standing k
// hairs each (strands/fiber_scale.h) meets
//     σ_t(x, ω) = k·D·λ(x)·E_x[cos θ],   cos θ = |ω × u|,
// fibers per unit length: the rate of the global term's n (DESIGN.md §5). E_x
// is over the fibers' tangents u at x, estimated from the voxel's mean tangent
// o = E[u] as the grid global term's coherence blend does
// (transmittance/grid_global_term.h, OrientationModel::CoherenceBlend): with
// the coherence c = |o|,
//     E[cos θ] ≈ c·cos θ(ω, o/c) + (1 − c)·π/4,
// π/4 being the mean of cos θ over fibers of uniformly random direction.
// Reconstruction is piecewise constant: voxel v's values hold in the box of
// one voxel around its vertex, [v − ½, v + ½)·h (the splat's total length
// Σ λ_v h³ is kept; the trilinear field of the global term would cost eight
// lookups per tentative collision for the same integral).
//
// Collisions. sampleCollision() draws the distance to the next fiber met by
// regular tracking: σ_t is constant in each voxel's box, so the flight walks
// the voxels it crosses in order (core/grid_traversal.h; blocks without
// fibers passed whole), summing σ_t·Δt until the optical depth reaches
// τ = −ln(1 − ξ), and meets its fiber inside the voxel where it does — the
// exact distribution, one random number a flight. (Replaced: delta tracking
// at each 8³ block's majorant, a logarithm, a voxel lookup and a random
// number per tentative collision; the walk visited the same voxels again for
// the flight's deposits, which now ride along: sampleCollision's `crossed`.)
//
// Scattering. The collision meets one fiber, drawn in proportion to the
// cross-section it shows the ray: the voxel's mean direction u = o/c with
// probability c·cos θ(ω, o/c)/E[cos θ]; otherwise a fiber of uniformly random
// direction weighted by its cos θ (rejection from the sphere, acceptance π/4).
// Its type is drawn by the voxel's type fractions f_t (fiber_grid.h).
//
// The fiber a flight leaves. A flight that starts on a fiber (a scattering)
// does not meet that fiber again — the path tracer's ribbons skip their own
// (geometry/ray_scene.h) — but the voxels around it hold its splat. Its
// share of voxel v, the splat of the straight line x + s·u,
//     λ_own,v = (1/h²)·∫ Π_i (1 − |x_i/h − v_i + s·u_i|)⁺ ds
// (s in voxels; the adjoint of trilinear interpolation, as the voxelizer
// splats; ownDensity() integrates the piecewise cubic exactly), is taken out
// of σ_t along the flight, σ_t − k·D·λ_own,v·|ω × u| (clamped at 0), and
// out of its deposits. The fiber grid's own-fiber correction of the shadow
// rays (transmittance/grid_global_term.h) is the same splat, integrated
// along a ray in closed form under its Gaussian blur.
#pragma once

#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/math.h>
#include <hairvox/core/rng.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/strands/fiber_scale.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <optional>
#include <ostream>
#include <type_traits>
#include <vector>

namespace hairvox {

struct FiberGrid;

/// A fiber met by a ray in the medium.
struct MediumCollision {
    float t = 0;             ///< distance along the ray
    Vec3f position{0.0f};
    Vec3f tangent{0.0f, 1.0f, 0.0f}; ///< unit u of the fiber met (root → tip)
    std::uint8_t fiberType = 0;
};

/// The fiber a flight leaves (see above): a straight line through
/// `position` along unit `tangent`.
struct OwnFiber {
    Vec3f position{0.0f};
    Vec3f tangent{0.0f, 1.0f, 0.0f};
};

class FiberMedium {
public:
    /// The medium of `grid` (whose fiber scale gives k and D). Keeps a
    /// reference to the grid, which must outlive it.
    explicit FiberMedium(const FiberGrid& grid);

    /// σ_t(x, ω) (1/length): fibers met per unit length by a ray of unit
    /// direction ω at x; 0 outside the hair.
    float extinction(const Vec3f& x, const Vec3f& omega) const;

    /// The next fiber a ray from `origin` along unit `dir` meets before
    /// `tMax`, or nothing (the ray leaves the hair, or reaches tMax first);
    /// never `own`, the fiber the ray leaves (null: none). Draws from `rng`
    /// (the optical depth to the collision, the fiber's orientation and type).
    std::optional<MediumCollision> sampleCollision(const Vec3f& origin, const Vec3f& dir,
                                                   float tMax, Pcg32& rng,
                                                   const OwnFiber* own = nullptr) const;
    /// The same, calling crossed(value index, voxel, λ, t0, t1) for each run
    /// [t0, t1] of an active voxel (index space) the ray crosses before the collision (or tMax), in
    /// order, λ the voxel's fiber density without own's share (clamped at
    /// 0): what the track-length estimates of the flight integrate.
    template <typename Crossed>
    std::optional<MediumCollision> sampleCollision(const Vec3f& origin, const Vec3f& dir,
                                                   float tMax, Pcg32& rng, const OwnFiber* own,
                                                   Crossed&& crossed) const;

    /// λ_own,v (fiber length per volume): the share of voxel v (index space)
    /// that the splat of the straight fiber `own` holds (see above).
    float ownDensity(const OwnFiber& own, const glm::ivec3& v) const;
    /// Whether voxel v can hold a share of `own` (a cheap bound before
    /// ownDensity): the line passes within its splat's reach of v.
    bool nearOwnFiber(const OwnFiber& own, const glm::ivec3& v) const;
    /// How far a ray from own.position along unit `dir` can meet a voxel that
    /// holds a share of `own`: beyond it no voxel is near the fiber.
    float ownFiberReach(const OwnFiber& own, const Vec3f& dir) const;

    /// Calls visit(value index, voxel, tEnter, tExit) for every active voxel
    /// the segment origin + t·dir, t ∈ [0, tEnd], crosses, in order (unit
    /// dir; voxels hold their value over the box around their vertex), while
    /// visit returns true (or void). Blocks without fibers are passed whole.
    template <typename Visit>
    void walkVoxels(const Vec3f& origin, const Vec3f& dir, float tEnd, Visit&& visit) const;

    /// World-space box of every voxel's extent.
    const Bounds3f& bounds() const { return bounds_; }
    float voxelSize() const { return h_; }
    const FiberGrid& grid() const { return *grid_; }
    std::size_t fiberTypeCount() const { return types_; }
    /// Bytes the medium holds besides the grid (its voxel records and block index).
    std::uint64_t memoryBytes() const;

private:
    /// A block of 8³ voxels as the walk reads it (the grid's FiberBlock and
    /// its mask words' running counts, kept here so the lookups inline).
    struct MediumBlock {
        std::array<std::uint64_t, 8> words{};  ///< active voxels by offset x·64 + y·8 + z
        std::array<std::uint16_t, 8> prefix{}; ///< active voxels before each word
        glm::ivec3 origin{0};                  ///< its first voxel (index space)
        std::uint32_t first = 0;               ///< value index of its first active voxel
    };

    /// The block at block coordinates b, or -1.
    std::int32_t blockAt(const glm::ivec3& c) const {
        const glm::ivec3 b = c - blockMin_;
        if (b.x < 0 || b.y < 0 || b.z < 0 || b.x >= blockDims_.x || b.y >= blockDims_.y ||
            b.z >= blockDims_.z)
            return -1;
        return blockIndex_[(std::size_t(b.x) * std::size_t(blockDims_.y) + std::size_t(b.y)) *
                               std::size_t(blockDims_.z) +
                           std::size_t(b.z)];
    }
    /// Index-space coordinates of a block's first voxel.
    glm::ivec3 blockOrigin(std::int32_t block) const { return blocks_[std::size_t(block)].origin; }
    /// The value index of voxel v (index space) in block `block`, or -1.
    std::int64_t voxelIn(std::int32_t block, const glm::ivec3& v) const {
        const MediumBlock& b = blocks_[std::size_t(block)];
        const auto offset = static_cast<unsigned>(((v.x & 7) << 6) | ((v.y & 7) << 3) | (v.z & 7));
        const std::uint64_t word = b.words[offset >> 6];
        const std::uint64_t bit = std::uint64_t(1) << (offset & 63);
        if (!(word & bit))
            return -1;
        return std::int64_t(b.first) + b.prefix[offset >> 6] + std::popcount(word & (bit - 1));
    }
    /// The value index of the voxel whose box holds x (shifted index space
    /// q = x/h + ½), or -1.
    std::int64_t voxelAt(const Vec3f& q) const;
    /// Calls visit(block, tEnter, tExit) for the blocks with fibers that the
    /// segment crosses, in order, while visit returns true.
    template <typename Visit>
    void walkBlocks(const Vec3f& origin, const Vec3f& dir, float tEnd, Visit&& visit) const;
    /// What a flight reads of a voxel, packed from the grid's arrays (its
    /// λ and o live apart there): 16 bytes, one cache line, the grid's own
    /// footprint, prefetched by walkVoxels. (Packing alone gained nothing
    /// measurable, nor did a 32-byte record with (1 − c)·π/4 stored: the two
    /// arrays' misses overlapped; the prefetch is what pays.)
    struct alignas(16) VoxelMedium {
        Vec3f o{0.0f};    ///< E[u], |o| = c ≤ 1 (not normalised)
        float lambda = 0; ///< λ, fiber length per volume
    };

    /// The fiber tangent and type met by a ray of direction ω in voxel `v`.
    void sampleFiber(std::size_t v, const Vec3f& omega, Pcg32& rng, MediumCollision& out) const;
    static constexpr float kQuarterPi = float(Pi / 4.0); ///< E[cos θ] over random tangents
    /// E_v[cos θ] of voxel v toward ω: c·cos θ(ω, o/c) = |ω × o|, so the
    /// blend needs no normalisation.
    static float meanCosTheta(const VoxelMedium& m, const Vec3f& omega) {
        const float c = std::min(1.0f, glm::length(m.o));
        return glm::length(glm::cross(omega, m.o)) + (1.0f - c) * kQuarterPi;
    }

    const FiberGrid* grid_;
    std::vector<VoxelMedium> voxels_; ///< per voxel value
    float h_ = 1, kD_ = 0;
    std::size_t types_ = 1;
    Bounds3f bounds_;
    /// Blocks in a dense array over the box of block coordinates
    /// [blockMin_, blockMin_ + blockDims_): index into blocks_, or -1.
    glm::ivec3 blockMin_{0}, blockDims_{0};
    std::vector<std::int32_t> blockIndex_;
    std::vector<MediumBlock> blocks_; ///< per grid block, in the grid's order
};

std::ostream& operator<<(std::ostream& os, const MediumCollision& c);

// ---------------------------------------------------------------------------

template <typename Visit>
void FiberMedium::walkBlocks(const Vec3f& origin, const Vec3f& dir, float tEnd,
                             Visit&& visit) const {
    if (blockIndex_.empty())
        return;
    // The line in block coordinates: b(t) = (x(t)/h + ½)/8, t in world units.
    constexpr float kBlockDim = 8.0f;
    const GridLine<float> line((origin / h_ + 0.5f) / kBlockDim, dir / (h_ * kBlockDim));
    float t0 = 0, t1 = tEnd;
    for (int i = 0; i < 3; ++i) {
        const auto lo = float(blockMin_[i]), hi = float(blockMin_[i] + blockDims_[i]);
        if (line.invDir[i] == 0.0f) {
            if (line.origin[i] < lo || line.origin[i] > hi)
                return;
            continue;
        }
        float a = (lo - line.origin[i]) * line.invDir[i], b = (hi - line.origin[i]) * line.invDir[i];
        if (a > b)
            std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
    }
    if (!(t0 < t1))
        return;
    traverseCells(line, t0, t1, blockMin_, blockMin_ + blockDims_ - 1,
                  [&](const glm::ivec3& cell, float tEnter, float tExit) {
                      const std::int32_t block = blockAt(cell);
                      return block < 0 || visit(block, tEnter, tExit);
                  });
}

template <typename Visit>
void FiberMedium::walkVoxels(const Vec3f& origin, const Vec3f& dir, float tEnd,
                             Visit&& visit) const {
    const GridLine<float> line(origin / h_ + 0.5f, dir / h_);
    // A block's active voxels on the line are found first and their records
    // prefetched, then visited: the walk waits on a cache miss per voxel
    // (the records of ~10^6 voxels exceed the cache), and so the misses of a
    // block overlap instead of following one another.
    struct Run {
        std::size_t index;
        glm::ivec3 voxel;
        float t0, t1;
    };
    std::array<Run, 24> runs; // a line meets at most 3·7 + 1 voxels of a block
    std::size_t count = 0;
    bool going = true;
    const auto visitRuns = [&] {
        for (std::size_t k = 0; k < count && going; ++k) {
            const Run& r = runs[k];
            if constexpr (std::is_void_v<decltype(visit(r.index, r.voxel, r.t0, r.t1))>)
                visit(r.index, r.voxel, r.t0, r.t1);
            else
                going = visit(r.index, r.voxel, r.t0, r.t1);
        }
        count = 0;
    };
    walkBlocks(origin, dir, tEnd, [&](std::int32_t block, float tEnter, float tExit) {
        const glm::ivec3 lo = blockOrigin(block);
        traverseCells(line, tEnter, tExit, lo, lo + 7,
                      [&](const glm::ivec3& v, float t0, float t1) {
                          if (const std::int64_t i = voxelIn(block, v); i >= 0) {
                              __builtin_prefetch(&voxels_[std::size_t(i)]);
                              runs[count++] = {std::size_t(i), v, t0, t1};
                              if (count == runs.size())
                                  visitRuns();
                          }
                          return going;
                      });
        visitRuns();
        return going;
    });
}

template <typename Crossed>
std::optional<MediumCollision>
FiberMedium::sampleCollision(const Vec3f& origin, const Vec3f& dir, float tMax, Pcg32& rng,
                             const OwnFiber* own, Crossed&& crossed) const {
    // The own fiber's cross-section toward dir, per unit λ_own: |dir × u|.
    const float ownCross = own ? glm::length(glm::cross(dir, own->tangent)) : 0.0f;
    const float ownReach = own ? ownFiberReach(*own, dir) : 0.0f;
    float tau = -std::log1p(-rng.uniformFloat()); // the optical depth left to the collision
    std::optional<MediumCollision> hit;
    walkVoxels(origin, dir, tMax, [&](std::size_t v, const glm::ivec3& ijk, float t0, float t1) {
        const VoxelMedium& m = voxels_[v];
        const float lambda = m.lambda;
        const float lambdaOwn =
            own && t0 < ownReach && nearOwnFiber(*own, ijk) ? ownDensity(*own, ijk) : 0.0f;
        const float sigma =
            std::max(0.0f, kD_ * (lambda * meanCosTheta(m, dir) - ownCross * lambdaOwn));
        const float depth = sigma * (t1 - t0);
        const float lambdaMet = std::max(0.0f, lambda - lambdaOwn);
        if (!(sigma > 0) || depth < tau) {
            tau -= depth;
            crossed(v, ijk, lambdaMet, t0, t1);
            return true;
        }
        MediumCollision c;
        c.t = std::min(t1, t0 + tau / sigma);
        c.position = origin + c.t * dir;
        crossed(v, ijk, lambdaMet, t0, c.t);
        sampleFiber(v, dir, rng, c);
        hit = c;
        return false;
    });
    return hit;
}

} // namespace hairvox
