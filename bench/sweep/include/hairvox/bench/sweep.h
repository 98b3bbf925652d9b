// hairvox bench: the benchmark sweep — run time against error, and how cost
// grows (docs/DESIGN.md §6 "Runtime against error"; `hairvox bench`).
//
// The sweep is a program over the pipeline's public API, split by job:
// job.h (a job and its files, worker processes), measure.h (running one job:
// timings and errors), report.h (CSV and Markdown), plots.h (matplotlib).
//
// Accuracy sweep. For each scene: global-term mode (exact, grid, approx) ×
// voxel size × shading rate. Each configuration is rendered end to end with
// renderScene() (outputs written to a scratch directory, so the `write` stage
// is real) `runs` times (once if the first run exceeds `singleRunAbove`);
// every stage time is the median over the runs and the total is the median of
// the totals. It is compared with the scene's
// reference, an exact-mode render of the same scene and camera:
//  - image: relative L1 = Σ|I − I_ref| / Σ|I_ref| and relative RMSE =
//    sqrt(mean (I − I_ref)²) / mean I_ref of the beauty RGB over hair pixels
//    (the reference's Film::hairAlpha > 0), per pixel and over the means of
//    kAccuracyBlock² pixel blocks (where the reference's noise averages out);
//  - probe: MAE of V and T_s (transmittance/probe.h) at `probePoints` points on
//    the fibers, toward every light, against exact mode with `probeRays` rays
//    spread over a disk of radius = the configuration's voxel size (the
//    footprint a voxel resolves). The head is left out of the probe: points it
//    shadows are GlobalTerm::blocked() in every mode and would only dilute it.
// The image reference uses `referenceRays` rays per shading point (exact mode
// costs K Embree rays per point: 1–16 is affordable per frame, 256 is not)
// spread over a disk of one default voxel h0, the scene's grid voxel size
// (its grid.voxel_size, else defaultVoxelSize(groom)), rendered as two
// independent halves of K/2 rays (seeds 1 and 2): their mean is the reference
// and half A's difference from it its noise, which film/image_compare.h
// removes from every image error. Exact configurations of the sweep use the
// same footprint with fewer rays. Voxel sizes are given as multiples of h0.
//
// Scaling sweep: grid mode at the default voxel size, fragment shading, over
// scenes of increasing segment count and increasing image size, with the
// growth rate of each stage's time and of peak memory as the least-squares
// exponent k of  cost ∝ size^k  (fitPowerLaw); and a real groom at
// decreasing voxel sizes, fitted against its active voxels (issue 16: the
// global term's time and memory linear in them).
//
// Model sweep (docs/DESIGN.md §8): how far the dual-scattering *model* is from
// the light transport it approximates. Each scene × hair colour (a eumelanin
// concentration) is path traced — the reference, of the same fibers with the
// same f_s (pathtrace/), its two independent halves giving its noise — and
// rendered with dual scattering in each global-term mode and with the
// volumetric integrator (docs/DESIGN.md §9). The hair's radiance
// (pipeline's hairRadianceOf: the beauty without head and background) is
// compared per pixel and as means over block × block pixels, where the
// rasterizer's point sampling and the path tracer's per-pixel noise average
// out but a bias does not: relative L1 raw, the reference's noise floor, the
// L1 with the noise removed (film/image_compare.h) and the signed bias; with
// the reference's time, samples, rays/s and paths/s. The time-against-error
// frontier adds the volumetric integrator at other budgets (paths per cell)
// and the path tracer itself at fewer samples than the reference, seeded
// apart from it: its error with the reference's noise removed is its own
// noise, so every method is read on one axis — what a time budget buys.
//
// Isolation: with a worker command (the CLI passes `hairvox bench --one`),
// every job runs in its own child process, so its peak resident memory is
// that job's alone; without one (tests) jobs run in this process and peak
// memory is not reported. The exact reference is rendered once per scene and
// cached in the output directory's .work/ for the run (removed at the end).
//
// Outputs in SweepOptions::outDir, rewritten after each scene:
//   results.csv            one row per measured configuration (kBenchCsvColumns)
//   host.json              the machine (bench/host: CPU, cores, SIMD target, calibration)
//   results.md             the tables: summary, per scene, scaling with exponents
//   scaling_fits.csv       the fitted growth exponents
//   runtime_vs_error.png   total time against image error, one curve (the
//                          Pareto front) per scene, points labelled (matplotlib)
//   frontier.png           the model sweep's time against error per scene and
//                          hair colour: dual scattering, volumetric over its
//                          budgets and path tracing over its samples
//   scaling.png            time against segment count, pixel count and active voxels
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/pipeline/scene.h>
#include <hairvox/strands/procedural.h>
#include <hairvox/transmittance/probe.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace hairvox {

