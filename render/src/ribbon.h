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
// Coverage of a pixel is the area of ribbon ∩ pixel square, accumulated per
// edge: each edge adds, in every pixel row it crosses, the signed area its
// piece there contributes to the cells it passes, and a running sum along the
// row gives each pixel's area (accumulateEdge: font-rs's accumulation, exact
// for straight edges). It costs a few operations per edge and row, where
// clipping the ribbon to each row and column cost two polygon clips per row;
// the ribbons are tall and thin (the 1080p head: 11 rows a ribbon, 1.4
// pixels a row). Double precision, relative to the ribbon's bounding box,
// keeps the areas exact to ~1e-12 pixel²; a ribbon reaching far beyond the
// tile is clipped to it first. A quad that is not convex (the projected
// tangents bend sharply) is covered as its two triangles ABC and ACD.
#pragma once

#include <hairvox/core/vecmath.h>
#include <hairvox/geometry/camera.h>

#include <glm/vec2.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <vector>

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
};

/// Where a pixel centre falls along a ribbon: the parameter on the original
/// segment (perspective-correct) and the depth there. Made once per ribbon
/// (its axis scaled by 1/|axis|², so that a fragment divides once, for its
/// depth: three double divisions in a row were the raster's longest chain),
/// asked once per fragment.
class RibbonLocator {
public:
    explicit RibbonLocator(const ScreenRibbon& r)
        : s0_(r.s0)
        , invZ0_(r.invZ0)
        , invZ1_(r.invZ1)
        , t0_(r.t0)
        , t1_(r.t1) {
        const Vec2d d = r.s1 - r.s0;
        const double len2 = glm::dot(d, d);
        degenerate_ = !(len2 > 1e-18);
        axis_ = degenerate_ ? Vec2d(0.0) : d / len2;
    }

    void locate(const Vec2d& c, float& t, float& depth) const {
        const double ts = degenerate_ ? 0.5 : std::clamp(glm::dot(c - s0_, axis_), 0.0, 1.0);
        // 1/z is affine in raster space; the 3D parameter is perspective-correct.
        const double z = 1.0 / ((1.0 - ts) * invZ0_ + ts * invZ1_);
        const double tw = ts * invZ1_ * z;
        depth = static_cast<float>(z);
        t = static_cast<float>((1.0 - tw) * t0_ + tw * t1_);
    }

private:
    Vec2d s0_, axis_;
    double invZ0_, invZ1_, t0_, t1_;
    bool degenerate_;
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

/// The cells of one polygon's coverage (rasterizePolygon), kept by the caller
/// from polygon to polygon: every cell is 0 between calls, and each row's
/// touched span is reset, so that a polygon clears only what it touched.
/// (An exception thrown by emit() leaves them dirty: a tile's scratch, which
/// a failed render discards.)
struct CoverageCells {
    std::vector<double> acc; ///< rows of `width` cells
    std::vector<int> lo, hi; ///< per row: the first and last cell an edge touched
    int width = 0;

