// The grid and approx modes: per-light rate volumes built from the fiber grid
// and integrated along shadow rays (see grid_global_term.h).
#include "brick_volume.h"
#include "light_space_cache.h"

#include <hairvox/core/disk_cache.h>
#include <hairvox/core/error.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/math.h>
#include <hairvox/core/thread_scratch.h>
#include <hairvox/transmittance/grid_global_term.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

namespace hairvox {

using detail::BrickVolume;
using detail::LightSpaceCache;
using detail::OpticalDepths;

void GridOptions::validate(const FiberGrid& grid) const {
    if (!(startOffset >= 0 && startOffset <= 8))
        throw InputError(
            strCat("grid start offset = ", startOffset, " voxels should be in the range [0, 8]"));
    if (!(cacheSpacing >= 0.5f && cacheSpacing <= 4))
        throw InputError(strCat("grid cache spacing = ", cacheSpacing,
                                " voxels should be in the range [0.5, 4]"));
    if (!(fiberSampleSpacing >= 0 && fiberSampleSpacing <= 4))
        throw InputError(strCat("grid fiber sample spacing = ", fiberSampleSpacing,
                                " voxels should be in the range [0, 4] (0: every point)"));
    if (orientation == OrientationModel::Tensor && !grid.hasTensor())
        throw InputError("the tensor orientation model needs a fiber grid with the orientation "
                         "tensor (voxelize --orientation-tensor)");
    const std::size_t voxels = grid.density.size();
    const bool fractionPerVoxel = std::all_of(grid.typeFraction.begin(), grid.typeFraction.end(),
                                              [&](const auto& f) { return f.size() == voxels; });
    if (grid.orientation.size() != voxels ||
        (grid.hasTensor() &&
         (grid.tensorDiag.size() != voxels || grid.tensorOffDiag.size() != voxels)) ||
        !fractionPerVoxel ||
        (!grid.blocks.empty() &&
         grid.blocks.back().first + grid.blocks.back().active.countOn() != voxels) ||
        !(grid.info.voxelSize > 0))
        throw InputError("the fiber grid's arrays do not hold a value per active voxel, or it "
                         "has no voxel size");
}

void GridOptions::hashInto(Hasher& hasher) const {
    hasher.value(orientation).value(estimator).value(evaluation);
    hasher.value(startOffset).value(cacheSpacing).value(fiberSampleSpacing);
}

std::ostream& operator<<(std::ostream& os, const GridOptions& options) {
    return os << "GridOptions(orientation=" << toString(options.orientation)
              << ", estimator=" << toString(options.estimator)
              << ", evaluation=" << toString(options.evaluation)
              << ", startOffset=" << options.startOffset
              << " voxels, cacheSpacing=" << options.cacheSpacing
              << " voxels, fiberSampleSpacing=" << options.fiberSampleSpacing << " voxels)";
}

namespace {

/// The disk cache's kind of a light's prepared cache (core/disk_cache.h).
constexpr const char* kLightCacheKind = "light";

/// Beyond this optical depth in n and every channel of tauP, V and P are
/// below 1e-7: the rest of the path cannot change the global term.
constexpr float kOpaqueDepth = 16.2f;

/// The optical depth, in expected crossings, that a point's own fiber adds to
/// the grid's integral from `start` along a shadow ray that leaves it at
/// inclination θ (cos θ = |ω × u|): a fiber splatted k·D_i = `ribbonWidth`
/// wide into voxels of size h, integrated through a cache whose lines lie
/// `lineSpacing` voxels apart (0: marched). docs/DESIGN.md §5.
///
/// Splatting is the adjoint of trilinear reconstruction, so averaged over the
/// point's place in its voxel the own fiber's reconstructed density is its
/// centreline convolved with K = ∏_axes B₃(x_i/h)/h³ (B₃ = tent ∗ tent,
/// variance h²/3 per axis); the cache's bilinear interpolation between its
/// lines adds a tent of half-width `lineSpacing`·h across the ray (variance
/// lineSpacing²·h²/6). Along the ray the own fiber's rate is λ_own·k·D·cos θ;
/// substituting p = sω − lu (Jacobian cos θ) turns ∫ds ∫dl into an integral
/// of K over the plane of ω and u, and the cos θ cancels:
///   n_own = k·D·∫_{s > start} K dA.
/// With K taken as Gaussian of variance σ² (the B₃ product's marginal peak on
/// a plane is 0.669–0.689/h over orientations, the Gaussian's 0.691/h), the
/// plane integral is the normal marginal's peak 1/(√(2π)·σ) times the share of
/// the in-plane kernel beyond the line s = start, a distance start·cos θ away:
///   n_own = k·D/(√(2π)·σ) · ½·erfc(start·cos θ / (√2·σ)),
///   σ² = h²·(1/3 + lineSpacing²/6).
/// At start 0 that is 0.34·k·D/h crossings marched, 0.24·k·D/h through the
/// default cache.
float ownFiberCrossings(float ribbonWidth, float cosTheta, float start, float h,
                        float lineSpacing) {
    const float sigma = h * std::sqrt(1.0f / 3.0f + lineSpacing * lineSpacing / 6.0f);
    return ribbonWidth * std::numbers::inv_sqrtpi_v<float> /
           (std::numbers::sqrt2_v<float> * sigma) * 0.5f *
           std::erfc(start * cosTheta / (std::numbers::sqrt2_v<float> * sigma));
}

/// What the per-voxel rates are made of: the fiber grid's statistics at one voxel.
struct VoxelFibers {
    float lambda;
    Vec3f meanTangent;
    Vec3f tensorDiag, tensorOffDiag;
};

/// E_v[rates(θ)] over the fibers of a voxel for light direction ω.
CrossingTable::Rates expectedRates(const VoxelFibers& v, const Vec3f& omega,
                                   const CrossingTable& table, OrientationModel model) {
    const float coherence = std::min(glm::length(v.meanTangent), 1.0f);
    if (!std::isfinite(coherence)) // a foreign .vdb: no orientation to trust
        return table.isotropicRates();
    switch (model) {
    case OrientationModel::MeanTangent:
        if (coherence < 1e-6f)
            return table.isotropicRates();
        return table.rates(glm::dot(omega, v.meanTangent) / coherence);
    case OrientationModel::CoherenceBlend: {
        CrossingTable::Rates r = table.isotropicRates() * (1.0f - coherence);
        if (coherence > 0)
            r += table.rates(glm::dot(omega, v.meanTangent) / coherence) * coherence;
        return r;
    }
    case OrientationModel::Tensor: {
        // E[(ω·u)²] = ωᵀ T ω with T = [[xx xy xz] [xy yy yz] [xz yz zz]].
        const Vec3f& d = v.tensorDiag;
        const Vec3f& o = v.tensorOffDiag;
        const float s2 =
            d.x * omega.x * omega.x + d.y * omega.y * omega.y + d.z * omega.z * omega.z +
            2.0f * (o.x * omega.x * omega.y + o.y * omega.x * omega.z + o.z * omega.y * omega.z);
        const float s = std::sqrt(std::clamp(s2, 0.0f, 1.0f));
        // The tensor has no sign: average the two inclinations ±θ.
        return (table.rates(s) + table.rates(-s)) * 0.5f;
    }
    }
    return table.isotropicRates();
}

class GridModel final : public GlobalTermModel {
public:
    GridModel(GlobalTermMode mode, const FiberGrid& grid, CrossingTables crossings,
              const GlobalTermSettings& settings, const GridOptions& options)
        : mode_(mode)
        , grid_(grid)
        , crossings_(std::move(crossings))
        , settings_(settings)
        , options_(options) {}

