#include "ribbon.h"

#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/large_array.h>
#include <hairvox/core/math.h>
#include <hairvox/core/parallel.h>
#include <hairvox/core/progress.h>
#include <hairvox/render/rasterizer.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>

namespace hairvox {

namespace {

using raster::ScreenRibbon;
using raster::Vec2d;
using Clock = std::chrono::steady_clock;

/// The film's tiles: a tile of the raster writes one tile of each layer.
constexpr int kTileSize = Film::kTileSize;
constexpr std::uint32_t kSurfaceFragment = std::numeric_limits<std::uint32_t>::max();
/// A film layer RasterSettings::layers leaves out.
constexpr std::size_t kNotStored = std::numeric_limits<std::size_t>::max();
constexpr std::size_t kShadeBatch = 1024;
constexpr std::size_t kMaxWarnings = 10;
/// Segments per binning chunk: at least this many, and at most 256 chunks.
constexpr std::size_t kMinBinChunk = 8192;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// --- geometry shared by all tiles ------------------------------------------

/// Unit tangent at every point (strandTangents(): the bisector of the
/// adjacent segments' directions), and every point's projection with its
/// ribbon half-width k·D_i/2 (ribbonWidthAt()).
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

inline void prefetch(const void* address) { __builtin_prefetch(address); }

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
    std::vector<SegmentRef> segments; ///< per segment
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

/// Per tile, the depth behind which surfaces hide everything: the farthest
/// surface depth of a tile whose every pixel is wholly covered, else +∞.
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

/// Per segment, its root-side point and its strand.
std::vector<SegmentRef> indexSegments(const Groom& groom) {
    std::vector<SegmentRef> segments;
    segments.reserve(groom.segmentCount());
    for (std::size_t s = 0; s < groom.strandCount(); ++s)
        for (std::uint32_t k = groom.strandStart[s]; k + 1 < groom.strandStart[s + 1]; ++k)
            segments.push_back({k, static_cast<std::uint32_t>(s)});
    return segments;
}

/// Bins segments to the tiles their ribbon may touch. Chunks of segments are
/// counted, then written, in chunk order: each tile's list is sorted by
/// segment index whatever the thread count.
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

// --- one tile ----------------------------------------------------------------

constexpr std::uint32_t kNoPoint = std::numeric_limits<std::uint32_t>::max();
/// No vertex slot (vertex rate) or no smooth probe (adaptive rate) for a segment.
constexpr std::uint32_t kNoSlot = std::numeric_limits<std::uint32_t>::max();
/// Segments rasterized between two compositing steps (see TileRenderer).
constexpr std::size_t kSegmentsPerStep = 64;

struct Fragment {
    float depth;
    float alpha;         ///< coverage, (0, 1]
    float t;             ///< parameter on the segment, 0 at its root-side vertex
    std::uint32_t local; ///< index in the tile's segment list, or kSurfaceFragment
    std::uint32_t pixel; ///< index in the tile, row-major
};

/// A composited hair fragment: what shading needs.
struct Visible {
    std::uint32_t pixel;
    std::uint32_t local;
    float t;
    float weight; ///< transmittance in front × coverage
};

/// Compositing state of one pixel, carried from one step to the next.
struct PixelState {
    float T = 1;                        ///< transmittance of everything composited so far
    float groupT = 1;                   ///< T in front of the current strand group
    float groupCoverage = 0;            ///< coverage of the current strand group
    std::uint32_t lastPoint = kNoPoint; ///< root-side point of the last composited hair fragment
    bool closed = false;                ///< opaque: nothing behind is composited
    float depthSum = 0, hairWeight = 0;
    Rgb surface{0.0f};
};

/// One tile of a film layer as a raster tile writes it: the film holds the
/// tile only once a value other than the layer's fill is written (what a tile
/// it does not hold reads as: +0, or the background colour for the background
/// and the beauty), so hair layers take no memory where no hair is seen, nor
/// the background and the beauty where nothing is.
class TileOutput {
public:
    TileOutput(FilmLayer* layer, int tx, int ty)
        : layer_(layer)
        , tx_(tx)
        , ty_(ty)
        , channels_(layer ? std::size_t(layer->channels) : 0) {}

    /// Sets channel c of the pixel at `pixel` (its index in the film's tile),
    /// which nothing has written yet; nothing where the layer is not stored.
    void set(std::size_t pixel, std::size_t c, float v) {
        if (layer_ && !layer_->isFill(c, v))
            values()[pixel * channels_ + c] = v;
    }
    /// Adds v to channel c of the pixel at `pixel`.
    void add(std::size_t pixel, std::size_t c, float v) {
        if (layer_ && !isPositiveZero(v))
            values()[pixel * channels_ + c] += v;
    }

private:
    float* values() {
        if (!values_)
            values_ = layer_->tile(tx_, ty_);
        return values_;
    }

