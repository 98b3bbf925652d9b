// hairvox pipeline: the whole render of one scene (docs/DESIGN.md §1), by the
// scene's integrator:
//  - dual scattering (the default): load the groom → splat the fiber grid
//    (grid and approx modes) → dual-scattering tables (disk cache) → global
//    term per light → surfaces → raster + shade → EXR and PNG;
//  - path: load the groom → path trace the same fibers (pathtrace/) → EXR and
//    PNG; optionally continuing from the scene's own earlier EXR;
// timed stage by stage, with the counts of what each stage skipped (§7).
// The CLI's render, probe and transmittance commands and the benchmarks all go
// through loadSceneAssets(), so every consumer switches global-term modes the
// same way.
#pragma once

#include <hairvox/core/disk_cache.h>
#include <hairvox/core/hash.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/geometry/environment_map.h>
#include <hairvox/pathtrace/path_tracer.h>
#include <hairvox/pipeline/scene.h>
#include <hairvox/render/rasterizer.h>
#include <hairvox/shading/dual_scattering_tables.h>
#include <hairvox/strands/groom.h>
#include <hairvox/transmittance/global_term_model.h>
#include <hairvox/transmittance/grid_global_term.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

namespace hairvox {

/// How the dual-scattering integrator lights with an environment
/// (docs/environment.md, where each default is measured against the path
/// tracer). The number of regions is the scene's (Scene::environmentLights).
struct EnvironmentOptions {
    /// What the median cut weighs: energy (the default), or solid angle (the
    /// baseline of uniform directions).
    EnvironmentSplit split = EnvironmentSplit::Energy;
    /// The regions' lights in the grid modes: voxels between their caches'
    /// shadow lines (GridOptions::cacheSpacing) and between their samples
    /// along the fibers (GridOptions::fiberSampleSpacing; the surfaces'
    /// shadow on the hair is sampled there too). An area of the sky casts
    /// softer shadows than a directional light. [0.5, 4] and [0, 4].
    float cacheSpacing = 3.0f;
    float fiberSampleSpacing = 2.0f;
    /// Sub-regions a region is cut into for what surfaces see of it
    /// (environment_lights.h RegionIrradiance).
    std::size_t surfaceSubdivisions = 16; ///< [1, 4096]
    /// Rays a sample on the hair casts per region for the surfaces' shadow
    /// (detail::RegionSurfaceShadow), [1, 64]. 4 took Ratboy's error under
    /// sky.exr from 0.431 to 0.404 but cost 2.5-2.9x the two lights' CPU time at
    /// 1024² (the bound is 2x; one ray 1.8-1.9x; 2 gained nothing).
    std::size_t hairShadowRays = 1;
    /// Widen the fiber's lobes by each region's angular spread; false: every
    /// region a directional light.
    bool spread = true;

