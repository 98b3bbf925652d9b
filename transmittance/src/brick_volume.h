// Internal to hairvox transmittance: a sparse volume of optical-depth channels
// (rates per unit length, or accumulated depths), its trilinear reconstruction
// and its exact line integral.
//
// Values live at voxel vertices (the fiber grid's vertex-centred convention):
// voxel (i,j,k) sits at world position (i,j,k)·h and values between voxels are
// trilinear. Storage is a hash map of bricks of 8³ voxels (the fiber grid's
// leaf layout) with a one-voxel apron on the +x, +y, +z sides (9³ values), so
// the 8 corners of every cell a brick owns are in that brick: one lookup per
// brick, none per corner. A value is 8 floats (7 channels and padding) so
// that the per-cell arithmetic vectorises.
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>

#include <glm/vec3.hpp>

#include <cstdint>
#include <memory>
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
        return {{d.n, d.tauP.r, d.tauP.g, d.tauP.b, d.sumBeta2.r, d.sumBeta2.g, d.sumBeta2.b, 0.0f}};
    }
    bool opaque(float depth) const {
        return v[0] > depth && v[1] > depth && v[2] > depth && v[3] > depth;
    }
    OpticalDepths depths() const {
        return {v[0], Rgb(v[1], v[2], v[3]), Rgb(v[4], v[5], v[6])};
    }
};

class BrickVolume {
public:
    static constexpr int kBrick = 8;                            ///< voxels per brick side
    static constexpr int kSide = kBrick + 1;                    ///< with the apron
    static constexpr int kBrickValues = kSide * kSide * kSide;  ///< 729

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

    /// Registers brick b and, for each bit of `lowFaces` (4 x, 2 y, 1 z: b
    /// has values on that low face), the bricks whose aprons hold them. Not
    /// thread-safe; call for every brick, then allocate(), before any set().
    void reserveBrick(const glm::ivec3& b, int lowFaces);
    /// Allocates the values of every reserved brick at once, zeroed in
    /// parallel (the pages are first touched by the threads that will fill
    /// them, not faulted in serially by a growing vector).
    void allocate();
    BrickSet brickSet(const glm::ivec3& b) const;
    /// Stores the value of the voxel at `local` ∈ [0, 8)³ of the brick set's
    /// brick, in its brick and the aprons below. Thread-safe for distinct voxels.
    void set(const BrickSet& bricks, const glm::ivec3& local, const OpticalDepths& value);


    /// ∫_{tStart}^{tEnd} of the trilinear field along origin + t·dir (dir unit,
    /// world units), exact. Stops early once n and every channel of tauP
    /// exceed `opaqueDepth`. `touched` reports whether any brick was entered.
    OpticalDepths integrate(const Vec3f& origin, const Vec3f& dir, float tStart, float tEnd,
                            float opaqueDepth, bool& touched) const;

    /// Cumulative integrals along origin + t·dir at t_k = tStart + k·step:
    /// out[k] = ∫_{tStart}^{t_k}, k = 0 .. out.size() − 1 (out[0] = 0). Stops
    /// once n and every channel of tauP exceed `opaqueDepth`; returns how many
    /// entries it filled (the rest would only grow).
    std::size_t integrateCumulative(const Vec3f& origin, const Vec3f& dir, float tStart, float step,
                                    float opaqueDepth, std::span<Lanes> out) const;

    /// The trilinear value at a world position (zero outside every brick).
    OpticalDepths sample(const Vec3f& position) const;
    /// World-space bounds of every brick.
    Bounds3f bounds() const;



private:
    /// Calls visit(brickIndex, brickCoord, sEnter, sExit) for the bricks that
    /// exist along O + s·dir (index space), s ∈ [s0, s1), in order, while it
    /// returns true.
    template <typename F>
    void walkBricks(const Vec3f& O, const Vec3f& dir, float s0, float s1, F&& visit) const;
    /// Walks the cells of one brick over s ∈ [sa, sb), cut further at
    /// nextSplit(s) (the next cut after s), calling onPiece(s0, s1, f0, fm, f1)
    /// with the field at each piece's ends and middle (nothing for cells whose
    /// corners are all zero).
    template <typename NextSplit, typename OnPiece>
    void forEachPiece(std::size_t brick, const glm::ivec3& b, const Vec3f& O, const Vec3f& dir,
                      float sa, float sb, NextSplit&& nextSplit, OnPiece&& onPiece) const;
    /// Index of the brick at brick coordinate b, or −1.
    std::int64_t find(const glm::ivec3& b) const;
    std::int64_t insert(const glm::ivec3& b);
    void grow();

    double h_;
    float invH_;
    std::vector<std::int64_t> slots_;  ///< open addressing: brick index per slot, −1 if free
    std::size_t brickCount_ = 0;
    std::vector<glm::ivec3> brickCoord_; ///< per brick
    struct AlignedDelete {
        void operator()(Lanes* p) const;
    };
    /// brickCount_ × kBrickValues, once allocate() has run.
    std::unique_ptr<Lanes[], AlignedDelete> values_;
    std::size_t valueCount_ = 0;
    glm::ivec3 brickMin_{0}, brickMax_{-1};
};

} // namespace hairvox::detail