    FilmLayer* layer_;
    int tx_, ty_;
    std::size_t channels_;
    float* values_ = nullptr;
};

struct TileScratch {
    std::vector<ScreenRibbon> ribbons;   ///< per local segment
    std::vector<float> zMin;             ///< per local segment: its nearest depth
    std::vector<std::uint32_t> order;    ///< local segments by (zMin, index)
    std::vector<std::uint64_t> keys;     ///< sort keys of `order`
    std::vector<std::uint32_t> strandOf; ///< per local segment
    std::vector<std::uint32_t> pointOf;  ///< per local segment: its root-side point
    std::vector<Fragment> pending, sorted;
    std::vector<Fragment> settling; ///< as long as the longest pending: settle() counts its part
    std::vector<std::uint32_t> pixelStart, cursor;
    std::vector<PixelState> pixels;
    std::vector<Visible> visible;
    std::vector<Visible> tail; ///< visible behind the tail transmittance: interpolated
    std::vector<Visible> grouped;            ///< visible, ordered by segment
    std::vector<std::uint32_t> segmentStart; ///< per local segment: its first grouped fragment
    std::vector<std::uint32_t> vertexSlot;   ///< per local segment: slot of its root-side vertex
    std::vector<std::uint32_t> slotPoint;    ///< per vertex slot: the point index
    std::vector<std::uint32_t> slotStrand;   ///< per vertex slot: its strand
    std::vector<float> vertexResults;        ///< per vertex slot: stride floats
    std::vector<ShadingPoint> points;
    std::vector<float> results;          ///< per point of a batch: stride floats
    std::vector<std::uint32_t> probed;   ///< adaptive rate: local segments shaded at t = 0, ½, 1
    std::vector<float> probeResults;     ///< per probed segment: 3 × stride floats
    std::vector<std::uint32_t> probeOf;  ///< per local segment: its smooth probe, or none
    std::vector<float> pixelSum;         ///< per pixel: stride floats of weighted sums
    raster::CoverageCells coverageCells; ///< rasterizeRibbon's, all 0 between ribbons
    std::vector<TileOutput> radianceOutputs, averageOutputs; ///< finishShading()'s
};

struct TileResult {
    double rasterSeconds = 0, shadeSeconds = 0;
    std::uint64_t fragments = 0, behindOpaque = 0, composited = 0, shadingPoints = 0, invalid = 0;
    std::uint64_t segmentsSkipped = 0;
    std::uint64_t probedSegments = 0, smoothSegments = 0, interpolated = 0;
    std::uint64_t tailFragments = 0, tailVertices = 0;
    std::vector<std::string> warnings;
};

/// Radiance finite and non-negative, averages finite. Branch-free integer
/// tests on the bits, or-ed together, so that the loops vectorise: every
/// fragment's results pass through here.
bool isValid(std::span<const float> r, std::size_t radianceFloats) {
    std::uint32_t bad = 0;
    for (std::size_t i = 0; i < radianceFloats; ++i) {
        // Finite and not negative: below 0x7f800000, or −0.
        const std::uint32_t bits = std::bit_cast<std::uint32_t>(r[i]);
        bad |= std::uint32_t(bits >= 0x7f800000u) & std::uint32_t(bits != 0x80000000u);
    }
    for (std::size_t i = radianceFloats; i < r.size(); ++i)
        bad |= std::uint32_t((std::bit_cast<std::uint32_t>(r[i]) & 0x7f800000u) == 0x7f800000u);
    return bad == 0;
}

/// Adaptive rate: a segment is probed at this many points (t = 0, ½, 1) when
/// it has more visible fragments than that in a tile.
constexpr std::size_t kProbePoints = 3;

/// Adaptive rate: whether a segment's shading is smooth enough to interpolate,
/// from its results a, m, b at t = 0, ½, 1 (radiance floats, ≥ 0): the
/// midpoint's distance from the ends' interpolation against the segment's
/// mean radiance,
///     Σ_k |m_k − (a_k + b_k)/2|  ≤  τ · Σ_k (a_k + m_k + b_k)/3,
/// summed over every radiance float (each layer, each channel), so that no
/// lobe's error hides behind another's.
bool smoothAlong(const float* a, const float* m, const float* b, std::size_t radianceFloats,
                 float tolerance) {
    float error = 0, mean = 0;
    for (std::size_t k = 0; k < radianceFloats; ++k) {
        error += std::abs(m[k] - 0.5f * (a[k] + b[k]));
        mean += (a[k] + m[k] + b[k]) * (1.0f / 3.0f);
    }
    return error <= tolerance * mean;
}

/// Renders one tile.
///
/// Visibility without sorting everything: the tile's segments are taken in
/// order of their nearest depth, kSegmentsPerStep at a time. After a step,
/// every fragment nearer than the next segment's nearest depth Z is final (no
/// later segment can put anything in front of it): those fragments are sorted
/// per pixel by (depth, segment) and composited front to back, continuing each
/// pixel's state. A pixel whose transmittance reaches the opaque threshold is
/// closed, and later segments skip it before computing any coverage. The
/// composited order is the full per-pixel depth order, so the result does not
/// depend on the step size; it only decides how early hidden work is skipped.
///
/// Compositing: a fragment over the pixel, T ← T·(1 − α), weight T·α — except
/// that a fragment of the segment adjacent to the previous composited fragment
/// of the same strand (they tile one ribbon) adds its coverage to that
/// strand's group: weight T_group·α, T ← T_group·(1 − Σα), Σα ≤ 1.
class TileRenderer {
public:
    TileRenderer(const RenderContext& ctx, TileScratch& s, int tile)
        : ctx_(ctx)
        , s_(s)
        , stride_(ctx.stride) {
        tx_ = tile % ctx.tilesX;
        ty_ = tile / ctx.tilesX;
        x0_ = tx_ * kTileSize;
        y0_ = ty_ * kTileSize;
        x1_ = std::min(ctx.camera.width(), x0_ + kTileSize);
        y1_ = std::min(ctx.camera.height(), y0_ + kTileSize);
        width_ = x1_ - x0_;
        area_ = static_cast<std::uint32_t>(width_ * (y1_ - y0_));
        bins_ = {ctx.binSegments.data() + ctx.binStart[std::size_t(tile)],
                 ctx.binSegments.data() + ctx.binStart[std::size_t(tile) + 1]};
        if (ctx.settings.shadingRate != ShadingRate::Vertex)
            tailTransmittance_ = ctx.settings.tailTransmittance;
    }

