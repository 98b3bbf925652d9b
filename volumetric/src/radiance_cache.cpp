#include <hairvox/volumetric/radiance_cache.h>

#include <hairvox/core/error.h>
#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/math.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace hairvox {

namespace {

/// Cells of the dense index at most (4 GiB of int32).
constexpr std::uint64_t kMaxIndexCells = 1ull << 30;
/// A frame needs at least this share of coherent length (|Σλo| / Σλ) in its
/// cell, or it is taken from the 3³ neighbourhood.
constexpr double kMinCoherence = 0.05;

/// The box (first cell, cells a side) of the cells holding the grid's blocks.
std::pair<glm::ivec3, glm::ivec3> cellBox(const FiberGrid& grid, int m) {
    glm::ivec3 lo(std::numeric_limits<int>::max()), hi(std::numeric_limits<int>::min());
    for (const FiberBlock& b : grid.blocks) {
        const glm::ivec3 o(b.origin.x(), b.origin.y(), b.origin.z());
        for (int i = 0; i < 3; ++i) {
            lo[i] = std::min(lo[i], CellGrid::floorDiv(o[i], m));
            hi[i] = std::max(hi[i], CellGrid::floorDiv(o[i] + FiberBlock::kDim - 1, m));
        }
    }
    return {lo, hi - lo + 1};
}

std::uint64_t boxCells(const glm::ivec3& dims) {
    return std::uint64_t(dims.x) * std::uint64_t(dims.y) * std::uint64_t(dims.z);
}

} // namespace

void RadianceCacheSettings::validate() const {
    basis.validate();
    if (cellVoxels < 1 || cellVoxels > 16)
        throw InputError(strCat("volumetric: cell_voxels = ", cellVoxels,
                                ": expected an integer in [1, 16]"));
}

std::ostream& operator<<(std::ostream& os, const RadianceCacheSettings& s) {
    return os << "RadianceCacheSettings(" << s.basis << ", cellVoxels=" << s.cellVoxels << ")";
}

std::uint64_t RadianceCache::estimateBytes(const FiberGrid& grid,
                                           const RadianceCacheSettings& settings,
                                           std::size_t types) {
    if (grid.blocks.empty())
        return 0;
    const int m = settings.cellVoxels;
    const auto [lo, dims] = cellBox(grid, m);
    (void)lo;
    // Occupied cells at most: one per active voxel, or the whole box.
    const std::uint64_t cells = std::min<std::uint64_t>(grid.activeVoxelCount(), boxCells(dims));
    const std::uint64_t perCell =
        4 * 3 * std::uint64_t(settings.basis.coefficients()) * std::max<std::size_t>(1, types) +
        sizeof(FiberFrame) + sizeof(glm::ivec3) + sizeof(float);
    return boxCells(dims) * 4 + cells * perCell;
}

