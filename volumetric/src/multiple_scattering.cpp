#include "light_emission.h"

#include <hairvox/core/error.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/math.h>
#include <hairvox/core/parallel.h>
#include <hairvox/core/progress.h>
#include <hairvox/core/rng.h>
#include <hairvox/core/sampling.h>
#include <hairvox/shading/marschner.h>
#include <hairvox/volumetric/fiber_medium.h>
#include <hairvox/volumetric/multiple_scattering.h>
#include <hairvox/volumetric/spherical_harmonics.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace hairvox {

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::uint64_t kChunkPaths = 1024; ///< paths a task traces together
/// Chunks traced before their deposits are added, per thread (at least 16):
/// a chunk's record holds its flights' basis values, ~0.8 MB. The result
/// does not depend on it (each cell takes its deposits in chunk order).
constexpr std::size_t kBatchChunksPerThread = 4;
constexpr std::size_t kMaxBuckets = 256;    ///< cell ranges the deposits are added by

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A light's share of the paths: where they start and the power each carries.
struct Emitter {
    std::size_t index = 0; ///< in the scene's lights
    std::shared_ptr<const LightEmission> emission;
    std::uint64_t count = 0; ///< its paths
};

struct Ray {
    Vec3f origin, dir;
};

/// One flight of a path after its first scattering, and its crossings.
struct Flight {
    Rgb power;
};
struct Crossing {
    std::uint32_t slot;
    std::uint32_t flight; ///< in the chunk's flights
    float weight;         ///< ∫ λ dt over the cell's voxels the flight crosses
    Vec3f offset;         ///< ∫ λ·(x − the cell's centre) dt / weight (radiance_cache.h)
};
/// A scattered path's power arriving on a surface.
struct SurfaceDeposit {
    std::uint32_t slot;
    Rgb power;
};

/// A chunk's record: its flights, its crossings grouped by bucket
/// (bucketStart[b] .. bucketStart[b + 1]), its surface deposits, and its counts.
struct ChunkRecord {
    std::vector<Flight> flights;
    /// Per flight, Y_lm(ω_i) ((L + 1)² floats; ω_i toward where the light
    /// comes from, −direction of flight): evaluated once for its crossings.
    std::vector<float> basis;
    std::vector<Crossing> crossings;
    std::vector<Crossing> sorted; ///< the crossings grouped by bucket (kept: no page faults)
    std::vector<std::uint32_t> bucketStart;
    std::vector<SurfaceDeposit> surfaceDeposits;
    VolumetricStats counts;

    void addFlight(const Vec3f& omega_i, const Rgb& power, int order) {
        flights.push_back({power});
        const std::size_t nc = std::size_t(SphericalHarmonics::coefficients(order));
        basis.resize(basis.size() + nc);
        SphericalHarmonics::evaluate(omega_i, order, basis.data() + basis.size() - nc);
    }
};

class PathTracer {
public:
    PathTracer(const VolumetricScene& scene, const VolumetricSettings& settings,
               const FiberMedium& medium, const RayScene* rays, const RadianceCache& cache,
               const SurfaceIrradiance* surfaceCells)
        : scene_(scene), settings_(settings), medium_(medium), rays_(rays), cache_(cache),
          surfaceCells_(surfaceCells), bcsdfs_(scene.fibers.begin(), scene.fibers.end()) {
        if (rays)
            slack_ = 2.0f * rays->ribbonWidth();
        const Bounds3f b = cache.bounds();
        centre_ = b.center();
        radius_ = 0.5f * glm::length(b.extent());
    }

    std::vector<Emitter> emitters(std::uint64_t paths) const {
        std::vector<Emitter> out;
        double total = 0;
        for (std::size_t l = 0; l < scene_.lights.size(); ++l) {
            const Light& light = scene_.lights[l];
            if (light.isDark())
                continue;
            Emitter e;
            e.index = l;
            e.emission = std::make_shared<const LightEmission>(light, *scene_.grid, centre_, radius_);
            if (e.emission->power().isBlack())
                continue;
            total += double(e.emission->power().average());
            out.push_back(e);
        }
        // Largest-remainder shares of the paths, by power toward the hair.
        std::uint64_t given = 0;
        std::vector<std::pair<double, std::size_t>> remainders;
        for (std::size_t i = 0; i < out.size(); ++i) {
            const double exact = double(paths) * double(out[i].emission->power().average()) / total;
            out[i].count = std::uint64_t(exact);
            given += out[i].count;
            remainders.emplace_back(exact - double(out[i].count), i);
        }
        std::stable_sort(remainders.begin(), remainders.end(),
                         [](const auto& a, const auto& b) { return a.first > b.first; });
        for (std::size_t k = 0; given < paths && k < remainders.size(); ++k, ++given)
            ++out[remainders[k].second].count;
        return out;
    }