    /// InputError naming the option and its range.
    void validate() const;
    void hashInto(Hasher& hasher) const;
};

struct PipelineOptions {
    int threads = 0;       ///< 0: all cores
    bool progress = false; ///< progress bars on stderr (the caller checks for a terminal)
    std::filesystem::path tableCacheDir; ///< empty: defaultTableCacheDir()
    GridOptions grid; ///< settings of the grid and approx modes (measured defaults)
    EnvironmentOptions environment; ///< of an environment light, dual scattering
    /// The volumetric integrator's samples along the fibers, in its cache's
    /// cells (docs/DESIGN.md §9): its cells are read, and rotated into the
    /// fiber's frame, there, and each fragment interpolates between two
    /// samples. Measured on key_back.json at 512² against reading every
    /// fragment: `multiple` moves 0.5% / 1.7% / 4.9% rel L1 per pixel (bias
    /// ≤ 0.02%) at 1/4, 1/2, 1. 0: every fragment read where it is. [0, 2].
    float multipleSampleSpacing = 0.5f;
    /// Path tracing: add samples to the scene's own EXR output when it exists
    /// (InputError if it was rendered from another scene or seed).
    bool continuePathTrace = false;
    /// A render whose estimated memory (estimateRenderMemory) exceeds this is
    /// refused before anything is allocated; the fiber grid's budget
    /// (SplatOptions::memoryBudgetBytes) shrinks to what the estimate leaves.
    /// 0: defaultMemoryLimit() in renderScene(), no limit in loadSceneAssets().
    std::uint64_t maxMemoryBytes = 0;
    /// A cache shared by the processes of many machines (a shot's render
    /// tasks on a farm, docs/farm.md): the fiber grid and the grid modes'
    /// per-light caches are taken from it where it holds them (keyed by what
    /// they are made of, as FrameReuse's keys) and stored there otherwise.
    /// The same bytes either way. Null: none.
    std::shared_ptr<const DiskCache> diskCache;
    /// What the disk cache is given to keep: what other frames share. A
    /// shot's per-frame groom makes a grid (and light preparations) of one
    /// frame, an orbiting light a preparation of one frame: kept, they would
    /// only fill the disk. Entries are looked for in any case.
    bool diskCacheStoresGrid = true;
    std::set<std::string> diskCacheSkipsLights; ///< by name
    /// String attributes added to the EXR output (a shot frame's hash).
    std::map<std::string, std::string> outputAttributes;
};

/// The default memory limit: 3/4 of the physical memory (sysconf), 8 GiB if unknown.
std::uint64_t defaultMemoryLimit();

/// What a render will allocate, estimated from the scene alone (before the
/// groom is read): the film's AOV layers and the integrator's per-pixel
/// buffers (float channels × pixels × 4 bytes, the path tracer's double sums),
/// the surface layer, the output files' encoding buffers, and the groom with
/// its per-point buffers (procedural: strands × points; a file: from its
/// size). The fiber grid is budgeted separately by splatStrands (what the
/// limit leaves).
struct MemoryEstimate {
    std::uint64_t film = 0;  ///< film layers + per-pixel integrator buffers + output encoding
    std::uint64_t groom = 0; ///< points, per-point render buffers, acceleration structure
    std::uint64_t meshes = 0; ///< the OBJ text while read, triangles, normals, Embree's BVH
    /// The environment map (EnvironmentMap::kBytesPerPixel a pixel, from its
    /// file's header; 0 when the header cannot be read: loading says why).
    std::uint64_t environment = 0;
    /// Libraries, tables, the fiber grid and per-light caches of a typical
    /// groom (the default scene peaks at ~1.1 GiB at 2000², ~430 MiB at 500²).
    std::uint64_t fixed = 320ull << 20;
    int filmChannels = 0; ///< float channels per pixel in the film
    std::uint64_t total() const { return film + groom + meshes + environment + fixed; }
};
MemoryEstimate estimateRenderMemory(const Scene& scene);

/// InputError if the scene's voxel size (when given) leaves the groom less
/// than 2 voxels across: the grid could not resolve the hair. Names
/// grid.voxel_size, the groom's extent and its default voxel size.
void checkVoxelSizeForGroom(const Scene& scene, const Groom& groom);

/// Wall-clock seconds per stage.
struct StageTimes {
    double load = 0, voxelize = 0, tables = 0, globalTerm = 0;
    double multiple = 0; ///< the volumetric integrator's solve (its lookups are in shade)
    double raster = 0, shade = 0;
    double trace = 0; ///< path tracing
    double write = 0;
    double total() const {
        return load + voxelize + tables + globalTerm + multiple + raster + shade + trace + write;
    }
    StageTimes& operator+=(const StageTimes& o) {
        load += o.load, voxelize += o.voxelize, tables += o.tables, globalTerm += o.globalTerm;
        multiple += o.multiple, raster += o.raster, shade += o.shade, trace += o.trace;
        write += o.write;
        return *this;
    }
};

/// The scene's opaque surfaces — the head sphere, then the meshes in scene
/// order — and each one's Lambertian albedo.
struct SceneSurfaces {
    std::shared_ptr<const SurfaceScene> scene; ///< null when the scene has none
    std::vector<Rgb> albedo;                   ///< one per surface
    std::vector<std::string> warnings;         ///< what the mesh readers dropped
};

/// Reads, generates and transforms the scene's meshes and builds their
/// surface scene. InputError (naming the scene's meshes[i] and the file)
/// for a mesh that cannot be used.
SceneSurfaces loadSurfaces(const Scene& scene);

/// What an environment map may take at most: 1 GiB (26.8M pixels, e.g. 7300 x
/// 3650, at EnvironmentMap::kBytesPerPixel).
inline constexpr std::uint64_t kEnvironmentBudgetBytes = 1ull << 30;

/// The scene's environment map, read from its file (with its colour,
/// intensity and rotation) or uniform; null when the scene has none.
/// InputError naming the scene, the light and the file for a map that cannot
/// be used (geometry/environment_map.h: unreadable, not RGB, not 2:1,
/// negative or non-finite pixels, over `maxBytes`).
std::shared_ptr<const EnvironmentMap>
loadEnvironment(const Scene& scene, std::uint64_t maxBytes = kEnvironmentBudgetBytes);

/// The scene's groom, generated or read from its file, with its per-point
/// attributes resolved (groom_attributes.h): groom.thickness holds diameters
/// in scene units, groom.fiberType indexes `palette`.
struct SceneGroom {
    Groom groom;
    FiberPalette palette;
    std::vector<std::string> warnings; ///< dropped segments, attributes not rendered, ...
    std::vector<std::string> notes;    ///< what was taken from the file's attributes
};

SceneGroom loadGroom(const Scene& scene);

/// Everything a scene's global term is computed from.
struct SceneAssets {
    SceneGroom groom;
    SceneSurfaces surfaces;
    /// Present in the grid and approx modes; shared with the next frame's
    /// assets when it reuses the grid (FrameReuse).
    std::shared_ptr<const FiberGrid> grid;
    std::vector<DualScatteringTables> tables;    ///< per fiber type (groom.palette)
    std::unique_ptr<GlobalTermModel> globalTerm; ///< refers to `grid`: keep the assets together
    /// The environment light's map (null: none) and the model of its
    /// regions' global terms: the scene's mode with EnvironmentOptions'
    /// spacings and without the surfaces' shadow (their rays are cast
    /// along what each point sees of a region, environment_lights.h).
    std::shared_ptr<const EnvironmentMap> environment;
    std::unique_ptr<GlobalTermModel> environmentTerm;
    double environmentLoadSeconds = 0; ///< of times.load
    StageTimes times;                  ///< load, voxelize, tables
};

/// Loads or generates the scene's groom and builds what its global-term mode needs.
/// The result must not be moved while globalTerm is in use (it refers to grid).
std::unique_ptr<SceneAssets> loadSceneAssets(const Scene& scene, const PipelineOptions& options);

/// The global-term settings a scene implies (fiber scale, d_f, its surfaces as occluders).
GlobalTermSettings globalTermSettings(const Scene& scene, const SceneSurfaces& surfaces);
/// The rasterizer settings a scene implies (fiber scale, shading rate, background).
RasterSettings rasterSettings(const Scene& scene, const PipelineOptions& options = {});

/// What happened to one light.
struct LightReport {
    std::string name;
    bool skipped = false;      ///< no irradiance, or nothing it can reach: never evaluated
    bool reused = false;       ///< prepared for the frame before (FrameReuse)
    double prepareSeconds = 0; ///< per-light preparation (the grid mode's cache)
    /// What the preparation holds for the render (LightGlobalTerm::memoryBytes).
    std::size_t heldBytes = 0;
    GlobalTermStats stats;
};

/// What the environment light cost and how it was sampled.
struct EnvironmentReport {
    std::string source; ///< the file, or "uniform"
    int width = 0, height = 0;
    std::size_t mapBytes = 0; ///< the map with its sampling distribution
    EnvironmentMap::NegativeFolds folds;
    double loadSeconds = 0; ///< reading it and building its distribution
    bool visible = false;
    // Dual scattering: the regions as lights.
    std::size_t lights = 0; ///< regions lit with
    EnvironmentSplit split = EnvironmentSplit::Energy;
    float widestSpreadDegrees = 0; ///< the largest region's √spread2
    double splitSeconds = 0;       ///< the median cut and the surfaces' table
    double prepareSeconds = 0;     ///< the regions' global terms (one after another)
    std::size_t reusedLights = 0;  ///< prepared for the frame before
    std::size_t heldBytes = 0;     ///< their caches
    GlobalTermStats stats;         ///< the hair's queries toward the regions
};

struct SceneRender {
    Film film;
    std::optional<RasterStats> raster;       ///< the rasterized integrators'
    std::optional<PathTraceStats> pathTrace; ///< the path tracer's
    std::optional<VolumetricStats> volumetric; ///< the volumetric integrator's solve
    bool multipleReused = false; ///< its solution taken from the frame before (FrameReuse)
    std::vector<std::string> warnings;       ///< for the user (rejected shader results, ...)
    StageTimes times;
    std::vector<LightReport> lights;
    std::optional<EnvironmentReport> environment; ///< when the scene has one
    /// Of times.globalTerm, the lights' preparation (wall time, the lights
    /// concurrently); the rest is the lookups made while shading.
    double globalTermPrepareSeconds = 0;
    std::vector<std::filesystem::path> written;
    /// What the outputs record besides the scene's (writeOutputs' `attributes`):
    /// the fiber grid's voxel size, or a path trace's spp, seed and render
    /// hash. Set whether or not the render wrote them, so that a caller that
    /// writes later (the Python module's Render.save) writes the same files.
    std::map<std::string, std::string> outputAttributes;
    std::uint64_t activeVoxels = 0; ///< of the fiber grid (0 in exact mode)
    bool gridReused = false; ///< the fiber grid splatted for the frame before (FrameReuse)
    std::uint64_t surfaceTriangles = 0; ///< of the scene's meshes
    double voxelSize = 0;
    std::size_t fiberTypes = 1;         ///< of the groom (SceneGroom::palette)
    std::vector<std::string> groomNotes; ///< SceneGroom::notes, for the report
};

/// What the renders of a sequence in one process carry from one frame to the
/// next (`hairvox render a.json b.json ...`): the fiber grid, and each light's
/// prepared global term (the grid modes' cache), wherever everything they are
/// computed from is what it was for the frame before. The keys are contents,
/// not names: the groom's points, diameters and fiber types as loaded, the
/// surfaces' triangles, and every setting the splat and the lights'
/// preparation read (pipeline/src/frame_reuse.h). So a camera
/// moving around a still groom under still lights (a turntable) splats and
/// prepares once; a frame that moves one light prepares that light again; a
/// new colour keeps the grid and prepares the lights; a groom file rewritten
/// between frames is splatted again. The volumetric integrator's solution is
/// kept when its grid, model, lights, surfaces and settings are unchanged
/// (it does not depend on the camera). Each frame is still loaded (its
/// contents are the key), and reused or not it is the same bytes as rendered
/// alone. Between frames it holds one frame's groom, grid, light terms and
/// solution. The path integrator does not use it.
class FrameReuse {
public:
    FrameReuse();
    ~FrameReuse();
    FrameReuse(const FrameReuse&) = delete;
    FrameReuse& operator=(const FrameReuse&) = delete;

