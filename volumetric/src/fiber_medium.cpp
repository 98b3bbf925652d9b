#include <hairvox/volumetric/fiber_medium.h>

#include <hairvox/core/error.h>
#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/math.h>
#include <hairvox/core/sampling.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hairvox {

namespace {

constexpr int kBlockDim = FiberBlock::kDim; // 8

} // namespace

FiberMedium::FiberMedium(const FiberGrid& grid)
    : grid_(&grid)
    , h_(float(grid.info.voxelSize))
    , kD_(grid.info.fiberScale.ribbonWidth())
    , types_(grid.fiberTypeCount()) {
    if (!(h_ > 0))
        throw std::invalid_argument("FiberMedium: the grid has no voxel size");
    if (grid.blocks.empty())
        return;
    voxels_.resize(grid.density.size());
    for (std::size_t v = 0; v < voxels_.size(); ++v) {
        VoxelMedium& m = voxels_[v];
        m.o = Vec3f(grid.orientation[v].x(), grid.orientation[v].y(), grid.orientation[v].z());
        m.lambda = grid.density[v];
    }
    glm::ivec3 lo(std::numeric_limits<int>::max()), hi(std::numeric_limits<int>::min());
    for (const FiberBlock& b : grid.blocks) {
        const glm::ivec3 c(b.origin.x() / kBlockDim, b.origin.y() / kBlockDim,
                           b.origin.z() / kBlockDim);
        lo = glm::min(lo, c);
        hi = glm::max(hi, c);
    }
    blockMin_ = lo;
    blockDims_ = hi - lo + 1;
    const std::uint64_t cells =
        std::uint64_t(blockDims_.x) * std::uint64_t(blockDims_.y) * std::uint64_t(blockDims_.z);
    // A grid of at most 2^31 voxels a side has at most (2^28)^3 blocks in its
    // box; a box this size would hold a few active blocks spread over a huge
    // volume, which the grid's own memory budget already refused.
    if (cells > (1ull << 30))
        throw InputError(strCat("the fiber grid spans ", blockDims_.x, " x ", blockDims_.y, " x ",
                                blockDims_.z,
                                " blocks of 8 voxels: too sparse a groom for the volumetric "
                                "integrator; raise the voxel size"));
    blockIndex_.assign(cells, -1);
    blocks_.resize(grid.blocks.size());
    using Word = openvdb::Index64;
    for (std::size_t b = 0; b < grid.blocks.size(); ++b) {
        const FiberBlock& block = grid.blocks[b];
        MediumBlock& mb = blocks_[b];
        mb.origin = glm::ivec3(block.origin.x(), block.origin.y(), block.origin.z());
        mb.first = block.first;
        const glm::ivec3 c = glm::ivec3(block.origin.x(), block.origin.y(), block.origin.z()) /
                                 kBlockDim -
                             blockMin_;
        blockIndex_[(std::size_t(c.x) * std::size_t(blockDims_.y) + std::size_t(c.y)) *
                        std::size_t(blockDims_.z) +
                    std::size_t(c.z)] = static_cast<std::int32_t>(b);
        std::uint16_t count = 0;
        for (int w = 0; w < 8; ++w) {
            const Word word = block.active.getWord<Word>(openvdb::Index(w));
            mb.words[std::size_t(w)] = word;
            mb.prefix[std::size_t(w)] = count;
            count = static_cast<std::uint16_t>(count + openvdb::util::CountOn(word));
        }
        const Vec3f lo3 = (Vec3f(block.origin.x(), block.origin.y(), block.origin.z()) - 0.5f) * h_;
        bounds_.extend(lo3);
        bounds_.extend(lo3 + float(kBlockDim) * h_);
    }
}

std::int64_t FiberMedium::voxelAt(const Vec3f& q) const {
    const glm::ivec3 v(floorToInt(q.x), floorToInt(q.y), floorToInt(q.z));
    const std::int32_t block = blockAt(glm::ivec3(v.x >> 3, v.y >> 3, v.z >> 3));
    return block < 0 ? -1 : voxelIn(block, v);
}

std::uint64_t FiberMedium::memoryBytes() const {
    return voxels_.capacity() * sizeof(VoxelMedium) +
           blockIndex_.capacity() * sizeof(std::int32_t) + blocks_.capacity() * sizeof(MediumBlock);
}

float FiberMedium::extinction(const Vec3f& x, const Vec3f& omega) const {
    const std::int64_t v = voxelAt(x / h_ + 0.5f);
    if (v < 0)
        return 0.0f;
    const VoxelMedium& m = voxels_[std::size_t(v)];
    return kD_ * m.lambda * meanCosTheta(m, omega);
}

