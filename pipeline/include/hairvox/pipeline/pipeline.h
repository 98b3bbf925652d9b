// hairvox pipeline: the whole render of one scene (docs/DESIGN.md §1):
//   load the groom → splat the fiber grid (grid and approx modes) → dual-
//   scattering tables (disk cache) → global term per light → surfaces →
//   raster + shade → EXR and PNG,
// timed stage by stage, with the counts of what each stage skipped (§7).
// The CLI's render, probe and transmittance commands and the benchmarks all go
// through loadSceneAssets(), so every consumer switches global-term modes the
// same way.
#pragma once

#include <hairvox/pipeline/scene.h>
#include <hairvox/render/rasterizer.h>
#include <hairvox/shading/dual_scattering_tables.h>
#include <hairvox/strands/groom.h>
#include <hairvox/transmittance/global_term_model.h>
#include <hairvox/transmittance/grid_global_term.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace hairvox {

struct PipelineOptions {
    int threads = 0;       ///< 0: all cores
    bool progress = false; ///< progress bars on stderr (the caller checks for a terminal)
    std::filesystem::path tableCacheDir; ///< empty: defaultTableCacheDir()
    GridOptions grid; ///< settings of the grid and approx modes (measured defaults)
};

/// Wall-clock seconds per stage.
struct StageTimes {
    double load = 0, voxelize = 0, tables = 0, globalTerm = 0, raster = 0, shade = 0, write = 0;
    double total() const { return load + voxelize + tables + globalTerm + raster + shade + write; }
};

/// Everything a scene's global term is computed from.
struct SceneAssets {
    Groom groom;
    std::string groomWarnings;     ///< dropped segments etc., for the user
    std::optional<FiberGrid> grid; ///< present in the grid and approx modes
    std::unique_ptr<DualScatteringTables> tables;
    std::unique_ptr<GlobalTermModel> globalTerm; ///< refers to `grid`: keep the assets together
    StageTimes times;                            ///< load, voxelize, tables
};

/// The scene's groom: generated, or read from its file. `warnings` receives
/// what the reader dropped (empty when nothing).
Groom loadGroom(const Scene& scene, std::string& warnings);

/// Loads or generates the scene's groom and builds what its global-term mode needs.
/// The result must not be moved while globalTerm is in use (it refers to grid).
std::unique_ptr<SceneAssets> loadSceneAssets(const Scene& scene, const PipelineOptions& options);

/// The global-term settings a scene implies (fiber scale, d_f, the head as occluder).
GlobalTermSettings globalTermSettings(const Scene& scene);
/// The rasterizer settings a scene implies (fiber scale, shading rate, background).
RasterSettings rasterSettings(const Scene& scene, const PipelineOptions& options = {});

/// What happened to one light.
struct LightReport {
    std::string name;
    bool skipped = false;      ///< no irradiance, or nothing it can reach: never evaluated
    double prepareSeconds = 0; ///< per-light preparation (the grid mode's cache)
    GlobalTermStats stats;
};

struct SceneRender {
    RasterOutput image;
    StageTimes times;
    std::vector<LightReport> lights;
    std::vector<std::filesystem::path> written;
    std::uint64_t activeVoxels = 0; ///< of the fiber grid (0 in exact mode)
    double voxelSize = 0;
};

/// Renders the scene end to end and writes its outputs (unless writeFiles is false).
SceneRender renderScene(const Scene& scene, const PipelineOptions& options, bool writeFiles = true);

/// Writes the outputs the scene asks for (scene.output.exr and .png, each if
/// non-empty) and returns their paths. EXR attributes record the scene's name,
/// mode, voxel size and shading rate plus `attributes`; the camera's
/// world-to-camera matrix goes with it.
std::vector<std::filesystem::path>
writeOutputs(const Film& film, const Scene& scene,
             const std::map<std::string, std::string>& attributes = {});

/// The closing report: time per stage and what was skipped.
void printTimingReport(std::ostream& os, const Scene& scene, const SceneRender& render);

} // namespace hairvox
