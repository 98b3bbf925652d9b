// The one cell traversal (core/grid_traversal.h): cells in order, exact at
// faces, and no drift on long lines in float — where accumulating the
// per-axis step (the textbook form, which the brick volume used before) puts
// boundaries in the wrong place.
#include <hairvox/core/enum_names.h>
#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/rng.h>
#include <hairvox/core/vecmath.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace hairvox {
namespace {

struct Piece {
    glm::ivec3 cell;
    double t0, t1;
};

template <typename T>
std::vector<Piece> walk(const glm::vec<3, T>& o, const glm::vec<3, T>& d, T t0, T t1,
                        glm::ivec3 lo = glm::ivec3(-(1 << 24)),
                        glm::ivec3 hi = glm::ivec3(1 << 24)) {
    std::vector<Piece> pieces;
    traverseCells(GridLine<T>(o, d), t0, t1, lo, hi, [&](const glm::ivec3& c, T a, T b) {
        pieces.push_back({c, double(a), double(b)});
        return true;
    });
    return pieces;
}

TEST(GridTraversal, AxisAlignedLineVisitsEachCellOnce) {
    const auto p = walk<double>({0.5, 0.25, 3.75}, {1, 0, 0}, 0.0, 4.0);
    ASSERT_EQ(p.size(), 5u); // x from 0.5 to 4.5: cells 0..4
    for (int i = 0; i < 5; ++i) {
        EXPECT_EQ(p[std::size_t(i)].cell, glm::ivec3(i, 0, 3));
        EXPECT_DOUBLE_EQ(p[std::size_t(i)].t0, i == 0 ? 0.0 : double(i) - 0.5);
    }
    EXPECT_DOUBLE_EQ(p.back().t1, 4.0);
}

TEST(GridTraversal, StartsInTheCellItEntersOnAFace) {
    // On the face x = 2 moving −x: the first cell is 1, not 2 (no zero-length piece).
    const auto p = walk<float>({2.0f, 0.5f, 0.5f}, {-1.0f, 0.0f, 0.0f}, 0.0f, 1.5f);
    ASSERT_EQ(p.size(), 2u);
    EXPECT_EQ(p[0].cell, glm::ivec3(1, 0, 0));
    EXPECT_EQ(p[1].cell, glm::ivec3(0, 0, 0));
    // Moving +x from the same face: cell 2.
    EXPECT_EQ(walk<float>({2.0f, 0.5f, 0.5f}, {1.0f, 0.0f, 0.0f}, 0.0f, 0.5f)[0].cell,
              glm::ivec3(2, 0, 0));
}

TEST(GridTraversal, StopsWhenAskedAndAtTheBox) {
    int visited = 0;
    const bool finished = traverseCells(
        GridLine<float>({0.5f, 0.5f, 0.5f}, {1.0f, 0.0f, 0.0f}), 0.0f, 100.0f, glm::ivec3(0),
        glm::ivec3(1000), [&](const glm::ivec3&, float, float) { return ++visited < 3; });
    EXPECT_FALSE(finished);
    EXPECT_EQ(visited, 3);
    const auto p = walk<float>({0.5f, 0.5f, 0.5f}, {1.0f, 0.0f, 0.0f}, 0.0f, 100.0f, glm::ivec3(0),
                               glm::ivec3(9, 0, 0));
    EXPECT_EQ(p.size(), 10u); // cells 0..9, then the box ends the walk
}

/// Checks a walk against exact (double) geometry: pieces tile [t0, t1] in
/// order, consecutive cells step forward along the line (a step on two axes
/// at once where the line passes a cell edge closer than float resolves), and
/// each piece's midpoint lies in its cell. Returns the number of misplaced pieces.
int misplacedPieces(const std::vector<Piece>& pieces, const Vec3d& o, const Vec3d& d, double t0,
                    double t1) {
    int bad = 0;
    double t = t0;
    for (std::size_t i = 0; i < pieces.size(); ++i) {
        const Piece& p = pieces[i];
        EXPECT_NEAR(p.t0, t, 1e-9 * std::max(1.0, std::abs(t)));
        t = p.t1;
        if (i > 0)
            for (int a = 0; a < 3; ++a) {
                const int step = p.cell[a] - pieces[i - 1].cell[a];
                EXPECT_TRUE(step == 0 || step == (d[a] > 0 ? 1 : -1)) << i << " axis " << a;
            }
        const Vec3d mid = o + 0.5 * (p.t0 + p.t1) * d;
        // A boundary computed in float is off by up to about one ulp of t
        // (1.2e-7·t): a piece shorter than a few ulps cannot be placed by any
        // float traversal; judge the ones that can.
        if (p.t1 - p.t0 > 1e-6 * std::max(1.0, p.t1) &&
            glm::ivec3(int(std::floor(mid.x)), int(std::floor(mid.y)), int(std::floor(mid.z))) !=
                p.cell)
            ++bad;
    }
    EXPECT_NEAR(t, t1, 1e-9 * t1);
    return bad;
}

TEST(GridTraversal, NoDriftOnLongLinesInFloat) {
    Pcg32 rng(3);
    for (int trial = 0; trial < 20; ++trial) {
        // Directions with exactly representable float components, 20,000
        // cells long: the float walk is compared with exact double geometry.
        const Vec3f d =
            glm::normalize(Vec3f(0.9f + 0.1f * rng.uniformFloat(),
                                 0.3f * rng.uniformFloat() - 0.15f, 0.5f * rng.uniformFloat()));
        const Vec3f o(100.0f * rng.uniformFloat(), 100.0f * rng.uniformFloat(),
                      100.0f * rng.uniformFloat());
        const float length = 20000.0f;
        const auto pieces = walk<float>(o, d, 0.0f, length);
        const int bad = misplacedPieces(pieces, Vec3d(o), Vec3d(d), 0.0, double(length));
        EXPECT_EQ(bad, 0) << "trial " << trial << ": " << bad << " of " << pieces.size();
        // The walk ends in the cell of the line's end (no cell skipped on the way:
        // every step moves one cell forward on each axis it changes).
        const Vec3d end = Vec3d(o) + double(length) * Vec3d(d);
        EXPECT_EQ(pieces.back().cell, glm::ivec3(int(std::floor(end.x)), int(std::floor(end.y)),
                                                 int(std::floor(end.z))))
            << trial;
    }
}

// The textbook form — tNext += 1/|d| per step — on the same lines, as a
// witness that the test above can fail: accumulated in float it misplaces
// boundaries thousands of cells out.
TEST(GridTraversal, AccumulatedStepsDriftWhereTheOneTraversalDoesNot) {
    const Vec3f d = glm::normalize(Vec3f(1.0f, 0.37f, 0.11f));
    const Vec3f o(0.3f, 0.6f, 0.2f);
    std::vector<Piece> drifting;
    {
        glm::ivec3 cell(0), step(1);
        Vec3f tNext, tDelta;
        for (int a = 0; a < 3; ++a) {
            tDelta[a] = 1.0f / d[a];
            tNext[a] = (1.0f - o[a]) / d[a];
        }
        float t = 0;
        while (t < 20000.0f) {
            const int a =
                tNext.x <= tNext.y ? (tNext.x <= tNext.z ? 0 : 2) : (tNext.y <= tNext.z ? 1 : 2);
            const float e = std::min(tNext[a], 20000.0f);
            drifting.push_back({cell, double(t), double(e)});
            t = e;
            cell[a] += step[a];
            tNext[a] += tDelta[a];
        }
    }
    EXPECT_GT(misplacedPieces(drifting, Vec3d(o), Vec3d(d), 0.0, 20000.0), 0);
    EXPECT_EQ(misplacedPieces(walk<float>(o, d, 0.0f, 20000.0f), Vec3d(o), Vec3d(d), 0.0, 20000.0),
              0);
}

enum class Colour { Red, Green };
constexpr EnumNames<Colour, 2> kColourNames{{{{Colour::Red, "red"}, {Colour::Green, "green"}}}};

TEST(EnumNames, NamesParseAndListInTableOrder) {
    EXPECT_STREQ(kColourNames.name(Colour::Green), "green");
    EXPECT_EQ(kColourNames.parse("red"), Colour::Red);
    EXPECT_FALSE(kColourNames.parse("Red"));
    EXPECT_FALSE(kColourNames.parse(""));
    EXPECT_EQ(kColourNames.names(), (std::vector<std::string>{"red", "green"}));
    static_assert(kColourNames.parse("green") == Colour::Green); // usable at compile time
}

} // namespace
} // namespace hairvox
