// hairvox render (private): one tile of the raster, rendered by one thread —
// its fragments' visibility and compositing (tile_compositing.cpp) and their
// deferred shading (tile_shading.cpp) — with the per-thread scratch it reuses
// from tile to tile and the film tiles it writes.
#pragma once

#include "raster_context.h"

#include <hairvox/film/film.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace hairvox::raster {

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
    std::vector<Visible> tail;    ///< visible behind the tail transmittance: interpolated
    std::vector<Visible> grouped; ///< visible, ordered by segment
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
    TileRenderer(const RenderContext& ctx, TileScratch& s, int tile);

    TileResult run();

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

    // Defined in tile_compositing.cpp and tile_shading.cpp; those marked
    // inline are used only in the file that defines them (as they were when
    // the class was defined in one file), so that the compiler may inline
    // the per-fragment ones.

    // --- visibility: coverage and compositing (tile_compositing.cpp) ---------

    /// Projects the tile's segments, orders them by nearest depth, and puts
    /// the surfaces' fragments in the queue.
    inline void prepare();

    /// Whether any pixel of the ribbon's bounding box in the tile is open: a
    /// segment wholly behind opaque pixels is skipped before its coverage.
    inline bool anyOpenUnder(const ScreenRibbon& r) const;

    inline void rasterizeAndComposite();

    /// Composites, in depth order, every pending fragment nearer than z.
    inline void settle(float z);

    inline void composite(PixelState& st, const Fragment& f);

    inline void finishCoverage();

    // --- deferred shading (tile_shading.cpp) ---------------------------------

    inline ShadingPoint pointOnSegment(std::uint32_t local, float t) const;

    /// A strand vertex, independent of the tile and segment it is shaded for
    /// (so that tiles sharing it agree).
    inline ShadingPoint pointAtVertex(std::uint32_t point, std::uint32_t strand) const;

    /// Shades `count` points from s_.points into s_.results; rejects invalid
    /// results (zeroing them) and reports them with `where(i)`.
    template <typename Where>
    void shadeBatch(std::size_t count, Where&& where);

    /// Adds a shaded fragment to its pixel's sums.
    inline void accumulate(const Visible& v, const float* __restrict r);

    inline std::string pixelName(std::uint32_t pixel) const;

    /// Orders the visible fragments by segment (a stable counting sort;
    /// segment i's are then [segmentStart[i], segmentStart[i + 1])):
    /// the points of a batch then come segment by segment, which lets a
    /// shader share work along a segment (the global term's fiber samples,
    /// transmittance/alongFibers()) and the segment's data between points.
    inline void groupVisibleBySegment();

    void shadeFragments();

    /// Shades points pointAt(0 .. n − 1), in batches, into `out` (n × stride
    /// floats); `where` names them in warnings.
    template <typename PointAt>
    void shadeInto(std::size_t n, PointAt&& pointAt, const char* where, std::vector<float>& out);

    /// Shades each fragment at its point, in batches, into its pixel's sums.
    inline void shadeEach(std::span<const Visible> fragments);

    void shadeVertices();

    /// Fragment and adaptive rates: the hair behind the tail transmittance
    /// interpolates its segments' vertices.
    inline void interpolateTail();

    /// Shades the strand vertices of the segments of `fragments` (vertex
    /// slots in segment order; a segment's tip-side vertex is always the slot
    /// after its root-side one, which the next segment of the strand reuses)
    /// and adds each fragment's interpolation of its segment's two vertices.
    inline void interpolateVertices(std::span<const Visible> fragments);

    /// Adaptive rate: the error of interpolating a segment is measured on
    /// the segment before its fragments are shaded. A segment with more than
    /// kProbePoints visible fragments in the tile is shaded at t = 0, ½ and 1;
    /// when the midpoint's radiance is within the tolerance of the ends'
    /// linear interpolation (smoothAlong()), the fragments interpolate the
    /// three results piecewise linearly, and otherwise each is shaded. The
    /// probe's verdict depends on the segment alone, whether it is probed on
    /// the tile's fragments: neither on the threads.
    void shadeAdaptive();

    /// accumulate() of the result (1 − u)·a + u·b, interpolated as it is added.
    inline void accumulateLerp(const Visible& v, float u, const float* __restrict a,
                               const float* __restrict b);

    /// Radiance layers get the premultiplied sums (and add to the beauty);
    /// average layers the sums divided by the hair's weight, 0 without hair.
    void finishShading();

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

} // namespace hairvox::raster