/// A scene of the sweep: a scene file, or the embedded default scene (a
/// procedural groom's style swapped when `style` is set), then overrides. The
/// sweeps of full() and quick() start from data/scenes/key_back.json, the
/// default look under its two directional lights.
struct BenchScene {
    std::string label;               ///< names the scene in tables and plots
    std::filesystem::path file;      ///< scene JSON; empty: defaultScene()
    std::optional<GroomStyle> style; ///< procedural grooms only: replaces the groom's style
    std::uint32_t strands = 0;       ///< procedural grooms: strand count; 0: the scene's
    /// Procedural grooms: points per strand; 0: the scene's, or the style's
    /// default when `style` swaps it.
    std::uint32_t pointsPerStrand = 0;
    std::uint32_t width = 0, height = 0; ///< resolution; 0: the scene's
    std::optional<double> voxelSize;     ///< the grid's voxel size (metres); unset: the scene's
    /// Replaces the fiber's absorption by this eumelanin concentration (no
    /// pheomelanin; FiberParams::sigmaFromMelanin).
    std::optional<float> eumelanin;

    /// The scene with the overrides applied, validated; writes no outputs.
    Scene build() const;
    /// This scene `width` pixels wide, its height keeping the camera's aspect.
    BenchScene atWidth(std::uint32_t width) const;
};

/// One point of the accuracy sweep.
struct BenchConfig {
    GlobalTermMode mode = GlobalTermMode::Grid;
    /// Grid and approx: voxel size in units of h0; exact: footprint radius in units of h0.
    double voxelScale = 1;
    std::uint32_t rays = 1; ///< exact: rays per shading point
    ShadingRate shadingRate = ShadingRate::Fragment;
    /// Dual scattering (the mode above), volumetric (the model sweep: its
    /// single scattering in grid mode, its multiple scattering solved on the
    /// grid) or path tracing (the model sweep's time-against-error frontier).
    Integrator integrator = Integrator::DualScattering;
    /// Volumetric: its budget, light paths per cache cell; 0: the scene's.
    float pathsPerCell = 0;
    /// Path tracing: samples per pixel, with another seed than the reference's.
    std::uint32_t spp = 0;

    /// "grid x1.4", "exact K=4", "volumetric", "volumetric 4 paths/cell", "path 16 spp".
    std::string label() const;
    /// The mode's name, or the integrator's (the CSV's "mode").
    std::string method() const;
};

/// y ≈ coefficient · x^exponent by least squares on (ln x, ln y).
struct PowerLawFit {
    double exponent = 0;
    double coefficient = 0;
    double r2 = 0; ///< coefficient of determination in log space
};

/// Uses the pairs with x > 0 and y > 0; nullopt with fewer than two distinct x.
std::optional<PowerLawFit> fitPowerLaw(std::span<const double> x, std::span<const double> y);

/// Side in pixels of the blocks whose means the accuracy sweep also compares
/// (BenchMeasurement::imageBlocks). Measured on the default scene at 512²
/// against an exact reference of K = 4 rays: the reference's noise floor in
/// rel L1 is ~0.05 per pixel, at the level of the grid's error, and a
/// quarter of that over 4×4 blocks, below it.
inline constexpr int kAccuracyBlock = 4;

/// What was measured for one configuration.
struct BenchMeasurement {
    StageTimes times;        ///< per-stage medians over the runs
    double totalSeconds = 0; ///< median of the end-to-end totals
    /// Of times.globalTerm, the lights' preparation (median; the rest is the
    /// lookups made while shading).
    double prepareSeconds = 0;
    int runs = 0;
    std::optional<double> peakMiB; ///< peak resident memory of the job's own process
    std::uint64_t segments = 0, shadingPoints = 0, activeVoxels = 0;
    double voxelSize = 0;        ///< grid voxel size, or the exact mode's footprint radius
    double defaultVoxelSize = 0; ///< h0
    std::optional<ImageError> image;
    /// The accuracy sweep's image error over kAccuracyBlock² means: where the
    /// exact reference's few rays per point average out (resolvable errors).
    std::optional<ImageError> imageBlocks;
    std::optional<ProbeError> probe;
    std::optional<PathTraceStats> pathTrace; ///< a path-traced reference's
};

