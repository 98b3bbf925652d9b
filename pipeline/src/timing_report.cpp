// hairvox pipeline: the report a render prints — its stages' times and what
// each did and skipped (printTimingReport(), pipeline.h).
#include <hairvox/core/error.h>
#include <hairvox/core/format.h>
#include <hairvox/geometry/camera.h>
#include <hairvox/pipeline/pipeline.h>

#include <cstdio>
#include <ostream>
#include <string>

namespace hairvox {

void printTimingReport(std::ostream& os, const Scene& scene, const SceneRender& r) {
    char line[512];
    const Camera camera(scene.camera);
    if (r.pathTrace)
        std::snprintf(line, sizeof(line), "hairvox: %s, path traced, %dx%d: %.2f s\n",
                      scene.name.c_str(), camera.width(), camera.height(), r.times.total());
    else
        std::snprintf(line, sizeof(line), "hairvox: %s, %s%s mode, %dx%d: %.2f s\n",
                      scene.name.c_str(), r.volumetric ? "volumetric, " : "",
                      toString(scene.globalTermMode), camera.width(), camera.height(),
                      r.times.total());
    os << line;
    const auto row = [&](const char* stage, double seconds, const std::string& detail) {
        std::snprintf(line, sizeof(line), "  %-12s %7.3f s  %s\n", stage, seconds, detail.c_str());
        os << line;
    };
    // A further line of the stage above, under row()'s detail column
    // ("  " + 12 + " " + "%7.3f s" + "  "): no time of its own.
    const auto more = [&](const std::string& detail) { os << std::string(26, ' ') << detail << '\n'; };
    std::string written;
    for (const auto& p : r.written)
        written += (written.empty() ? "" : ", ") + p.string();
    const auto megabytes = [](std::uint64_t bytes) {
        return (bytes + 500'000) / 1'000'000;
    };
    // The environment map: what was read, and what reading it folded away.
    const auto environmentMap = [&]() {
        const EnvironmentReport& e = *r.environment;
        std::string text = strCat("environment: ", e.source, ", ", e.width, "x", e.height, ", ",
                                  megabytes(e.mapBytes), " MB with its distribution, ",
                                  int(std::lround(1000 * e.loadSeconds)), " ms to read",
                                  e.visible ? "; seen behind everything" : "; not seen");
        if (e.folds.values > 0) {
            std::snprintf(line, sizeof(line),
                          "; %s negative values (a lossy codec's ringing, as low as %.4g) folded "
                          "into the light within %d pixel(s) around them (%.2g%% of the energy)",
                          thousands(e.folds.values).c_str(), double(e.folds.lowest), e.folds.radius,
                          100 * e.folds.energy);
            text += line;
        }
        more(text);
    };
    if (r.pathTrace) {
        const PathTraceStats& pt = *r.pathTrace;
        row("load", r.times.load, "the groom");
        if (r.environment)
            environmentMap();
        std::snprintf(
            line, sizeof(line),
            "%u spp (%u this run%s); %s paths, %s rays + %s shadow rays: %.2f M rays/s, "
            "%.3f M paths/s; %.1f scattering events per path, deepest %u",
            pt.spp, pt.sppThisRun,
            pt.interrupted ? ", interrupted" : (pt.timeLimited ? ", time limit" : ""),
            thousands(pt.paths).c_str(), thousands(pt.rays).c_str(),
            thousands(pt.shadowRays).c_str(), 1e-6 * pt.raysPerSecond(), 1e-6 * pt.pathsPerSecond(),
            pt.paths > 0 ? double(pt.scatteringEvents) / double(pt.paths) : 0.0, pt.deepestPath);
        row("trace", r.times.trace, line);
        std::snprintf(line, sizeof(line), "%s paths stopped at the depth cap %u (throughput %.2g)",
                      thousands(pt.pathsAtDepthCap).c_str(), scene.pathTrace.maxDepth,
                      pt.energyAtDepthCap);
        more(line);
        if (r.environment)
            more(strCat("environment: importance-sampled by luminance x sin(theta) at every "
                        "scattering event (",
                        thousands(pt.environmentShadowRays), " of the shadow rays), ",
                        thousands(pt.escapedRays),
                        " continuation rays escaped to it; both weighted by the power heuristic"));
        row("write", r.times.write, written.empty() ? "nothing" : written);
        return;
    }
    const RasterStats& st = *r.raster;
    row("load", r.times.load,
        thousands(st.segments) + " segments" +
            (r.surfaceTriangles > 0 ? ", " + thousands(r.surfaceTriangles) + " triangles" : ""));
    for (const std::string& note : r.groomNotes)
        more(note);
    if (r.environment)
        environmentMap();
    if (r.voxelSize > 0) {
        std::snprintf(line, sizeof(line), "%s active voxels of %.3g%s",
                      thousands(r.activeVoxels).c_str(), r.voxelSize,
                      r.gridReused ? ": the frame before's grid (the same groom and voxel size)"
                                   : "");
        row("voxelize", r.times.voxelize, line);
    } else {
        row("voxelize", r.times.voxelize, "not needed (exact mode)");
    }
    row("tables", r.times.tables,
        strCat("dual-scattering tables (disk cache), ", r.fiberTypes, " fiber type(s)"));
    std::uint64_t queries = 0, evaluated = 0, blocked = 0, empty = 0, skippedLights = 0, held = 0;
    for (const LightReport& l : r.lights) {
        held += l.heldBytes;
        queries += l.stats.queries;
        evaluated += l.stats.evaluated;
        blocked += l.stats.blockedBySurface;
        empty += l.stats.emptyPaths;
        skippedLights += l.skipped ? 1 : 0;
    }
    if (r.lights.empty() && r.environment)
        row("global term", r.times.globalTerm, "the environment's regions alone (below)");
    else
        row("global term", r.times.globalTerm,
            thousands(queries) + " queries" +
                (evaluated < queries - blocked
                     ? strCat(" (", thousands(evaluated),
                              " evaluated, the rest interpolated along fibers)")
                     : std::string()) +
                "; skipped: " + thousands(skippedLights) + " light(s), " + thousands(blocked) +
                " behind surfaces, " + thousands(empty) + " with nothing in front" +
                (held > 0 ? strCat("; ", megabytes(held), " MB held") : std::string()));
    // What each light's preparation (the grid modes' cache) took: the lights
    // are prepared one after another, so these add up to the stage's time.
    std::string prepared;
    for (const LightReport& l : r.lights)
        if (!l.skipped) {
            if (l.reused)
                std::snprintf(line, sizeof(line), "%s the frame before's", l.name.c_str());
            else
                std::snprintf(line, sizeof(line), "%s %.3f s", l.name.c_str(), l.prepareSeconds);
            prepared += (prepared.empty() ? "" : ", ") + std::string(line);
        }
    if (!prepared.empty() && scene.globalTermMode != GlobalTermMode::Exact) {
        std::snprintf(line, sizeof(line), "%.3f s preparing the lights (one after another: ",
                      r.globalTermPrepareSeconds);
        more(line + prepared + "); the rest: lookups while shading");
    }
    if (r.environment) {
        const EnvironmentReport& e = *r.environment;
        std::snprintf(
            line, sizeof(line),
            "environment: %zu regions by median cut of %s (%.0f ms; spread up to %.0f "
            "deg), each a light: %.3f s preparing them%s, %s hair queries (%s "
            "evaluated), %llu MB held",
            e.lights, kEnvironmentSplitNames.name(e.split), 1000 * e.splitSeconds,
            double(e.widestSpreadDegrees), e.prepareSeconds,
            e.reusedLights > 0 ? strCat(" (", e.reusedLights, " the frame before's)").c_str() : "",
            thousands(e.stats.queries).c_str(), thousands(e.stats.evaluated).c_str(),
            static_cast<unsigned long long>(megabytes(e.heldBytes)));
        more(line);
    }
    if (r.volumetric) {
        const VolumetricStats& v = *r.volumetric;
        if (r.multipleReused) {
            row("multiple", r.times.multiple,
                "the frame before's solution (the same grid, lights, surfaces and settings)");
        } else {
            std::snprintf(line, sizeof(line),
                          "%s light paths through the fiber grid: %s fiber and %s surface "
                          "scatterings, deepest %u, %s stopped at the depth cap",
                          thousands(v.paths).c_str(), thousands(v.fiberEvents).c_str(),
                          thousands(v.surfaceEvents).c_str(), v.deepestPath,
                          thousands(v.pathsAtDepthCap).c_str());
            row("multiple", r.times.multiple, line);
            std::snprintf(
                line, sizeof(line),
                "%s cells of %.3g (SH order %d, %d coefficients per channel), %s "
                "deposits; %llu MB held; trace %.3f s, scattering kernels %.3f s",
                thousands(v.cells).c_str(), double(scene.volumetric.cache.cellVoxels) * r.voxelSize,
                scene.volumetric.cache.shOrder, scene.volumetric.cache.coefficients(),
                thousands(v.crossings).c_str(), static_cast<unsigned long long>(megabytes(v.bytes)),
                v.traceSeconds, v.finishSeconds);
            more(line);
        }
    }
    row("raster", r.times.raster,
        thousands(st.fragments) + " fragments; skipped: " + thousands(st.segmentsOutsideView) +
            " segments outside the view, " + thousands(st.segmentTilesBehindSurfaces) +
            " segment-tiles behind surfaces, " + thousands(st.segmentTilesSkipped) +
            " segment-tiles opaque");
    more(strCat("film: ", megabytes(r.film.bytesHeld()), " of ", megabytes(r.film.denseBytes()),
                " MB held (a layer holds no ", Film::kTileSize,
                "-pixel tile that is all its fill: zero, or the background)"));
    const std::string rate =
        scene.shadingRate == ShadingRate::Adaptive
            ? strCat("adaptive rate, tolerance ", scene.shadingTolerance, ": ",
                     thousands(st.smoothSegments), " of ", thousands(st.probedSegments),
                     " probed segment-tiles smooth")
            : strCat(toString(scene.shadingRate), " rate");
    const std::uint64_t rateInterpolated = st.fragmentsInterpolated - st.tailFragments;
    row("shade", r.times.shade,
        strCat(thousands(st.shadingPoints), " shading points (", rate, "); skipped ",
               thousands(st.fragmentsBehindOpaque), " fragments behind opaque pixels",
               rateInterpolated > 0 ? strCat(", ", thousands(rateInterpolated),
                                             " visible fragments interpolated instead of shaded")
                                    : std::string(),
               st.tailFragments > 0
                   ? strCat(", ", thousands(st.tailFragments),
                            " seen through transmittance < ", scene.tailTransmittance,
                            " interpolated from ", thousands(st.tailVertices), " strand vertices")
                   : std::string()));
    row("write", r.times.write, written.empty() ? "nothing" : written);
    if (scene.output.layers) {
        int stored = 0, all = 4; // the beauty and "A" are always there
        for (const FilmLayer& l : r.film.layers())
            stored += l.channels;
        for (const RasterLayer& l : layersOf(scene))
            all += l.channels;
        more(strCat(stored, " of ", all,
                    " channels (output.layers): the others are neither stored "
                    "in the film nor written"));
    }
}

} // namespace hairvox