    TileResult run() {
        const Clock::time_point start = Clock::now();
        prepare();
        rasterizeAndComposite();
        finishCoverage();
        const Clock::time_point shadeStart = Clock::now();
        switch (ctx_.settings.shadingRate) {
        case ShadingRate::Fragment: shadeFragments(); break;
        case ShadingRate::Vertex: shadeVertices(); break;
        case ShadingRate::Adaptive: shadeAdaptive(); break;
        }
        finishShading();
        result_.shadeSeconds = secondsSince(shadeStart);
        result_.rasterSeconds = secondsSince(start) - result_.shadeSeconds;
        result_.fragments = result_.composited + result_.behindOpaque;
        return std::move(result_);
    }

private:
    /// The index of a pixel of the tile in the surface layer (row-major).
    std::size_t imageIndex(std::uint32_t pixel) const {
        return std::size_t(y0_ + int(pixel / std::uint32_t(width_))) *
                   std::size_t(ctx_.camera.width()) +
               std::size_t(x0_ + int(pixel % std::uint32_t(width_)));
    }
    /// Its index in the film's tile, which is kTileSize wide at the image's edge too.
    std::size_t tileIndex(std::uint32_t pixel) const {
        return std::size_t(pixel / std::uint32_t(width_)) * kTileSize +
               std::size_t(pixel % std::uint32_t(width_));
    }
    TileOutput output(std::size_t layer) const { return {ctx_.layer(layer), tx_, ty_}; }
    std::uint32_t pixelIndex(int x, int y) const {
        return static_cast<std::uint32_t>((y - y0_) * width_ + (x - x0_));
    }

    /// Projects the tile's segments, orders them by nearest depth, and puts
    /// the surfaces' fragments in the queue.
    void prepare() {
        const std::size_t n = bins_.size();
        s_.ribbons.resize(n);
        s_.zMin.resize(n);
        s_.order.resize(n);
        s_.strandOf.resize(n);
        s_.pointOf.resize(n);
        s_.keys.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            if (i + 2 * kPrefetchAhead < n)
                prefetch(&ctx_.segments[bins_[i + 2 * kPrefetchAhead]]);
            if (i + kPrefetchAhead < n) {
                const std::uint32_t k = ctx_.segments[bins_[i + kPrefetchAhead]].firstPoint;
                prefetch(&ctx_.projected[k]);
                prefetch(&ctx_.projected[k + 1].invZ); // the pair's end: the next line at most
            }
            s_.ribbons[i] = *ctx_.ribbon(bins_[i]);
            s_.zMin[i] = 1.0f / std::max(s_.ribbons[i].invZ0, s_.ribbons[i].invZ1);
            s_.pointOf[i] = ctx_.segments[bins_[i]].firstPoint;
            s_.strandOf[i] = ctx_.segments[bins_[i]].strand;
            // (zMin, index) as one integer: positive floats order like their bits.
            s_.keys[i] = (std::uint64_t(std::bit_cast<std::uint32_t>(s_.zMin[i])) << 32) | i;
        }
        std::sort(s_.keys.begin(), s_.keys.end());
        for (std::size_t i = 0; i < n; ++i)
            s_.order[i] = static_cast<std::uint32_t>(s_.keys[i]);
        s_.pixels.assign(area_, PixelState{});
        openPixels_ = area_;
        openRows_.fill(0);
        std::fill_n(openRows_.begin(), y1_ - y0_, lowBits(width_));
        s_.pending.clear();
        s_.visible.clear();
        s_.tail.clear();
        if (ctx_.surfaces.empty())
            return;
        for (int y = y0_; y < y1_; ++y)
            for (int x = x0_; x < x1_; ++x) {
                const std::size_t i =
                    std::size_t(y) * std::size_t(ctx_.camera.width()) + std::size_t(x);
                if (ctx_.surfaces.coverage[i] > 0)
                    s_.pending.push_back({ctx_.surfaces.depth[i], ctx_.surfaces.coverage[i], 0,
                                          kSurfaceFragment, pixelIndex(x, y)});
            }
    }

