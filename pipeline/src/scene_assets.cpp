#include "scene_assets.h"

#include "asset_cache.h"

#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/transmittance/exact_global_term.h>

#include <algorithm>
#include <chrono>

namespace hairvox {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

} // namespace

std::shared_ptr<const EnvironmentMap> loadEnvironment(const Scene& scene, std::uint64_t maxBytes) {
    if (!scene.environment)
        return nullptr;
    const EnvironmentLight& e = *scene.environment;
    const Rgb scale = e.intensity * e.color;
    try {
        if (e.isUniform()) {
            EnvironmentMap uniform = EnvironmentMap::uniform(scale);
            return std::make_shared<const EnvironmentMap>(std::move(uniform));
        }
        return std::make_shared<const EnvironmentMap>(
            EnvironmentMap::readExr(e.source(), scale, e.rotation, maxBytes));
    } catch (const InputError& error) {
        throw InputError(
            strCat(scene.name, ": environment light \"", e.name, "\": ", error.what()));
    }
}

void checkVoxelSizeForGroom(const Scene& scene, const Groom& groom) {
    if (!scene.voxelSize || groom.empty())
        return;
    const Vec3f extent = groom.bounds().extent();
    const float longest = std::max({extent.x, extent.y, extent.z});
    if (!(longest > 0))
        return;
    const float h = *scene.voxelSize;
    if (longest < 2 * h)
        throw InputError(
            strCat(scene.name, ": grid.voxel_size = ", h,
                   " is too large for the groom: its bounding box is ", extent.x, " x ", extent.y,
                   " x ", extent.z, ", ", longest / h,
                   " voxel(s) along its longest side (at least 2 are needed to resolve the hair; "
                   "the default, \"auto\", is the longest side / ",
                   kDefaultVoxelsAcross, " = ", longest / float(kDefaultVoxelsAcross), ")"));
}

SceneSurfaces loadSurfaces(const Scene& scene) {
    SceneSurfaces out;
    std::vector<Sphere> spheres;
    if (scene.head) {
        spheres.push_back(scene.head->sphere);
        out.albedo.push_back(scene.head->albedo);
    }
    std::vector<TriangleMesh> meshes;
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
        const MeshSource& source = scene.meshes[i];
        try {
            if (source.isMannequin()) {
                meshes.push_back(generateHeadMesh(source.mannequin, source.mannequinRings));
            } else {
                LoadedMesh loaded = readObjMesh(source.file);
                meshes.push_back(std::move(loaded.mesh));
                for (std::string& w : loaded.warnings)
                    out.warnings.push_back(std::move(w));
            }
        } catch (const InputError& e) {
            throw InputError(strCat(scene.name, ": meshes[", i, "]: ", e.what()));
        }
        source.transform.apply(meshes.back());
        out.albedo.push_back(source.albedo);
        throwIfInterrupted();
    }
    if (!spheres.empty() || !meshes.empty())
        out.scene = std::make_shared<const SurfaceScene>(std::move(spheres), std::move(meshes));
    return out;
}

GlobalTermSettings globalTermSettings(const Scene& scene, const SceneSurfaces& surfaces) {
    GlobalTermSettings s;
    s.fiberScale = scene.fiberScale;
    s.dualScattering = scene.dualScattering;
    s.surfaces = surfaces.scene;
    return s;
}

RasterSettings rasterSettings(const Scene& scene, const PipelineOptions& options) {
    RasterSettings s;
    s.fiberScale = scene.fiberScale;
    s.shadingRate = scene.shadingRate;
    s.shadingTolerance = scene.shadingTolerance;
    s.tailTransmittance = scene.tailTransmittance;
    s.background = scene.background;
    s.layers = scene.output.layers;
    s.threads = options.threads;
    s.progress = options.progress;
    return s;
}

