// hairvox render (private): a strand segment as a camera-facing ribbon in
// raster space, and its exact box-filtered pixel coverage.
//
// The ribbon of segment p0 → p1 (vertex tangents u0, u1) is the quad
//   A = s0 + o0,  B = s1 + o1,  C = s1 − o1,  D = s0 − o0
// where s_k is the raster position of p_k and o_k is the image of the
// half-width of the ray-facing ribbon at p_k (r_k = k·D_k/2 across the tangent
// and the line of sight: the ribbon Embree's flat curves intersect), lengthened
// at a bend to a miter join so that the ribbon is 2·r_k wide along both
// segments there. The width is linear along the segment, as Embree's is.
// Since o_k depends only on vertex k, consecutive segments of a strand share
// an edge.
// A segment crossing the near plane is clipped in 3D first; t0/t1 remember
// which part of the original segment the ribbon spans.
//
// Coverage of a pixel is the area of ribbon ∩ pixel square, computed by
// clipping: per pixel row the ribbon is clipped to the row's slab, then the
// area left of each pixel column boundary is a one-sided clip, and a pixel's
// coverage is the difference of two of those areas. Double precision keeps
// the difference exact to ~1e-9 pixel² at any raster coordinate; a ribbon
// reaching far beyond the tile is clipped to it first. A quad that
// is not convex (the projected tangents bend sharply) is covered as its two
// triangles ABC and ACD.
#pragma once

#include <hairvox/core/vecmath.h>
#include <hairvox/geometry/camera.h>

#include <glm/vec2.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <span>

namespace hairvox::raster {

using Vec2d = glm::dvec2;

struct ScreenRibbon {
    Vec2d s0, s1;                  ///< raster positions of the (clipped) ends
    Vec2d o0, o1;                  ///< half-width offsets at the ends
    float invZ0, invZ1;            ///< 1 / depth at the ends
    float t0, t1;                  ///< the ends' parameters on the original segment
    double xMin, yMin, xMax, yMax; ///< raster bounds of the quad

    /// Finite bounds and depths (a groom with absurd coordinates can overflow).
    bool finite() const {
        return std::isfinite(xMin) && std::isfinite(xMax) && std::isfinite(yMin) &&
               std::isfinite(yMax) && std::isfinite(invZ0) && std::isfinite(invZ1) && invZ0 > 0 &&
               invZ1 > 0;
    }

    /// Where the pixel centre `c` falls along the ribbon: the parameter on the
    /// original segment (perspective-correct) and the depth there.
    void locate(const Vec2d& c, float& t, float& depth) const;
};

/// A strand vertex seen by the camera: what the ribbons of its two segments
/// share. invZ = 0 marks a vertex nearer than the near plane.
struct ProjectedVertex {
    Vec2d raster;
    Vec2d offset; ///< half-width offset (o_k above)
    float invZ;   ///< 1 / depth

