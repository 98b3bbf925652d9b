#include "dual_scattering_fragment_shader.h"
#include "surfaces.h"

#include <hairvox/core/error.h>
#include <hairvox/core/format.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/parallel.h>
#include <hairvox/film/image_file.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/transmittance/exact_global_term.h>

#include <chrono>
#include <cstdio>
#include <sstream>

namespace hairvox {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

} // namespace

GlobalTermSettings globalTermSettings(const Scene& scene) {
    GlobalTermSettings s;
    s.fiberScale = scene.fiberScale;
    s.dualScattering = scene.dualScattering;
    if (scene.head)
        s.occluder = scene.head->sphere;
    return s;
}

RasterSettings rasterSettings(const Scene& scene, const PipelineOptions& options) {
    RasterSettings s;
    s.fiberScale = scene.fiberScale;
    s.shadingRate = scene.shadingRate;
    s.background = scene.background;
    s.threads = options.threads;
    s.progress = options.progress;
    return s;
}

Groom loadGroom(const Scene& scene, std::string& warnings) {
    warnings.clear();
    if (scene.groom.isProcedural())
        return generateGroom(scene.groom.procedural);
    LoadedGroom loaded = readGroom(scene.groom.file);
    std::ostringstream os;
    for (const std::string& w : loaded.warnings)
        os << w << "; ";
    if (loaded.sanitized.droppedSegments > 0)
        os << "dropped " << loaded.sanitized.droppedSegments << " zero-length segment(s); ";
    if (loaded.sanitized.droppedStrands > 0)
        os << "dropped " << loaded.sanitized.droppedStrands << " degenerate strand(s); ";
    warnings = os.str();
    return std::move(loaded.groom);
}

std::unique_ptr<SceneAssets> loadSceneAssets(const Scene& scene, const PipelineOptions& options) {
    auto assets = std::make_unique<SceneAssets>();
    auto start = Clock::now();
    assets->groom = loadGroom(scene, assets->groomWarnings);
    assets->times.load = secondsSince(start);
    throwIfInterrupted();

    if (scene.globalTermMode != GlobalTermMode::Exact) {
        start = Clock::now();
        SplatOptions splat;
        splat.voxelSize = scene.voxelSize.value_or(0.0f);
        splat.fiberScale = scene.fiberScale;
        splat.storeOrientationTensor = options.grid.orientation == OrientationModel::Tensor;
        splat.sourceFile =
            scene.groom.isProcedural() ? std::string("procedural") : scene.groom.file.string();
        splat.showProgress = options.progress;
        assets->grid = splatStrands(assets->groom, splat);
        assets->times.voxelize = secondsSince(start);
    }

    start = Clock::now();
    TableBuildOptions tableOptions;
    tableOptions.d_b = scene.dualScattering.d_b;
    assets->tables = std::make_unique<DualScatteringTables>(DualScatteringTables::loadOrBuild(
        scene.fiber, options.tableCacheDir.empty() ? defaultTableCacheDir() : options.tableCacheDir,
        tableOptions));
    assets->times.tables = secondsSince(start);

    start = Clock::now();
    const CrossingTable crossings = CrossingTable::fromDualScattering(*assets->tables);
    const GlobalTermSettings settings = globalTermSettings(scene);
    switch (scene.globalTermMode) {
    case GlobalTermMode::Exact: {
        ExactOptions exact;
        exact.rays = static_cast<int>(scene.exact.rays);
        exact.radius = scene.exact.radius;
        assets->globalTerm = makeExactModel(assets->groom, crossings, settings, exact);
        break;
    }
    case GlobalTermMode::Grid:
        assets->globalTerm = makeGridModel(*assets->grid, crossings, settings, options.grid);
        break;
    case GlobalTermMode::Approx:
        assets->globalTerm = makeApproxModel(*assets->grid, crossings, settings, options.grid);
        break;
    }
    assets->times.globalTerm = secondsSince(start);
    return assets;
}