    struct State; ///< (pipeline/src/frame_reuse.h)

private:
    friend SceneRender renderScene(const Scene&, const PipelineOptions&, bool, FrameReuse*);
    std::unique_ptr<State> state_;
};

/// Renders the scene end to end and writes its outputs (unless writeFiles is
/// false). With `reuse`, takes what the frame before left there that this
/// frame would compute the same, and leaves this frame's for the next. Refuses (InputError, before allocating) a render whose
/// estimateRenderMemory() exceeds the options' limit. Warns (SceneRender::warnings)
/// about a light that lights nothing (inside the head, or dark) by name and
/// about an image in which no pixel covers hair.
SceneRender renderScene(const Scene& scene, const PipelineOptions& options, bool writeFiles = true,
                        FrameReuse* reuse = nullptr);

/// Writes the outputs the scene asks for (scene.output.exr and .png, each if
/// non-empty) and returns their paths. EXR attributes record the scene's name
/// and integrator — the global-term mode, voxel size and shading rate of dual
/// scattering, or a path trace's spp, seed and render hash — plus
/// `attributes`; the camera's world-to-camera matrix goes with it.
std::vector<std::filesystem::path>
writeOutputs(const Film& film, const Scene& scene,
             const std::map<std::string, std::string>& attributes = {});

/// The layers that sum to the hair's radiance in a film of either integrator:
/// direct_R, direct_TT, direct_TRT and back_direct + scatter (dual
/// scattering) or multiple (path tracing). std::out_of_range if the film has
/// neither set.
std::vector<std::string> hairRadianceLayers(const Film& film);
/// The hair's radiance over the hair pixels, with the path tracer's variance
/// of it where the film has one: what the dual-scattering model is judged on.
ComparedImage hairRadianceOf(const Film& film);

/// What a path trace's samples depend on (groom content with its per-point
/// diameters and fiber types, fiber scale, each fiber type's optics, lights,
/// camera, surfaces and their content, background, the environment's pixels,
/// colour, rotation and visibility, seed, depth settings): the
/// key under which a run may continue another.
std::string pathTraceHash(const Scene& scene, const SceneGroom& groom,
                          const SceneSurfaces& surfaces,
                          const EnvironmentMap* environment = nullptr);

/// The closing report: time per stage and what was skipped.
void printTimingReport(std::ostream& os, const Scene& scene, const SceneRender& render);

} // namespace hairvox
