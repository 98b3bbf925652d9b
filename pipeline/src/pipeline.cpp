#include "dual_scattering_fragment_shader.h"
#include "environment_lights.h"
#include "frame_reuse.h"
#include "scene_assets.h"
#include "surfaces.h"

#include <hairvox/core/disk_cache.h>
#include <hairvox/core/error.h>
#include <hairvox/core/format.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/parallel.h>
#include <hairvox/film/image_file.h>
#include <hairvox/pipeline/pipeline.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iomanip>
#include <map>
#include <span>
#include <sstream>
#include <unistd.h>

namespace hairvox {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string gib(double bytes) {
    std::ostringstream os;
    os << std::fixed << std::setprecision(bytes < double(1ull << 30) ? 2 : 1)
       << bytes / double(1ull << 30) << " GiB";
    return os.str();
}

std::string vecText(const Vec3f& v) {
    return strCat("(", v.x, ", ", v.y, ", ", v.z, ")");
}

/// Warnings about lights that cannot light anything, by name.
void warnAboutLights(const Scene& scene, const SceneSurfaces& surfaces,
                     std::vector<std::string>& warnings) {
    for (const Light& light : scene.lights) {
        if (light.isDark()) {
            warnings.push_back(strCat("light '", light.name, "' has zero intensity or colour; ",
                                      "it lights nothing and is skipped"));
        } else if (light.kind == Light::Kind::Point && scene.head &&
                   scene.head->sphere.contains(light.position)) {
            warnings.push_back(strCat(
                "light '", light.name, "' at ", vecText(light.position),
                " is inside the head (center ", vecText(scene.head->sphere.center), ", radius ",
                scene.head->sphere.radius, "); it lights nothing and is skipped"));
        } else if (light.kind == Light::Kind::Point && surfaces.scene &&
                   surfaces.scene->contains(light.position)) {
            warnings.push_back(strCat(
                "light '", light.name, "' at ", vecText(light.position),
                " is inside a mesh (bounds ", vecText(surfaces.scene->bounds().min), " to ",
                vecText(surfaces.scene->bounds().max), "); it lights nothing and is skipped"));
        }
    }
}

/// Whether a pixel of the film covers hair (its hair alpha layer), or
/// nothing is known (no such layer, no pixel).
bool filmShowsHair(const Film& film) {
    const auto hair = film.find(kHairAlphaLayer);
    if (!hair || film.pixelCount() == 0)
        return true;
    const FilmLayer& a = film.layer(*hair);
    for (int ty = 0; ty < a.tilesY(); ++ty)
        for (int tx = 0; tx < a.tilesX(); ++tx)
            if (const float* t = a.tileOrNull(tx, ty);
                t && std::any_of(t, t + FilmLayer::kTilePixels, [](float x) { return x > 0; }))
                return true;
    return false;
}

/// A warning when no pixel of the rendered image covers hair.
void warnIfNoHairSeen(const Scene& scene, bool hairSeen, const Groom* groom,
                      std::vector<std::string>& warnings) {
    if (hairSeen)
        return;
    std::string bounds;
    if (groom) {
        const Bounds3f b = groom->bounds();
        bounds = b.empty() ? std::string(" (the groom is empty)")
                           : strCat(" (groom bounds ", vecText(b.min), " to ", vecText(b.max), ")");
    }
    warnings.push_back(strCat("the camera sees no hair: no pixel of the ", scene.camera.width, "x",
                              scene.camera.height, " image covers a fiber", bounds,
                              "; camera.position ", vecText(scene.camera.position), ", look_at ",
                              vecText(scene.camera.lookAt), ", fov ", scene.camera.fovY));
}

} // namespace