void FiberMedium::sampleFiber(std::size_t v, const Vec3f& omega, Pcg32& rng,
                              MediumCollision& out) const {
    const Vec3f& o = voxels_[v].o;
    const float len = glm::length(o);
    const float c = std::min(1.0f, len);
    const float coherent = glm::length(glm::cross(omega, o));
    const float isotropic = (1.0f - c) * kQuarterPi;
    if (len > 0 && rng.uniformFloat() * (coherent + isotropic) < coherent) {
        out.tangent = o / len;
    } else {
        // A uniformly random direction, kept with probability cos θ = |ω × u|.
        for (;;) {
            const Vec3f u = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
            if (rng.uniformFloat() < glm::length(glm::cross(omega, u))) {
                out.tangent = u;
                break;
            }
        }
    }
    out.fiberType = 0;
    if (types_ > 1) {
        float xi = rng.uniformFloat(), sum = 0;
        for (std::size_t t = 0; t < types_; ++t) {
            sum += grid_->typeFraction[t][v];
            if (xi < sum || t + 1 == types_) {
                out.fiberType = static_cast<std::uint8_t>(t);
                break;
            }
        }
    }
}

bool FiberMedium::nearOwnFiber(const OwnFiber& own, const glm::ivec3& v) const {
    // The splat of v reaches the cube |p − v|∞ < 1 (voxels), which lies within √3 of v.
    const Vec3f a = own.position / h_ - Vec3f(v);
    const float along = glm::dot(a, own.tangent);
    return glm::dot(a, a) - along * along < 3.0f;
}

float FiberMedium::ownFiberReach(const OwnFiber& own, const Vec3f& dir) const {
    // A voxel whose box holds x(t) lies within √3/2 voxels of it, and the line
    // must pass within √3 of the voxel: x(t) within (3/2)√3 h of the line,
    // which it leaves at t·|dir × u|.
    constexpr float kReach = 1.5f * 1.7320508f;
    const float away = glm::length(glm::cross(dir, own.tangent));
    return away * std::numeric_limits<float>::max() > kReach * h_
               ? kReach * h_ / away
               : std::numeric_limits<float>::max();
}

float FiberMedium::ownDensity(const OwnFiber& own, const glm::ivec3& v) const {
    // p(s) = a + s·b in voxels from v; the tents' product is positive on
    // (s0, s1) and a cubic between the points where a coordinate crosses 0:
    // two Gauss–Legendre nodes per piece integrate it exactly.
    const Vec3f a = own.position / h_ - Vec3f(v);
    const Vec3f& b = own.tangent;
    float s0 = -std::numeric_limits<float>::infinity(), s1 = -s0;
    for (int i = 0; i < 3; ++i) {
        if (std::abs(b[i]) < 1e-7f) {
            if (!(std::abs(a[i]) < 1.0f))
                return 0.0f;
            continue;
        }
        const float lo = (-1.0f - a[i]) / b[i], hi = (1.0f - a[i]) / b[i];
        s0 = std::max(s0, std::min(lo, hi));
        s1 = std::min(s1, std::max(lo, hi));
    }
    if (!(s0 < s1))
        return 0.0f;
    std::array<float, 5> knots{s0, s1, s1, s1, s1};
    int n = 2;
    for (int i = 0; i < 3; ++i)
        if (std::abs(b[i]) >= 1e-7f) {
            const float z = -a[i] / b[i];
            if (z > s0 && z < s1)
                knots[std::size_t(n++)] = z;
        }
    std::sort(knots.begin(), knots.begin() + n);
    const auto tents = [&](float s) {
        const Vec3f p = a + s * b;
        return std::max(0.0f, 1.0f - std::abs(p.x)) * std::max(0.0f, 1.0f - std::abs(p.y)) *
               std::max(0.0f, 1.0f - std::abs(p.z));
    };
    constexpr float kNode = 0.57735026919f; // 1/√3
    float integral = 0;
    for (int k = 0; k + 1 < n; ++k) {
        const float mid = 0.5f * (knots[std::size_t(k)] + knots[std::size_t(k + 1)]);
        const float half = 0.5f * (knots[std::size_t(k + 1)] - knots[std::size_t(k)]);
        integral += half * (tents(mid - kNode * half) + tents(mid + kNode * half));
    }
    return integral / (h_ * h_);
}

std::optional<MediumCollision> FiberMedium::sampleCollision(const Vec3f& origin, const Vec3f& dir,
                                                            float tMax, Pcg32& rng,
                                                            const OwnFiber* own) const {
    return sampleCollision(origin, dir, tMax, rng, own,
                           [](std::size_t, const glm::ivec3&, float, float, float) {});
}

std::ostream& operator<<(std::ostream& os, const MediumCollision& c) {
    return os << "MediumCollision(t=" << c.t << ", x=" << c.position << ", u=" << c.tangent
              << ", type=" << int(c.fiberType) << ")";
}

} // namespace hairvox