    GlobalTermMode mode() const override { return mode_; }
    using GlobalTermModel::forLight;
    std::unique_ptr<LightGlobalTerm> forLight(const Light& light,
                                              LightWorkspace* workspace) const override;
    std::unique_ptr<LightWorkspace> makeWorkspace() const override;

    /// A rates volume with a value for every active voxel of the fiber grid
    /// (and its apron copies), all zero: the same layout for every light.
    BrickVolume reserveRates() const;
    /// Sets every active voxel's rates toward `light` in a volume of
    /// reserveRates()' layout. Every value it sets is set for any light, and
    /// the others stay zero, so a volume filled for one light is refilled
    /// for the next as if new.
    void fillRates(BrickVolume& volume, const Light& light) const;

    /// The crossing table of fiber type `type`.
    const CrossingTable& crossings(std::uint8_t type) const { return crossings_.at(type); }
    std::size_t crossingTypes() const { return crossings_.size(); }
    /// The disk cache's key of a light's prepared cache: the caller's key of
    /// the grid, tables and settings (GlobalTermSettings::diskCacheKey), what
    /// of the options the cache is made of, and the light.
    std::uint64_t lightCacheKey(const Light& light) const {
        Hasher h;
        h.value(settings_.diskCacheKey).value(mode_);
        options_.hashInto(h);
        settings_.fiberScale.hashInto(h);
        light.hashInto(h);
        return h.digest();
    }
    const GlobalTermSettings& settings() const { return settings_; }
    const GridOptions& options() const { return options_; }
    double voxelSize() const { return grid_.info.voxelSize; }

private:
    GlobalTermMode mode_;
    const FiberGrid& grid_;
    CrossingTables crossings_; ///< per fiber type
    GlobalTermSettings settings_;
    GridOptions options_;
};

/// The rates volume's brick of a fiber grid block (both are 8³ voxels).
glm::ivec3 brickOf(const FiberBlock& block) {
    static_assert(FiberBlock::kDim == BrickVolume::kBrick);
    return glm::ivec3(block.origin.x(), block.origin.y(), block.origin.z()) / BrickVolume::kBrick;
}

/// A voxel's coordinates in its block.
glm::ivec3 localOf(const FiberBlock& block, const openvdb::Coord& ijk) {
    const openvdb::Coord l = ijk - block.origin;
    return {l.x(), l.y(), l.z()};
}

/// Which low faces of a block hold an active voxel (4 x, 2 y, 1 z), from its
/// mask's words: word x holds the voxels (x, y, z) at bits y·8 + z. (Visiting
/// the voxels one by one was a serial pass over all of them.)
int lowFacesOf(const FiberBlock& block) {
    static_assert(FiberBlock::kDim == 8);
    std::uint64_t any = 0;
    for (openvdb::Index w = 0; w < 8; ++w)
        any |= block.active.getWord<std::uint64_t>(w);
    return (block.active.getWord<std::uint64_t>(0) != 0 ? 4 : 0) | ((any & 0xFFu) != 0 ? 2 : 0) |
           ((any & 0x0101010101010101u) != 0 ? 1 : 0);
}

/// A grid model's LightWorkspace: the rates volume of the last light.
struct RatesWorkspace final : LightWorkspace {
    explicit RatesWorkspace(const GridModel& m)
        : model(&m) {}