SceneGroom loadGroom(const Scene& scene) {
    SceneGroom g;
    const bool procedural = scene.groom.isProcedural();
    const std::string source = procedural ? "procedural groom" : scene.groom.sourceName();
    SanitizeReport sanitized;
    if (procedural) {
        g.groom = generateGroom(scene.groom.procedural);
    } else if (scene.groom.inMemory) {
        g.groom = *scene.groom.inMemory; // its attributes are resolved below, in this copy
        sanitized = sanitizeGroom(g.groom, source);
    } else {
        LoadedGroom loaded = readGroom(scene.groom.file);
        g.warnings = std::move(loaded.warnings);
        sanitized = loaded.sanitized;
        g.groom = std::move(loaded.groom);
    }
    if (sanitized.droppedSegments > 0)
        g.warnings.push_back(
            strCat("dropped ", sanitized.droppedSegments, " zero-length segment(s)"));
    if (sanitized.droppedStrands > 0)
        g.warnings.push_back(strCat("dropped ", sanitized.droppedStrands, " degenerate strand(s)"));
    if (std::string note =
            resolveThickness(g.groom, scene.groom.thickness, scene.fiberScale, source, g.warnings);
        !note.empty())
        g.notes.push_back(std::move(note));
    g.palette = resolveColors(g.groom, scene.groom.color, scene.fiber, source, g.warnings);
    if (!g.palette.colors.empty())
        g.notes.push_back(strCat(g.palette.size(), " fiber type(s) from the ",
                                 procedural             ? "procedural groom's"
                                 : scene.groom.inMemory ? "groom's"
                                                        : "file's",
                                 " colours (groom.color \"use\"): sigma_a replaces the scene's"));
    else if (!g.groom.color.empty())
        g.notes.push_back("per-point colours ignored (groom.color \"ignore\")");
    if (!g.groom.transparency.empty())
        g.warnings.push_back(strCat(source, " carries per-point transparency, which hairvox does "
                                            "not render: every fiber is opaque"));
    return g;
}

namespace {

SplatOptions splatOptions(const Scene& scene, const PipelineOptions& options) {
    SplatOptions splat;
    splat.voxelSize = scene.voxelSize.value_or(0.0f);
    splat.fiberScale = scene.fiberScale;
    splat.storeOrientationTensor = options.grid.orientation == OrientationModel::Tensor;
    splat.sourceFile = scene.groom.sourceName();
    splat.showProgress = options.progress;
    if (options.maxMemoryBytes > 0) {
        const std::uint64_t used = estimateRenderMemory(scene).total();
        splat.memoryBudgetBytes =
            std::min(splat.memoryBudgetBytes,
                     options.maxMemoryBytes > used ? options.maxMemoryBytes - used : 1);
    }
    return splat;
}

} // namespace

