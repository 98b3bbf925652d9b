// hairvox pipeline: the scene — everything a render needs besides the groom's
// points: fiber scale and optics, lights, camera, the opaque head and meshes, global-term
// and output settings. Read from a JSON scene file whose schema (with an example
// per feature) is docs/scene.md; the embedded default scene is
// data/scenes/default.json, compiled into the library.
//
// Validation follows DEVELOPERS.md: every error is an InputError naming the
// file, the JSON path and the valid range or type, e.g.
//   scene.json: /lights/1/intensity: expected a number in [0, 1e+06], got "bright"
// Unknown keys are errors (a typo must not be silently ignored). Ranges of the
// fiber scale and optics and the procedural groom are those of
// FiberScale::validate(), FiberParams::validate(), DualScatteringParams::validate()
// and ProceduralGroomParams::validate().
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/film/image_file.h>
#include <hairvox/geometry/camera.h>
#include <hairvox/geometry/light.h>
#include <hairvox/geometry/triangle_mesh.h>
#include <hairvox/pathtrace/path_tracer.h>
#include <hairvox/pipeline/groom_attributes.h>
#include <hairvox/render/fragment_shader.h>
#include <hairvox/render/rasterizer.h>
#include <hairvox/shading/fiber_params.h>
#include <hairvox/strands/fiber_scale.h>
#include <hairvox/strands/groom.h>
#include <hairvox/strands/procedural.h>
#include <hairvox/transmittance/global_term_mode.h>
#include <hairvox/volumetric/multiple_scattering.h>

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace hairvox {

/// Where the strands come from: a groom file, a groom in memory or the
/// procedural generator.
struct GroomSource {
    /// .hair/.tfx/.obj, resolved against the scene file's directory; empty → procedural.
    std::filesystem::path file;
    /// A groom built in memory by the caller (the Python module's
    /// hairvox.Groom) in place of a file; never read from a scene file.
    /// loadGroom() copies and sanitizes it and resolves its attributes as a
    /// file's (under "auto", thickness is diameters in scene units).
    std::shared_ptr<const Groom> inMemory;
    ProceduralGroomParams procedural;
    /// How the file's per-point thickness is read (groom_attributes.h).
    GroomThickness thickness = GroomThickness::Auto;
    /// Whether the file's per-point colours set the fibers' σ_a (groom_attributes.h).
    GroomColor color = GroomColor::Use;

    bool isProcedural() const { return file.empty() && !inMemory; }
    /// What messages and the fiber grid's metadata call the groom.
    std::string sourceName() const {
        return inMemory ? "in-memory groom" : file.empty() ? "procedural" : file.string();
    }
};

/// The optional opaque head: hides the hair behind it, blocks light, and is
/// drawn with a Lambertian BRDF lit by the scene's lights (not shadowed by the hair).
struct Head {
    Sphere sphere{Vec3f(0.0f), 0.1f}; ///< radius in [1e-6, 1e4]
    Rgb albedo{0.55f, 0.40f, 0.33f};  ///< diffuse reflectance, each channel in [0, 1]
};

/// An opaque triangle mesh (a body, a head): it hides the hair behind it,
/// blocks light in every global-term mode and in the path tracer, and is drawn
/// as a Lambertian surface lit through the hair (the global term's V and T_s at
/// the surface point). From an OBJ file, or generated: a mannequin head around
/// a sphere (geometry/triangle_mesh.h generateHeadMesh()).
struct MeshSource {
    /// .obj, resolved against the scene file's directory; empty: the mannequin.
    std::filesystem::path file;
    Sphere mannequin{Vec3f(0.0f), 0.1f}; ///< the mannequin's cranium (its hair's head sphere)
    int mannequinRings = 96; ///< its latitude rings, [8, 1024]: 4·rings·(rings − 1) triangles
    MeshTransform transform;
    Rgb albedo{0.55f, 0.40f, 0.33f}; ///< diffuse reflectance, each channel in [0, 1]

    bool isMannequin() const { return file.empty(); }
};

/// The environment light (docs/scene.md "Environment light"): radiance from
/// every direction, color × intensity × a latitude–longitude map (or × 1
/// without a map), turned by `rotation` about +y (geometry/environment_map.h
/// has the layout). At most one per scene.
struct EnvironmentLight {
    std::string name = "environment"; ///< as a light's (unique among the lights)
    /// An RGB(A) EXR, resolved against the scene file's directory.
    std::filesystem::path file;
    /// Or a map built into the program (geometry/builtin_environment.h):
    /// "studio", "sky", "city". Neither: uniform.
    std::string builtin;
    Rgb color{1.0f};        ///< each channel in [0, 1000]
    float intensity = 1.0f; ///< [0, 1e6]
    float rotation = 0;     ///< degrees about +y, right-handed, [-360, 360]
    /// The camera sees it behind everything, in the beauty and the background
    /// layer (instead of Scene::background). Either way it lights the scene.
    bool visible = true;

    bool isUniform() const { return file.empty() && builtin.empty(); }
    /// Where its map is read from (a file or a built-in map's bytes); not for a
    /// uniform environment.
    ExrSource source() const;
    /// What the report calls the map: the file, "built-in map studio" or "uniform".
    std::string sourceName() const;
};

/// Scene::environmentLights unless a scene says otherwise (docs/environment.md).
inline constexpr std::uint32_t kDefaultEnvironmentLights = 8;

/// Options of the `exact` global-term mode (DESIGN.md §5–6): K shadow rays per
/// shading point from a disk of radius r perpendicular to the light.
struct ExactSettings {
    std::uint32_t rays = 1; ///< K, [1, 65536]
    float radius = 0;       ///< r, scene units, [0, 1000]
    /// Of the rays' jitter; renders with different seeds are independent.
    std::uint64_t seed = 1;
};

/// How a scene is rendered: the dual-scattering rasterizer, the path tracer
/// of the same fibers (the ground truth; pathtrace/path_tracer.h), or the
/// rasterizer with multiple scattering solved on the fiber grid
/// (volumetric/multiple_scattering.h).
enum class Integrator { DualScattering, Path, Volumetric };

inline constexpr EnumNames<Integrator, 3> kIntegratorNames{{{
    {Integrator::DualScattering, "dual_scattering"},
    {Integrator::Path, "path"},
    {Integrator::Volumetric, "volumetric"},
}}};
/// Whether the integrator draws the hair with the rasterizer (its fragment
/// shading, shading rates, global term and layers).
inline bool isRasterized(Integrator i) {
    return i != Integrator::Path;
}
inline const char* toString(Integrator i) {
    return kIntegratorNames.name(i);
}

struct OutputSettings {
    std::filesystem::path exr;         ///< relative to the working directory; empty: not written
    std::filesystem::path png;         ///< relative to the working directory; empty: not written
    float exposure = 0;                ///< stops applied to the PNG preview only, [-20, 20]
    ToneMap toneMap = ToneMap::Filmic; ///< of the PNG preview (film/image_file.h)
    int exrZipLevel = kDefaultExrZipLevel; ///< zlib level of the EXR, [1, 9] (ExrHeader)
    ExrCompression exrCompression = ExrCompression::Rle; ///< of the EXR (ExrCompression)
    /// The EXR's layers besides the beauty and "A" (always written), dual
    /// scattering only: null ("all"), every layer; else those named
    /// (layersOf(); "none": an empty list). The others are not stored in
    /// the film at all.
    std::optional<std::vector<std::string>> layers;
};

struct Scene {
    std::string name; ///< where the scene came from (file name or "default scene"), for messages
    GroomSource groom;
    FiberScale fiberScale; ///< D (scene units: m for the procedural grooms) and k
    FiberParams fiber;
    DualScatteringParams dualScattering;
    /// Regions of the environment map the dual-scattering integrator lights
    /// with, each a light (docs/environment.md), [1, 1024].
    std::uint32_t environmentLights = kDefaultEnvironmentLights;
    std::vector<Light> lights; ///< at most 16 (each adds per-light AOV layers)
    /// The environment light, if any (an entry of the scene file's "lights").
    std::optional<EnvironmentLight> environment;
    CameraParams camera;
    std::optional<Head> head;
    std::vector<MeshSource> meshes; ///< at most kMaxMeshes
    std::optional<float> voxelSize; ///< fiber grid voxel size; nullopt: derived from the groom
    /// Voxels between the global term's samples along a fiber (grid and
    /// approx modes, GridOptions::fiberSampleSpacing); nullopt: the default.
    std::optional<float> fiberSampleSpacing;
    Integrator integrator = Integrator::DualScattering;
    PathTraceSettings pathTrace;   ///< the path integrator's spp, time limit, depth and seed
    VolumetricSettings volumetric; ///< the volumetric integrator's paths, cache and seed
    GlobalTermMode globalTermMode = GlobalTermMode::Grid;
    ExactSettings exact;
    ShadingRate shadingRate = ShadingRate::Fragment;
    float shadingTolerance = kDefaultShadingTolerance; ///< the adaptive rate's τ, [0, 1]
    /// T_tail of the fragment and adaptive rates, [0, 1] (render/fragment_shader.h)
    float tailTransmittance = kDefaultTailTransmittance;
    /// Radiance behind everything, each channel in [0, 1e6] (a visible
    /// environment takes its place).
    Rgb background{0.0f};
    OutputSettings output;

    /// Re-checks every field and the cross-field rules (camera outside the
    /// head, unique light names, a valid camera frame) — call it after
    /// overriding fields from the command line. parseScene() already did.
    /// Messages name the field (e.g. "camera.resolution").
    void validate() const;
};

std::ostream& operator<<(std::ostream& os, const Scene& scene);

/// The layers a dual-scattering render of the scene can write besides the
/// beauty and "A" (rasterLayers() for its lights), in the EXR's order:
/// what OutputSettings::layers chooses from.
std::vector<RasterLayer> layersOf(const Scene& scene);

inline constexpr std::size_t kMaxLights = 16;
inline constexpr std::size_t kMaxMeshes = 64;
inline constexpr std::uint64_t kMaxProceduralPoints = 1ull << 26;

/// Reads and validates a scene file (at most 16 MiB). Relative groom paths are
/// resolved against the file's directory.
Scene loadScene(const std::filesystem::path& path);

/// Validates a parsed JSON document. `sourceName` prefixes error messages and
/// names the default outputs (out/<stem>.exr, out/<stem>.png); `baseDir`
/// resolves a relative groom file.
Scene parseScene(const nlohmann::json& json, const std::string& sourceName,
                 const std::filesystem::path& baseDir);

/// Parses JSON text, then parseScene() (syntax errors name line and column).
Scene parseSceneText(std::string_view text, const std::string& sourceName,
                     const std::filesystem::path& baseDir);

/// The embedded default scene (data/scenes/default.json): a procedural
/// light-blond wavy groom on a head, a key and a back light, 1024², grid mode,
/// writing out/default.exr and out/default.png.
Scene defaultScene();
/// Its JSON text, as compiled in.
std::string_view defaultSceneJson();

} // namespace hairvox