RadianceCache::RadianceCache(const FiberGrid& grid, const RadianceCacheSettings& settings,
                             std::uint64_t memoryBudget)
    : settings_(settings)
    , types_(grid.fiberTypeCount()) {
    settings.validate();
    if (grid.blocks.empty())
        return;
    const std::uint64_t estimate = estimateBytes(grid, settings, types_);
    const int m = settings.cellVoxels;
    const auto [lo, dims] = cellBox(grid, m);
    if (estimate > memoryBudget || boxCells(dims) > kMaxIndexCells)
        throw InputError(strCat(
            "volumetric: the radiance cache of ", dims.x, " x ", dims.y, " x ", dims.z,
            " cells of ", m, " voxels would need about ", (estimate + (1ull << 20) - 1) >> 20,
            " MiB, over the ", memoryBudget >> 20, " MiB the render can give it; raise "
            "integrator.cell_voxels or the voxel size, or lower integrator.theta_bins / "
            "azimuthal_order"));
    grid_ = CellGrid(float(grid.info.voxelSize), m, lo, dims);
    const auto boxIndex = [&](const glm::ivec3& c) { return std::size_t(grid_.boxIndex(c)); };
    const auto cellOfVoxel = [&](const openvdb::Coord& v) {
        return grid_.cellOfVoxel(glm::ivec3(v.x(), v.y(), v.z()));
    };

    // The cells holding fibers, in the order of their box index.
    std::vector<std::uint8_t> mark(grid_.boxCells(), 0);
    grid.forEachVoxel([&](std::size_t, const openvdb::Coord& v) { mark[boxIndex(cellOfVoxel(v))] = 1; });
    for (const std::size_t i : grid_.makePresent(mark))
        cells_.push_back(grid_.cellOfBoxIndex(i));

    // Λ and the frames from the fibers' length and mean tangents.
    std::vector<Vec3d> sumO(cells_.size(), Vec3d(0.0));
    std::vector<double> sumL(cells_.size(), 0.0);
    grid.forEachVoxel([&](std::size_t v, const openvdb::Coord& ijk) {
        const auto slot = std::size_t(grid_.slotOfCell(cellOfVoxel(ijk)));
        const openvdb::Vec3s& o = grid.orientation[v];
        sumO[slot] += double(grid.density[v]) * Vec3d(o.x(), o.y(), o.z());
        sumL[slot] += double(grid.density[v]);
    });
    frames_.resize(cells_.size());
    fiberLength_.resize(cells_.size());
    const double h = double(grid_.voxelSize()), voxelVolume = h * h * h;
    for (std::size_t s = 0; s < cells_.size(); ++s) {
        fiberLength_[s] = float(sumL[s] * voxelVolume);
        Vec3d o = sumO[s];
        double l = sumL[s];
        if (glm::length(o) <= kMinCoherence * l || l == 0) {
            o = Vec3d(0.0);
            l = 0;
            for (int dx = -1; dx <= 1; ++dx)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dz = -1; dz <= 1; ++dz) {
                        const std::int64_t n = grid_.slotOfCell(cells_[s] + glm::ivec3(dx, dy, dz));
                        if (n >= 0) {
                            o += sumO[std::size_t(n)];
                            l += sumL[std::size_t(n)];
                        }
                    }
        }
        const Vec3f axis = glm::length(o) > kMinCoherence * l && l > 0
                               ? Vec3f(glm::normalize(o))
                               : Vec3f(0.0f, 1.0f, 0.0f);
        frames_[s] = FiberFrame::about(axis);
    }

    coefficients_.assign(cells_.size() * floatsPerCell(), 0.0f);
}

Bounds3f RadianceCache::bounds() const {
    Bounds3f b;
    if (cells_.empty())
        return b;
    const float size = cellSize(), h = grid_.voxelSize();
    b.extend(Vec3f(grid_.boxMin()) * size - 0.5f * h);
    b.extend(Vec3f(grid_.boxMin() + grid_.boxDims()) * size - 0.5f * h);
    return b;
}

std::uint64_t RadianceCache::memoryBytes() const {
    std::uint64_t bytes = grid_.memoryBytes() +
                          cells_.capacity() * sizeof(glm::ivec3) +
                          frames_.capacity() * sizeof(FiberFrame) +
                          fiberLength_.capacity() * sizeof(float) +
                          coefficients_.size() * sizeof(float);
    for (const auto& o : outgoing_)
        bytes += o.size() * sizeof(float);
    return bytes;
}

std::int64_t RadianceCache::slotOfVoxel(const glm::ivec3& v) const {
    return grid_.slotOfCell(grid_.cellOfVoxel(v));
}

void RadianceCache::deposit(std::uint32_t slot, const Vec3f& omega_i, const Rgb& power) {
    const RadianceBasis& basis = settings_.basis;
    const AzimuthalHarmonics h =
        AzimuthalHarmonics::of(omega_i, frames_[slot], basis.azimuthalOrder);
    const int perBin = basis.coefficientsPerBin();
    // The projection's normalisation: a_0 by 2πΔs, a_k and b_k by πΔs; and
    // the fiber average's, by Λ.
    const float inv = float(InvPi) / (basis.binWidth() * fiberLength_[slot]);
    float* c = coefficients_.data() + std::size_t(slot) * floatsPerCell() +
               std::size_t(basis.bin(h.s)) * std::size_t(perBin);
    const std::size_t channel = std::size_t(basis.coefficients());
    for (int ch = 0; ch < 3; ++ch) {
        const float w = power[ch] * inv;
        float* cc = c + std::size_t(ch) * channel;
        cc[0] += 0.5f * w;
        for (int m = 1; m < perBin; ++m)
            cc[m] += w * h.harmonic[std::size_t(m)];
    }
}