void EnvironmentOptions::validate() const {
    if (!(cacheSpacing >= 0.5f && cacheSpacing <= 4.0f))
        throw InputError(strCat("environment cache spacing = ", cacheSpacing,
                                " voxels: expected a number in [0.5, 4]"));
    if (!(fiberSampleSpacing >= 0.0f && fiberSampleSpacing <= 4.0f))
        throw InputError(strCat("environment fiber sample spacing = ", fiberSampleSpacing,
                                " voxels: expected a number in [0, 4]"));
    if (surfaceSubdivisions < 1 || surfaceSubdivisions > 4096)
        throw InputError(strCat("environment surface subdivisions = ", surfaceSubdivisions,
                                ": expected an integer in [1, 4096]"));
    if (hairShadowRays < 1 || hairShadowRays > 64)
        throw InputError(strCat("environment hair shadow rays = ", hairShadowRays,
                                ": expected an integer in [1, 64]"));
}

void EnvironmentOptions::hashInto(Hasher& hasher) const {
    hasher.value(split).value(cacheSpacing).value(fiberSampleSpacing).value(surfaceSubdivisions);
    hasher.value(hairShadowRays);
    hasher.value(spread);
}

std::uint64_t defaultMemoryLimit() {
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long pageSize = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || pageSize <= 0)
        return 8ull << 30;
    return std::uint64_t(pages) / 4 * 3 * std::uint64_t(pageSize);
}

MemoryEstimate estimateRenderMemory(const Scene& scene) {
    MemoryEstimate m;
    const std::uint64_t pixels = std::uint64_t(scene.camera.width) * scene.camera.height;
    constexpr std::uint64_t kOutputBytesPerPixel = 8; // PNG pixels + its encoder; EXR in bands
    std::uint64_t perPixel = kOutputBytesPerPixel;
    if (scene.integrator == Integrator::Path) {
        // 9 accumulated layers (23 channels) and the two half-sample layers
        // (6), as floats in the film and doubles in the running sums.
        m.filmChannels = 29;
        perPixel += 29 * (4 + 8);
        if (scene.output.exr.empty() ? false : std::filesystem::exists(scene.output.exr))
            perPixel += 2 * 29 * 4; // a continued run reads the earlier EXR into a film
    } else {
        // beauty 3, A 1, and the layers output.layers keeps.
        m.filmChannels = 4;
        const RasterSettings raster = rasterSettings(scene);
        for (const RasterLayer& l : layersOf(scene))
            if (raster.stores(l.name))
                m.filmChannels += l.channels;
        perPixel += std::uint64_t(m.filmChannels) * 4;
        if (scene.head || !scene.meshes.empty())
            // The surface layer (coverage, depth, radiance), the corner rays'
            // hits and the points to shade with their radiance.
            perPixel += 5 * 4 + 8 + 56 + 12;
    }
    m.film = pixels * perPixel;
    // Per point: the point, its tangent and projection in the rasterizer, the
    // segment bins and splat buckets or the ray-tracing structure.
    constexpr std::uint64_t kBytesPerPoint = 96;
    if (scene.groom.inMemory) {
        m.groom = scene.groom.inMemory->pointCount() * kBytesPerPoint;
    } else if (scene.groom.isProcedural()) {
        m.groom = std::uint64_t(scene.groom.procedural.strands) *
                  scene.groom.procedural.resolvedPointsPerStrand() * kBytesPerPoint;
    } else {
        std::error_code ec;
        const std::uintmax_t size = std::filesystem::file_size(scene.groom.file, ec);
        // A binary groom file holds 12–16 bytes per point.
        m.groom = ec ? 0 : std::uint64_t(size) / 12 * kBytesPerPoint;
    }
    // Per triangle: indices, three corner normals and Embree's BVH (~150
    // bytes); an OBJ file holds ~40 bytes per triangle and is read whole.
    constexpr std::uint64_t kBytesPerTriangle = 150;
    for (const MeshSource& mesh : scene.meshes) {
        if (mesh.isMannequin()) {
            const auto rings = std::uint64_t(mesh.mannequinRings);
            m.meshes += 4 * rings * rings * kBytesPerTriangle;
        } else {
            std::error_code ec;
            const std::uintmax_t size = std::filesystem::file_size(mesh.file, ec);
            m.meshes += ec ? 0 : std::uint64_t(size) * (1 + kBytesPerTriangle / 40);
        }
    }
    if (scene.environment && !scene.environment->isUniform()) {
        try {
            const ExrInfo info = readExrInfo(scene.environment->source());
            m.environment = std::uint64_t(std::max<std::int64_t>(info.width, 0)) *
                            std::uint64_t(std::max<std::int64_t>(info.height, 0)) *
                            EnvironmentMap::kBytesPerPixel;
        } catch (const InputError&) {
            // loadEnvironment() names the problem with the file.
        }
    }
    return m;
}