    const GridModel* model; ///< the model that made it
    std::optional<BrickVolume> rates;
};

BrickVolume GridModel::reserveRates() const {
    BrickVolume volume(grid_.info.voxelSize);
    const std::vector<FiberBlock>& blocks = grid_.blocks;
    // Bricks reserved serially (their order is the blocks'), voxels in parallel.
    for (const FiberBlock& block : blocks)
        volume.reserveBrick(brickOf(block), lowFacesOf(block));
    volume.allocateSlots();
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, blocks.size(), 16), [&](const auto& range) {
            for (std::size_t b = range.begin(); b != range.end(); ++b) {
                const BrickVolume::BrickSet bricks = volume.brickSet(brickOf(blocks[b]));
                FiberGrid::forEachVoxelOf(blocks[b], [&](std::size_t, const openvdb::Coord& ijk) {
                    volume.reserveVoxel(bricks, localOf(blocks[b], ijk));
                });
            }
        });
    volume.allocateValues();
    return volume;
}

void GridModel::fillRates(BrickVolume& volume, const Light& light) const {
    const double h = grid_.info.voxelSize;
    const std::vector<FiberBlock>& blocks = grid_.blocks;
    const float kD = settings_.fiberScale.ribbonWidth();
    const bool tensor = options_.orientation == OrientationModel::Tensor;
    const bool poisson = options_.estimator == AttenuationEstimator::Poisson;
    const auto vec = [](const openvdb::Vec3s& v) {
        return Vec3f(v.x(), v.y(), v.z());
    };
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size(), 4), [&](const auto& range) {
        for (std::size_t b = range.begin(); b != range.end(); ++b) {
            const BrickVolume::BrickSet bricks = volume.brickSet(brickOf(blocks[b]));
            FiberGrid::forEachVoxelOf(blocks[b], [&](std::size_t i, const openvdb::Coord& c) {
                const VoxelFibers fibers{grid_.density[i], vec(grid_.orientation[i]),
                                         tensor ? vec(grid_.tensorDiag[i]) : Vec3f(0.0f),
                                         tensor ? vec(grid_.tensorOffDiag[i]) : Vec3f(0.0f)};
                const Vec3f world = Vec3f(float(c.x()), float(c.y()), float(c.z())) * float(h);
                const Vec3f omega = light.pathFrom(world).omega;
                // Several fiber types: their rates mixed by the voxel's fractions.
                CrossingTable::Rates r;
                if (grid_.typeFraction.empty()) {
                    r = expectedRates(fibers, omega, crossings_[0], options_.orientation);
                } else {
                    for (std::size_t t = 0; t < grid_.typeFraction.size(); ++t)
                        if (const float f = grid_.typeFraction[t][i]; f > 0)
                            r += expectedRates(fibers, omega, crossings_[t], options_.orientation) *
                                 f;
                }
                const float scale = fibers.lambda * kD;
                volume.set(bricks, localOf(blocks[b], c),
                           {scale * r.cosTheta, (poisson ? r.wAbsorb : r.wLogA) * scale,
                            r.wBeta2 * scale});
            });
        }
    });
}