    /// Traces paths [begin, end) of emitter e into `record`.
    void trace(const Emitter& e, std::uint64_t begin, std::uint64_t end, ChunkRecord& record) const {
        for (std::uint64_t j = begin; j < end; ++j)
            tracePath(e, j, record);
    }

private:
    void tracePath(const Emitter& e, std::uint64_t j, ChunkRecord& record) const {
        Pcg32 rng(Hasher().value(settings_.seed).value(e.index).value(j).digest());
        // The start: the j-th point of R2 (Roberts 2018), shifted per light.
        const std::uint64_t shift = Hasher().value(settings_.seed).value(e.index).digest();
        const Vec2f u = r2Point(double(j) + 1.0, shift);
        const LightEmission::Start start = e.emission->start(u.x, u.y, e.count);
        Ray ray{start.origin, start.dir};
        Rgb power = start.power;
        const float roulette = 1.0f / power.maxComponent();
        VolumetricStats& c = record.counts;
        ++c.paths;
        bool scattered = false;
        std::uint32_t events = 0;
        const SurfaceScene* surfaces =
            scene_.surfaces && !scene_.surfaces->empty() ? scene_.surfaces.get() : nullptr;
        std::optional<RayOrigin> from; // the fiber a ray leaves (fiber transport)
        std::optional<OwnFiber> own;   // the fiber a flight leaves, as the medium holds it
        for (;;) {
            std::optional<SurfaceHit> surface;
            std::optional<MediumCollision> hit;
            float tSurface = std::numeric_limits<float>::infinity();
            if (rays_) {
                // The strands themselves (and the surfaces) as the path tracer meets them.
                if (const std::optional<RayHit> h = rays_->intersect(
                        ray.origin, ray.dir, std::numeric_limits<float>::infinity(),
                        from ? &*from : nullptr)) {
                    if (h->kind == RayHit::Kind::Surface) {
                        surface = SurfaceHit{h->t, h->surface, h->normal, h->geometricNormal};
                        tSurface = h->t;
                    } else {
                        hit = MediumCollision{h->t, ray.origin + h->t * ray.dir, h->tangent,
                                              fiberTypeAt(*scene_.groom, segmentStartPoint(
                                                  h->fiber.strand, h->fiber.segment))};
                        from = RayOrigin{h->fiber, slack_};
                    }
                }
            } else {
                // The nearest surface first: the medium is tracked up to it.
                if (surfaces)
                    surface = surfaces->intersect(ray.origin, ray.dir,
                                                  std::numeric_limits<float>::infinity());
                tSurface = surface ? surface->t : std::numeric_limits<float>::infinity();
                // From its first scattering on, the flight's deposits ride along.
                if (scattered) {
                    Deposits deposits(*this, record, ray);
                    hit = medium_.sampleCollision(ray.origin, ray.dir, tSurface, rng,
                                                  own ? &*own : nullptr, deposits);
                    deposits.finish(ray.dir, power);
                } else {
                    hit = medium_.sampleCollision(ray.origin, ray.dir, tSurface, rng);
                }
                if (hit)
                    surface.reset();
            }
            if (surface)
                from.reset();
            if (scattered && rays_)
                depositAlong(ray, hit ? hit->t : tSurface, power, record);
            if (surface && scattered && surfaceCells_) {
                const Vec3f x = ray.origin + surface->t * ray.dir;
                if (const std::int64_t slot = surfaceCells_->slotAt(x); slot >= 0)
                    record.surfaceDeposits.push_back({std::uint32_t(slot), power});
            }
            if (surface) {
                ++c.surfaceEvents;
                const Vec3f x = ray.origin + surface->t * ray.dir;
                power *= scene_.surfaceAlbedo[surface->surface];
                const Vec3f& ng = surface->geometricNormal;
                ray.origin = x + surfaceOffset(x) * ng;
                ray.dir = cosineHemisphere(surface->normal, rng.uniformFloat(), rng.uniformFloat());
                if (!(glm::dot(ray.dir, ng) > 0))
                    break; // below the surface: the shading normal's lobe dips under it
                own.reset();
            } else if (hit) {
                ++c.fiberEvents;
                const MarschnerBcsdf& bcsdf = bcsdfs_[hit->fiberType];
                const BcsdfSample s =
                    bcsdf.sample(-ray.dir, hit->tangent,
                                 {rng.uniformFloat(), rng.uniformFloat(), rng.uniformFloat(),
                                  rng.uniformFloat()});
                if (!s.valid())
                    break;
                power *= s.weight;
                ray.origin = hit->position;
                ray.dir = s.wi;
                own = OwnFiber{hit->position, hit->tangent};
            } else {
                break; // left the hair
            }
            scattered = true;
            ++events;
            if (power.isBlack())
                break;
            if (events >= settings_.maxDepth) {
                ++c.pathsAtDepthCap;
                break;
            }
            if (events >= settings_.rouletteDepth) {
                const float q = std::min(1.0f, power.maxComponent() * roulette);
                if (rng.uniformFloat() >= q)
                    break;
                power /= q;
            }
        }
        c.deepestPath = std::max(c.deepestPath, events);
    }

