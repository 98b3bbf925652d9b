#include "tile_binning.h"

#include <hairvox/core/interrupt.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace hairvox::raster {

namespace {

/// Segments per binning chunk: at least this many, and at most 256 chunks.
constexpr std::size_t kMinBinChunk = 8192;

/// Tiles a segment touches, or nothing (culled).
struct TileRect {
    std::uint16_t x0 = 0, y0 = 0, x1 = 0, y1 = 0; ///< [x0, x1) × [y0, y1); empty when culled
    bool empty() const { return x0 >= x1 || y0 >= y1; }
};

enum class Cull : std::uint8_t { None, OutsideView };

/// Whether the segment a → b passes within `r` of the box [lo, hi]: a
/// conservative test (the box grown by r, slab method).
bool segmentNearBox(const Vec2d& a, const Vec2d& b, Vec2d lo, Vec2d hi, double r) {
    lo -= r;
    hi += r;
    double tMin = 0, tMax = 1;
    for (int axis = 0; axis < 2; ++axis) {
        const double d = b[axis] - a[axis];
        if (std::abs(d) < 1e-12) {
            if (a[axis] < lo[axis] || a[axis] > hi[axis])
                return false;
            continue;
        }
        double t0 = (lo[axis] - a[axis]) / d, t1 = (hi[axis] - a[axis]) / d;
        if (t0 > t1)
            std::swap(t0, t1);
        tMin = std::max(tMin, t0);
        tMax = std::min(tMax, t1);
        if (tMin > tMax)
            return false;
    }
    return true;
}

} // namespace

void prepareVertices(const Groom& groom, const Camera& camera, const FiberScale& scale,
                     LargeVector<Vec3f>& tangents,
                     LargeVector<raster::ProjectedVertex>& projected) {
    // Left unwritten here, filled strand by strand below on the threads.
    tangents.resize(groom.pointCount());
    projected.resize(groom.pointCount());
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, groom.strandCount(), 512),
        [&](const tbb::blocked_range<std::size_t>& range) {
            std::vector<float> radii;
            for (std::size_t s = range.begin(); s != range.end(); ++s) {
                const std::size_t begin = groom.strandStart[s], end = groom.strandStart[s + 1];
                strandTangents({groom.points.data() + begin, end - begin},
                               {tangents.data() + begin, end - begin});
                radii.resize(end - begin);
                for (std::size_t i = begin; i < end; ++i)
                    radii[i - begin] = 0.5f * ribbonWidthAt(groom, scale, i);
                const std::span<const Vec3f> points(groom.points.data() + begin, end - begin);
                raster::projectStrand(camera, points, {tangents.data() + begin, end - begin}, radii,
                                      camera.nearClip(), {projected.data() + begin, end - begin});
            }
        });
}

std::vector<float> tileSurfaceDepths(const SurfaceLayer& surfaces, int width, int height,
                                     int tilesX, int tilesY) {
    constexpr float inf = std::numeric_limits<float>::infinity();
    std::vector<float> depth(std::size_t(tilesX) * std::size_t(tilesY), inf);
    if (surfaces.empty())
        return depth;
    for (int ty = 0; ty < tilesY; ++ty)
        for (int tx = 0; tx < tilesX; ++tx) {
            float farthest = 0;
            bool covered = true;
            for (int y = ty * kTileSize; covered && y < std::min(height, (ty + 1) * kTileSize); ++y)
                for (int x = tx * kTileSize; x < std::min(width, (tx + 1) * kTileSize); ++x) {
                    const std::size_t p = std::size_t(y) * std::size_t(width) + std::size_t(x);
                    if (!(surfaces.coverage[p] >= 1.0f)) {
                        covered = false;
                        break;
                    }
                    farthest = std::max(farthest, surfaces.depth[p]);
                }
            if (covered)
                depth[std::size_t(ty) * std::size_t(tilesX) + std::size_t(tx)] = farthest;
        }
    return depth;
}

std::vector<SegmentRef> indexSegments(const Groom& groom) {
    std::vector<SegmentRef> segments;
    segments.reserve(groom.segmentCount());
    for (std::size_t s = 0; s < groom.strandCount(); ++s)
        for (std::uint32_t k = groom.strandStart[s]; k + 1 < groom.strandStart[s + 1]; ++k)
            segments.push_back({k, static_cast<std::uint32_t>(s)});
    return segments;
}