    /// Whether any pixel of the ribbon's bounding box in the tile is open: a
    /// segment wholly behind opaque pixels is skipped before its coverage.
    bool anyOpenUnder(const ScreenRibbon& r) const {
        const auto clampTo = [](double v, int lo, int hi) {
            return static_cast<int>(std::clamp(v, double(lo), double(hi)));
        };
        const int xb = clampTo(std::floor(r.xMin), x0_, x1_) - x0_;
        const int xe = clampTo(std::ceil(r.xMax), x0_, x1_) - x0_;
        const int yb = clampTo(std::floor(r.yMin), y0_, y1_) - y0_;
        const int ye = clampTo(std::ceil(r.yMax), y0_, y1_) - y0_;
        if (xb >= xe)
            return false;
        const std::uint32_t columns = lowBits(xe - xb) << xb;
        for (int y = yb; y < ye; ++y)
            if (openRows_[std::size_t(y)] & columns)
                return true;
        return false;
    }

    void rasterizeAndComposite() {
        const std::size_t n = s_.order.size();
        auto open = [&](int x, int y) {
            // The row's mask (cleared with pixels[].closed): one word, not a PixelState.
            if ((openRows_[std::size_t(y - y0_)] >> (x - x0_)) & 1u)
                return true;
            ++result_.behindOpaque;
            return false;
        };
        for (std::size_t begin = 0; begin < n; begin += kSegmentsPerStep) {
            if (openPixels_ == 0) {
                result_.segmentsSkipped += n - begin;
                break;
            }
            const std::size_t end = std::min(n, begin + kSegmentsPerStep);
            for (std::size_t j = begin; j < end; ++j) {
                // Ribbons are read in depth order, scattered over the tile's
                // array: fetch the next ones while this one is covered.
                if (j + kPrefetchAhead < n) {
                    const ScreenRibbon* next = &s_.ribbons[s_.order[j + kPrefetchAhead]];
                    prefetch(&next->s0);
                    prefetch(&next->yMax);
                }
                const std::uint32_t local = s_.order[j];
                const ScreenRibbon& r = s_.ribbons[local];
                if (!anyOpenUnder(r)) {
                    ++result_.segmentsSkipped;
                    continue;
                }
                raster::rasterizeRibbon(
                    r, x0_, y0_, x1_, y1_, s_.coverageCells,
                    [&](int x, int y, float coverage) {
                        Fragment f;
                        r.locate(Vec2d(x + 0.5, y + 0.5), f.t, f.depth);
                        f.alpha = coverage;
                        f.local = local;
                        f.pixel = pixelIndex(x, y);
                        s_.pending.push_back(f);
                    },
                    open);
            }
            settle(end < n ? s_.zMin[s_.order[end]] : std::numeric_limits<float>::infinity());
        }
        settle(std::numeric_limits<float>::infinity());
    }