namespace detail {

std::filesystem::path tableCacheDirOf(const PipelineOptions& options) {
    if (!options.tableCacheDir.empty())
        return options.tableCacheDir;
    return options.diskCache ? options.diskCache->directory() : defaultTableCacheDir();
}

FrameAssets prepareAssets(const Scene& scene, const PipelineOptions& options, SceneAssets* assets,
                          FrameReuse::State* reuse) {
    FrameAssets out;
    auto start = Clock::now();
    assets->groom = loadGroom(scene);
    assets->surfaces = loadSurfaces(scene);
    const auto environmentStart = Clock::now();
    assets->environment = loadEnvironment(scene);
    assets->environmentLoadSeconds = secondsSince(environmentStart);
    assets->times.load = secondsSince(start);
    throwIfInterrupted();

    const DiskCache* disk = options.diskCache.get();
    const bool keyed = reuse || disk;
    const std::uint64_t groom = keyed ? detail::groomKey(assets->groom.groom) : 0;
    if (scene.globalTermMode != GlobalTermMode::Exact ||
        scene.integrator == Integrator::Volumetric) {
        checkVoxelSizeForGroom(scene, assets->groom.groom);
        const SplatOptions splat = splatOptions(scene, options);
        if (keyed)
            out.gridKey = detail::gridKey(groom, splat);
        if (reuse && reuse->assets && reuse->assets->grid && reuse->gridKey == out.gridKey) {
            out.gridReused = true;
        } else {
            if (reuse)
                reuse->release();
            start = Clock::now();
            assets->grid = std::make_shared<const FiberGrid>(
                disk ? detail::splatOrLoad(assets->groom.groom, splat, *disk, out.gridKey,
                                           options.diskCacheStoresGrid)
                     : splatStrands(assets->groom.groom, splat));
            assets->times.voxelize = secondsSince(start);
        }
    }
    if (keyed)
        out.modelKey = detail::modelKey(groom, out.gridKey, scene, options, assets->groom,
                                        assets->surfaces, assets->environment.get());
    if (reuse) {
        if (reuse->assets && reuse->modelKey == out.modelKey) {
            // The same groom, surfaces, grid and model: the frame before's.
            out.reused = reuse->assets.get();
            return out;
        }
        if (out.gridReused) // shared, not copied
            assets->grid = reuse->assets->grid;
        reuse->release();
    }

    start = Clock::now();
    TableBuildOptions tableOptions;
    tableOptions.d_b = scene.dualScattering.d_b;
    const std::filesystem::path tableCacheDir = tableCacheDirOf(options);
    CrossingTables crossings;
    for (const FiberParams& fiber : assets->groom.palette.fibers) {
        assets->tables.push_back(
            DualScatteringTables::loadOrBuild(fiber, tableCacheDir, tableOptions));
        crossings.push_back(CrossingTable::fromDualScattering(assets->tables.back()));
    }
    assets->times.tables = secondsSince(start);

    start = Clock::now();
    GlobalTermSettings settings = globalTermSettings(scene, assets->surfaces);
    settings.groom = &assets->groom.groom;
    settings.diskCache = disk;
    settings.diskCacheKey = out.modelKey;
    if (!options.diskCacheSkipsLights.empty())
        settings.diskCacheStores = [skip = options.diskCacheSkipsLights](const Light& light) {
            return skip.count(light.name) == 0;
        };
    GridOptions gridOptions = options.grid;
    if (scene.fiberSampleSpacing)
        gridOptions.fiberSampleSpacing = *scene.fiberSampleSpacing;
    ExactOptions exact;
    exact.rays = static_cast<int>(scene.exact.rays);
    exact.radius = scene.exact.radius;
    exact.seed = scene.exact.seed;
    const auto makeModel = [&](CrossingTables tables, const GlobalTermSettings& s,
                               const GridOptions& grid) -> std::unique_ptr<GlobalTermModel> {
        switch (scene.globalTermMode) {
        case GlobalTermMode::Exact:
            return makeExactModel(assets->groom.groom, std::move(tables), s, exact);
        case GlobalTermMode::Grid:
            return makeGridModel(*assets->grid, std::move(tables), s, grid);
        case GlobalTermMode::Approx:
            return makeApproxModel(*assets->grid, std::move(tables), s, grid);
        }
        throw std::logic_error("unknown global-term mode");
    };
    if (assets->environment) {
        // The environment's regions: a coarser cache, each query evaluated
        // as it is (no surfaces' shadow, no samples along the fibers: the
        // integrator adds both, environmentHairTerm()).
        GlobalTermSettings open = settings;
        open.surfaces = nullptr;
        open.groom = nullptr;
        GridOptions grid = gridOptions;
        grid.cacheSpacing = options.environment.cacheSpacing;
        assets->environmentTerm = makeModel(crossings, open, grid);
    }
    assets->globalTerm = makeModel(std::move(crossings), settings, gridOptions);
    assets->times.globalTerm = secondsSince(start);
    return out;
}

} // namespace detail

std::unique_ptr<SceneAssets> loadSceneAssets(const Scene& scene, const PipelineOptions& options) {
    auto assets = std::make_unique<SceneAssets>();
    detail::prepareAssets(scene, options, assets.get(), nullptr);
    return assets;
}

} // namespace hairvox
