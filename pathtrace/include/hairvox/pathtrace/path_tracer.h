// hairvox pathtrace: the ground truth — an unbiased path tracer of the same
// fibers with the same Marschner f_s (docs/DESIGN.md §8).
//
// Geometry: the strands as the ribbons exact mode casts against (width k·D,
// geometry/ray_scene.h), opaque Lambertian surfaces (spheres and triangle
// meshes, geometry/surface_scene.h: a mesh's interpolated shading normal), the
// rasterizer's pinhole camera (geometry/camera.h) with a box pixel filter. Every
// ray that meets a fiber scatters there (the far-field f_s needs only the
// tangent; nothing passes through a fiber unscattered, as dual scattering
// assumes).
//
// At a fiber, with ω_o toward where the path came from:
//  - next-event estimation toward every light: E·f_s(ω_l, ω_o)·cos θ_l, with a
//    binary shadow ray through the real strands and surfaces (the point's own
//    fiber skipped, RayScene::isOwnFiber);
//  - continuation: ω_i sampled from f_s·cos θ_i (MarschnerBcsdf::sample),
//    throughput × f_s·cos θ_i / pdf.
// At a surface: Lambertian, next-event estimation and a cosine-weighted
// continuation (throughput × albedo). The background is what camera rays see
// where they meet nothing; it lights nothing (as in the rasterizer).
//
// The environment light (geometry/environment_map.h), when the scene has one:
// at every scattering event one direction is drawn from the map's importance
// distribution (luminance × sin θ) and shadow-tested like a light, and every
// continuation ray that escapes sees the map — each weighted by the power
// heuristic against the other strategy's density (the fiber's f_s sampling,
// MarschnerBcsdf::pdf, or the surface's cos θ/π), so that a sun a few pixels
// wide is found by light sampling and a narrow R lobe by the fiber's. Camera
// rays that meet nothing see its backdrop when it is visible, the background
// colour otherwise. Escaped light is filed like a light's: by lobe at depth 1
// on a fiber (the direct_* layers), in `multiple` deeper, in `surface` on a
// path that began on a surface. A path stopped by `maxDepth` still traces its
// last continuation to the environment: that light is of the path's own
// depth (the other strategy of its last event), so that maxDepth = 1 is
// single scattering in full.
//
// Russian roulette from depth `rouletteDepth` on, with survival probability
// min(1, max channel of the throughput): unbiased, and light hair (albedo ~0.6
// per scattering) still reaches dozens of bounces when they matter. `maxDepth`
// is a guard, not a truncation: the statistics count the paths it stopped and
// the throughput they still carried (the energy the cap lost).
//
// Sampling: samples come in two independent halves, A (even sample indices)
// and B (odd). Sample 2j + h takes every uniform — its position in the pixel
// first, then each scattering event's — from the j-th point of a padded
// Owen-scrambled Sobol sampler (core/sobol.h; Burley 2020, pbrt-v4's
// PaddedSobolSampler): one (0,2)-sequence per pair of dimensions, so that the
// first 2^m samples of a half are stratified in every pair. Its randomization
// is seeded by (seed, pixel, h): the two halves are independent
// randomizations of one sequence, i.e. independent, identically distributed
// estimates — what the noise floor below needs. (One sequence split between
// the halves would not do: its points 2j and 2j + 1 fall in opposite halves
// of the pixel, the halves' errors would be anticorrelated and their
// difference would overstate the whole's error.) The image depends on (seed,
// spp) only — not on the thread count — and a run that continues an earlier
// one from sample N on gives the image the uninterrupted run would have, its
// samples having the same indices. Work proceeds in passes of two samples per
// pixel (one per half: spp is rounded up to an even number); the run stops
// after `spp` samples, at `timeLimit` seconds, or on Ctrl-C, always at the end
// of a whole pass (a pass interrupted midway is discarded), so every pixel has
// the same number of samples.
//
// Noise: the halves are two independent estimates of the same image, so the
// difference between half A and the whole is an unbiased measure of the
// whole's own error, whatever the samples' correlation within a half (a
// low-discrepancy sequence makes the samples' spread overstate it):
// E|I − μ| = E|I_A − I| per value (film/image_compare.h uses this).
//
// The film (film/film.h; layers in the rasterizer's names where the meaning is
// the same, all full-precision floats so that a run can be continued):
//   "" (beauty), A          the pixel's radiance and coverage (hair and surfaces)
//   hair.A                  the share of samples whose first hit is a fiber
//   direct_R, direct_TT, direct_TRT
//                           paths of depth 1 on a fiber (camera → fiber → light):
//                           single scattering with shadowing, per lobe — the
//                           rasterizer's layers of the same names
//   multiple                paths of depth ≥ 2 whose first hit is a fiber: multiple
//                           scattering (dual scattering's back_direct + scatter)
//   surface                 paths whose first hit is a surface
//   background              camera rays that meet nothing
//   half_a, hair_half_a     the beauty and the hair's radiance (direct + multiple)
//                           of half A alone: the noise of every comparison
//                           against this image
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/film/film.h>
#include <hairvox/geometry/camera.h>
#include <hairvox/geometry/environment_map.h>
#include <hairvox/geometry/light.h>
#include <hairvox/geometry/surface_scene.h>
#include <hairvox/shading/fiber_params.h>
#include <hairvox/strands/fiber_scale.h>
#include <hairvox/strands/groom.h>

