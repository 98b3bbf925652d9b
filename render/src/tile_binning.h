// hairvox render (private): the geometry shared by all tiles — every strand
// point's tangent and projection, the segment records — and the binning of
// segments to the tiles their ribbon may touch, culling those outside the
// view and those wholly behind surfaces that cover a tile.
#pragma once

#include "raster_context.h"

#include <vector>

namespace hairvox::raster {

/// Unit tangent at every point (strandTangents(): the bisector of the
/// adjacent segments' directions), and every point's projection with its
/// ribbon half-width k·D_i/2 (ribbonWidthAt()).
void prepareVertices(const Groom& groom, const Camera& camera, const FiberScale& scale,
                     LargeVector<Vec3f>& tangents, LargeVector<raster::ProjectedVertex>& projected);

/// Per tile, the depth behind which surfaces hide everything: the farthest
/// surface depth of a tile whose every pixel is wholly covered, else +∞.
std::vector<float> tileSurfaceDepths(const SurfaceLayer& surfaces, int width, int height,
                                     int tilesX, int tilesY);

/// Per segment, its root-side point and its strand.
std::vector<SegmentRef> indexSegments(const Groom& groom);

/// Bins segments to the tiles their ribbon may touch. Chunks of segments are
/// counted, then written, in chunk order: each tile's list is sorted by
/// segment index whatever the thread count.
void binSegments(RenderContext& ctx, RasterStats& stats);

} // namespace hairvox::raster
