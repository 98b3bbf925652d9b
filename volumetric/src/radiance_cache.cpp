#include <hairvox/core/error.h>
#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/math.h>
#include <hairvox/volumetric/radiance_cache.h>
#include <hairvox/volumetric/spherical_harmonics.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hairvox {

namespace {

/// Cells of the dense index at most (4 GiB of int32).
constexpr std::uint64_t kMaxIndexCells = 1ull << 30;

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
    if (shOrder < 1 || shOrder > SphericalHarmonics::kMaxOrder)
        throw InputError(strCat("volumetric: sh_order = ", shOrder, ": expected an integer in [1, ",
                                SphericalHarmonics::kMaxOrder, "]"));
    if (cellVoxels < 1 || cellVoxels > 16)
        throw InputError(
            strCat("volumetric: cell_voxels = ", cellVoxels, ": expected an integer in [1, 16]"));
}

std::ostream& operator<<(std::ostream& os, const RadianceCacheSettings& s) {
    return os << "RadianceCacheSettings(shOrder=" << s.shOrder << ", cellVoxels=" << s.cellVoxels
              << ", denoise=" << s.denoise << ", gradients=" << s.gradients << ")";
}

std::uint64_t RadianceCache::estimateBytes(const FiberGrid& grid,
                                           const RadianceCacheSettings& settings) {
    if (grid.blocks.empty())
        return 0;
    const int m = settings.cellVoxels;
    const auto [lo, dims] = cellBox(grid, m);
    (void)lo;
    // Occupied cells at most: one per active voxel, or the whole box.
    const std::uint64_t cells = std::min<std::uint64_t>(grid.activeVoxelCount(), boxCells(dims));
    const std::uint64_t perCell =
        4 * 3 * (std::uint64_t(settings.coefficients()) + 1) + sizeof(glm::ivec3) + sizeof(float) +
        sizeof(CellShape) + 3 * sizeof(Vec3f);
    return boxCells(dims) * 4 + cells * perCell;
}

RadianceCache::RadianceCache(const FiberGrid& grid, const RadianceCacheSettings& settings,
                             std::uint64_t memoryBudget)
    : settings_(settings) {
    settings.validate();
    if (grid.blocks.empty())
        return;
    const std::uint64_t estimate = estimateBytes(grid, settings);
    const int m = settings.cellVoxels;
    const auto [lo, dims] = cellBox(grid, m);
    if (estimate > memoryBudget || boxCells(dims) > kMaxIndexCells)
        throw InputError(
            strCat("volumetric: the radiance cache of ", dims.x, " x ", dims.y, " x ", dims.z,
                   " cells of ", m, " voxels would need about ",
                   (estimate + (1ull << 20) - 1) >> 20, " MiB, over the ", memoryBudget >> 20,
                   " MiB the render can give it; raise "
                   "integrator.cell_voxels or the voxel size, or lower integrator.sh_order"));
    grid_ = CellGrid(float(grid.info.voxelSize), m, lo, dims);
    const auto boxIndex = [&](const glm::ivec3& c) {
        return std::size_t(grid_.boxIndex(c));
    };
    const auto cellOfVoxel = [&](const openvdb::Coord& v) {
        return grid_.cellOfVoxel(glm::ivec3(v.x(), v.y(), v.z()));
    };

    // The cells holding fibers, in the order of their box index.
    std::vector<std::uint8_t> mark(grid_.boxCells(), 0);
    grid.forEachVoxel(
        [&](std::size_t, const openvdb::Coord& v) { mark[boxIndex(cellOfVoxel(v))] = 1; });
    for (const std::size_t i : grid_.makePresent(mark))
        cells_.push_back(grid_.cellOfBoxIndex(i));

    // Λ from the fibers' length.
    std::vector<double> sumL(cells_.size(), 0.0);
    grid.forEachVoxel([&](std::size_t v, const openvdb::Coord& ijk) {
        sumL[std::size_t(grid_.slotOfCell(cellOfVoxel(ijk)))] += double(grid.density[v]);
    });
    fiberLength_.resize(cells_.size());
    const double h = double(grid_.voxelSize()), voxelVolume = h * h * h;
    for (std::size_t s = 0; s < cells_.size(); ++s)
        fiberLength_[s] = float(sumL[s] * voxelVolume);

    // The fibers' centroid and the covariance of their positions, λ-weighted,
    // a voxel's value holding over the box around its vertex (h²/12 an axis).
    std::vector<glm::dvec3> sumX(cells_.size(), glm::dvec3(0.0));
    std::vector<glm::dmat3> sumXX(cells_.size(), glm::dmat3(0.0));
    grid.forEachVoxel([&](std::size_t v, const openvdb::Coord& ijk) {
        const std::size_t s = std::size_t(grid_.slotOfCell(cellOfVoxel(ijk)));
        const glm::dvec3 x = glm::dvec3(ijk.x(), ijk.y(), ijk.z()) * h;
        sumX[s] += double(grid.density[v]) * x;
        sumXX[s] += double(grid.density[v]) * glm::outerProduct(x, x);
    });
    shapes_.resize(cells_.size());
    for (std::size_t s = 0; s < cells_.size(); ++s) {
        const glm::dvec3 centroid =
            sumL[s] > 0 ? sumX[s] / sumL[s] : glm::dvec3(grid_.centre(cells_[s]));
        glm::dmat3 covariance = glm::dmat3(h * h / 12.0);
        if (sumL[s] > 0)
            covariance += sumXX[s] / sumL[s] - glm::outerProduct(centroid, centroid);
        shapes_[s] = {Vec3f(centroid), glm::mat3(glm::inverse(covariance))};
    }

    coefficients_.assign(cells_.size() * floatsPerCell(), 0.0f);
    secondMoment_.assign(cells_.size() * 3, 0.0f);
    slopes_.assign(cells_.size() * 3, Vec3f(0.0f));
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
    std::uint64_t bytes = grid_.memoryBytes() + cells_.capacity() * sizeof(glm::ivec3) +
                          fiberLength_.capacity() * sizeof(float) +
                          coefficients_.size() * sizeof(float) +
                          secondMoment_.capacity() * sizeof(float) +
                          shapes_.capacity() * sizeof(CellShape) +
                          slopes_.capacity() * sizeof(Vec3f);
    return bytes;
}