#include <cstdint>
#include <memory>
#include <ostream>
#include <vector>

namespace hairvox {

/// What the path tracer sees: the same fibers, lights, camera and surfaces as
/// the rasterizer.
struct PathTraceScene {
    const Groom* groom = nullptr;
    FiberScale fiberScale;
    /// The fiber of each fiber type (Groom::fiberType); a fiber scatters with
    /// its segment's. At least one.
    std::vector<FiberParams> fibers{FiberParams{}};
    std::vector<Light> lights;
    CameraParams camera;
    /// The opaque surfaces (null: none) and each one's Lambertian albedo, in
    /// the surfaces' order (spheres, then meshes).
    std::shared_ptr<const SurfaceScene> surfaces;
    std::vector<Rgb> surfaceAlbedo;
    Rgb background{0.0f};
    /// The environment light (null: none). Lights every path (see above).
    std::shared_ptr<const EnvironmentMap> environment;
    /// Camera rays that meet nothing see the environment's backdrop instead
    /// of `background`.
    bool environmentVisible = false;
};

struct PathTraceSettings {
    std::uint32_t spp = 64;            ///< samples per pixel to reach, [1, 10^6], rounded up to even
    /// Seconds; 0: none. The first of spp and this stops the run, after one pass at least.
    double timeLimit = 0;
    std::uint32_t maxDepth = 1000;     ///< scattering events a path may have, [1, 10^5]
    std::uint32_t rouletteDepth = 3;   ///< Russian roulette from this depth on, [1, 10^5]
    std::uint64_t seed = 1;
    int threads = 0;       ///< 0: all cores
    bool progress = false; ///< a progress bar with ETA on stderr

    /// Throws InputError naming the setting and its range.
    void validate() const;
};

std::ostream& operator<<(std::ostream& os, const PathTraceSettings& s);

struct PathTraceStats {
    std::uint32_t spp = 0;          ///< samples per pixel in the film (with a continued run's)
    std::uint32_t sppThisRun = 0;   ///< samples per pixel this run added
    double seconds = 0;             ///< wall time of this run
    std::uint64_t paths = 0;        ///< this run's
    std::uint64_t rays = 0;         ///< camera and continuation rays (closest hit)
    std::uint64_t shadowRays = 0;   ///< next-event rays (any hit)
    /// Of those, toward directions drawn from the environment map.
    std::uint64_t environmentShadowRays = 0;
    /// Continuation rays that escaped to the environment (after a scattering event).
    std::uint64_t escapedRays = 0;
    std::uint64_t scatteringEvents = 0; ///< at fibers and surfaces
    std::uint32_t deepestPath = 0;  ///< the most scattering events a path had
    std::uint64_t pathsAtDepthCap = 0;
    /// Mean over all paths of the throughput (mean of RGB) that paths stopped
    /// by maxDepth still carried: an upper bound on the share of radiance lost.
    double energyAtDepthCap = 0;
    bool timeLimited = false;       ///< stopped by the time limit before spp
    bool interrupted = false;       ///< stopped by Ctrl-C (the film holds the whole passes before)

    double raysPerSecond() const { return seconds > 0 ? double(rays + shadowRays) / seconds : 0; }
    double pathsPerSecond() const { return seconds > 0 ? double(paths) / seconds : 0; }
};

std::ostream& operator<<(std::ostream& os, const PathTraceStats& s);

struct PathTraceOutput {
    Film film;
    PathTraceStats stats;
};

/// Renders the scene. `previous` (optional): a film this function produced for
/// the same scene and seed with `previousSpp` (even) samples per pixel; the run
/// adds samples from there on. Throws InputError for invalid settings or a previous
/// film of another size or without the layers. Ctrl-C (throwIfInterrupted) is
/// not thrown: the run stops and says so in its statistics.
PathTraceOutput pathTrace(const PathTraceScene& scene, const PathTraceSettings& settings,
                          const Film* previous = nullptr, std::uint32_t previousSpp = 0);

} // namespace hairvox