void RadianceCache::finish(const std::vector<ScatteringKernel>& kernels) {
    if (kernels.size() < 2 * types_)
        throw std::invalid_argument(
            "RadianceCache::finish: a backward and a forward kernel per fiber type are needed");
    const std::size_t n = floatsPerCell();
    outgoing_.resize(2 * types_ - 1);
    for (auto& o : outgoing_)
        o.resize(cells_.size() * n); // every element written below
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells_.size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          std::vector<float> incident(n);
                          for (std::size_t s = r.begin(); s != r.end(); ++s) {
                              float* c = coefficients_.data() + s * n;
                              std::copy(c, c + n, incident.begin());
                              for (std::size_t k = 2 * types_; k-- > 0;)
                                  kernels[k].apply(incident, {table(k) + s * n, n});
                          }
                      });
    finished_ = true;
}

Rgb RadianceCache::outgoing(const Vec3f& x, const Vec3f& u, const Vec3f& omega_o,
                            std::size_t type) const {
    if (cells_.empty())
        return Rgb(0.0f);
    const RadianceBasis& basis = settings_.basis;
    const int bins = basis.thetaBins, perBin = basis.coefficientsPerBin();
    const std::size_t channel = std::size_t(basis.coefficients()), n = floatsPerCell();
    const float* backward = table(2 * type);
    const float* forward = table(2 * type + 1);
    // A table's value toward the direction with harmonics h: between the
    // tabulated s_o (the bins' centres), clamped at the ends.
    const auto read = [&](const float* cell, const AzimuthalHarmonics& h, Rgb& out, float w) {
        const float p = std::clamp((h.s + 1.0f) / basis.binWidth() - 0.5f, 0.0f, float(bins - 1));
        const int j0 = std::min(int(p), bins - 2), j1 = j0 + 1;
        const float tj = p - float(j0);
        for (int ch = 0; ch < 3; ++ch) {
            const float* a = cell + std::size_t(ch) * channel + std::size_t(j0) * std::size_t(perBin);
            const float* b = cell + std::size_t(ch) * channel + std::size_t(j1) * std::size_t(perBin);
            float v = 0;
            for (int m = 0; m < perBin; ++m)
                v += ((1.0f - tj) * a[m] + tj * b[m]) * h.harmonic[std::size_t(m)];
            out[ch] += w * v;
        }
    };
    Rgb sum(0.0f);
    const float weights = grid_.forEachAround(x, [&](std::size_t slot, float w) {
        const FiberFrame& frame = frames_[slot];
        const std::size_t offset = slot * n;
        // Backward lobes in the fragment's own frame, the forward lobe in the
        // cell's (the file comment).
        read(backward + offset,
             AzimuthalHarmonics::of(omega_o, FiberFrame::along(u, frame), basis.azimuthalOrder),
             sum, w);
        read(forward + offset, AzimuthalHarmonics::of(omega_o, frame, basis.azimuthalOrder), sum, w);
    });
    if (!(weights > 0))
        return Rgb(0.0f);
    sum /= weights;
    return {std::max(0.0f, sum.r), std::max(0.0f, sum.g), std::max(0.0f, sum.b)};
}

Rgb RadianceCache::incident(const Vec3f& x, const Vec3f& omega_i) const {
    if (cells_.empty() || finished_)
        return Rgb(0.0f);
    const RadianceBasis& basis = settings_.basis;
    const int perBin = basis.coefficientsPerBin();
    Rgb sum(0.0f);
    const float weights = grid_.forEachAround(x, [&](std::size_t slot, float w) {
        const AzimuthalHarmonics h =
            AzimuthalHarmonics::of(omega_i, frames_[slot], basis.azimuthalOrder);
        const float* c = coefficients_.data() + slot * floatsPerCell() +
                         std::size_t(basis.bin(h.s)) * std::size_t(perBin);
        for (int ch = 0; ch < 3; ++ch) {
            float v = 0;
            for (int m = 0; m < perBin; ++m)
                v += c[std::size_t(ch) * std::size_t(basis.coefficients()) + std::size_t(m)] *
                     h.harmonic[std::size_t(m)];
            sum[ch] += w * v;
        }
    });
    return weights > 0 ? sum / weights : Rgb(0.0f);
}

std::ostream& operator<<(std::ostream& os, const RadianceCache& c) {
    return os << "RadianceCache(" << c.settings() << ", cells=" << c.cellCount()
              << ", cellSize=" << c.cellSize() << ", bytes=" << c.memoryBytes() << ")";
}

} // namespace hairvox