    /// A flight's crossings (FiberMedium::sampleCollision's `crossed`): ∫ λ dt
    /// over each run of its voxels in one cell, the λ without the share of
    /// the fiber it leaves (fiber_medium.h). A cell's slot is looked up once
    /// a run, not once a voxel.
    class Deposits {
    public:
        Deposits(const PathTracer& tracer, ChunkRecord& record, const Ray& ray)
            : ray_(ray)
            , cache_(tracer.cache_)
            , record_(record)
            , flight_(static_cast<std::uint32_t>(record.flights.size()))
            , first_(record.crossings.size()) {}
        void operator()(std::size_t, const glm::ivec3& ijk, float lambda, float t0, float t1) {
            const glm::ivec3 cell = cache_.cells().cellOfVoxel(ijk);
            if (cell != cell_) {
                flush();
                cell_ = cell;
                slot_ = cache_.cells().slotOfCell(cell);
                sum_ = 0;
                moment_ = Vec3f(0.0f);
            }
            const float weight = lambda * (t1 - t0);
            sum_ += weight;
            moment_ += weight * (ray_.origin + (0.5f * (t0 + t1)) * ray_.dir);
        }
        /// Ends the flight: its record, if it crossed any cell.
        void finish(const Vec3f& dir, const Rgb& power) {
            flush();
            if (record_.crossings.size() > first_)
                record_.addFlight(-dir, power, cache_.settings().shOrder);
        }

    private:
        void flush() {
            if (slot_ >= 0 && sum_ > 0)
                record_.crossings.push_back({std::uint32_t(slot_), flight_, sum_,
                                             moment_ / sum_ - cache_.cells().centre(cell_)});
        }
        const Ray& ray_;
        const RadianceCache& cache_;
        ChunkRecord& record_;
        std::uint32_t flight_;
        std::size_t first_;
        glm::ivec3 cell_{std::numeric_limits<int>::min()}; ///< of the run being summed
        std::int64_t slot_ = -1;
        float sum_ = 0;
        Vec3f moment_{0.0f}; ///< ∫ λ·x dt of the run
    };

    /// The fibers transport's flight origin + t·dir, t ∈ [0, tEnd], into the
    /// cells it crosses (the strands themselves are met by rays: no fiber is
    /// left out of λ).
    void depositAlong(const Ray& ray, float tEnd, const Rgb& power, ChunkRecord& record) const {
        Deposits deposits(*this, record, ray);
        medium_.walkVoxels(ray.origin, ray.dir, tEnd,
                           [&](std::size_t v, const glm::ivec3& ijk, float t0, float t1) {
                               deposits(v, ijk, medium_.grid().density[v], t0, t1);
                           });
        deposits.finish(ray.dir, power);
    }

    const VolumetricScene& scene_;
    const VolumetricSettings& settings_;
    const FiberMedium& medium_;
    const RayScene* rays_; ///< fiber transport; null: the medium
    float slack_ = 0;
    const RadianceCache& cache_;
    const SurfaceIrradiance* surfaceCells_;
    std::vector<MarschnerBcsdf> bcsdfs_;
    Vec3f centre_{0.0f};
    float radius_ = 0;
};

void add(VolumetricStats& into, const VolumetricStats& c) {
    into.paths += c.paths;
    into.fiberEvents += c.fiberEvents;
    into.surfaceEvents += c.surfaceEvents;
    into.crossings += c.crossings;
    into.pathsAtDepthCap += c.pathsAtDepthCap;
    into.deepestPath = std::max(into.deepestPath, c.deepestPath);
}

} // namespace

