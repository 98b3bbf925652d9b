#include "tile_binning.h"
#include "tile_renderer.h"

#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/parallel.h>
#include <hairvox/core/progress.h>
#include <hairvox/render/rasterizer.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

namespace hairvox {

using raster::binSegments;
using raster::Clock;
using raster::indexSegments;
using raster::kMaxWarnings;
using raster::kNotStored;
using raster::kTileSize;
using raster::prepareVertices;
using raster::RenderContext;
using raster::secondsSince;
using raster::TileRenderer;
using raster::TileResult;
using raster::TileScratch;
using raster::tileSurfaceDepths;

std::ostream& operator<<(std::ostream& os, const RasterStats& s) {
    return os << "RasterStats(" << s.seconds << " s: setup " << s.setupSeconds << " s, raster "
              << s.rasterSeconds << " s, shade " << s.shadeSeconds << " s; " << s.segments
              << " segments, " << s.segmentsOutsideView << " outside the view, "
              << s.segmentTileRefs << " segment-tile pairs, " << s.segmentTilesBehindSurfaces
              << " behind surfaces; " << s.fragments << " fragments, " << s.fragmentsComposited
              << " composited, " << s.fragmentsBehindOpaque << " behind opaque pixels; "
              << s.shadingPoints << " shading points, " << s.fragmentsInterpolated
              << " fragments interpolated, " << s.smoothSegments << " of " << s.probedSegments
              << " probed segments smooth, " << s.tailFragments << " behind the tail from "
              << s.tailVertices << " vertices, " << s.invalidSamples << " rejected; " << s.tiles
              << " tiles)";
}

bool RasterSettings::stores(const std::string& layer) const {
    return !layers || std::find(layers->begin(), layers->end(), layer) != layers->end();
}

std::vector<RasterLayer> rasterLayers(const ShaderLayout& layout) {
    std::vector<RasterLayer> layers;
    for (const std::string& name : layout.radiance)
        layers.push_back({name, 3, false});
    layers.push_back({kSurfaceLayer, 3, false});
    layers.push_back({kBackgroundLayer, 3, false});
    layers.push_back({kHairAlphaLayer, 1, false});
    layers.push_back({kDepthLayer, 1, /*fullPrecision=*/true}); // half is too coarse for depth
    for (const ShaderLayout::AverageLayer& a : layout.averages)
        layers.push_back({a.name, a.channels, false});
    return layers;
}

RasterOutput rasterize(const Groom& groom, const Camera& camera, const FragmentShader& shader,
                       const RasterSettings& settings, const SurfaceLayer& surfaces,
                       const BackgroundLayer& background) {
    const Clock::time_point start = Clock::now();
    settings.fiberScale.validate();
    if (!(settings.opaqueTransmittance >= 0.0f && settings.opaqueTransmittance < 1.0f))
        throw InputError(strCat("opaque transmittance ", settings.opaqueTransmittance,
                                ": expected a number in [0, 1)"));
    if (!(settings.shadingTolerance >= 0.0f && settings.shadingTolerance <= 1.0f))
        throw InputError(strCat("shading tolerance ", settings.shadingTolerance,
                                ": expected a number in [0, 1]"));
    if (!(settings.tailTransmittance >= 0.0f && settings.tailTransmittance <= 1.0f))
        throw InputError(strCat("tail transmittance ", settings.tailTransmittance,
                                ": expected a number in [0, 1]"));
    if (!settings.background.isFinite() || settings.background.minComponent() < 0)
        throw InputError(
            strCat("background ", settings.background, ": expected finite values >= 0"));
    if (groom.pointCount() >= std::numeric_limits<std::uint32_t>::max())
        throw InputError(
            strCat("groom: ", groom.pointCount(), " points: expected fewer than 2^32"));
    const std::size_t pixels = std::size_t(camera.width()) * std::size_t(camera.height());
    if (!surfaces.empty() &&
        (surfaces.coverage.size() != pixels || surfaces.depth.size() != pixels ||
         surfaces.radiance.size() != pixels))
        throw InputError(strCat("surface layer of ", surfaces.coverage.size(), " pixels for a ",
                                camera.width(), " x ", camera.height(), " camera"));
    const ThreadLimit threadLimit(settings.threads);

    RenderContext ctx(groom, camera, shader, settings, surfaces, background);
    RasterOutput out;
    out.film = Film(camera.width(), camera.height());
    Film& film = out.film;
    // Each layer's tiles are allocated by the raster tile that writes them
    // (finishCoverage(), finishShading()), where it writes anything but +0.
    // Where nothing is seen, the beauty and the background layer are the
    // background colour: their fill (film.h), as the other layers' is 0.
    ctx.beautyLayer = film.addLayer(std::string(Film::kBeauty), 3, false, settings.background);
    ctx.alphaLayer = film.addLayer(std::string(Film::kAlpha), 1);
    const std::vector<RasterLayer> layers = rasterLayers(ctx.layout);
    if (settings.layers)
        for (const std::string& name : *settings.layers)
            if (std::none_of(layers.begin(), layers.end(),
                             [&](const RasterLayer& l) { return l.name == name; }))
                throw InputError(strCat("layer \"", name, "\": not a layer of this render"));
    std::vector<std::size_t> index;
    for (const RasterLayer& l : layers)
        index.push_back(
            settings.stores(l.name)
                ? film.addLayer(l.name, l.channels, l.fullPrecision,
                                l.name == kBackgroundLayer ? settings.background : Rgb(0.0f))
                : kNotStored);
    // rasterLayers()' order: radiance, the rasterizer's four, averages.
    const std::size_t radiance = ctx.layout.radiance.size();
    ctx.radianceLayer.assign(index.begin(), index.begin() + std::ptrdiff_t(radiance));
    ctx.surfaceLayer = index[radiance];
    ctx.backgroundLayer = index[radiance + 1];
    ctx.hairAlphaLayer = index[radiance + 2];
    ctx.depthLayer = index[radiance + 3];
    ctx.averageLayer.assign(index.begin() + std::ptrdiff_t(radiance + 4), index.end());
    ctx.film = &film;

    prepareVertices(groom, ctx.camera, settings.fiberScale, ctx.tangents, ctx.projected);
    ctx.segments = indexSegments(groom);
    ctx.tilesX = (ctx.camera.width() + kTileSize - 1) / kTileSize;
    ctx.tilesY = (ctx.camera.height() + kTileSize - 1) / kTileSize;
    ctx.tileSurfaceDepth =
        tileSurfaceDepths(surfaces, camera.width(), camera.height(), ctx.tilesX, ctx.tilesY);
    binSegments(ctx, out.stats);
    out.stats.setupSeconds = secondsSince(start);

    const int tiles = ctx.tilesX * ctx.tilesY;
    std::vector<TileResult> results(static_cast<std::size_t>(tiles));
    tbb::enumerable_thread_specific<TileScratch> scratch;
    ProgressReporter progress("render", static_cast<std::uint64_t>(tiles), settings.progress);
    const Clock::time_point tilesStart = Clock::now();
    tbb::parallel_for(
        tbb::blocked_range<int>(0, tiles, 1), [&](const tbb::blocked_range<int>& range) {
            for (int tile = range.begin(); tile != range.end(); ++tile) {
                throwIfInterrupted();
                results[std::size_t(tile)] = TileRenderer(ctx, scratch.local(), tile).run();
                progress.update();
            }
        });
    progress.finish();
    const double tilesSeconds = secondsSince(tilesStart);

    RasterStats& st = out.stats;
    double rasterThread = 0, shadeThread = 0;
    for (TileResult& r : results) {
        rasterThread += r.rasterSeconds;
        shadeThread += r.shadeSeconds;
        st.fragments += r.fragments;
        st.fragmentsBehindOpaque += r.behindOpaque;
        st.segmentTilesSkipped += r.segmentsSkipped;
        st.fragmentsComposited += r.composited;
        st.shadingPoints += r.shadingPoints;
        st.probedSegments += r.probedSegments;
        st.smoothSegments += r.smoothSegments;
        st.fragmentsInterpolated += r.interpolated;
        st.tailFragments += r.tailFragments;
        st.tailVertices += r.tailVertices;
        st.invalidSamples += r.invalid;
        for (std::string& w : r.warnings)
            if (out.warnings.size() < kMaxWarnings)
                out.warnings.push_back(std::move(w));
    }
    if (st.invalidSamples > out.warnings.size())
        out.warnings.push_back(
            strCat(st.invalidSamples - out.warnings.size(), " more shader results were rejected"));
    const double threadTotal = rasterThread + shadeThread;
    st.rasterSeconds = threadTotal > 0 ? tilesSeconds * rasterThread / threadTotal : 0;
    st.shadeSeconds = tilesSeconds - st.rasterSeconds;
    st.tiles = static_cast<std::uint64_t>(tiles);
    st.seconds = secondsSince(start);
    return out;
}

} // namespace hairvox