    /// Composites, in depth order, every pending fragment nearer than z.
    void settle(float z) {
        // Split without a branch: whether a pending fragment is final is a
        // coin toss to the branch predictor (on the head each is read 6.4
        // times, at every step until it settles), so each is written to both
        // arrays and the count of the one it belongs to advances.
        if (s_.settling.size() < s_.pending.size())
            s_.settling.resize(s_.pending.size());
        std::size_t kept = 0, settling = 0;
        for (const Fragment& f : s_.pending) {
            const bool settles = f.depth < z;
            s_.settling[settling] = f;
            s_.pending[kept] = f;
            settling += settles ? 1 : 0;
            kept += settles ? 0 : 1;
        }
        s_.pending.resize(kept);
        if (settling == 0)
            return;
        const std::span<const Fragment> settled(s_.settling.data(), settling);
        // Counting sort by pixel, then insertion sort per pixel by (depth,
        // segment; the head after hair at equal depth): a total order.
        s_.pixelStart.assign(area_ + 1, 0);
        for (const Fragment& f : settled)
            ++s_.pixelStart[f.pixel + 1];
        for (std::size_t p = 0; p < area_; ++p)
            s_.pixelStart[p + 1] += s_.pixelStart[p];
        s_.sorted.resize(settled.size());
        s_.cursor.assign(s_.pixelStart.begin(), s_.pixelStart.end() - 1);
        for (const Fragment& f : settled)
            s_.sorted[s_.cursor[f.pixel]++] = f;
        auto before = [](const Fragment& a, const Fragment& b) {
            return a.depth < b.depth || (a.depth == b.depth && a.local < b.local);
        };
        for (std::size_t p = 0; p < area_; ++p) {
            Fragment* first = s_.sorted.data() + s_.pixelStart[p];
            Fragment* last = s_.sorted.data() + s_.pixelStart[p + 1];
            if (first == last)
                continue;
            if (last - first > 32) {
                std::sort(first, last, before);
            } else {
                for (Fragment* i = first + 1; i < last; ++i) {
                    const Fragment f = *i;
                    Fragment* j = i;
                    for (; j > first && before(f, *(j - 1)); --j)
                        *j = *(j - 1);
                    *j = f;
                }
            }
            PixelState& st = s_.pixels[p];
            for (const Fragment* f = first; f != last; ++f)
                composite(st, *f);
        }
    }

    void composite(PixelState& st, const Fragment& f) {
        const bool hair = f.local != kSurfaceFragment;
        if (st.closed) {
            result_.behindOpaque += hair ? 1u : 0u;
            return;
        }
        const std::uint32_t point = hair ? s_.pointOf[f.local] : kNoPoint;
        // Root-side points of one strand's segments are consecutive; across
        // strands they differ by at least 2 (a strand's tip starts nothing).
        if (hair && st.lastPoint != kNoPoint &&
            (point > st.lastPoint ? point - st.lastPoint : st.lastPoint - point) <= 1) {
            st.groupCoverage = std::min(st.groupCoverage + f.alpha, 1.0f);
        } else {
            st.groupT = st.T;
            st.groupCoverage = f.alpha;
        }
        const float T = st.groupT * (1.0f - st.groupCoverage);
        const float w = st.T - T; // this fragment's share: what it took from the transmittance
        st.T = T;
        st.lastPoint = point;
        st.depthSum += w * f.depth;
        if (hair) {
            // Seen through less than the tail transmittance: interpolated.
            (st.groupT < tailTransmittance_ ? s_.tail : s_.visible)
                .push_back({f.pixel, f.local, f.t, w});
            st.hairWeight += w;
            ++result_.composited;
        } else {
            st.surface += w * ctx_.surfaces.radiance[imageIndex(f.pixel)];
        }
        if (st.T <= ctx_.settings.opaqueTransmittance) {
            st.closed = true;
            --openPixels_;
            openRows_[f.pixel / std::uint32_t(width_)] &=
                ~(std::uint32_t(1) << (f.pixel % std::uint32_t(width_)));
        }
    }

    void finishCoverage() {
        TileOutput alpha = output(ctx_.alphaLayer), hairAlpha = output(ctx_.hairAlphaLayer),
                   depth = output(ctx_.depthLayer), surface = output(ctx_.surfaceLayer),
                   background = output(ctx_.backgroundLayer), beauty = output(ctx_.beautyLayer);
        for (std::uint32_t p = 0; p < area_; ++p) {
            const PixelState& st = s_.pixels[p];
            const std::size_t i = tileIndex(p);
            alpha.set(i, 0, 1.0f - st.T);
            hairAlpha.set(i, 0, st.hairWeight);
            depth.set(i, 0, st.T < 1.0f ? st.depthSum / (1.0f - st.T) : 0.0f);
            const Rgb b =
                st.T * (ctx_.background.empty() ? ctx_.settings.background
                                                : ctx_.background.radiance[imageIndex(p)]);
            for (int c = 0; c < 3; ++c) {
                const auto k = std::size_t(c);
                surface.set(i, k, st.surface[c]);
                background.set(i, k, b[c]);
                beauty.set(i, k, st.surface[c] + b[c]);
            }
        }
    }

    ShadingPoint pointOnSegment(std::uint32_t local, float t) const {
        const std::uint32_t k = s_.pointOf[local];
        const Vec3f& p0 = ctx_.groom.points[k];
        const Vec3f& p1 = ctx_.groom.points[k + 1];
        ShadingPoint sp;
        sp.position = hairvox::lerp(t, p0, p1);
        sp.tangent = shadingTangent(ctx_.tangents[k], ctx_.tangents[k + 1], t,
                                    normalizeOr(p1 - p0, Vec3f(0.0f, 1.0f, 0.0f)));
        sp.toCamera = normalizeOr(ctx_.camera.position() - sp.position, sp.tangent);
        sp.strand = s_.strandOf[local];
        sp.segment = k;
        return sp;
    }