SceneRender renderScene(const Scene& scene, const PipelineOptions& options, bool writeFiles) {
    scene.validate();
    const ThreadLimit threadLimit(options.threads);
    SceneRender result;
    const std::unique_ptr<SceneAssets> assets = loadSceneAssets(scene, options);
    result.times = assets->times;
    if (assets->grid) {
        result.activeVoxels = assets->grid->activeVoxelCount();
        result.voxelSize = assets->grid->info.voxelSize;
    }

    // Per light: skip what cannot light anything, prepare the rest (the cache).
    std::vector<std::unique_ptr<LightGlobalTerm>> terms;
    for (const Light& light : scene.lights) {
        LightReport report;
        report.name = light.name;
        const auto start = Clock::now();
        std::unique_ptr<LightGlobalTerm> term;
        if (light.isDark()) {
            report.skipped = true;
        } else {
            term = assets->globalTerm->forLight(light);
            if (term->blocksEverything()) {
                report.skipped = true;
                term.reset();
            }
        }
        report.prepareSeconds = secondsSince(start);
        result.times.globalTerm += report.prepareSeconds;
        result.lights.push_back(report);
        terms.push_back(std::move(term));
    }

    const MarschnerBcsdf bcsdf(scene.fiber);
    const DualScatteringShader shader(bcsdf, *assets->tables, scene.dualScattering);
    const detail::DualScatteringFragmentShader fragmentShader(shader, scene.lights,
                                                              std::move(terms));
    const Camera camera(scene.camera);
    const auto surfacesStart = Clock::now();
    const SurfaceLayer surfaces =
        scene.head ? detail::headSurfaceLayer(*scene.head, camera, scene.lights) : SurfaceLayer{};
    const double surfaceSeconds = secondsSince(surfacesStart);
    result.image =
        rasterize(assets->groom, camera, fragmentShader, rasterSettings(scene, options), surfaces);

    // The renderer's shading time includes the global-term evaluations made
    // inside the shader: apportion it by the shader's own thread time.
    const RasterStats& st = result.image.stats;
    const double shaderThread = fragmentShader.shadeThreadSeconds();
    const double evalShare =
        shaderThread > 0 ? fragmentShader.globalTermThreadSeconds() / shaderThread : 0.0;
    result.times.raster = surfaceSeconds + st.setupSeconds + st.rasterSeconds;
    result.times.globalTerm += st.shadeSeconds * evalShare;
    result.times.shade = st.shadeSeconds * (1.0 - evalShare);
    const std::vector<GlobalTermStats> stats = fragmentShader.stats();
    for (std::size_t l = 0; l < stats.size(); ++l)
        result.lights[l].stats = stats[l];

    if (writeFiles) {
        const auto start = Clock::now();
        std::map<std::string, std::string> attributes;
        if (assets->grid)
            attributes["hairvox:voxel_size"] = std::to_string(assets->grid->info.voxelSize);
        result.written = writeOutputs(result.image.film, scene, attributes);
        result.times.write = secondsSince(start);
    }
    return result;
}

std::vector<std::filesystem::path> writeOutputs(const Film& film, const Scene& scene,
                                                const std::map<std::string, std::string>& extra) {
    std::vector<std::filesystem::path> written;
    if (!scene.output.exr.empty()) {
        ExrHeader header;
        header.worldToCamera = Camera(scene.camera).worldToCameraMatrix();
        header.attributes = {
            {"hairvox:scene", scene.name},
            {"hairvox:globalTermMode", toString(scene.globalTermMode)},
            {"hairvox:voxelSize", scene.voxelSize ? strCat(*scene.voxelSize) : "auto"},
            {"hairvox:shadingRate", toString(scene.shadingRate)},
        };
        for (const auto& [key, value] : extra)
            header.attributes[key] = value;
        writeExr(scene.output.exr, film, header);
        written.push_back(scene.output.exr);
    }
    if (!scene.output.png.empty()) {
        writePng(scene.output.png, film.width(), film.height(),
                 previewPixels(film, scene.output.exposure, scene.output.toneMap));
        written.push_back(scene.output.png);
    }
    return written;
}

void printTimingReport(std::ostream& os, const Scene& scene, const SceneRender& r) {
    const RasterStats& st = r.image.stats;
    char line[512];
    std::snprintf(line, sizeof(line), "hairvox: %s, %s mode, %dx%d: %.2f s\n", scene.name.c_str(),
                  toString(scene.globalTermMode), scene.camera.width, scene.camera.height,
                  r.times.total());
    os << line;
    const auto row = [&](const char* stage, double seconds, const std::string& detail) {
        std::snprintf(line, sizeof(line), "  %-12s %7.3f s  %s\n", stage, seconds, detail.c_str());
        os << line;
    };
    row("load", r.times.load, thousands(st.segments) + " segments");
    if (r.voxelSize > 0) {
        std::snprintf(line, sizeof(line), "%s active voxels of %.3g",
                      thousands(r.activeVoxels).c_str(), r.voxelSize);
        row("voxelize", r.times.voxelize, line);
    } else {
        row("voxelize", r.times.voxelize, "not needed (exact mode)");
    }
    row("tables", r.times.tables, "dual-scattering tables (disk cache)");
    std::uint64_t queries = 0, blocked = 0, empty = 0, skippedLights = 0;
    for (const LightReport& l : r.lights) {
        queries += l.stats.queries;
        blocked += l.stats.blockedByOccluder;
        empty += l.stats.emptyPaths;
        skippedLights += l.skipped ? 1 : 0;
    }
    row("global term", r.times.globalTerm,
        thousands(queries) + " queries; skipped: " + thousands(skippedLights) + " light(s), " +
            thousands(blocked) + " behind the head, " + thousands(empty) +
            " with nothing in front");
    row("raster", r.times.raster,
        thousands(st.fragments) + " fragments; skipped: " + thousands(st.segmentsOutsideView) +
            " segments outside the view, " + thousands(st.segmentTilesBehindSurfaces) +
            " segment-tiles behind the head, " + thousands(st.segmentTilesSkipped) +
            " segment-tiles opaque");
    row("shade", r.times.shade,
        thousands(st.shadingPoints) + " shading points; skipped " +
            thousands(st.fragmentsBehindOpaque) + " fragments behind opaque pixels");
    std::string written;
    for (const auto& p : r.written)
        written += (written.empty() ? "" : ", ") + p.string();
    row("write", r.times.write, written.empty() ? "nothing" : written);
}

} // namespace hairvox