    /// Room for `rows` rows of `cellsPerRow` cells (all 0 whatever the width).
    void prepare(int rows, int cellsPerRow) {
        width = cellsPerRow;
        const std::size_t need = std::size_t(rows) * std::size_t(cellsPerRow);
        if (acc.size() < need)
            acc.resize(need, 0.0);
        if (lo.size() < std::size_t(rows)) {
            lo.resize(std::size_t(rows), std::numeric_limits<int>::max());
            hi.resize(std::size_t(rows), -1);
        }
    }
};

/// Calls emit(x, y, coverage) for every pixel of [x0, x1) × [y0, y1) that the
/// ribbon covers by more than 1e-7 pixel² (coverage ≤ 1) and for which
/// wanted(x, y) is true, row by row; wanted() is asked only of those pixels.
template <typename Emit, typename Wanted>
void rasterizeRibbon(const ScreenRibbon& ribbon, int x0, int y0, int x1, int y1,
                     CoverageCells& cells, Emit&& emit, Wanted&& wanted);

// --- implementation --------------------------------------------------------

/// A convex polygon of up to 8 vertices (a quad clipped by four lines).
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

/// ⌈x⌉ for x ≥ 0 (a conversion and a compare: the x86-64 baseline has no
/// rounding instruction, and std::ceil is a longer sequence that also
/// handles negative and huge values).
inline int ceilNonNegative(double x) {
    const int i = static_cast<int>(x);
    return double(i) < x ? i + 1 : i;
}

/// Adds to `cells` (rows [0, rows), cell (i, r) = [i, i + 1] × [r, r + 1] in
/// coordinates local to the polygon's box, so x ≥ 0) the signed area that
/// the directed edge a → b contributes to each cell it passes: in each row
/// it crosses, its piece there, of signed height d (+ going down in y, − up),
/// adds d·(1 − m) to the cell it lies in and d·m to the next, where m is the
/// part of the cell left of the piece on average; a piece crossing several
/// cells splits d by the exact areas of its trapezoids. The running sum of a
/// row, left to right, is then each cell's signed area inside the polygon
/// (the accumulation of R. Levien's font-rs, 2016: exact for straight edges).
inline void accumulateEdge(Vec2d a, Vec2d b, int rows, CoverageCells& cells) {
    if (a.y == b.y)
        return;
    double dir = 1.0;
    if (a.y > b.y) {
        std::swap(a, b);
        dir = -1.0;
    }
    const double dxdy = (b.x - a.x) / (b.y - a.y);
    // Signed height per unit of x (used where the edge is not vertical).
    const double D = dir / std::abs(dxdy);
    // x along the edge stays between its ends (rounding cannot leave the cells).
    const double xLo = std::min(a.x, b.x), xHi = std::max(a.x, b.x);
    const auto xAt = [&](double y) {
        return y == b.y ? b.x : std::clamp(a.x + (y - a.y) * dxdy, xLo, xHi);
    };
    int r = std::max(0, static_cast<int>(a.y)); // rows above 0 are not drawn
    const int rowEnd = std::min(rows, b.y > 0 ? ceilNonNegative(b.y) : 0);
    double ya = std::max(a.y, double(r));
    double xa = ya == a.y ? a.x : xAt(ya);
    for (; r < rowEnd; ++r) {
        const double yb = std::min(b.y, double(r + 1));
        const double xb = xAt(yb);
        const double d = (yb - ya) * dir;
        const double lo = std::min(xa, xb), hi = std::max(xa, xb);
        const int i0 = static_cast<int>(lo), i1 = ceilNonNegative(hi);
        double* line = cells.acc.data() + std::size_t(r) * std::size_t(cells.width);
        cells.lo[std::size_t(r)] = std::min(cells.lo[std::size_t(r)], i0);
        cells.hi[std::size_t(r)] = std::max(cells.hi[std::size_t(r)], i1 + 1);
        if (i1 <= i0 + 1) {
            // Within one cell: the part of it left of the piece is its mean x.
            const double m = 0.5 * (xa + xb) - double(i0);
            line[i0] += d - d * m;
            line[i0 + 1] += d * m;
        } else {
            // Across cells i0 ... i1 − 1: in each the piece rises D per unit
            // of x, so the first and last cells take the triangles right of
            // it, the middle ones D each, and the second-to-last the rest
            // (the row's total is exactly d).
            const double f0 = lo - double(i0), f1 = hi - double(i1) + 1.0;
            const double first = 0.5 * D * (1.0 - f0) * (1.0 - f0);
            const double last = 0.5 * D * f1 * f1;
            line[i0] += first;
            double given = first + last;
            if (i1 > i0 + 2) {
                const double second = D * (1.5 - f0) - first;
                line[i0 + 1] += second;
                given += second;
                for (int i = i0 + 2; i < i1 - 1; ++i)
                    line[i] += D;
                given += double(i1 - i0 - 3) * D;
            }
            line[i1 - 1] += d - given;
            line[i1] += last;
        }
        ya = yb;
        xa = xb;
    }
}

bool isConvexQuad(const Vec2d q[4]);

/// Covers one polygon: emit(x, y, area of polygon ∩ pixel) for each pixel of
/// [x0, x1) × [y0, y1) it covers by more than 1e-7 pixel² and wanted(x, y)
/// accepts, row by row, x increasing. The areas are accumulated per edge
/// (accumulateEdge) in double precision relative to the polygon's box, then
/// summed along each row over the cells its edges touched.
template <typename Emit, typename Wanted>
void rasterizePolygon(const Polygon& poly, int x0, int y0, int x1, int y1, CoverageCells& cells,
                      Emit& emit, Wanted& wanted) {
    constexpr double minCoverage = 1e-7;
    if (poly.n < 3)
        return; // clipped away
    double xMin = poly.v[0].x, xMax = xMin, yMin = poly.v[0].y, yMax = yMin;
    for (int k = 1; k < poly.n; ++k) {
        xMin = std::min(xMin, poly.v[k].x);
        xMax = std::max(xMax, poly.v[k].x);
        yMin = std::min(yMin, poly.v[k].y);
        yMax = std::max(yMax, poly.v[k].y);
    }
    const int rowBegin = std::max(y0, static_cast<int>(std::floor(yMin)));
    const int rowEnd = std::min(y1, static_cast<int>(std::ceil(yMax)));
    // Cells from the polygon's left end: those left of x0 carry its area into the sum.
    const int colBase = static_cast<int>(std::floor(xMin));
    if (rowBegin >= rowEnd || std::max(x0, colBase) >= x1)
        return;
    const int rows = rowEnd - rowBegin;
    cells.prepare(rows, static_cast<int>(std::ceil(xMax)) - colBase + 2);
    const Vec2d origin(colBase, rowBegin);
    for (int k = 0; k < poly.n; ++k)
        accumulateEdge(poly.v[k] - origin, poly.v[k + 1 == poly.n ? 0 : k + 1] - origin, rows,
                       cells);
    for (int r = 0; r < rows; ++r) {
        int& lo = cells.lo[std::size_t(r)];
        int& hi = cells.hi[std::size_t(r)];
        double* line = cells.acc.data() + std::size_t(r) * std::size_t(cells.width);
        const int y = rowBegin + r;
        double area = 0;
        for (int i = lo; i < hi; ++i) {
            area += line[i];
            line[i] = 0.0;
            const int x = colBase + i;
            const double coverage = std::abs(area);
            if (x >= x0 && x < x1 && coverage > minCoverage && wanted(x, y))
                emit(x, y, static_cast<float>(std::min(coverage, 1.0)));
        }
        lo = std::numeric_limits<int>::max();
        hi = -1;
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
void rasterizeRibbon(const ScreenRibbon& r, int x0, int y0, int x1, int y1, CoverageCells& cells,
                     Emit&& emit, Wanted&& wanted) {
    const Vec2d q[4] = {r.s0 + r.o0, r.s1 + r.o1, r.s1 - r.o1, r.s0 - r.o0};
    const bool inside =
        r.xMin >= x0 - 1 && r.xMax <= x1 + 1 && r.yMin >= y0 - 1 && r.yMax <= y1 + 1;
    auto cover = [&](const Polygon& p) {
        if (inside)
            rasterizePolygon(p, x0, y0, x1, y1, cells, emit, wanted);
        else
            rasterizePolygon(clipToBox(p, x0 - 1, y0 - 1, x1 + 1, y1 + 1), x0, y0, x1, y1, cells,
                             emit, wanted);
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