    /// A strand vertex, independent of the tile and segment it is shaded for
    /// (so that tiles sharing it agree).
    ShadingPoint pointAtVertex(std::uint32_t point, std::uint32_t strand) const {
        ShadingPoint sp;
        sp.position = ctx_.groom.points[point];
        sp.tangent = ctx_.tangents[point];
        sp.toCamera = normalizeOr(ctx_.camera.position() - sp.position, sp.tangent);
        sp.strand = strand;
        sp.segment = point + 1 < ctx_.groom.strandStart[strand + 1] ? point : point - 1;
        return sp;
    }

    /// Shades `count` points from s_.points into s_.results; rejects invalid
    /// results (zeroing them) and reports them with `where(i)`.
    template <typename Where>
    void shadeBatch(std::size_t count, Where&& where) {
        throwIfInterrupted(); // an expensive shader (exact mode) makes a tile long
        s_.results.resize(count * stride_);
        // Isolated: a shader may run its own parallel loops (the global
        // term's lookups), and oneTBB allows a thread waiting in one to take
        // another tile's task ("Work Isolation"), which would reuse this
        // thread's scratch (s_) under this tile. (The shader's and the global
        // term's per-thread arrays, ThreadScratch, take their own storage when
        // re-entered. Debian's oneTBB 2021.8 was not seen to re-enter: none in
        // 2,000 nested loops at 2, 4 and 8 threads.)
        tbb::this_task_arena::isolate([&] {
            ctx_.shader.shade(std::span(s_.points.data(), count),
                              std::span(s_.results.data(), count * stride_));
        });
        result_.shadingPoints += count;
        for (std::size_t i = 0; i < count; ++i) {
            const std::span<float> r(s_.results.data() + i * stride_, stride_);
            if (isValid(r, ctx_.radianceFloats))
                continue;
            ++result_.invalid;
            if (result_.warnings.size() < kMaxWarnings) {
                std::string values;
                for (float x : r)
                    values += strCat(values.empty() ? "" : " ", x);
                result_.warnings.push_back(strCat("shader returned a non-finite or negative value ",
                                                  where(i), " for ", s_.points[i], ": [", values,
                                                  "]; set to black"));
            }
            std::fill(r.begin(), r.end(), 0.0f);
        }
    }

    /// Adds a shaded fragment to its pixel's sums.
    void accumulate(const Visible& v, const float* __restrict r) {
        // restrict: the sums and the results never overlap, so the loop vectorises.
        float* __restrict sum = s_.pixelSum.data() + std::size_t(v.pixel) * stride_;
        const float w = v.weight;
        for (std::size_t k = 0; k < stride_; ++k)
            sum[k] += w * r[k];
    }

    std::string pixelName(std::uint32_t pixel) const {
        return strCat("at pixel (", x0_ + int(pixel % std::uint32_t(width_)), ", ",
                      y0_ + int(pixel / std::uint32_t(width_)), ")");
    }

    /// Orders the visible fragments by segment (a stable counting sort;
    /// segment i's are then [segmentStart[i], segmentStart[i + 1])):
    /// the points of a batch then come segment by segment, which lets a
    /// shader share work along a segment (the global term's fiber samples,
    /// transmittance/alongFibers()) and the segment's data between points.
    void groupVisibleBySegment() {
        s_.segmentStart.assign(bins_.size() + 1, 0);
        for (const Visible& v : s_.visible)
            ++s_.segmentStart[v.local + 1];
        for (std::size_t i = 0; i < bins_.size(); ++i)
            s_.segmentStart[i + 1] += s_.segmentStart[i];
        s_.grouped.resize(s_.visible.size());
        s_.cursor.assign(s_.segmentStart.begin(), s_.segmentStart.end() - 1);
        for (const Visible& v : s_.visible)
            s_.grouped[s_.cursor[v.local]++] = v;
        s_.visible.swap(s_.grouped);
    }

    void shadeFragments() {
        s_.pixelSum.assign(std::size_t(area_) * stride_, 0.0f);
        interpolateTail();
        groupVisibleBySegment();
        shadeEach(s_.visible);
    }

