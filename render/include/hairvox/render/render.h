// hairvox render: rendering a groom — the rasterizer and its statistics.
//
// Strands are drawn as camera-facing ribbons of the fiber diameter D (world
// units, usually far below a pixel). Each segment becomes a quad whose edges
// at a vertex are offset by ±D/2 perpendicular to that vertex's projected
// tangent, so consecutive segments share an edge (no gaps, no overlaps).
// Coverage is analytic: the exact area of quad ∩ pixel square (box filter),
// so thin hair neither aliases nor sparkles.
//
// Per pixel, fragments are composited front to back in depth order (ties
// broken by segment index); fragments of adjacent segments of one strand that
// follow each other add their coverage (they tile the ribbon) instead of
// compositing over each other. A strand standing for k hairs (the scene's
// density multiplier) that covers α of a pixel transmits (1 − α)^k — k hairs
// at independent positions, as the global term counts them. A pixel is opaque
// once its transmittance falls to RenderOptions::opaqueTransmittance:
// fragments behind it are never shaded, and since segments are rasterized
// nearest first, most of them are not even generated (DESIGN.md §7). The
// opaque head sphere is one more fragment per pixel (coverage from 8×8
// samples on its silhouette); hair segments wholly behind it are culled
// before rasterization.
//
// Work is done per 32×32 tile (segments binned to tiles, then raster,
// composite and shade per tile) in parallel with TBB; memory beyond the film
// is bounded by a few tiles per thread, and the film's bytes do not depend on
// the thread count.
#pragma once

#include <hairvox/render/film.h>
#include <hairvox/render/fragment_shader.h>
#include <hairvox/render/scene.h>
#include <hairvox/strands/groom.h>

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace hairvox {

struct RenderOptions {
    int threads = 0;       ///< 0: all cores
    bool progress = false; ///< draw a progress bar on stderr (the caller checks it is a terminal)
    /// A pixel is opaque once its transmittance is ≤ this: fragments behind it
    /// are skipped. Their share of the pixel is at most this value. [0, 1)
    float opaqueTransmittance = 1.0f / 256.0f;
};

struct RenderStats {
    double seconds = 0;       ///< wall time of renderImage()
    double setupSeconds = 0;  ///< vertex tangents, projection and binning (wall)
    double rasterSeconds = 0; ///< raster, sort, composite (wall, apportioned by thread time)
    double shadeSeconds = 0;  ///< shader calls and accumulation (wall, apportioned by thread time)

    std::uint64_t segments = 0;
    std::uint64_t segmentsOutsideView = 0; ///< off screen or behind the camera
    std::uint64_t segmentsBehindHead = 0;  ///< wholly hidden by the head sphere
    std::uint64_t segmentTileRefs = 0;     ///< (segment, tile) pairs binned
    std::uint64_t segmentTilesSkipped = 0; ///< of those, skipped: the tile was already opaque
    std::uint64_t fragments = 0;           ///< hair (segment, pixel) pairs met
    /// Of those, skipped behind an opaque pixel (never shaded; counted per
    /// pixel of the ribbon's row span, coverage not computed).
    std::uint64_t fragmentsBehindOpaque = 0;
    std::uint64_t fragmentsComposited = 0;   ///< hair fragments that reached the pixel
    std::uint64_t shadingPoints = 0;         ///< points handed to the shader
    std::uint64_t invalidSamples = 0;        ///< shader results rejected (NaN, Inf, negative)
    std::uint64_t tiles = 0;
};

std::ostream& operator<<(std::ostream& os, const RenderStats& s);

struct RenderOutput {
    Film film;
    RenderStats stats;
    /// Human-readable notes (the first rejected shader results, pbrt-v4 style).
    std::vector<std::string> warnings;
};

/// Renders `groom` as seen by scene.camera, shaded by `shader` at
/// scene.shadingRate, with the scene's head and background. Polls
/// throwIfInterrupted() between tiles and shader batches. Throws InputError
/// for an invalid scene; segments with non-finite projections are culled.
RenderOutput renderImage(const Groom& groom, const Scene& scene, const FragmentShader& shader,
                         const RenderOptions& options = {});

} // namespace hairvox