enum class BenchSweepKind {
    Reference,     ///< the scene's exact reference render (one run)
    Accuracy,      ///< a configuration of the accuracy sweep
    Segments,      ///< scaling with segment count
    Pixels,        ///< scaling with image size
    Voxels,        ///< scaling with active voxels (one groom, decreasing voxel sizes)
    PathReference, ///< the model sweep's path-traced reference of a scene and hair colour
    Model,         ///< dual scattering in one mode against that reference
};

inline constexpr EnumNames<BenchSweepKind, 7> kBenchSweepKindNames{{{
    {BenchSweepKind::Reference, "reference"},
    {BenchSweepKind::Accuracy, "accuracy"},
    {BenchSweepKind::Segments, "segments"},
    {BenchSweepKind::Pixels, "pixels"},
    {BenchSweepKind::Voxels, "voxels"},
    {BenchSweepKind::PathReference, "path_reference"},
    {BenchSweepKind::Model, "model"},
}}};
inline const char* toString(BenchSweepKind kind) {
    return kBenchSweepKindNames.name(kind);
}

struct BenchRow {
    BenchSweepKind kind = BenchSweepKind::Accuracy;
    std::string scene;              ///< BenchScene::label
    std::optional<float> eumelanin; ///< BenchScene::eumelanin
    BenchConfig config;
    std::uint32_t width = 0, height = 0;
    int block = 0; ///< side in pixels of the blocks of m.imageBlocks; 0: none
    BenchMeasurement m;
};

/// Least-squares growth exponents of a scaling sweep (nullopt where not fitted).
struct ScalingFit {
    BenchSweepKind kind = BenchSweepKind::Segments;
    std::optional<PowerLawFit> total, voxelize, globalTerm, prepare, rasterShade, peakMemory;
};

inline constexpr std::array<const char*, 39> kBenchCsvColumns = {"sweep",
                                                                 "scene",
                                                                 "mode",
                                                                 "voxel_scale",
                                                                 "voxel_size",
                                                                 "rays",
                                                                 "shading_rate",
                                                                 "width",
                                                                 "height",
                                                                 "segments",
                                                                 "runs",
                                                                 "load_s",
                                                                 "voxelize_s",
                                                                 "tables_s",
                                                                 "global_term_s",
                                                                 "raster_s",
                                                                 "shade_s",
                                                                 "write_s",
                                                                 "total_s",
                                                                 "peak_mib",
                                                                 "shading_points",
                                                                 "active_voxels",
                                                                 "rel_l1",
                                                                 "rel_rmse",
                                                                 "mae_v",
                                                                 "mae_ts",
                                                                 "eumelanin",
                                                                 "rel_bias",
                                                                 "noise_floor_l1",
                                                                 "rel_l1_noise_removed",
                                                                 "spp",
                                                                 "rays_per_s",
                                                                 "paths_per_s",
                                                                 "block_rel_l1",
                                                                 "block_noise_floor_l1",
                                                                 "block_rel_l1_noise_removed",
                                                                 "global_term_prepare_s",
                                                                 "paths_per_cell",
                                                                 "block"};

/// The model sweep (see the file comment).
struct ModelSweepOptions {
    std::vector<BenchScene> scenes;
    /// Hair colours: a name and a eumelanin concentration (no pheomelanin).
    std::vector<std::pair<std::string, float>> melanins{
        {"blond", 0.3f}, {"medium", 1.3f}, {"dark", 3.0f}};
    std::vector<GlobalTermMode> modes{GlobalTermMode::Exact, GlobalTermMode::Grid,
                                      GlobalTermMode::Approx};
    /// The volumetric integrator in every cell too, beside dual scattering.
    bool volumetric = true;
    /// The time-against-error frontier: the volumetric integrator at these
    /// budgets too (paths per cell, (0, 10^4]; its default budget is the row
    /// above), and the path tracer at these samples per pixel (each below
    /// `spp`, seeded apart from the reference, so its error is its own noise).
    std::vector<float> frontierPathsPerCell;
    std::vector<std::uint32_t> frontierSpp;
    std::uint32_t spp = 256; ///< of each path-traced reference, [2, 10^6]
    double timeLimit = 0;    ///< seconds per reference, 0: none; the first of spp and this stops it
    int block = 8;           ///< side in pixels of the compared blocks, [1, 64]