void RadianceCache::deposit(std::uint32_t slot, const Vec3f& omega_i, const Rgb& sample) {
    std::array<float, SphericalHarmonics::kMaxCoefficients> y;
    SphericalHarmonics::evaluate(omega_i, settings_.shOrder, y.data());
    deposit(slot, y.data(), sample, shapes_[slot].centroid - grid_.centre(cells_[slot]));
}

void RadianceCache::deposit(std::uint32_t slot, const float* y, const Rgb& sample,
                            const Vec3f& offset) {
    const int nc = settings_.coefficients();
    float* c = coefficients_.data() + std::size_t(slot) * floatsPerCell();
    const float inv = 1.0f / fiberLength_[slot];
    for (int ch = 0; ch < 3; ++ch) {
        const float w = sample[ch] * inv;
        secondMoment_[std::size_t(slot) * 3 + std::size_t(ch)] += w * w;
        slopes_[std::size_t(slot) * 3 + std::size_t(ch)] += (w * y[0]) * offset;
        float* cc = c + ch * nc;
        for (int m = 0; m < nc; ++m)
            cc[m] += w * y[m];
    }
}

void RadianceCache::finish(std::vector<ScatteringKernel> kernels) {
    for (const ScatteringKernel& k : kernels)
        if (k.order() != settings_.shOrder)
            throw std::invalid_argument("RadianceCache::finish: a kernel of another SH order");
    kernels_ = std::move(kernels);
    finished_ = true;
    // The slopes from the first moments (see Gradients): β = Σ⁻¹(m − c_00·(x̄ − x_c)).
    const int nc = settings_.coefficients();
    for (std::size_t s = 0; s < cells_.size(); ++s) {
        const Vec3f shift = shapes_[s].centroid - grid_.centre(cells_[s]);
        for (std::size_t ch = 0; ch < 3; ++ch) {
            const float c00 = coefficients_[s * floatsPerCell() + ch * std::size_t(nc)];
            Vec3f& slope = slopes_[s * 3 + ch];
            slope = shapes_[s].covarianceInverse * (slope - c00 * shift);
        }
    }
}