namespace {

/// What the report says of the map itself.
void describeEnvironment(const EnvironmentMap& map, const Scene& scene, EnvironmentReport& report) {
    report.source = map.source();
    report.width = map.width();
    report.height = map.height();
    report.mapBytes = map.memoryBytes();
    report.folds = map.negativeFolds();
    report.visible = scene.environment && scene.environment->visible;
}

} // namespace

namespace {

/// The volumetric integrator's multiple scattering: solved on the fiber grid
/// (volumetric/), or the frame before's where everything it is made of is
/// unchanged (`key`).
std::shared_ptr<const MultipleScatteringSolution>
solveMultiple(const Scene& scene, const PipelineOptions& options, const SceneAssets& assets,
              std::span<const Light> environmentLights, FrameReuse::State* reuse, std::uint64_t key,
              bool& reused) {
    reused = false;
    if (reuse && reuse->multiple && reuse->multipleKey == key) {
        reused = true;
        return reuse->multiple;
    }
    if (reuse)
        reuse->multiple.reset(); // before allocating this frame's
    VolumetricScene vs;
    vs.grid = assets.grid.get();
    vs.groom = &assets.groom.groom;
    vs.fibers = assets.groom.palette.fibers;
    vs.lights = scene.lights;
    vs.lights.insert(vs.lights.end(), environmentLights.begin(), environmentLights.end());
    vs.surfaces = assets.surfaces.scene;
    vs.surfaceAlbedo = assets.surfaces.albedo;
    const DiskCache kernelCache(detail::tableCacheDirOf(options));
    vs.kernelCache = &kernelCache;
    VolumetricSettings settings = scene.volumetric;
    settings.threads = options.threads;
    settings.progress = options.progress;
    // What the limit leaves once the film, the groom and the grid are counted.
    const std::uint64_t used = estimateRenderMemory(scene).total() + assets.grid->memoryBytes();
    const std::uint64_t budget =
        options.maxMemoryBytes > used ? options.maxMemoryBytes - used : std::uint64_t(1);
    auto solution = std::make_shared<const MultipleScatteringSolution>(
        solveMultipleScattering(vs, settings, budget));
    if (reuse) {
        reuse->multiple = solution;
        reuse->multipleKey = key;
    }
    return solution;
}

SceneRender renderRasterized(const Scene& scene, const PipelineOptions& options, bool writeFiles,
                             FrameReuse::State* reuse) {
    SceneRender result;
    auto built = std::make_shared<SceneAssets>();
    const detail::FrameAssets frame = detail::prepareAssets(scene, options, built.get(), reuse);
    const SceneAssets* assets = frame.reused ? frame.reused : built.get();
    if (frame.reused) {
        result.times.load = built->times.load;
        built.reset(); // this frame's groom and surfaces, loaded for their keys
    } else {
        result.times = built->times;
        if (reuse) { // for the next frame (the frame before's is gone)
            reuse->assets = built;
            reuse->gridKey = frame.gridKey;
            reuse->modelKey = frame.modelKey;
        }
    }
    result.gridReused = frame.gridReused;
    if (assets->surfaces.scene)
        result.surfaceTriangles = assets->surfaces.scene->triangleCount();
    if (assets->grid) {
        result.activeVoxels = assets->grid->activeVoxelCount();
        result.voxelSize = assets->grid->info.voxelSize;
    }

    // Per light: skip what cannot light anything, prepare the rest (the
    // cache). The lights are prepared one after another, each in parallel,
    // sharing a workspace (the grid modes' rates volume: laid out and
    // allocated once, refilled per light, freed before the raster). Measured
    // against preparing them concurrently (docs/DESIGN.md §7): the same
    // time on the 2-core machine, one light's transient memory instead of
    // all of theirs at once.
    // With reuse, a light prepared for the frame before under the same model
    // is taken as it is.
    // The environment's regions are lights too (environment_lights.h), of
    // their own model, after the scene's.
    std::optional<detail::EnvironmentLighting> environment;
    if (assets->environment) {
        const auto start = Clock::now();
        environment = detail::environmentLighting(
            *assets->environment, scene.environment->name, scene.environmentLights,
            options.environment.split, options.environment.surfaceSubdivisions,
            options.environment.hairShadowRays);
        EnvironmentReport& report = result.environment.emplace();
        report.splitSeconds = secondsSince(start);
        report.lights = environment->lights.size();
        report.split = options.environment.split;
        for (const EnvironmentRegion& region : environment->regions)
            report.widestSpreadDegrees =
                std::max(report.widestSpreadDegrees, degrees(std::sqrt(region.spread2)));
        if (!options.environment.spread)
            std::fill(environment->spread2.begin(), environment->spread2.end(), 0.0f);
        result.times.globalTerm += report.splitSeconds;
    }
    const std::size_t lightCount = scene.lights.size();
    const std::size_t environmentCount = environment ? environment->lights.size() : 0;
    std::vector<std::shared_ptr<const LightGlobalTerm>> terms(lightCount),
        environmentTerms(environmentCount);
    std::vector<std::uint64_t> lightKeys(lightCount), environmentKeys(environmentCount);
    if (reuse) { // the frame before's lights this frame does not have are freed first
        for (std::size_t l = 0; l < lightCount; ++l)
            lightKeys[l] = detail::lightKey(frame.modelKey, scene.lights[l]);
        const std::uint64_t environmentModel =
            Hasher().value(frame.modelKey).string("environment").digest();
        for (std::size_t l = 0; l < environmentCount; ++l)
            environmentKeys[l] = detail::lightKey(environmentModel, environment->lights[l]);
        std::erase_if(reuse->lights, [&](const auto& entry) {
            return std::find(lightKeys.begin(), lightKeys.end(), entry.first) == lightKeys.end() &&
                   std::find(environmentKeys.begin(), environmentKeys.end(), entry.first) ==
                       environmentKeys.end();
        });
    }
    result.lights.resize(lightCount);
    const auto prepareStart = Clock::now();
    std::unique_ptr<LightWorkspace> workspace = assets->globalTerm->makeWorkspace();
    for (std::size_t l = 0; l < lightCount; ++l) {
        const Light& light = scene.lights[l];
        LightReport& report = result.lights[l];
        report.name = light.name;
        const auto start = Clock::now();
        if (light.isDark()) {
            report.skipped = true;
        } else {
            if (reuse) {
                if (const auto it = reuse->lights.find(lightKeys[l]); it != reuse->lights.end()) {
                    terms[l] = it->second;
                    report.reused = true;
                }
            }
            if (!terms[l])
                terms[l] = assets->globalTerm->forLight(light, workspace.get());
            if (terms[l]->blocksEverything()) {
                report.skipped = true;
                terms[l].reset();
            } else {
                report.heldBytes = terms[l]->memoryBytes();
            }
        }
        report.prepareSeconds = secondsSince(start);
    }
    workspace.reset(); // what no light keeps
    if (environment) {
        const auto start = Clock::now();
        EnvironmentReport& report = *result.environment;
        workspace = assets->environmentTerm->makeWorkspace();
        for (std::size_t l = 0; l < environmentCount; ++l) {
            if (environment->lights[l].isDark())
                continue;
            if (reuse)
                if (const auto it = reuse->lights.find(environmentKeys[l]);
                    it != reuse->lights.end()) {
                    environmentTerms[l] = it->second;
                    ++report.reusedLights;
                }
            if (!environmentTerms[l])
                environmentTerms[l] =
                    assets->environmentTerm->forLight(environment->lights[l], workspace.get());
            report.heldBytes += environmentTerms[l]->memoryBytes();
        }
        workspace.reset();
        report.prepareSeconds = secondsSince(start);
        report.heldBytes += environment->surfaces.memoryBytes();
    }
    result.globalTermPrepareSeconds = secondsSince(prepareStart);
    result.times.globalTerm += result.globalTermPrepareSeconds;
    if (reuse) { // this frame's lights, for the next (the others' caches are freed)
        reuse->lights.clear();
        for (std::size_t l = 0; l < lightCount; ++l)
            if (terms[l])
                reuse->lights.emplace(lightKeys[l], terms[l]);
        for (std::size_t l = 0; l < environmentCount; ++l)
            if (environmentTerms[l])
                reuse->lights.emplace(environmentKeys[l], environmentTerms[l]);
    }

    // The volumetric integrator's multiple scattering, solved once the
    // lights' global terms are prepared (and their workspace freed).
    std::shared_ptr<const MultipleScatteringSolution> multiple;
    if (scene.integrator == Integrator::Volumetric) {
        const auto start = Clock::now();
        Hasher key;
        key.value(frame.modelKey);
        // The environment's regions light the solve as they light the
        // shader: directional lights of each region's irradiance.
        const std::span<const Light> regions =
            environment ? std::span<const Light>(environment->lights) : std::span<const Light>{};
        for (const Light& light : scene.lights)
            key.value(detail::lightKey(frame.modelKey, light));
        for (const Light& light : regions)
            key.value(detail::lightKey(frame.modelKey, light));
        scene.volumetric.hashInto(key);
        multiple = solveMultiple(scene, options, *assets, regions, reuse, key.digest(),
                                 result.multipleReused);
        result.volumetric = multiple->stats;
        result.times.multiple = secondsSince(start);
    }
    const RadianceCache* cache = multiple ? multiple->cache.get() : nullptr;

    // The surfaces as the camera sees them, lit through the hair.
    const Camera camera(scene.camera);
    const auto surfacesStart = Clock::now();
    SurfaceLayer surfaces;
    if (assets->surfaces.scene) {
        std::vector<const LightGlobalTerm*> lightTerms;
        for (const auto& t : terms)
            lightTerms.push_back(t.get());
        detail::SurfaceEnvironment seen;
        if (environment) {
            seen.irradiance = &environment->surfaces;
            seen.lights = environment->lights;
            for (const auto& t : environmentTerms)
                seen.terms.push_back(t.get());
        }
        surfaces = detail::surfaceLayer(*assets->surfaces.scene, assets->surfaces.albedo, camera,
                                        scene.lights, lightTerms, environment ? &seen : nullptr,
                                        multiple ? multiple->surfaces.get() : nullptr);
    }
    BackgroundLayer background;
    if (assets->environment && scene.environment->visible)
        background = detail::backgroundLayer(*assets->environment, camera);
    const double surfaceSeconds = secondsSince(surfacesStart);

    // The hair's view of a region: the share of it the surfaces leave
    // (EnvironmentOptions::hairShadowRays rays along the region cut again by
    // energy), sampled along the fibers (grid and approx modes) every
    // EnvironmentOptions::fiberSampleSpacing voxels — the surfaces' shadow
    // too, which a directional light's keeps exact per point: a region of
    // the sky casts a soft one, and rays per fragment and region were a
    // third of an environment-lit render's lookups.
    detail::ShadedEnvironment shadedEnvironment;
    if (environment) {
        shadedEnvironment.lights = environment->lights;
        shadedEnvironment.spread2 = environment->spread2;
        for (std::size_t l = 0; l < environmentCount; ++l)
            shadedEnvironment.terms.push_back(environmentTerms[l]
                                                  ? std::make_shared<detail::RegionSurfaceShadow>(
                                                        environmentTerms[l], assets->surfaces.scene,
                                                        environment->shadowDirections[l])
                                                  : nullptr);
        if (assets->grid) {
            shadedEnvironment.groom = &assets->groom.groom;
            shadedEnvironment.spacing = options.environment.fiberSampleSpacing *
                                        static_cast<float>(assets->grid->info.voxelSize);
        }
    }

    // One shader per fiber type (the shaders refer to their bcsdf and tables).
    // The volumetric integrator reads their single scattering only: with
    // d_b = 0 and T_s = 0 they spend nothing on dual scattering's terms.
    const SceneGroom& groom = assets->groom;
    std::vector<MarschnerBcsdf> bcsdfs(groom.palette.fibers.begin(), groom.palette.fibers.end());
    DualScatteringParams shaderParams = scene.dualScattering;
    if (cache)
        shaderParams.d_b = 0;
    std::vector<DualScatteringShader> shaders;
    for (std::size_t t = 0; t < bcsdfs.size(); ++t)
        shaders.emplace_back(bcsdfs[t], assets->tables[t], shaderParams);
    // The volumetric integrator's cells read at samples along the fibers
    // (detail::ShadedMultiple; PipelineOptions::multipleSampleSpacing).
    detail::ShadedMultiple shadedMultiple;
    if (cache) {
        shadedMultiple.cache = cache;
        shadedMultiple.groom = &groom.groom;
        shadedMultiple.spacing = options.multipleSampleSpacing * cache->cellSize();
    }
    const detail::DualScatteringFragmentShader fragmentShader(
        std::move(shaders), groom.groom.fiberType, scene.lights, std::move(terms),
        std::move(shadedEnvironment), shadedMultiple);
    RasterOutput image = rasterize(groom.groom, camera, fragmentShader,
                                   rasterSettings(scene, options), surfaces, background);
    result.film = std::move(image.film);
    result.raster = image.stats;
    result.fiberTypes = groom.palette.size();
    result.groomNotes = groom.notes;
    result.warnings.insert(result.warnings.end(), groom.warnings.begin(), groom.warnings.end());
    for (const std::string& w : assets->surfaces.warnings)
        result.warnings.push_back(w);
    warnAboutLights(scene, assets->surfaces, result.warnings);
    for (std::string& w : image.warnings)
        result.warnings.push_back(std::move(w));
    // (From the stats: the hair alpha layer may not be stored.)
    warnIfNoHairSeen(scene, image.stats.fragmentsComposited > 0, &groom.groom, result.warnings);

    // The renderer's shading time includes the global-term evaluations made
    // inside the shader: apportion it by the shader's own thread time.
    const RasterStats& st = *result.raster;
    const double shaderThread = fragmentShader.shadeThreadSeconds();
    const double evalShare =
        shaderThread > 0 ? fragmentShader.globalTermThreadSeconds() / shaderThread : 0.0;
    result.times.raster = surfaceSeconds + st.setupSeconds + st.rasterSeconds;
    result.times.globalTerm += st.shadeSeconds * evalShare;
    result.times.shade = st.shadeSeconds * (1.0 - evalShare);
    const std::vector<GlobalTermStats> stats = fragmentShader.stats();
    for (std::size_t l = 0; l < stats.size(); ++l)
        result.lights[l].stats = stats[l];
    if (result.environment) {
        describeEnvironment(*assets->environment, scene, *result.environment);
        result.environment->loadSeconds = assets->environmentLoadSeconds;
        result.environment->stats = fragmentShader.environmentStats();
    }

    if (assets->grid)
        result.outputAttributes["hairvox:voxel_size"] =
            std::to_string(assets->grid->info.voxelSize);
    result.outputAttributes.insert(options.outputAttributes.begin(),
                                   options.outputAttributes.end());
    if (writeFiles) {
        const auto start = Clock::now();
        result.written = writeOutputs(result.film, scene, result.outputAttributes);
        result.times.write = secondsSince(start);
    }
    return result;
}

SceneRender renderPathTraced(const Scene& scene, const PipelineOptions& options, bool writeFiles) {
    SceneRender result;
    auto start = Clock::now();
    const SceneGroom sceneGroom = loadGroom(scene);
    const Groom& groom = sceneGroom.groom;
    result.warnings = sceneGroom.warnings;
    result.fiberTypes = sceneGroom.palette.size();
    result.groomNotes = sceneGroom.notes;
    const SceneSurfaces surfaces = loadSurfaces(scene);
    for (const std::string& w : surfaces.warnings)
        result.warnings.push_back(w);
    const auto environmentStart = Clock::now();
    const std::shared_ptr<const EnvironmentMap> environment = loadEnvironment(scene);
    if (environment) {
        describeEnvironment(*environment, scene, result.environment.emplace());
        result.environment->loadSeconds = secondsSince(environmentStart);
    }
    result.times.load = secondsSince(start);
    const std::string hash = pathTraceHash(scene, sceneGroom, surfaces, environment.get());

    // Continue from the scene's own earlier output, if asked and it is there.
    std::optional<Film> previous;
    std::uint32_t previousSpp = 0;
    if (options.continuePathTrace && !scene.output.exr.empty() &&
        std::filesystem::exists(scene.output.exr)) {
        const ExrImage exr = readExr(scene.output.exr);
        const auto attribute = [&](const char* key) -> std::string {
            const auto it = exr.attributes.find(key);
            return it == exr.attributes.end() ? std::string() : it->second;
        };
        const std::string& file = scene.output.exr.string();
        if (attribute("hairvox:integrator") != toString(Integrator::Path))
            throw InputError(strCat(file, ": not a path-traced image; cannot continue it"));
        if (attribute("hairvox:pathTraceHash") != hash)
            throw InputError(strCat(
                file, ": rendered from another scene, groom or seed (render hash ",
                attribute("hairvox:pathTraceHash"), ", this scene's ", hash, "); not continued"));
        const std::string spp = attribute("hairvox:spp");
        char* end = nullptr;
        const unsigned long n = std::strtoul(spp.c_str(), &end, 10);
        if (spp.empty() || *end != '\0' || n < 1 || n > 1'000'000)
            throw InputError(strCat(file, ": hairvox:spp = \"", spp, "\": not a sample count"));
        previousSpp = static_cast<std::uint32_t>(n);
        previous = filmFromExr(exr);
    }

    PathTraceScene pts;
    pts.groom = &groom;
    pts.fiberScale = scene.fiberScale;
    pts.fibers = sceneGroom.palette.fibers;
    pts.lights = scene.lights;
    pts.camera = scene.camera;
    pts.surfaces = surfaces.scene;
    pts.surfaceAlbedo = surfaces.albedo;
    pts.background = scene.background;
    pts.environment = environment;
    pts.environmentVisible = scene.environment && scene.environment->visible;
    PathTraceSettings settings = scene.pathTrace;
    settings.threads = options.threads;
    settings.progress = options.progress;
    start = Clock::now();
    PathTraceOutput traced = pathTrace(pts, settings, previous ? &*previous : nullptr, previousSpp);
    result.times.trace = secondsSince(start);
    result.film = std::move(traced.film);
    result.pathTrace = traced.stats;
    warnAboutLights(scene, surfaces, result.warnings);
    if (traced.stats.spp > 0) // an image without samples says nothing about what the camera sees
        warnIfNoHairSeen(scene, filmShowsHair(result.film), &groom, result.warnings);
    for (const Light& light : scene.lights)
        result.lights.push_back({.name = light.name, .skipped = light.isDark(), .stats = {}});

    result.outputAttributes = {{"hairvox:spp", std::to_string(traced.stats.spp)},
                               {"hairvox:seed", std::to_string(scene.pathTrace.seed)},
                               {"hairvox:pathTraceHash", hash}};
    result.outputAttributes.insert(options.outputAttributes.begin(),
                                   options.outputAttributes.end());
    if (writeFiles && traced.stats.spp > previousSpp) {
        start = Clock::now();
        result.written = writeOutputs(result.film, scene, result.outputAttributes);
        result.times.write = secondsSince(start);
    }
    return result;
}

} // namespace

