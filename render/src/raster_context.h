// hairvox render (private): what every tile of one raster shares — the
// camera's view of the groom (tangents, projected vertices, segment records),
// the tiles' segment lists (tile_binning.h) and the film's layer indices —
// and the constants the rasterizer's files agree on.
#pragma once

#include "ribbon.h"

#include <hairvox/core/large_array.h>
#include <hairvox/render/rasterizer.h>

#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

namespace hairvox::raster {

using Clock = std::chrono::steady_clock;

/// The film's tiles: a tile of the raster writes one tile of each layer.
constexpr int kTileSize = Film::kTileSize;
constexpr std::uint32_t kSurfaceFragment = std::numeric_limits<std::uint32_t>::max();
/// A film layer RasterSettings::layers leaves out.
constexpr std::size_t kNotStored = std::numeric_limits<std::size_t>::max();
constexpr std::size_t kShadeBatch = 1024;
constexpr std::size_t kMaxWarnings = 10;

inline double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A segment: the point index of its root-side vertex, and its strand. One
/// record, so that a tile's gather of its segments misses the cache once each.
struct SegmentRef {
    std::uint32_t firstPoint;
    std::uint32_t strand;
};

/// A tile reads its segments' records and vertices scattered across the
/// groom: it asks for them this many segments ahead (a record twice as far,
/// since the vertices' address needs it), so that the misses overlap.
constexpr std::size_t kPrefetchAhead = 8;

inline void prefetch(const void* address) {
    __builtin_prefetch(address);
}

/// The mask of bits 0 … n − 1 (n ≤ 32).
constexpr std::uint32_t lowBits(int n) {
    return n >= 32 ? ~std::uint32_t(0) : (std::uint32_t(1) << n) - 1;
}

/// Everything the tiles share.
struct RenderContext {
    const Groom& groom;
    const Camera& camera;
    const FragmentShader& shader;
    const ShaderLayout& layout;
    const RasterSettings& settings;
    const SurfaceLayer& surfaces;
    const BackgroundLayer& background;
    std::size_t stride;         ///< floats per shaded point
    std::size_t radianceFloats; ///< of those, the radiance layers'
    LargeVector<Vec3f> tangents;
    LargeVector<raster::ProjectedVertex> projected; ///< per point
    std::vector<SegmentRef> segments;               ///< per segment
    int tilesX = 0, tilesY = 0;
    /// Per tile: the farthest surface depth if surfaces cover every pixel wholly, else +∞.
    std::vector<float> tileSurfaceDepth;
    std::vector<std::size_t> binStart; ///< per tile, into binSegments (+1 entry)
    std::vector<std::uint32_t> binSegments;
    Film* film = nullptr;
    /// Film layer indices: the shader's radiance and average layers, then the rasterizer's own.
    /// kNotStored where RasterSettings::layers leaves a layer out.
    std::vector<std::size_t> radianceLayer, averageLayer;
    std::size_t beautyLayer = 0, alphaLayer = 0, surfaceLayer = 0, backgroundLayer = 0,
                hairAlphaLayer = 0, depthLayer = 0;

    /// The layer, or null where it is not stored.
    FilmLayer* layer(std::size_t index) const {
        return index == kNotStored ? nullptr : &film->layer(index);
    }

    RenderContext(const Groom& g, const Camera& c, const FragmentShader& sh,
                  const RasterSettings& st, const SurfaceLayer& su, const BackgroundLayer& bg)
        : groom(g)
        , camera(c)
        , shader(sh)
        , layout(sh.layout())
        , settings(st)
        , surfaces(su)
        , background(bg)
        , stride(layout.stride())
        , radianceFloats(layout.radianceFloats()) {}

    std::optional<ScreenRibbon> ribbon(std::uint32_t segment) const {
        const std::uint32_t k = segments[segment].firstPoint;
        if (projected[k].valid() && projected[k + 1].valid())
            return raster::ribbonBetween(projected[k], projected[k + 1]);
        return raster::projectRibbon(
            camera, groom.points[k], groom.points[k + 1], tangents[k], tangents[k + 1],
            0.5f * ribbonWidthAt(groom, settings.fiberScale, k),
            0.5f * ribbonWidthAt(groom, settings.fiberScale, k + 1), camera.nearClip());
    }
};

} // namespace hairvox::raster