class GridLightGlobalTerm final : public LightGlobalTerm {
public:
    /// `workspace`: the rates volume of the light before, refilled for this
    /// one and handed back once the cache is built (null: none).
    GridLightGlobalTerm(const GridModel& model, const Light& light, RatesWorkspace* workspace)
        : model_(model)
        , light_(light) {
        // A cache another process prepared (GlobalTermSettings::diskCache).
        const DiskCache* disk = model.options().evaluation == GridEvaluation::Cache
                                    ? model.settings().diskCache
                                    : nullptr;
        const std::uint64_t key = disk ? model.lightCacheKey(light) : 0;
        if (disk) {
            if (const auto bytes = disk->load(kLightCacheKind, key)) {
                cache_ = LightSpaceCache::deserialize(*bytes);
                if (cache_) {
                    tabulateOwnFiber();
                    return;
                }
                std::cerr << "hairvox: warning: cache entry "
                          << disk->entryPath(kLightCacheKind, key).string()
                          << " is not a light-space cache of this build; computed again\n";
                disk->discard(kLightCacheKind, key);
            }
        }
        BrickVolume rates =
            workspace && workspace->rates ? std::move(*workspace->rates) : model.reserveRates();
        if (workspace)
            workspace->rates.reset();
        model.fillRates(rates, light);
        if (model.options().evaluation == GridEvaluation::Cache)
            cache_ =
                LightSpaceCache::build(rates, light, kOpaqueDepth, model.options().cacheSpacing);
        // The cache holds everything its lookups read: the rates (8 float
        // lanes per voxel) are kept only for marching, not for the whole render.
        if (!cache_)
            rates_.emplace(std::move(rates));
        else if (workspace)
            workspace->rates.emplace(std::move(rates));
        // (A point light inside the volume marches: nothing to keep.)
        const auto& stores = model.settings().diskCacheStores;
        if (disk && cache_ && (!stores || stores(light)))
            disk->store(kLightCacheKind, key, cache_->serialize());
        tabulateOwnFiber();
    }

    std::size_t memoryBytes() const override {
        return cache_ ? cache_->memoryBytes() : rates_->memoryBytes();
    }

    GlobalTermStats evaluate(std::span<const GlobalTermQuery> queries,
                             std::span<GlobalTerm> out) const override {
        struct Scratch {
            std::vector<unsigned char> empty; // per query: its path crossed no hair
        };
        ThreadScratch<Scratch> scratch;
        std::vector<unsigned char>& empty = scratch->empty;
        empty.resize(queries.size()); // every element written by evaluateBatch
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), kBatch),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t b = range.begin(); b < range.end(); b += kBatch)
                                  evaluateBatch(
                                      queries.subspan(b, std::min(kBatch, range.end() - b)),
                                      out.subspan(b), std::span(empty).subspan(b));
                          });
        GlobalTermStats stats;
        stats.queries = stats.evaluated = queries.size();
        for (unsigned char e : empty)
            stats.emptyPaths += e;
        return stats;
    }