bool RadianceCache::blend(const Vec3f& x, float* out) const {
    const std::size_t n = floatsPerCell();
    std::fill(out, out + n, 0.0f);
    Rgb moment(0.0f); // Σ_i w_i²·Σ_f w_f² of the cells blended (each as scaled)
    const std::size_t perChannel = std::size_t(settings_.coefficients());
    const bool slopes = settings_.gradients && finished_;
    const float weights = grid_.forEachAround(x, [&](std::size_t slot, float w) {
        const float* c = coefficients_.data() + slot * n;
        for (std::size_t ch = 0; ch < 3; ++ch) {
            // The cell's level at x (see Gradients), within [½, 2] of its mean.
            float level = 1;
            if (const float c00 = c[ch * perChannel]; slopes && c00 > 0) {
                const float at = c00 + glm::dot(slopes_[slot * 3 + ch], x - shapes_[slot].centroid);
                level = std::clamp(at / c00, 0.5f, 2.0f);
            }
            const float wl = w * level;
            for (std::size_t i = ch * perChannel; i < (ch + 1) * perChannel; ++i)
                out[i] += wl * c[i];
            moment[int(ch)] += wl * wl * secondMoment_[slot * 3 + ch];
        }
    });
    if (!(weights > 0))
        return false;
    for (std::size_t i = 0; i < n; ++i)
        out[i] /= weights;
    if (settings_.denoise) {
        // James–Stein per band (see the header): N_l = (2l + 1)/4π·moment/W².
        const int nc = settings_.coefficients();
        const float unitNoise = float(1.0 / (4.0 * Pi)) / (weights * weights);
        for (int ch = 0; ch < 3; ++ch) {
            float* c = out + ch * nc;
            for (int l = 1; l <= settings_.shOrder; ++l) {
                float energy = 0;
                for (int i = l * l; i < (l + 1) * (l + 1); ++i)
                    energy += c[i] * c[i];
                const float noise = float(2 * l + 1) * unitNoise * moment[ch];
                const float gain = energy > noise ? 1.0f - noise / energy : 0.0f;
                for (int i = l * l; i < (l + 1) * (l + 1); ++i)
                    c[i] *= gain;
            }
        }
    }
    return true;
}

Rgb RadianceCache::outgoing(const Vec3f& x, const Vec3f& u, const Vec3f& omega_o,
                            std::size_t type) const {
    const ShFrameRotation frame(u, settings_.shOrder);
    std::array<float, 3 * SphericalHarmonics::kMaxCoefficients> c;
    incidentInFrames({&x, 1}, {&frame, 1}, c.data());
    return outgoingInFrame(c.data(), frame, omega_o, type);
}

void RadianceCache::incidentInFrames(std::span<const Vec3f> x,
                                     std::span<const ShFrameRotation> frames, float* out) const {
    if (frames.size() != x.size())
        throw std::invalid_argument("RadianceCache::incidentInFrames: one frame a point");
    constexpr std::size_t kLanes = ShFrameRotation::kLanes;
    const std::size_t n = floatsPerCell();
    // The blends lane-interleaved, [channel][lm][lane], rotated together.
    alignas(64) std::array<float, 3 * SphericalHarmonics::kMaxCoefficients * kLanes> in{}, rotated;
    std::array<float, 3 * SphericalHarmonics::kMaxCoefficients> c;
    for (std::size_t first = 0; first < x.size(); first += kLanes) {
        const std::size_t count = std::min(kLanes, x.size() - first);
        for (std::size_t lane = 0; lane < count; ++lane) {
            if (cells_.empty() || !blend(x[first + lane], c.data()))
                std::fill(c.begin(), c.begin() + std::ptrdiff_t(n), 0.0f);
            for (std::size_t i = 0; i < n; ++i)
                in[i * kLanes + lane] = c[i];
        }
        ShFrameRotation::applyLanes(frames.subspan(first, count), in.data(), rotated.data(), 3);
        for (std::size_t lane = 0; lane < count; ++lane)
            for (std::size_t i = 0; i < n; ++i)
                out[(first + lane) * n + i] = rotated[i * kLanes + lane];
    }
}

Rgb RadianceCache::outgoingInFrame(const float* c, const ShFrameRotation& frame,
                                   const Vec3f& omega_o, std::size_t type) const {
    if (type >= kernels_.size())
        throw std::invalid_argument("RadianceCache::outgoingInFrame: no kernel for the fiber type");
    const Rgb sum = kernels_[type].applyInFrame(c, frame, omega_o);
    return {std::max(0.0f, sum.r), std::max(0.0f, sum.g), std::max(0.0f, sum.b)};
}

Rgb RadianceCache::incident(const Vec3f& x, const Vec3f& omega_i) const {
    if (cells_.empty())
        return Rgb(0.0f);
    std::array<float, 3 * SphericalHarmonics::kMaxCoefficients> c;
    if (!blend(x, c.data()))
        return Rgb(0.0f);
    std::array<float, SphericalHarmonics::kMaxCoefficients> y;
    SphericalHarmonics::evaluate(omega_i, settings_.shOrder, y.data());
    const int nc = settings_.coefficients();
    Rgb sum(0.0f);
    for (int ch = 0; ch < 3; ++ch)
        for (int m = 0; m < nc; ++m)
            sum[ch] += c[std::size_t(ch * nc + m)] * y[std::size_t(m)];
    return sum;
}

std::ostream& operator<<(std::ostream& os, const RadianceCache& c) {
    return os << "RadianceCache(" << c.settings() << ", cells=" << c.cellCount()
              << ", cellSize=" << c.cellSize() << ", bytes=" << c.memoryBytes() << ")";
}

} // namespace hairvox