SceneRender renderScene(const Scene& scene, const PipelineOptions& options, bool writeFiles,
                        FrameReuse* reuse) {
    scene.validate();
    options.environment.validate();
    if (!(options.multipleSampleSpacing >= 0.0f && options.multipleSampleSpacing <= 2.0f))
        throw InputError(
            strCat("volumetric multiple sample spacing = ", options.multipleSampleSpacing,
                   " cells: expected a number in [0, 2]"));
    const std::uint64_t limit =
        options.maxMemoryBytes > 0 ? options.maxMemoryBytes : defaultMemoryLimit();
    const MemoryEstimate memory = estimateRenderMemory(scene);
    if (memory.total() > limit)
        throw InputError(strCat(
            scene.name, ": a ", scene.camera.width, " x ", scene.camera.height,
            " render would need about ", gib(double(memory.total())),
            " (film: ", memory.filmChannels,
            " float channels per pixel and the integrator's buffers, ", gib(double(memory.film)),
            "; groom: ", gib(double(memory.groom)), "; meshes: ", gib(double(memory.meshes)),
            "; the rest: ", gib(double(memory.fixed)), "), over the memory limit of ",
            gib(double(limit)), options.maxMemoryBytes > 0 ? "" : " (3/4 of the physical memory)",
            "; lower the resolution or raise the limit (--max-memory GiB)"));
    PipelineOptions withLimit = options;
    withLimit.maxMemoryBytes = limit;
    const ThreadLimit threadLimit(options.threads);
    return scene.integrator == Integrator::Path
               ? renderPathTraced(scene, withLimit, writeFiles)
               : renderRasterized(scene, withLimit, writeFiles,
                                  reuse ? reuse->state_.get() : nullptr);
}

