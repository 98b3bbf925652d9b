// hairvox core: the cells of a regular grid that a line crosses, in order
// (Amanatides & Woo 1987, "A Fast Voxel Traversal Algorithm for Ray
// Tracing") — the one traversal used by the splat (segments into voxels and
// bricks) and by the global term's line integrals (bricks, then cells).
//
// Cells are unit cubes: cell c is [c, c + 1]³ in the grid's own coordinates
// (index space; a grid of 8-voxel bricks is traversed with the line scaled by
// 1/8). The line is p(t) = origin + t·dir.
//
// Drift: the parameter at which the line leaves a cell through axis i is
// recomputed from the cell index at every step, t = (c_i + [d_i > 0] − o_i)/d_i,
// rather than accumulated by adding 1/|d_i| per step, so it carries one
// rounding error however long the line is (a float accumulation drifts by
// about one ulp of t per cell crossed: a cell boundary 10⁴ cells away would be
// off by ~1e-3 cell). tests/core/grid_traversal_test.cpp checks this on long
// lines in float.
#pragma once

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <concepts>
#include <limits>

namespace hairvox {

/// A line in grid coordinates with its per-axis inverse direction (0 on an
/// axis the line does not advance along, or too little for 1/d to be finite).
template <std::floating_point T>
struct GridLine {
    using Vec = glm::vec<3, T>;
    Vec origin, dir, invDir;

    GridLine(const Vec& origin_, const Vec& dir_)
        : origin(origin_)
        , dir(dir_) {
        for (int i = 0; i < 3; ++i) {
            const T inv = T(1) / dir[i];
            invDir[i] = std::isfinite(inv) ? inv : T(0);
        }
    }
    Vec at(T t) const { return origin + t * dir; }
};

/// ⌊x⌋ as an int for |x| < 2³¹ (std::floor is a libm call on baseline x86-64).
template <std::floating_point T>
int floorToInt(T x) {
    const auto i = static_cast<int>(x);
    return x < static_cast<T>(i) ? i - 1 : i;
}

/// Calls visit(cell, tEnter, tExit) for every cell the line crosses for
/// t ∈ [t0, t1], in order, skipping pieces of zero length, while visit returns
/// true. The first cell is the one the line enters at t0 (on a cell face, the
/// cell on the side it moves toward). Cells are kept in [cellMin, cellMax]: the
/// walk stops where the line would leave that box (callers clip [t0, t1] to
/// it, so at most a rounding-sized piece is lost). Returns false if visit
/// stopped the walk.
template <std::floating_point T, typename Visit>
bool traverseCells(const GridLine<T>& line, T t0, T t1, const glm::ivec3& cellMin,
                   const glm::ivec3& cellMax, Visit&& visit) {
    constexpr T kInfinity = std::numeric_limits<T>::infinity();
    glm::ivec3 cell, step;
    glm::vec<3, T> tNext;
    const glm::vec<3, T> x0 = line.at(t0);
    for (int i = 0; i < 3; ++i) {
        step[i] = line.invDir[i] > 0 ? 1 : (line.invDir[i] < 0 ? -1 : 0);
        int c = floorToInt(x0[i]);
        if (step[i] < 0 && static_cast<T>(c) == x0[i])
            --c;
        cell[i] = std::clamp(c, cellMin[i], cellMax[i]);
        tNext[i] = step[i] == 0
                       ? kInfinity
                       : (T(cell[i] + (step[i] > 0 ? 1 : 0)) - line.origin[i]) * line.invDir[i];
    }
    T t = t0;
    for (;;) {
        // The axis whose boundary comes first, written to compile without branches.
        const bool xFirst = tNext.x < tNext.y;
        const T tXY = xFirst ? tNext.x : tNext.y;
        const int i = tNext.z < tXY ? 2 : (xFirst ? 0 : 1);
        const T tExit = std::min(tNext[i], t1);
        if (tExit > t) {
            if (!visit(static_cast<const glm::ivec3&>(cell), t, tExit))
                return false;
            t = tExit;
        }
        if (tExit >= t1)
            return true;
        cell[i] += step[i];
        if (cell[i] < cellMin[i] || cell[i] > cellMax[i])
            return true;
        tNext[i] = (T(cell[i] + (step[i] > 0 ? 1 : 0)) - line.origin[i]) * line.invDir[i];
    }
}

} // namespace hairvox