    /// Jobs per scene and hair colour: the reference and each method.
    std::size_t jobsPerCell() const;
};

struct SweepOptions {
    std::vector<BenchScene> scenes;       ///< the accuracy sweep
    std::vector<double> voxelScales;      ///< grid and approx voxel sizes, × h0
    std::vector<std::uint32_t> exactRays; ///< exact configurations: rays per point
    std::uint32_t referenceRays = 16;     ///< the image reference's rays per point, [1, 65536]
    std::vector<ShadingRate> shadingRates{ShadingRate::Fragment, ShadingRate::Vertex,
                                          ShadingRate::Adaptive};
    std::size_t probePoints = 1000; ///< 0: no probe errors
    std::uint32_t probeRays = 256;
    std::uint64_t probeSeed = 1;
    std::vector<BenchScene> segmentScaling; ///< scenes of increasing segment count
    std::vector<BenchScene> pixelScaling;   ///< scenes of increasing image size
    std::vector<BenchScene> voxelScaling;   ///< one groom at decreasing voxel sizes
    ModelSweepOptions model;                ///< no scenes: no model sweep
    int runs = 3;                           ///< timed renders per configuration, [1, 100]
    /// A configuration whose first run takes longer (seconds) is run once: the
    /// exact configurations cost minutes and vary little. 0: always `runs`.
    double singleRunAbove = 60;
    int threads = 0; ///< 0: all cores
    std::filesystem::path outDir = "bench";
    /// Runs each job as `workerCommand... JOB.json` in a child process (the
    /// CLI: its own executable, "bench", "--one"); empty: in this process.
    std::vector<std::string> workerCommand;
    std::string commandLine;     ///< recorded in results.md
    std::ostream* log = nullptr; ///< one line per job

    /// Everything: the straight, wavy (the default scene) and curly grooms
    /// (1024²), Ratboy_mohawk (`ratboyScene`, 960²), the TressFX bear's fur
    /// (`bear.json`, 144k segments, 1280²) and the 50,000-strand ×
    /// 29-point wavy head (1.4M segments, 1920×1080); five voxel sizes; exact
    /// with 1 and 4 rays against 16; scaling 10k–1.4M segments at 1920×1080,
    /// 256²–2048², and Ratboy at 1280² from 2 mm to 0.5 mm voxels; the model
    /// sweep on the default scene, the curly close-up and Ratboy at 256² (the
    /// scenes' aspect), blond, medium and dark, 1024 spp, 8 × 8 blocks, its
    /// frontier with volumetric at 3 and 48 paths per cell and path tracing
    /// at 4, 16, 64 and 256 spp.
    static SweepOptions full(const std::filesystem::path& scenesDir);
    /// A representative subset in 3–7 minutes on 2 cores: wavy and curly
    /// at 512², voxel sizes ×4, ×2, ×1, exact with 1 ray against 4, fragment
    /// shading, one run per configuration; scaling 10k–400k segments at
    /// 960×540, 256²–1024², and Ratboy at 640² at 2, 1 and 0.5 mm voxels;
    /// the model sweep on the default scene and the curly close-up at 128²,
    /// 64 spp, 4 × 4 blocks, its frontier with volumetric at 4 paths per
    /// cell and path tracing at 4 and 16 spp.
    static SweepOptions quick(const std::filesystem::path& scenesDir);

    void validate() const;
};

struct SweepResult {
    std::vector<BenchRow> rows;
    std::vector<ScalingFit> fits;
    std::vector<std::filesystem::path> written;
};

/// Runs the sweep and writes its outputs (see the file comment).
SweepResult runSweep(const SweepOptions& options);

/// The worker side (`hairvox bench --one JOB.json`): runs the job a sweep wrote
/// and writes its result file next to it.
void runBenchJobFile(const std::filesystem::path& jobFile);

} // namespace hairvox
