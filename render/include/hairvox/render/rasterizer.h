// hairvox render: the hair rasterizer — strands as ribbons, exact coverage,
// front-to-back compositing, deferred shading through a FragmentShader.
//
// Strands are drawn as camera-facing ribbons of the fiber diameter D (world
// units, usually far below a pixel), or of the groom's per-point diameter D_i
// (strands/groom.h ribbonWidthAt(): linear along a segment). Each segment
// becomes a quad whose edges at a vertex are offset by ±D_i/2 perpendicular
// to that vertex's projected tangent, so consecutive segments share an edge
// (no gaps, no overlaps).
// Coverage is analytic: the exact area of quad ∩ pixel square (box filter),
// so thin hair neither aliases nor sparkles (ribbon.h).
//
// Per pixel, fragments are composited front to back in depth order (ties
// broken by segment index); fragments of adjacent segments of one strand that
// follow each other add their coverage (they tile the ribbon) instead of
// compositing over each other. A strand standing for k hairs (the density
// multiplier, strands/fiber_scale.h) is a ribbon k·D wide, the ribbon exact
// mode and the path tracer meet. A pixel is opaque once its transmittance falls to
// RasterSettings::opaqueTransmittance: fragments behind it are never shaded,
// and since segments are rasterized nearest first, most of them are not even
// generated (docs/DESIGN.md §7). Hair seen through less than
// RasterSettings::tailTransmittance is interpolated from its strand vertices
// instead of being shaded (the tail, fragment_shader.h).
//
// Opaque surfaces (the head, meshes) are not drawn here: the caller gives
// them as a SurfaceLayer — per pixel the coverage, depth and radiance of what
// it found there — and each covered pixel gets one surface fragment,
// composited with the hair. A tile whose every pixel is wholly covered by a
// surface culls the segments that lie wholly behind its farthest surface
// depth before they are rasterized.
//
// Work is done per 32×32 tile (segments binned to tiles, then raster,
// composite and shade per tile) in parallel with TBB; memory beyond the film
// is bounded by a few tiles per thread, and the film's bytes do not depend on
// the thread count.
//
// The film (film/film.h) gets: the beauty "" and alpha "A"; the shader's
// radiance layers; the surfaces' radiance (kSurfaceLayer) and the background
// (a colour, or a BackgroundLayer per pixel: an environment) seen through
// everything (kBackgroundLayer) — all premultiplied, and
//     beauty = Σ shader radiance layers + surface + background;
// the hair's share of the alpha (kHairAlphaLayer); the depth (kDepthLayer,
// camera-space z averaged with the compositing weights, 0 where empty); and
// the shader's average layers. RasterSettings::layers keeps only some of
// them besides the beauty and "A": the others are neither allocated nor
// written, and the beauty is the same.
#pragma once

#include <hairvox/core/large_array.h>
#include <hairvox/core/rgb.h>
#include <hairvox/film/film.h>
#include <hairvox/geometry/camera.h>
#include <hairvox/render/fragment_shader.h>
#include <hairvox/strands/fiber_scale.h>
#include <hairvox/strands/groom.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace hairvox {

inline constexpr const char* kSurfaceLayer = "surface";
inline constexpr const char* kBackgroundLayer = "background";
inline constexpr const char* kHairAlphaLayer = "hair.A";
inline constexpr const char* kDepthLayer = "Z";

/// A film layer the rasterizer can store besides the beauty "" and "A".
struct RasterLayer {
    std::string name;
    int channels = 3;           ///< 1 or 3
    bool fullPrecision = false; ///< FilmLayer::fullPrecision
};

/// Every such layer for a shader's layout, in film order: the shader's
/// radiance layers, kSurfaceLayer, kBackgroundLayer, kHairAlphaLayer,
/// kDepthLayer, then the shader's average layers.
std::vector<RasterLayer> rasterLayers(const ShaderLayout& layout);

/// Opaque surfaces as the camera sees them, per pixel (row-major, the
/// camera's resolution): the fraction of the pixel they cover, their mean
/// camera depth there and their mean outgoing radiance. Empty: no surfaces.
struct SurfaceLayer {
    // (core/large_array.h: pipeline/surfaces.cpp fills them on its threads.)
    LargeVector<float> coverage; ///< [0, 1]; 0 where no surface
    LargeVector<float> depth;
    LargeBuffer<Rgb> radiance;

    bool empty() const { return coverage.empty(); }
};

/// What the camera sees behind everything, per pixel: an environment seen
/// through the pixel, averaged over it (premultiplied by nothing: each pixel's
/// transmittance weighs it). `radiance(x, y)` is asked for a pixel only where
/// the surfaces and the hair leave it some transmittance, once, from the
/// rasterizer's threads (so it must be thread-safe): a pixel they cover
/// entirely is not looked at (on the default scene 10% of the pixels: hair
/// closes a pixel at a transmittance above 0), and no image-sized buffer is
/// held. Empty: RasterSettings::background everywhere.
struct BackgroundLayer {
    std::function<Rgb(int x, int y)> radiance;

