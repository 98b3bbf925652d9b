// hairvox strands: the in-memory groom every stage consumes.
//
// A groom is a set of strands; strand i is the polyline
// points[strandStart[i]] .. points[strandStart[i+1] - 1], ordered root → tip
// (the fiber tangent u of DESIGN.md §2 points along increasing index).
// Optional per-point attributes are either empty or exactly one value per point.
// Units are the file's (metres for TressFX and the procedural grooms).
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/strands/fiber_scale.h>

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <span>
#include <string>
#include <vector>

namespace hairvox {

struct Groom {
    std::vector<Vec3f> points;
    /// strandStart.size() == strandCount() + 1; strandStart.front() == 0 and
    /// strandStart.back() == points.size(). Empty for an empty groom.
    std::vector<std::uint32_t> strandStart;
    /// Per point, optional: the fiber diameter D_i there. A reader stores the
    /// file's values (.hair: a diameter in file units; .tfx: a per-strand
    /// ratio); the pipeline resolves them into scene units before rendering
    /// (scene key fiber.groom_thickness), and from then on every stage reads
    /// D_i through ribbonWidthAt().
    std::vector<float> thickness;
    std::vector<float> transparency; ///< per point, optional (not rendered: a warning says so)
    std::vector<Rgb> color;          ///< per point, optional (linear RGB reflectance)
    /// Per point, optional: the fiber type — an index into the scene's fiber
    /// palette (pipeline/fiber_palette.h) — of the segment that starts at the
    /// point (a strand's last point repeats its last segment's). Empty: every
    /// fiber is type 0.
    std::vector<std::uint8_t> fiberType;

    std::size_t strandCount() const { return strandStart.empty() ? 0 : strandStart.size() - 1; }
    std::size_t pointCount() const { return points.size(); }
    /// Valid for sanitized grooms (every strand has ≥ 2 points; see sanitizeGroom()).
    std::size_t segmentCount() const { return points.size() - strandCount(); }
    bool empty() const { return strandCount() == 0; }

    std::span<const Vec3f> strand(std::size_t i) const {
        return {points.data() + strandStart[i], strandStart[i + 1] - strandStart[i]};
    }

    /// Appends one strand's points. Grooms built this way carry no optional
    /// attributes (readers of files that have them fill the arrays directly).
    void addStrand(std::span<const Vec3f> strandPoints);

    Bounds3f bounds() const;
    /// Σ over segments of |p_{k+1} − p_k|, accumulated in double.
    double totalLength() const;
};

/// The unit tangents at one strand's points (root → tip): at an inner point
/// the bisector of its two segments' directions, at the root and the tip
/// their one segment's. Between points, the shading tangent is these
/// interpolated along the segment — the rasterizer's and the path tracer's
/// fibers are shaded alike.
void strandTangents(std::span<const Vec3f> points, std::span<Vec3f> tangents);

/// The unit tangent at a point `t` ∈ [0, 1] of the segment between two points
/// with unit tangents t0, t1 (interpolated; the segment's direction d where
/// that degenerates).
inline Vec3f shadingTangent(const Vec3f& t0, const Vec3f& t1, float t, const Vec3f& d) {
    return normalizeOr((1.0f - t) * t0 + t * t1, d);
}

/// The width k·D_i of the ray-facing ribbon at point i (fiber_scale.h): D_i
/// is groom.thickness[i] when the groom carries per-point diameters, the
/// scale's D otherwise. Along a segment the width is linear between its points.
inline float ribbonWidthAt(const Groom& groom, const FiberScale& scale, std::size_t point) {
    return groom.thickness.empty() ? scale.ribbonWidth()
                                   : groom.thickness[point] * scale.densityMultiplier;
}

/// The largest ribbonWidthAt() over the groom's points (k·D without per-point diameters).
float maxRibbonWidth(const Groom& groom, const FiberScale& scale);

/// At most this many fiber types (the fiber grid splats one fraction per type).
inline constexpr std::size_t kMaxFiberTypes = 8;

/// The point a segment starts at: in a sanitized groom, global segment s of
/// strand i (segments numbered consecutively, strand by strand) starts at
/// point s + i.
inline std::size_t segmentStartPoint(std::uint32_t strand, std::uint32_t segment) {
    return std::size_t(segment) + strand;
}

/// The fiber type of the segment starting at `point`, from a groom's
/// fiberType array (0 when it is empty: an untyped groom).
inline std::uint8_t fiberTypeAt(std::span<const std::uint8_t> fiberType, std::size_t point) {
    return fiberType.empty() ? 0 : fiberType[point];
}
inline std::uint8_t fiberTypeAt(const Groom& groom, std::size_t point) {
    return fiberTypeAt(groom.fiberType, point);
}

/// 1 + the largest fiber type of the groom (1 for an untyped groom).
std::size_t fiberTypeCount(const Groom& groom);

/// Summary figures printed by `hairvox info` and recorded as grid metadata.
struct GroomStats {
    std::size_t strands = 0, points = 0, segments = 0;
    Bounds3f bounds;
    double totalLength = 0, meanSegmentLength = 0;
    double minSegmentLength = 0, maxSegmentLength = 0;
};

GroomStats computeStats(const Groom& groom);

/// Content hash of the strand geometry (points and strand offsets): identifies a
/// groom for caches and provenance metadata (DESIGN.md §7).
std::uint64_t contentHash(const Groom& groom);

std::ostream& operator<<(std::ostream& os, const Groom& groom);

/// What sanitizeGroom() removed: reported to the user as warnings, not errors.
struct SanitizeReport {
    std::size_t droppedSegments = 0; ///< zero-length segments (a point repeating its predecessor)
    std::size_t droppedStrands = 0;  ///< strands left with a single point after that
};

/// Checks a freshly read groom and makes it valid for every later stage.
/// Throws InputError naming `source`, the strand and the point for non-finite
/// coordinates and for strands with fewer than 2 points; drops zero-length
/// segments (and strands that collapse to one point) and reports the counts.
/// Also checks that optional attribute arrays have one value per point.
SanitizeReport sanitizeGroom(Groom& groom, const std::string& source);

} // namespace hairvox