    /// Shades points pointAt(0 .. n − 1), in batches, into `out` (n × stride
    /// floats); `where` names them in warnings.
    template <typename PointAt>
    void shadeInto(std::size_t n, PointAt&& pointAt, const char* where, std::vector<float>& out) {
        out.resize(n * stride_);
        for (std::size_t begin = 0; begin < n; begin += kShadeBatch) {
            const std::size_t count = std::min(kShadeBatch, n - begin);
            s_.points.resize(count);
            for (std::size_t i = 0; i < count; ++i)
                s_.points[i] = pointAt(begin + i);
            shadeBatch(count, [&](std::size_t) { return std::string(where); });
            std::copy_n(s_.results.begin(), count * stride_,
                        out.begin() + std::ptrdiff_t(begin * stride_));
        }
    }

    /// Shades each fragment at its point, in batches, into its pixel's sums.
    void shadeEach(std::span<const Visible> fragments) {
        for (std::size_t begin = 0; begin < fragments.size(); begin += kShadeBatch) {
            const std::size_t count = std::min(kShadeBatch, fragments.size() - begin);
            s_.points.resize(count);
            for (std::size_t i = 0; i < count; ++i) {
                if (begin + i + kPrefetchAhead < fragments.size()) {
                    const std::uint32_t k = s_.pointOf[fragments[begin + i + kPrefetchAhead].local];
                    prefetch(&ctx_.groom.points[k]);
                    prefetch(&ctx_.groom.points[k + 1]);
                    prefetch(&ctx_.tangents[k]);
                    prefetch(&ctx_.tangents[k + 1]);
                }
                const Visible& v = fragments[begin + i];
                s_.points[i] = pointOnSegment(v.local, v.t);
            }
            shadeBatch(count, [&](std::size_t i) { return pixelName(fragments[begin + i].pixel); });
            for (std::size_t i = 0; i < count; ++i)
                accumulate(fragments[begin + i], s_.results.data() + i * stride_);
        }
    }

    void shadeVertices() {
        s_.pixelSum.assign(std::size_t(area_) * stride_, 0.0f);
        interpolateVertices(s_.visible);
    }

    /// Fragment and adaptive rates: the hair behind the tail transmittance
    /// interpolates its segments' vertices.
    void interpolateTail() {
        const std::uint64_t shaded = result_.shadingPoints;
        interpolateVertices(s_.tail);
        result_.tailFragments += s_.tail.size();
        result_.tailVertices += result_.shadingPoints - shaded;
    }

    /// Shades the strand vertices of the segments of `fragments` (vertex
    /// slots in segment order; a segment's tip-side vertex is always the slot
    /// after its root-side one, which the next segment of the strand reuses)
    /// and adds each fragment's interpolation of its segment's two vertices.
    void interpolateVertices(std::span<const Visible> fragments) {
        if (fragments.empty())
            return;
        s_.vertexSlot.assign(bins_.size(), kNoSlot);
        for (const Visible& v : fragments)
            s_.vertexSlot[v.local] = 0;
        s_.slotPoint.clear();
        s_.slotStrand.clear();
        for (std::size_t i = 0; i < bins_.size(); ++i) {
            if (s_.vertexSlot[i] == kNoSlot)
                continue;
            const std::uint32_t k = s_.pointOf[i];
            if (s_.slotPoint.empty() || s_.slotPoint.back() != k) {
                s_.slotPoint.push_back(k);
                s_.slotStrand.push_back(s_.strandOf[i]);
            }
            s_.vertexSlot[i] = static_cast<std::uint32_t>(s_.slotPoint.size() - 1);
            s_.slotPoint.push_back(k + 1);
            s_.slotStrand.push_back(s_.strandOf[i]);
        }
        shadeInto(
            s_.slotPoint.size(),
            [&](std::size_t j) { return pointAtVertex(s_.slotPoint[j], s_.slotStrand[j]); },
            "at a strand vertex", s_.vertexResults);
        result_.interpolated += fragments.size();
        for (const Visible& v : fragments) {
            const float* a =
                s_.vertexResults.data() + std::size_t(s_.vertexSlot[v.local]) * stride_;
            accumulateLerp(v, v.t, a, a + stride_);
        }
    }