std::vector<std::string> hairRadianceLayers(const Film& film) {
    std::vector<std::string> layers = {"direct_R", "direct_TT", "direct_TRT"};
    if (film.find("multiple")) {
        layers.emplace_back("multiple");
    } else if (film.find("back_direct") && film.find("scatter")) {
        layers.emplace_back("back_direct");
        layers.emplace_back("scatter");
    } else {
        throw std::out_of_range(
            "the image has neither layer 'multiple' (path tracer, volumetric) nor the "
            "dual-scattering layers 'back_direct' and 'scatter'");
    }
    return layers;
}

ComparedImage hairRadianceOf(const Film& film) {
    return ComparedImage::fromFilm(film, hairRadianceLayers(film), kHairAlphaLayer,
                                   film.find("hair_half_a") ? "hair_half_a" : std::string_view{});
}

std::string pathTraceHash(const Scene& scene, const SceneGroom& groom,
                          const SceneSurfaces& surfaces, const EnvironmentMap* environment) {
    Hasher h;
    h.value(contentHash(groom.groom));
    h.values(std::span<const float>(groom.groom.thickness));
    h.values(std::span<const std::uint8_t>(groom.groom.fiberType));
    scene.fiberScale.hashInto(h);
    for (const FiberParams& fiber : groom.palette.fibers)
        fiber.hashInto(h);
    for (const Light& l : scene.lights) {
        l.hashInto(h);
        h.string(l.name);
    }
    const CameraParams& c = scene.camera;
    h.value(c.position).value(c.lookAt).value(c.up).value(c.fovY).value(c.width).value(c.height);
    h.value(scene.head.has_value());
    if (scene.head)
        h.value(scene.head->sphere.center)
            .value(scene.head->sphere.radius)
            .value(scene.head->albedo);
    h.value(surfaces.albedo.size());
    for (const Rgb& a : surfaces.albedo)
        h.value(a);
    if (surfaces.scene)
        for (const TriangleMesh& m : surfaces.scene->meshes())
            h.value(m.contentHash());
    h.value(scene.background);
    h.value(environment != nullptr);
    if (environment) {
        environment->hashInto(h);
        h.value(scene.environment && scene.environment->visible);
    }
    h.value(scene.pathTrace.seed)
        .value(scene.pathTrace.maxDepth)
        .value(scene.pathTrace.rouletteDepth);
    return hexDigest(h.digest());
}

} // namespace hairvox