void binSegments(RenderContext& ctx, RasterStats& stats) {
    const std::size_t segments = ctx.segments.size();
    const std::size_t tiles = std::size_t(ctx.tilesX) * std::size_t(ctx.tilesY);
    const std::size_t chunkSize = std::max(kMinBinChunk, (segments + 255) / 256);
    const std::size_t chunks = (segments + chunkSize - 1) / chunkSize;
    const int width = ctx.camera.width(), height = ctx.camera.height();

    std::vector<TileRect> rects(segments);
    std::vector<Cull> culls(segments, Cull::None);
    std::vector<std::size_t> counts(chunks * tiles, 0), culled(chunks, 0);
    auto touches = [&](const ScreenRibbon& r, int tx, int ty) {
        const Vec2d lo(tx * kTileSize, ty * kTileSize);
        return segmentNearBox(r.s0, r.s1, lo, lo + double(kTileSize),
                              std::max(glm::length(r.o0), glm::length(r.o1)));
    };
    // Visible in the tile: near it, and not wholly behind the surfaces that cover it.
    auto visibleIn = [&](const ScreenRibbon& r, int tx, int ty) {
        const float zMin = 1.0f / std::max(r.invZ0, r.invZ1);
        return zMin <= ctx.tileSurfaceDepth[std::size_t(ty) * std::size_t(ctx.tilesX) +
                                            std::size_t(tx)] &&
               touches(r, tx, ty);
    };
    tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t chunk) {
        throwIfInterrupted();
        std::size_t* chunkCounts = counts.data() + chunk * tiles;
        const std::size_t end = std::min(segments, (chunk + 1) * chunkSize);
        for (std::size_t j = chunk * chunkSize; j < end; ++j) {
            const auto seg = static_cast<std::uint32_t>(j);
            const std::optional<ScreenRibbon> r = ctx.ribbon(seg);
            if (!r || !r->finite() ||
                !(r->xMax > 0 && r->yMax > 0 && r->xMin < width && r->yMin < height)) {
                culls[j] = Cull::OutsideView;
                continue;
            }
            TileRect& rect = rects[j];
            rect.x0 = static_cast<std::uint16_t>(std::max(0.0, r->xMin) / kTileSize);
            rect.y0 = static_cast<std::uint16_t>(std::max(0.0, r->yMin) / kTileSize);
            rect.x1 = static_cast<std::uint16_t>(
                std::min(double(ctx.tilesX), std::floor(r->xMax / kTileSize) + 1));
            rect.y1 = static_cast<std::uint16_t>(
                std::min(double(ctx.tilesY), std::floor(r->yMax / kTileSize) + 1));
            for (int ty = rect.y0; ty < rect.y1; ++ty)
                for (int tx = rect.x0; tx < rect.x1; ++tx) {
                    if (visibleIn(*r, tx, ty))
                        ++chunkCounts[std::size_t(ty) * std::size_t(ctx.tilesX) + std::size_t(tx)];
                    else if (touches(*r, tx, ty))
                        ++culled[chunk];
                }
        }
    });

    // Offsets in (tile, chunk) order.
    ctx.binStart.assign(tiles + 1, 0);
    std::vector<std::size_t> offsets(chunks * tiles);
    std::size_t total = 0;
    for (std::size_t t = 0; t < tiles; ++t) {
        ctx.binStart[t] = total;
        for (std::size_t c = 0; c < chunks; ++c) {
            offsets[c * tiles + t] = total;
            total += counts[c * tiles + t];
        }
    }
    ctx.binStart[tiles] = total;
    ctx.binSegments.resize(total);
    tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t chunk) {
        std::size_t* chunkOffsets = offsets.data() + chunk * tiles;
        const std::size_t end = std::min(segments, (chunk + 1) * chunkSize);
        for (std::size_t j = chunk * chunkSize; j < end; ++j) {
            const TileRect& rect = rects[j];
            if (rect.empty())
                continue;
            const std::optional<ScreenRibbon> r = ctx.ribbon(static_cast<std::uint32_t>(j));
            for (int ty = rect.y0; ty < rect.y1; ++ty)
                for (int tx = rect.x0; tx < rect.x1; ++tx)
                    if (visibleIn(*r, tx, ty))
                        ctx.binSegments[chunkOffsets[std::size_t(ty) * std::size_t(ctx.tilesX) +
                                                     std::size_t(tx)]++] =
                            static_cast<std::uint32_t>(j);
        }
    });

    stats.segments = segments;
    stats.segmentTileRefs = total;
    for (Cull c : culls)
        stats.segmentsOutsideView += c == Cull::OutsideView ? 1u : 0u;
    for (std::size_t c : culled)
        stats.segmentTilesBehindSurfaces += c;
}

} // namespace hairvox::raster