void VolumetricSettings::validate() const {
    cache.validate();
    if (!(pathsPerCell > 0 && pathsPerCell <= 1e4f))
        throw InputError(strCat("volumetric: paths_per_cell = ", pathsPerCell,
                                ": expected a number in (0, 10000]"));
    if (paths > (1ull << 40))
        throw InputError(strCat("volumetric: paths = ", paths, ": expected at most 2^40"));
    if (maxDepth < 1 || maxDepth > 100'000)
        throw InputError(
            strCat("volumetric: max_depth = ", maxDepth, ": expected an integer in [1, 100000]"));
    if (rouletteDepth < 1 || rouletteDepth > 100'000)
        throw InputError(strCat("volumetric: roulette_depth = ", rouletteDepth,
                                ": expected an integer in [1, 100000]"));
}

void VolumetricSettings::hashInto(Hasher& h) const {
    h.value(paths).value(pathsPerCell).value(cache.shOrder);
    h.value(cache.cellVoxels)
        .value(cache.denoise)
        .value(cache.gradients)
        .value(maxDepth)
        .value(rouletteDepth)
        .value(seed)
        .value(transport);
}

std::ostream& operator<<(std::ostream& os, const VolumetricSettings& s) {
    return os << "VolumetricSettings(paths=" << s.paths << ", pathsPerCell=" << s.pathsPerCell
              << ", " << s.cache << ", maxDepth=" << s.maxDepth
              << ", rouletteDepth=" << s.rouletteDepth << ", seed=" << s.seed << ")";
}

std::ostream& operator<<(std::ostream& os, const VolumetricStats& s) {
    return os << "VolumetricStats(" << s.paths << " paths, " << s.fiberEvents << " fiber and "
              << s.surfaceEvents << " surface events, " << s.crossings << " crossings, deepest "
              << s.deepestPath << ", " << s.pathsAtDepthCap << " at the depth cap; " << s.cells
              << " cells, " << s.bytes << " bytes; trace " << s.traceSeconds << " s, finish "
              << s.finishSeconds << " s)";
}

MultipleScatteringSolution solveMultipleScattering(const VolumetricScene& scene,
                                                   const VolumetricSettings& settings,
                                                   std::uint64_t memoryBudget) {
    settings.validate();
    if (!scene.grid)
        throw std::invalid_argument("solveMultipleScattering: no fiber grid");
    if (scene.fibers.size() < scene.grid->fiberTypeCount())
        throw std::invalid_argument("solveMultipleScattering: one fiber per fiber type is needed");
    if (scene.surfaceAlbedo.size() != (scene.surfaces ? scene.surfaces->surfaceCount() : 0))
        throw std::invalid_argument("solveMultipleScattering: one albedo per surface is needed");
    const ThreadLimit threadLimit(settings.threads);
    const auto start = Clock::now();

    // The medium's records first (16 bytes a voxel, a copy of the grid's λ
    // and o, and its block table); the cache gets what is left.
    const FiberMedium medium(*scene.grid);
    const std::uint64_t cacheBudget =
        memoryBudget > medium.memoryBytes() ? memoryBudget - medium.memoryBytes() : 1;
    MultipleScatteringSolution out;
    VolumetricStats& stats = out.stats;
    out.cache = std::make_unique<RadianceCache>(*scene.grid, settings.cache, cacheBudget);
    RadianceCache& cache = *out.cache;
    stats.cells = cache.cellCount();
    stats.pathsPerLight.assign(scene.lights.size(), 0);
    if (scene.surfaces && !scene.surfaces->empty() && cache.cellCount() > 0) {
        // The surfaces within a cell of the hair's cells.
        const CellGrid& cells = cache.cells();
        out.surfaces = std::make_unique<SurfaceIrradiance>(
            *scene.surfaces, CellGrid(cells.voxelSize(), cells.cellVoxels(), cells.boxMin() - 1,
                                      cells.boxDims() + 2));
        stats.surfaceCells = out.surfaces->cellCount();
    }

    std::unique_ptr<RayScene> rays;
    if (settings.transport == VolumetricTransport::Fibers) {
        if (!scene.groom)
            throw std::invalid_argument("solveMultipleScattering: fiber transport needs the groom");
        rays = std::make_unique<RayScene>(*scene.groom, scene.grid->info.fiberScale, scene.surfaces);
    }
    const PathTracer tracer(scene, settings, medium, rays.get(), cache, out.surfaces.get());
    const std::uint64_t paths =
        settings.paths > 0 ? settings.paths
                           : std::uint64_t(std::ceil(double(settings.pathsPerCell) * double(cache.cellCount())));
    const std::vector<Emitter> emitters = cache.cellCount() > 0 ? tracer.emitters(paths) : std::vector<Emitter>{};

    // Chunks: fixed ranges of one emitter's paths.
    struct Chunk {
        std::size_t emitter;
        std::uint64_t begin, end;
    };
    std::vector<Chunk> chunks;
    for (std::size_t e = 0; e < emitters.size(); ++e) {
        stats.pathsPerLight[emitters[e].index] = emitters[e].count;
        for (std::uint64_t b = 0; b < emitters[e].count; b += kChunkPaths)
            chunks.push_back({e, b, std::min(emitters[e].count, b + kChunkPaths)});
    }
    const std::size_t slots = cache.cellCount();
    const std::size_t buckets = std::clamp<std::size_t>(slots / 512, 1, kMaxBuckets);
    const std::size_t bucketSlots = (slots + buckets - 1) / std::max<std::size_t>(buckets, 1);

    ProgressReporter progress("multiple scattering", paths, settings.progress);
    const std::size_t batchChunks = std::max<std::size_t>(
        16, kBatchChunksPerThread * std::size_t(tbb::this_task_arena::max_concurrency()));
    std::vector<ChunkRecord> records(batchChunks);
    for (std::size_t batch = 0; batch < chunks.size(); batch += batchChunks) {
        const std::size_t n = std::min(batchChunks, chunks.size() - batch);
        tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
            throwIfInterrupted();
            flushDenormalsToZero();
            const Chunk& chunk = chunks[batch + k];
            ChunkRecord& r = records[k];
            r.flights.clear();
            r.basis.clear();
            r.crossings.clear();
            r.surfaceDeposits.clear();
            r.counts = {};
            tracer.trace(emitters[chunk.emitter], chunk.begin, chunk.end, r);
            r.counts.crossings = r.crossings.size();
            // Group the crossings by bucket, keeping their order within each.
            r.bucketStart.assign(buckets + 1, 0);
            for (const Crossing& x : r.crossings)
                ++r.bucketStart[x.slot / bucketSlots + 1];
            for (std::size_t b = 0; b < buckets; ++b)
                r.bucketStart[b + 1] += r.bucketStart[b];
            r.sorted.resize(r.crossings.size());
            std::vector<std::uint32_t> next(r.bucketStart.begin(), r.bucketStart.end() - 1);
            for (const Crossing& x : r.crossings)
                r.sorted[next[x.slot / bucketSlots]++] = x;
            r.crossings.swap(r.sorted);
            progress.update(chunk.end - chunk.begin);
        });
        const std::size_t nc = std::size_t(settings.cache.coefficients());
        tbb::parallel_for(std::size_t(0), buckets, [&](std::size_t b) {
            for (std::size_t k = 0; k < n; ++k) {
                const ChunkRecord& r = records[k];
                for (std::uint32_t i = r.bucketStart[b]; i < r.bucketStart[b + 1]; ++i) {
                    const Crossing& x = r.crossings[i];
                    // The next crossing's cell and basis on their way while this one adds.
                    if (i + 1 < r.bucketStart[b + 1]) {
                        const Crossing& next = r.crossings[i + 1];
                        cache.prefetch(next.slot);
                        const float* y = r.basis.data() + std::size_t(next.flight) * nc;
                        for (std::size_t j = 0; j < nc; j += 16)
                            __builtin_prefetch(y + j);
                    }
                    cache.deposit(x.slot, r.basis.data() + std::size_t(x.flight) * nc,
                                  r.flights[x.flight].power * x.weight, x.offset);
                }
            }
        });
        for (std::size_t k = 0; k < n; ++k) {
            add(stats, records[k].counts);
            for (const SurfaceDeposit& d : records[k].surfaceDeposits)
                out.surfaces->deposit(d.slot, d.power);
        }
    }
    progress.finish();
    stats.traceSeconds = secondsSince(start);

    const auto finishStart = Clock::now();
    std::vector<ScatteringKernel> kernels;
    for (const FiberParams& fiber : scene.fibers)
        kernels.push_back(
            ScatteringKernel::loadOrBuild(fiber, settings.cache.shOrder, scene.kernelCache));
    cache.finish(std::move(kernels));
    stats.finishSeconds = secondsSince(finishStart);
    stats.bytes = cache.memoryBytes() + (out.surfaces ? out.surfaces->memoryBytes() : 0);
    return out;
}

} // namespace hairvox