    /// Adaptive rate: the error of interpolating a segment is measured on
    /// the segment before its fragments are shaded. A segment with more than
    /// kProbePoints visible fragments in the tile is shaded at t = 0, ½ and 1;
    /// when the midpoint's radiance is within the tolerance of the ends'
    /// linear interpolation (smoothAlong()), the fragments interpolate the
    /// three results piecewise linearly, and otherwise each is shaded. The
    /// probe's verdict depends on the segment alone, whether it is probed on
    /// the tile's fragments: neither on the threads.
    void shadeAdaptive() {
        s_.pixelSum.assign(std::size_t(area_) * stride_, 0.0f);
        interpolateTail();
        groupVisibleBySegment();
        auto fragmentsOf = [&](std::size_t i) {
            return s_.segmentStart[i + 1] - s_.segmentStart[i];
        };
        s_.probed.clear();
        for (std::size_t i = 0; i < bins_.size(); ++i)
            if (fragmentsOf(i) > kProbePoints)
                s_.probed.push_back(static_cast<std::uint32_t>(i));
        shadeInto(
            kProbePoints * s_.probed.size(),
            [&](std::size_t j) {
                return pointOnSegment(s_.probed[j / kProbePoints], 0.5f * float(j % kProbePoints));
            },
            "probing a segment", s_.probeResults);

        s_.probeOf.assign(bins_.size(), kNoSlot);
        for (std::size_t p = 0; p < s_.probed.size(); ++p) {
            const float* a = s_.probeResults.data() + kProbePoints * p * stride_;
            if (smoothAlong(a, a + stride_, a + 2 * stride_, ctx_.radianceFloats,
                            ctx_.settings.shadingTolerance)) {
                s_.probeOf[s_.probed[p]] = static_cast<std::uint32_t>(p);
                ++result_.smoothSegments;
                result_.interpolated += fragmentsOf(s_.probed[p]);
            }
        }
        result_.probedSegments += s_.probed.size();

        // The fragments of the other segments, shaded in segment order.
        s_.grouped.clear();
        for (const Visible& v : s_.visible) {
            const std::uint32_t p = s_.probeOf[v.local];
            if (p == kNoSlot) {
                s_.grouped.push_back(v);
                continue;
            }
            const float* a = s_.probeResults.data() + kProbePoints * p * stride_;
            const float* m = a + stride_;
            const float u = 2.0f * v.t;
            if (u > 1.0f)
                accumulateLerp(v, u - 1.0f, m, m + stride_);
            else
                accumulateLerp(v, u, a, m);
        }
        shadeEach(s_.grouped);
    }

    /// accumulate() of the result (1 − u)·a + u·b, interpolated as it is added.
    void accumulateLerp(const Visible& v, float u, const float* __restrict a,
                        const float* __restrict b) {
        float* __restrict sum = s_.pixelSum.data() + std::size_t(v.pixel) * stride_;
        const float w = v.weight;
        for (std::size_t k = 0; k < stride_; ++k)
            sum[k] += w * hairvox::lerp(u, a[k], b[k]);
    }

    /// Radiance layers get the premultiplied sums (and add to the beauty);
    /// average layers the sums divided by the hair's weight, 0 without hair.
    void finishShading() {
        TileOutput beauty = output(ctx_.beautyLayer);
        std::vector<TileOutput>& radiance = s_.radianceOutputs;
        std::vector<TileOutput>& average = s_.averageOutputs;
        radiance.clear();
        average.clear();
        for (std::size_t layer : ctx_.radianceLayer)
            radiance.push_back(output(layer));
        for (std::size_t layer : ctx_.averageLayer)
            average.push_back(output(layer));
        for (std::uint32_t p = 0; p < area_; ++p) {
            const float w = s_.pixels[p].hairWeight;
            const std::size_t i = tileIndex(p);
            // Zero where no fragment was shaded: nothing accumulated.
            const float* sum = s_.pixelSum.data() + std::size_t(p) * stride_;
            for (std::size_t l = 0; l < radiance.size(); ++l)
                for (std::size_t c = 0; c < 3; ++c) {
                    radiance[l].set(i, c, sum[3 * l + c]);
                    beauty.add(i, c, sum[3 * l + c]);
                }
            const float invW = w > 0 ? 1.0f / w : 0.0f;
            std::size_t k = ctx_.radianceFloats;
            for (std::size_t l = 0; l < average.size(); ++l) {
                const auto channels = static_cast<std::size_t>(ctx_.layout.averages[l].channels);
                for (std::size_t c = 0; c < channels; ++c)
                    average[l].set(i, c, sum[k + c] * invW);
                k += channels;
            }
        }
    }

    const RenderContext& ctx_;
    TileScratch& s_;
    std::size_t stride_;
    int tx_, ty_, x0_, y0_, x1_, y1_, width_;
    std::uint32_t area_;
    std::span<const std::uint32_t> bins_;
    std::size_t openPixels_ = 0;
    /// Per row of the tile, bit x − x0 set while that pixel is open.
    static_assert(kTileSize <= 32, "a tile row's open pixels are one 32-bit mask");
    std::array<std::uint32_t, kTileSize> openRows_{};
    /// Hair behind this transmittance is interpolated from strand vertices
    /// (none at vertex rate: everything is).
    float tailTransmittance_ = 0;
    TileResult result_;
};

} // namespace

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
              << s.tailVertices << " vertices, " << s.invalidSamples << " rejected; "
              << s.tiles << " tiles)";
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
    if (!background.empty() && background.radiance.size() != pixels)
        throw InputError(strCat("background layer of ", background.radiance.size(),
                                " pixels for a ", camera.width(), " x ", camera.height(),
                                " camera"));
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