private:
    /// Queries evaluated together: the cache's lookups go as one batch
    /// (LightSpaceCache::lookup), so that their memory latencies overlap.
    static constexpr std::size_t kBatch = 64;

    /// out[q] for each query q of the batch, and empty[q] = 1 where its path
    /// toward the light crossed no hair.
    void evaluateBatch(std::span<const GlobalTermQuery> queries, std::span<GlobalTerm> out,
                       std::span<unsigned char> empty) const {
        // Each path starts `start` from its point (the grid's start offset);
        // a light nearer than that leaves the point unoccluded.
        const float start = model_.options().startOffset * static_cast<float>(model_.voxelSize());
        std::array<Light::Path, kBatch> paths;
        std::array<std::uint32_t, kBatch> open; // the queries with a path, in order
        std::array<Vec3f, kBatch> from;
        std::array<OpticalDepths, kBatch> depths;
        std::size_t opened = 0;
        for (std::size_t q = 0; q < queries.size(); ++q) {
            paths[q] = light_.pathFrom(queries[q].position);
            empty[q] = 1;
            if (paths[q].distance > start) {
                open[opened] = static_cast<std::uint32_t>(q);
                from[opened++] = queries[q].position + start * paths[q].omega;
            } else {
                out[q] = GlobalTerm::unoccluded();
            }
        }
        if (cache_)
            cache_->lookup(std::span(from).first(opened), std::span(depths).first(opened));
        for (std::size_t k = 0; k < opened; ++k) {
            const std::size_t q = open[k];
            bool touched = false;
            if (cache_)
                touched = depths[k].n > 0;
            else
                depths[k] = rates_->integrate(queries[q].position, paths[q].omega, start,
                                              paths[q].distance, kOpaqueDepth, touched);
            if (queries[q].onFiber)
                leaveOutOwnFiber(queries[q], paths[q], depths[k]);
            out[q] = fromDepths(queries[q], paths[q], depths[k]);
            empty[q] = touched ? 0 : 1;
        }
    }

    /// Entries of the own fiber's table, uniform in sin θ ∈ [−1, 1] (no asin
    /// per query; the sin θ-steep ends, within 7° of the poles, weigh little).
    static constexpr std::size_t kOwnFiberEntries = 257;

    /// ownFiber_[type][j]: the optical depths a fiber of unit k·D_i adds beyond
    /// the start offset (ownFiberCrossings()) at sin θ_j — n_own crossings,
    /// each adding 1 to n, its tauP (tauPPerCrossing()) and β̄_f² at θ_j. Per
    /// light: the blur depends on whether its queries go through a cache.
    void tabulateOwnFiber() {
        const float h = static_cast<float>(model_.voxelSize());
        const float start = model_.options().startOffset * h;
        const float lineSpacing = cache_ ? model_.options().cacheSpacing : 0.0f;
        ownFiber_.resize(model_.crossingTypes());
        for (std::size_t type = 0; type < ownFiber_.size(); ++type) {
            ownFiber_[type].resize(kOwnFiberEntries);
            for (std::size_t j = 0; j < kOwnFiberEntries; ++j) {
                const float sinTheta =
                    -1.0f + 2.0f * static_cast<float>(j) / float(kOwnFiberEntries - 1);
                const float c = ownFiberCrossings(1.0f, safeSqrt(1.0f - sinTheta * sinTheta), start,
                                                  h, lineSpacing);
                const CrossingTable::Values x =
                    model_.crossings(static_cast<std::uint8_t>(type)).crossing(sinTheta);
                ownFiber_[type][j] = {c, c * tauPPerCrossing(x), c * x.beta2Bar_f};
            }
        }
    }

    /// Takes the expected optical depths of query q's own fiber beyond the
    /// start offset (ownFiber_) out of d: the grid splats every fiber, exact
    /// mode and the path tracer skip the point's own (RayScene::isOwnFiber) —
    /// the whole ribbon of k hairs, as the grid's own splat is. Each channel
    /// stays ≥ 0.
    void leaveOutOwnFiber(const GlobalTermQuery& q, const Light::Path& path,
                          OpticalDepths& d) const {
        const GlobalTermSettings& settings = model_.settings();
        const float kD = settings.groom && q.segment != kUnknownSegment
                             ? ribbonWidthAt(*settings.groom, settings.fiberScale, q.segment)
                             : settings.fiberScale.ribbonWidth();
        const float sinTheta = std::clamp(glm::dot(path.omega, q.tangent), -1.0f, 1.0f);
        const float x = (sinTheta + 1.0f) * (0.5f * float(kOwnFiberEntries - 1));
        const auto j = std::min(static_cast<std::size_t>(std::max(x, 0.0f)), kOwnFiberEntries - 2);
        const float t = std::clamp(x - static_cast<float>(j), 0.0f, 1.0f);
        const std::vector<OpticalDepths>& table = ownFiber_[q.fiberType];
        const OpticalDepths own = (table[j] * (1.0f - t) + table[j + 1] * t) * kD;
        d.n = std::max(d.n - own.n, 0.0f);
        d.tauP = max(d.tauP - own.tauP, Rgb(0.0f));
        d.sumBeta2 = max(d.sumBeta2 - own.sumBeta2, Rgb(0.0f));
    }

    /// The global term of query q from the optical depths along its path.
    GlobalTerm fromDepths(const GlobalTermQuery& q, const Light::Path& path,
                          const OpticalDepths& d) const {
        const float d_f = model_.settings().dualScattering.d_f;
        if (model_.mode() == GlobalTermMode::Grid)
            return globalTermFromDepths(d.n, d.tauP, d.sumBeta2, d_f);
        // approx: every fiber in front shares the shading point's orientation and type.
        const float s = glm::dot(path.omega, q.tangent);
        const CrossingTable::Values x = model_.crossings(q.fiberType).crossing(s);
        return globalTermFromDepths(d.n, d.n * tauPPerCrossing(x), d.n * x.beta2Bar_f, d_f);
    }

    /// What one crossing of values x adds to tauP under the model's estimator:
    /// 1 − ā_f (Poisson) or −ln ā_f (geometric).
    Rgb tauPPerCrossing(const CrossingTable::Values& x) const {
        return model_.options().estimator == AttenuationEstimator::Poisson
                   ? Rgb(1.0f) - exp(x.logABar_f)
                   : -x.logABar_f;
    }

    const GridModel& model_;
    Light light_;
    /// Present when evaluating by march (no cache, or a point light inside the volume).
    std::optional<BrickVolume> rates_;
    /// Empty when evaluating by march, or for a point light inside the volume.
    std::optional<LightSpaceCache> cache_;
    std::vector<std::vector<OpticalDepths>> ownFiber_; ///< per fiber type, see tabulateOwnFiber()
};