    bool empty() const { return !radiance; }
};

struct RasterSettings {
    FiberScale fiberScale; ///< ribbons k·D (k·D_i) wide: a strand's coverage counts k hairs
    ShadingRate shadingRate = ShadingRate::Fragment;
    /// Adaptive rate: a segment's fragments interpolate three shaded points
    /// when the midpoint's radiance is within this fraction of the segment's
    /// mean radiance from the ends' interpolation (fragment_shader.h). [0, 1]
    float shadingTolerance = kDefaultShadingTolerance;
    Rgb background{0.0f}; ///< radiance behind everything (where no BackgroundLayer is given)
    /// A pixel is opaque once its transmittance is ≤ this: fragments behind it
    /// are skipped. Their share of the pixel is at most this value. [0, 1)
    float opaqueTransmittance = 1.0f / 256.0f;
    /// Fragment and adaptive rates: hair seen through less than this
    /// transmittance interpolates strand-vertex results instead of being
    /// shaded (fragment_shader.h); at most this share of a pixel. 0: none. [0, 1]
    float tailTransmittance = kDefaultTailTransmittance;
    /// The layers stored besides the beauty and "A" (always stored): null,
    /// every one of rasterLayers(); else those named, in any order (an
    /// unknown name is an InputError).
    std::optional<std::vector<std::string>> layers;
    int threads = 0;       ///< 0: all cores
    bool progress = false; ///< draw a progress bar on stderr (the caller checks it is a terminal)

    /// Whether `layers` keeps the named layer (every one when null).
    bool stores(const std::string& layer) const;
};

struct RasterStats {
    double seconds = 0;       ///< wall time of rasterize()
    double setupSeconds = 0;  ///< vertex tangents, projection and binning (wall)
    double rasterSeconds = 0; ///< raster, sort, composite (wall, apportioned by thread time)
    double shadeSeconds = 0;  ///< shader calls and accumulation (wall, apportioned by thread time)
    std::uint64_t segments = 0;
    std::uint64_t segmentsOutsideView = 0; ///< off screen or behind the camera
    std::uint64_t segmentTileRefs = 0;     ///< (segment, tile) pairs binned
    /// (segment, tile) pairs culled: the segment lies behind a tile wholly covered by surfaces.
    std::uint64_t segmentTilesBehindSurfaces = 0;
    /// Of those binned, skipped whole: every pixel under the segment's
    /// bounding box in the tile was already opaque.
    std::uint64_t segmentTilesSkipped = 0;
    std::uint64_t fragments = 0; ///< hair (segment, pixel) pairs met
    /// Of those, skipped behind an opaque pixel (never shaded; counted per
    /// pixel of the ribbon's row span, coverage not computed; a segment-tile
    /// skipped whole counts none).
    std::uint64_t fragmentsBehindOpaque = 0;
    std::uint64_t fragmentsComposited = 0; ///< hair fragments that reached the pixel
    std::uint64_t shadingPoints = 0;       ///< points handed to the shader
    /// Adaptive rate: (segment, tile) pairs probed at t = 0, ½, 1, those found
    /// smooth, and the hair fragments that interpolated them instead of being
    /// shaded.
    std::uint64_t probedSegments = 0, smoothSegments = 0, fragmentsInterpolated = 0;
    /// Fragment and adaptive rates: hair fragments behind the tail
    /// transmittance (interpolated, and counted in fragmentsInterpolated too),
    /// and the strand vertices shaded for them.
    std::uint64_t tailFragments = 0, tailVertices = 0;
    std::uint64_t invalidSamples = 0; ///< shader results rejected (NaN, Inf, negative)
    std::uint64_t tiles = 0;
};

std::ostream& operator<<(std::ostream& os, const RasterStats& s);

struct RasterOutput {
    Film film;
    RasterStats stats;
    /// Human-readable notes (the first rejected shader results, pbrt-v4 style).
    std::vector<std::string> warnings;
};

/// Rasterizes `groom` as the camera sees it, shaded by `shader`, over the
/// opaque `surfaces` (empty: none) and the `background` (empty: the settings'
/// colour). Polls throwIfInterrupted() between tiles and shader batches.
/// Throws InputError for invalid settings or a surface or background layer of
/// the wrong size; segments with non-finite projections are culled.
RasterOutput rasterize(const Groom& groom, const Camera& camera, const FragmentShader& shader,
                       const RasterSettings& settings, const SurfaceLayer& surfaces = {},
                       const BackgroundLayer& background = {});

} // namespace hairvox