    bool valid() const { return invZ > 0; }
};

/// Projects the points of one strand (unit tangents, world half-widths
/// `radii`, one per point). A tangent pointing at the camera takes its offset
/// from the direction toward a projected neighbour.
void projectStrand(const Camera& camera, std::span<const Vec3f> points,
                   std::span<const Vec3f> tangents, std::span<const float> radii, float zNear,
                   std::span<ProjectedVertex> out);

/// The ribbon between two valid projected vertices.
ScreenRibbon ribbonBetween(const ProjectedVertex& a, const ProjectedVertex& b);

/// The ribbon of a segment p0 → p1 (world half-widths r0, r1 at its ends)
/// that crosses the near plane `zNear` (camera space), clipped in 3D; nullopt
/// if it lies wholly nearer. Raster bounds are not clipped to the image.
std::optional<ScreenRibbon> projectRibbon(const Camera& camera, const Vec3f& p0, const Vec3f& p1,
                                          const Vec3f& u0, const Vec3f& u1, float r0, float r1,
                                          float zNear);

/// Calls emit(x, y, coverage) for every pixel of [x0, x1) × [y0, y1) that the
/// ribbon covers by more than 1e-7 pixel² (coverage ≤ 1) and for which
/// wanted(x, y) is true; wanted() is asked first, for every pixel of the
/// ribbon's span in each row, so that unwanted pixels cost no clipping.
template <typename Emit, typename Wanted>
void rasterizeRibbon(const ScreenRibbon& ribbon, int x0, int y0, int x1, int y1, Emit&& emit,
                     Wanted&& wanted);

// --- implementation --------------------------------------------------------

/// A convex polygon of up to 8 vertices (a quad clipped by three lines has ≤ 7).
struct Polygon {
    Vec2d v[8];
    int n = 0;
};

/// out = the part of `in` with coordinate Axis ≤ c (KeepBelow) or ≥ c.
template <int Axis, bool KeepBelow>
void clip(const Polygon& in, double c, Polygon& out) {
    out.n = 0;
    for (int k = 0; k < in.n; ++k) {
        const Vec2d& a = in.v[k];
        const Vec2d& b = in.v[k + 1 == in.n ? 0 : k + 1];
        const bool aIn = KeepBelow ? a[Axis] <= c : a[Axis] >= c;
        const bool bIn = KeepBelow ? b[Axis] <= c : b[Axis] >= c;
        if (aIn)
            out.v[out.n++] = a;
        if (aIn != bIn) {
            Vec2d p;
            p[Axis] = c; // exactly on the line
            p[1 - Axis] =
                a[1 - Axis] + (c - a[Axis]) / (b[Axis] - a[Axis]) * (b[1 - Axis] - a[1 - Axis]);
            out.v[out.n++] = p;
        }
    }
}

/// |area| of a polygon (shoelace).
inline double polygonArea(const Polygon& p) {
    double twice = 0;
    for (int k = 0; k < p.n; ++k) {
        const Vec2d& a = p.v[k];
        const Vec2d& b = p.v[k + 1 == p.n ? 0 : k + 1];
        twice += a.x * b.y - b.x * a.y;
    }
    return 0.5 * std::abs(twice);
}

/// |area| of the part of `p` left of x = c: the clip of `clip<0, true>`
/// fused with the shoelace sum (the clipped polygon is never stored).
inline double areaLeftOf(const Polygon& p, double c) {
    double twice = 0;
    Vec2d first, previous;
    bool any = false;
    auto emit = [&](const Vec2d& q) {
        if (any) {
            twice += previous.x * q.y - q.x * previous.y;
        } else {
            first = q;
            any = true;
        }
        previous = q;
    };
    for (int k = 0; k < p.n; ++k) {
        const Vec2d& a = p.v[k];
        const Vec2d& b = p.v[k + 1 == p.n ? 0 : k + 1];
        const bool aIn = a.x <= c, bIn = b.x <= c;
        if (aIn)
            emit(a);
        if (aIn != bIn)
            emit(Vec2d(c, a.y + (c - a.x) / (b.x - a.x) * (b.y - a.y)));
    }
    if (any)
        twice += previous.x * first.y - first.x * previous.y;
    return 0.5 * std::abs(twice);
}

bool isConvexQuad(const Vec2d q[4]);

/// Covers one convex polygon.
template <typename Emit, typename Wanted>
void rasterizeConvex(const Polygon& poly, int x0, int y0, int x1, int y1, Emit& emit,
                     Wanted& wanted) {
    constexpr double minCoverage = 1e-7;
    double yMin = poly.v[0].y, yMax = yMin;
    for (int k = 1; k < poly.n; ++k) {
        yMin = std::min(yMin, poly.v[k].y);
        yMax = std::max(yMax, poly.v[k].y);
    }
    const int rowBegin = std::max(y0, static_cast<int>(std::floor(yMin)));
    const int rowEnd = std::min(y1, static_cast<int>(std::ceil(yMax)));
    Polygon slab, row;
    for (int y = rowBegin; y < rowEnd; ++y) {
        clip<1, false>(poly, double(y), slab);
        clip<1, true>(slab, double(y + 1), row);
        if (row.n < 3)
            continue;
        const double rowArea = polygonArea(row);
        if (rowArea < minCoverage)
            continue;
        double xMin = row.v[0].x, xMax = xMin;
        for (int k = 1; k < row.n; ++k) {
            xMin = std::min(xMin, row.v[k].x);
            xMax = std::max(xMax, row.v[k].x);
        }
        const int colBegin = std::max(x0, static_cast<int>(std::floor(xMin)));
        const int colEnd = std::min(x1, static_cast<int>(std::ceil(xMax)));
        // Area of the row polygon left of the current column's left edge,
        // computed afresh after unwanted pixels.
        double left = 0;
        bool leftKnown = false;
        for (int x = colBegin; x < colEnd; ++x) {
            if (!wanted(x, y)) {
                leftKnown = false;
                continue;
            }
            if (!leftKnown) {
                left = double(x) > xMin ? areaLeftOf(row, double(x)) : 0.0;
                leftKnown = true;
            }
            const double right = double(x + 1) >= xMax ? rowArea : areaLeftOf(row, double(x + 1));
            const double coverage = right - left;
            left = right;
            if (coverage > minCoverage)
                emit(x, y, static_cast<float>(std::min(coverage, 1.0)));
        }
    }
}

/// The polygon clipped to [x0, x1] × [y0, y1] (keeps coordinates small
/// before they are converted to pixel indices).
inline Polygon clipToBox(const Polygon& p, double x0, double y0, double x1, double y1) {
    Polygon a, b;
    clip<0, false>(p, x0, a);
    clip<0, true>(a, x1, b);
    clip<1, false>(b, y0, a);
    clip<1, true>(a, y1, b);
    return b;
}

template <typename Emit, typename Wanted>
void rasterizeRibbon(const ScreenRibbon& r, int x0, int y0, int x1, int y1, Emit&& emit,
                     Wanted&& wanted) {
    const Vec2d q[4] = {r.s0 + r.o0, r.s1 + r.o1, r.s1 - r.o1, r.s0 - r.o0};
    const bool inside =
        r.xMin >= x0 - 1 && r.xMax <= x1 + 1 && r.yMin >= y0 - 1 && r.yMax <= y1 + 1;
    auto cover = [&](const Polygon& p) {
        if (inside)
            rasterizeConvex(p, x0, y0, x1, y1, emit, wanted);
        else
            rasterizeConvex(clipToBox(p, x0 - 1, y0 - 1, x1 + 1, y1 + 1), x0, y0, x1, y1, emit,
                            wanted);
    };
    if (isConvexQuad(q)) {
        Polygon p;
        p.n = 4;
        for (int k = 0; k < 4; ++k)
            p.v[k] = q[k];
        cover(p);
        return;
    }
    for (const auto& [a, b, c] : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
        Polygon t;
        t.n = 3;
        t.v[0] = q[a];
        t.v[1] = q[b];
        t.v[2] = q[c];
        cover(t);
    }
}

} // namespace hairvox::raster
