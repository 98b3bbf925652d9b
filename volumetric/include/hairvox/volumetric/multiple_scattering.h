// hairvox volumetric: multiple scattering solved on the fiber grid
// (docs/DESIGN.md §9) — the first pass of the volumetric integrator.
//
// Light paths start at the lights and are traced through the fiber grid as an
// anisotropic medium (fiber_medium.h), scattering at each fiber they meet by
// the same Marschner f_s the shader and the path tracer use
// (MarschnerBcsdf::sample: f_s is reciprocal, so drawing the continuation
// ω ∝ f_s(ω_l, ω)·cos θ_ω with ω_l toward where the light came from is the
// adjoint of the path tracer's step) and off the opaque surfaces
// (Lambertian, both ways: light the skin reflects lights the hair, and the
// hair's scattered light lights the skin through the cache's irradiance).
// From its first scattering on, every flight of a path deposits into the
// cells it crosses the λ-weighted track-length estimate of their radiance
// (Φ·∫λ dt/Λ, at the flight's direction and the λ-weighted mean of the
// track's points, for the cell's gradient; radiance_cache.h; λ without the
// share of the fiber the flight leaves, which it neither meets nor lights:
// fiber_medium.h), and where it
// meets a surface its power onto the surface (surface_irradiance.h): the
// caches hold light that has scattered at least once, so the fragments'
// single scattering — f_s·V per light with the global term's V — and the
// surfaces' direct lighting are not counted twice. A path ends by
// absorption (Russian roulette), by leaving the cells, or at maxDepth.
//
// Emission. A light sends its paths only toward the hair: through the texels
// of a plane across its axis that the hair's voxels project to
// (src/light_emission.h), each carrying its share of the power the light
// sends through them; the paths are shared among the lights by that power.
// A path's start is the j-th point of the R2 sequence (Roberts 2018, as the
// path tracer places pixel samples), shifted per light; its other decisions
// draw from a PCG32 stream seeded by (seed, light, j).
//
// Determinism. Paths are traced in chunks of fixed photon ranges, each
// chunk recording its flights' cell crossings; the crossings are then
// bucketed by cell and added to the cells bucket by bucket in parallel, each
// bucket in chunk order — the same bytes for any thread count.
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/core/rgb.h>
#include <hairvox/geometry/light.h>
#include <hairvox/geometry/ray_scene.h>
#include <hairvox/geometry/surface_scene.h>
#include <hairvox/shading/fiber_params.h>
#include <hairvox/volumetric/radiance_cache.h>
#include <hairvox/volumetric/surface_irradiance.h>

#include <cstdint>
#include <memory>
#include <ostream>
#include <vector>

namespace hairvox {

class DiskCache;
struct FiberGrid;

/// What the light paths are traced through.
enum class VolumetricTransport {
    Medium, ///< the fiber grid as an anisotropic medium (fiber_medium.h)
    Fibers, ///< the strands themselves (geometry/ray_scene.h, the path tracer's ribbons)
};

inline constexpr EnumNames<VolumetricTransport, 2> kVolumetricTransportNames{{{
    {VolumetricTransport::Medium, "medium"},
    {VolumetricTransport::Fibers, "fibers"},
}}};
inline const char* toString(VolumetricTransport t) {
    return kVolumetricTransportNames.name(t);
}

struct VolumetricSettings {
    /// Light paths traced; 0: pathsPerCell per cache cell.
    std::uint64_t paths = 0;
    float pathsPerCell = 12; ///< (0, 1e4]
    RadianceCacheSettings cache;
    std::uint32_t maxDepth = 1000;   ///< scattering events a path may have, [1, 10^5]
    std::uint32_t rouletteDepth = 3; ///< Russian roulette from this depth on, [1, 10^5]
    std::uint64_t seed = 1;
    VolumetricTransport transport = VolumetricTransport::Medium;
    int threads = 0;       ///< 0: all cores
    bool progress = false; ///< a progress bar on stderr

    /// Throws InputError naming the setting and its range.
    void validate() const;
    /// Every setting the solution depends on (not threads or progress).
    void hashInto(Hasher& hasher) const;
};

std::ostream& operator<<(std::ostream& os, const VolumetricSettings& s);

/// What the solve sees: the fiber grid (its fiber scale gives k and D), each
/// fiber type's optics, the lights, and the opaque surfaces with their albedo.
struct VolumetricScene {
    const FiberGrid* grid = nullptr;
    /// The strands (VolumetricTransport::Fibers; their fiber types index `fibers`).
    const Groom* groom = nullptr;
    std::vector<FiberParams> fibers{FiberParams{}}; ///< per fiber type; at least the grid's types
    std::vector<Light> lights;
    std::shared_ptr<const SurfaceScene> surfaces; ///< null: none
    std::vector<Rgb> surfaceAlbedo;               ///< per surface
    /// Where the fiber types' scattering kernels are kept between processes
    /// (ScatteringKernel::loadOrBuild); null: built in every solve.
    const DiskCache* kernelCache = nullptr;
};

struct VolumetricStats {
    std::uint64_t paths = 0;
    std::uint64_t fiberEvents = 0;   ///< scatterings at fibers
    std::uint64_t surfaceEvents = 0; ///< reflections off surfaces
    std::uint64_t crossings = 0;     ///< (flight, cell) deposits
    std::uint64_t surfaceCells = 0;  ///< cells of the surface irradiance
    std::uint64_t pathsAtDepthCap = 0;
    std::uint32_t deepestPath = 0;
    std::uint64_t cells = 0;
    std::uint64_t bytes = 0;         ///< held by the cache
    double traceSeconds = 0;         ///< tracing and depositing
    double finishSeconds = 0;        ///< kernels and the outgoing tables
    std::vector<std::uint64_t> pathsPerLight;
};

std::ostream& operator<<(std::ostream& os, const VolumetricStats& s);

struct MultipleScatteringSolution {
    std::unique_ptr<RadianceCache> cache;
    /// The scattered light on the surfaces near the hair; null without surfaces.
    std::unique_ptr<SurfaceIrradiance> surfaces;
    VolumetricStats stats;
};

/// Solves the scene's multiple scattering into a finished radiance cache.
/// Throws InputError for invalid settings or a cache over `memoryBudget`
/// bytes; polls throwIfInterrupted().
MultipleScatteringSolution solveMultipleScattering(const VolumetricScene& scene,
                                                   const VolumetricSettings& settings,
                                                   std::uint64_t memoryBudget);

} // namespace hairvox