std::unique_ptr<LightWorkspace> GridModel::makeWorkspace() const {
    return std::make_unique<RatesWorkspace>(*this);
}

std::unique_ptr<LightGlobalTerm> GridModel::forLight(const Light& light,
                                                     LightWorkspace* workspace) const {
    throwIfInterrupted();
    auto* rates = dynamic_cast<RatesWorkspace*>(workspace);
    if (workspace && (!rates || rates->model != this))
        throw std::invalid_argument("grid global term: a workspace of another model");
    std::unique_ptr<LightGlobalTerm> term =
        std::make_unique<GridLightGlobalTerm>(*this, light, rates);
    if (settings_.groom)
        // Grid mode reads no sample's tangent: a strand vertex is one
        // sample for both its segments (approx mode's differ by tangent).
        term = alongFibers(std::move(term), *settings_.groom,
                           options_.fiberSampleSpacing * static_cast<float>(voxelSize()),
                           mode() == GlobalTermMode::Grid);
    // Surfaces outermost: their shadow is exact per point, not interpolated.
    return withSurfaces(std::move(term), settings_.surfaces, light);
}

} // namespace

std::unique_ptr<GlobalTermModel> makeGridModel(const FiberGrid& grid, CrossingTables crossings,
                                               const GlobalTermSettings& settings,
                                               const GridOptions& options) {
    settings.validate();
    options.validate(grid);
    checkCrossingTables(crossings, grid.fiberTypeCount());
    return std::make_unique<GridModel>(GlobalTermMode::Grid, grid, std::move(crossings), settings,
                                       options);
}

std::unique_ptr<GlobalTermModel> makeApproxModel(const FiberGrid& grid, CrossingTables crossings,
                                                 const GlobalTermSettings& settings,
                                                 const GridOptions& options) {
    settings.validate();
    options.validate(grid);
    checkCrossingTables(crossings, grid.fiberTypeCount());
    return std::make_unique<GridModel>(GlobalTermMode::Approx, grid, std::move(crossings), settings,
                                       options);
}

} // namespace hairvox
