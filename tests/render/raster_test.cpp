#include "../../render/src/ribbon.h"
#include "film/film_bytes.h"
#include "render/test_shaders.h"

#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/render/rasterizer.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <span>

namespace hairvox {
namespace {

using test::addStraightStrand;
using Vec2d = glm::dvec2;
using test::testCamera;
using test::testSettings;

double sum(std::span<const float> v) {
    return std::accumulate(v.begin(), v.end(), 0.0,
                           [](double a, float b) { return a + double(b); });
}

std::vector<float> alpha(const Film& f) {
    return f.layer(Film::kAlpha).dense();
}
std::vector<float> hairAlpha(const Film& f) {
    return f.layer(kHairAlphaLayer).dense();
}
std::vector<float> depth(const Film& f) {
    return f.layer(kDepthLayer).dense();
}
Rgb rgb(const Film& f, std::string_view layer, std::size_t p) {
    return f.layer(layer).rgb(p);
}

/// Focal length in pixels of a testScene camera of the given height and fov.
double focalPixels(int height, double fovDegrees) {
    return 0.5 * height / std::tan(0.5 * fovDegrees * Pi / 180.0);
}

/// The image area, in pixels, of the ray-facing ribbon along a → b whose
/// width runs linearly from Da at a to Db at b, seen by a pinhole at `eye`
/// looking down −z with focal length f pixels, built independently of the
/// rasterizer: the exact images of the ribbon's edges
/// p ± (D/2)·(ω × u)/|ω × u|, ω the line of sight, over 4096 sub-segments
/// (shoelace). On the optical axis it is D·f × L·f for a width D; off it the
/// pinhole stretches the width radially by 1/cos of the angle to the axis.
double rayFacingRibbonArea(const Vec3d& eye, double f, const Vec3f& a, const Vec3f& b, double Da,
                           double Db) {
    const Vec3d u = glm::normalize(Vec3d(b - a));
    const auto image = [&](const Vec3d& q) {
        const Vec3d d = q - eye;
        return Vec2d(d.x, d.y) * (f / -d.z);
    };
    const auto edges = [&](double t) {
        const Vec3d p = glm::mix(Vec3d(a), Vec3d(b), t);
        const Vec3d w = 0.5 * glm::mix(Da, Db, t) * glm::normalize(glm::cross(p - eye, u));
        return std::pair{image(p + w), image(p - w)};
    };
    double area = 0;
    constexpr int kSteps = 4096;
    for (int i = 0; i < kSteps; ++i) {
        const auto [l0, r0] = edges(double(i) / kSteps);
        const auto [l1, r1] = edges(double(i + 1) / kSteps);
        const Vec2d d0 = r1 - l0, d1 = l1 - r0; // the quad's diagonals
        area += 0.5 * std::abs(d0.x * d1.y - d0.y * d1.x);
    }
    return area;
}

// Camera at z = 1 looking down −z: a fiber in the plane z = 0 is a rectangle
// of D·f × L·f pixels, widened off the axis (rayFacingRibbonArea()).
TEST(RasterCoverage, ThinFiberCoversWidthTimesLength) {
    const int size = 256;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    const RasterSettings settings = testSettings(5e-4f); // 0.24 pixel
    const double f = focalPixels(size, 30.0);
    for (int segments : {1, 7}) {
        SCOPED_TRACE(segments);
        Groom groom;
        const Vec3f a(-0.1013f, -0.0571f, 0.0f), b(0.0877f, 0.0719f, 0.0f);
        addStraightStrand(groom, a, b, segments);
        const test::ConstantShader shader;
        const RasterOutput out = rasterize(groom, camera, shader, settings);
        const double expected =
            rayFacingRibbonArea(Vec3d(0, 0, 1), f, a, b, double(settings.fiberScale.diameter),
                                double(settings.fiberScale.diameter));
        // Within 1e-4 of the axis-on rectangle here.
        EXPECT_NEAR(expected,
                    double(settings.fiberScale.diameter) * f * double(glm::distance(a, b)) * f,
                    1e-4 * expected);
        // Adjacent segments add their coverage: the strand counts once.
        EXPECT_NEAR(sum(alpha(out.film)), expected, 1e-6 * expected);
        EXPECT_NEAR(sum(hairAlpha(out.film)), expected, 1e-6 * expected);
        EXPECT_GT(out.stats.fragments, std::uint64_t(double(glm::distance(a, b)) * f));
        for (float x : alpha(out.film))
            ASSERT_LE(x, 0.35f); // sub-pixel width: at most width · √2 per pixel
    }
}

TEST(RasterCoverage, PerPointDiameterSetsTheWidth) {
    // The groom's per-point diameters D_i replace D (ribbonWidthAt()), linear
    // along each segment: a strand twice as thick covers twice the area, one
    // tapering from D to 0 the area of that trapezoid.
    const int size = 256;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    const RasterSettings settings = testSettings(5e-4f); // 0.24 pixel
    const float D = settings.fiberScale.diameter;
    const double f = focalPixels(size, 30.0);
    const Vec3f a(-0.1013f, -0.0571f, 0.0f), b(0.0877f, 0.0719f, 0.0f);
    constexpr int kSegments = 7;
    Groom plain;
    addStraightStrand(plain, a, b, kSegments);
    const test::ConstantShader shader;
    const auto render = [&](std::vector<float> thickness, const RasterSettings& s) {
        Groom groom = plain;
        groom.thickness = std::move(thickness);
        return rasterize(groom, camera, shader, s).film;
    };
    const Film one = render({}, settings);
    // D_i = D everywhere: the same bytes as no per-point diameters.
    EXPECT_TRUE(alpha(render(std::vector<float>(kSegments + 1, D), settings)) == alpha(one));
    // k·D_i: D_i = D with k = 3 is the film of diameter 3·D.
    RasterSettings k3 = settings, thick3 = settings;
    k3.fiberScale.densityMultiplier = 3.0f;
    thick3.fiberScale.diameter *= 3.0f;
    EXPECT_TRUE(alpha(render(std::vector<float>(kSegments + 1, D), k3)) ==
                alpha(render({}, thick3)));

    const double sumOne = sum(alpha(one));
    const double twice = sum(alpha(render(std::vector<float>(kSegments + 1, 2 * D), settings)));
    const double expectedTwice =
        rayFacingRibbonArea(Vec3d(0, 0, 1), f, a, b, 2.0 * double(D), 2.0 * double(D));
    EXPECT_NEAR(twice, expectedTwice, 1e-6 * expectedTwice);
    EXPECT_NEAR(twice / sumOne, 2.0, 1e-4);

    std::vector<float> taper;
    for (int k = 0; k <= kSegments; ++k)
        taper.push_back(D * float(kSegments - k) / float(kSegments));
    const Film tapered = render(taper, settings);
    const double expectedTaper = rayFacingRibbonArea(Vec3d(0, 0, 1), f, a, b, double(D), 0.0);
    EXPECT_NEAR(sum(alpha(tapered)), expectedTaper, 1e-6 * expectedTaper);
    EXPECT_NEAR(sum(alpha(tapered)) / sumOne, 0.5, 1e-3);
    // Near the tip the ribbon is thin: the pixel on the centreline a tenth of
    // the length from the tip (a pixel spans ~2% of it) is covered about a
    // tenth as much as on the plain strand.
    const Vec2f nearTip = camera.toRaster(camera.toCamera(a + 0.9f * (b - a)));
    const std::size_t p = one.index(int(nearTip.x), int(nearTip.y));
    ASSERT_GT(alpha(one)[p], 0.05f);
    EXPECT_NEAR(alpha(tapered)[p] / alpha(one)[p], 0.1f, 0.03f);
}

TEST(RasterCoverage, NearPlaneClipInterpolatesTheWidth) {
    // A tapered segment through the near plane is clipped in 3D, its width at
    // the clip point interpolated: the film of the same strand starting just
    // in front of the near plane, with the width there.
    const int size = 64;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    const RasterSettings settings = testSettings(1e-5f);
    const Vec3f p0(0.001f, 0.0005f, 1.5f), p1(0.05f, 0.02f, -0.5f);
    const float d0 = 4e-5f, d1 = 1e-5f;
    // Depth 1 − z = 1.0005 × the near plane's (camera at z = 1 looking down −z).
    const float t = (1.5f - (1.0f - 1.0005f * camera.nearClip())) / 2.0f;
    const test::ConstantShader shader;
    Groom clipped, inFront;
    const Vec3f whole[2] = {p0, p1}, part[2] = {p0 + t * (p1 - p0), p1};
    clipped.addStrand(whole);
    clipped.thickness = {d0, d1};
    inFront.addStrand(part);
    inFront.thickness = {d0 + t * (d1 - d0), d1};
    const RasterOutput c = rasterize(clipped, camera, shader, settings);
    const RasterOutput n = rasterize(inFront, camera, shader, settings);
    EXPECT_EQ(c.stats.segmentsOutsideView, 0u);
    const double expected = sum(alpha(n.film));
    EXPECT_GT(expected, 1.0);
    EXPECT_NEAR(sum(alpha(c.film)), expected, 2e-3 * expected);
}

TEST(RasterCoverage, WideRibbonGivesTheExactQuadArea) {
    const int size = 128;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    const RasterSettings settings = testSettings(0.0137f); // 6.5 pixels
    const double f = focalPixels(size, 30.0);
    Groom groom;
    const Vec3f a(-0.0731f, -0.0322f, 0.0f), b(0.0655f, 0.0491f, 0.0f);
    addStraightStrand(groom, a, b, 1);
    const test::ConstantShader shader;
    const RasterOutput out = rasterize(groom, camera, shader, settings);
    const double expected =
        rayFacingRibbonArea(Vec3d(0, 0, 1), f, a, b, double(settings.fiberScale.diameter),
                            double(settings.fiberScale.diameter));
    EXPECT_NEAR(sum(alpha(out.film)), expected, 1e-6 * expected);
    // The pixel at the ribbon's middle is wholly covered.
    const Vec2f mid = camera.toRaster(camera.toCamera(0.5f * (a + b)));
    const std::size_t p = out.film.index(int(mid.x), int(mid.y));
    EXPECT_NEAR(alpha(out.film)[p], 1.0f, 1e-5f);
    // And each radiance layer is the shader's value there.
    EXPECT_NEAR(rgb(out.film, "r0", p).r, test::ConstantShader::kR0[0], 1e-5f);
    EXPECT_NEAR(rgb(out.film, "r1", p).g, test::ConstantShader::kR1[1], 1e-5f);
}

/// The area of the convex polygon `poly` inside the pixel [x, x+1] × [y, y+1]:
/// the polygon clipped by the four sides (Sutherland–Hodgman), then its
/// shoelace area. The rasterizer accumulates signed areas instead.
double areaInPixel(std::vector<Vec2d> poly, int x, int y) {
    auto clipTo = [&](int axis, double c, bool below) {
        std::vector<Vec2d> out;
        for (std::size_t k = 0; k < poly.size(); ++k) {
            const Vec2d a = poly[k], b = poly[(k + 1) % poly.size()];
            const bool aIn = below ? a[axis] <= c : a[axis] >= c;
            const bool bIn = below ? b[axis] <= c : b[axis] >= c;
            if (aIn)
                out.push_back(a);
            if (aIn != bIn)
                out.push_back(a + (c - a[axis]) / (b[axis] - a[axis]) * (b - a));
        }
        poly = out;
    };
    clipTo(0, x, false);
    clipTo(0, x + 1, true);
    clipTo(1, y, false);
    clipTo(1, y + 1, true);
    double twice = 0;
    for (std::size_t k = 0; k < poly.size(); ++k) {
        const Vec2d a = poly[k], b = poly[(k + 1) % poly.size()];
        twice += a.x * b.y - b.x * a.y;
    }
    return 0.5 * std::abs(twice);
}

// A fiber in the plane z = 0 on a line through the optical axis is, seen
// from z = 1, a rectangle of width D·f exactly (the ray-facing direction
// ω × u is the same along it): each pixel's coverage must be that
// rectangle's area in the pixel, across tile borders, at any angle, for
// ribbons thinner and wider than a pixel.
TEST(RasterCoverage, EachPixelGetsTheAreaOfRibbonAndPixel) {
    const int size = 100; // 4 × 4 tiles, the last ones partial
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    const double f = focalPixels(size, 30.0);
    const test::ConstantShader shader;
    int compared = 0;
    for (const auto& [degrees, t0, t1, diameter] :
         {std::tuple{0.0, -0.21, 0.17, 0.0031}, std::tuple{90.0, 0.013, 0.3, 0.0008},
          std::tuple{17.3, -0.3, 0.24, 0.0004}, std::tuple{41.0, -0.08, 0.31, 0.0113},
          std::tuple{63.7, -0.27, -0.02, 0.0021}, std::tuple{128.9, -0.19, 0.22, 0.0057},
          std::tuple{-71.2, 0.02, 0.29, 0.0015}}) {
        SCOPED_TRACE(testing::Message() << degrees << "°, D = " << diameter);
        const double angle = degrees * Pi / 180.0;
        const Vec3f u(float(std::cos(angle)), float(std::sin(angle)), 0.0f);
        const Vec3f a = float(t0) * u, b = float(t1) * u;
        Groom groom;
        addStraightStrand(groom, a, b, 1);
        const RasterOutput out =
            rasterize(groom, camera, shader, testSettings(float(diameter)));
        const auto raster = [&](const Vec3f& p) { return Vec2d(camera.toRaster(camera.toCamera(p))); };
        const Vec2d s0 = raster(a), s1 = raster(b);
        const Vec2d along = glm::normalize(s1 - s0);
        const Vec2d o = Vec2d(-along.y, along.x) * (0.5 * diameter * f);
        const std::vector<Vec2d> quad = {s0 + o, s1 + o, s1 - o, s0 - o};
        double worst = 0;
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const double expected = std::min(areaInPixel(quad, x, y), 1.0);
                const double got = alpha(out.film)[out.film.index(x, y)];
                worst = std::max(worst, std::abs(got - expected));
                compared += expected > 0 ? 1 : 0;
            }
        // The corners come from float projections: ~1e-5 pixel.
        EXPECT_LT(worst, 1e-4);
    }
    EXPECT_GT(compared, 900);
}

// The accumulation itself (raster::rasterizePolygon), on polygons no ribbon
// test reaches: random convex triangles and quads, from a hundredth of a
// pixel to wider than the tile, partly outside it on every side (clipped to
// it: up to 8 vertices), near horizontal and vertical edges, at large raster
// coordinates; and one scratch kept from polygon to polygon, as a tile keeps it.
TEST(RasterCoverage, AccumulatedAreasAreTheClippedAreasOfEachPixel) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    raster::CoverageCells cells;
    double worst = 0;
    int emitted = 0;
    for (int trial = 0; trial < 400; ++trial) {
        const int x0 = 32 * (trial % 7) + (trial % 3 == 0 ? 4064 : 0), y0 = 32 * (trial % 5);
        const int x1 = x0 + 32, y1 = y0 + 32;
        const double scale = std::pow(10.0, -2.0 + 3.7 * unit(rng)); // 0.01 to 50 pixels
        const Vec2d centre(x0 - 4 + 40 * unit(rng), y0 - 4 + 40 * unit(rng));
        // A convex polygon: points on an ellipse at sorted angles, flattened
        // to near-horizontal or near-vertical edges now and then.
        const int n = 3 + trial % 2; // clipToBox() below adds up to 4 vertices
        std::vector<double> angles(std::size_t(n), 0.0);
        for (double& a : angles)
            a = 2 * Pi * unit(rng);
        std::sort(angles.begin(), angles.end());
        const double squash = trial % 4 == 1 ? 1e-3 : 1.0;
        raster::Polygon poly;
        poly.n = n;
        std::vector<Vec2d> points;
        for (int k = 0; k < n; ++k) {
            const double a = angles[std::size_t(k)];
            Vec2d p = centre + scale * Vec2d(std::cos(a), squash * std::sin(a));
            if (trial % 8 == 3) { // transposed: near vertical
                std::swap(p.x, p.y);
                p += Vec2d(x0 - y0, y0 - x0);
            }
            poly.v[k] = p;
            points.push_back(p);
        }
        // What the tile's clip to its box ± 1 gives rasterizeRibbon.
        const raster::Polygon clipped = raster::clipToBox(poly, x0 - 1, y0 - 1, x1 + 1, y1 + 1);
        std::vector<double> got(32 * 32, 0.0);
        auto emit = [&](int x, int y, float coverage) {
            ASSERT_TRUE(x >= x0 && x < x1 && y >= y0 && y < y1);
            got[std::size_t((y - y0) * 32 + (x - x0))] += double(coverage);
            ++emitted;
        };
        auto wanted = [](int, int) {
            return true;
        };
        raster::rasterizePolygon(clipped, x0, y0, x1, y1, cells, emit, wanted);
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                const double expected = std::min(areaInPixel(points, x, y), 1.0);
                const double g = got[std::size_t((y - y0) * 32 + (x - x0))];
                // Below 1e-7 pixel² nothing is emitted; floats round at ~6e-8.
                worst = std::max(worst, std::abs(g - expected));
                if (expected > 2e-7) {
                    EXPECT_NEAR(g, expected, 1e-6)
                        << "trial " << trial << " pixel " << x << "," << y;
                }
            }
    }
    EXPECT_LT(worst, 1e-6);
    EXPECT_GT(emitted, 5000);
    // Every cell went back to 0 after its polygon.
    for (double c : cells.acc)
        ASSERT_EQ(c, 0.0);
}

TEST(RasterCoverage, FiberLeavingTheImageIsClippedNotLost) {
    const int size = 64;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    Groom groom;
    addStraightStrand(groom, Vec3f(-1, 0.01f, 0), Vec3f(1, 0.01f, 0),
                      10);                                          // far wider than the view
    addStraightStrand(groom, Vec3f(0, 0, 2), Vec3f(0.1f, 0, 3), 2); // behind the camera
    const test::ConstantShader shader;
    const RasterOutput out = rasterize(groom, camera, shader, testSettings(1e-3f));
    const double f = focalPixels(size, 30.0);
    EXPECT_NEAR(sum(alpha(out.film)), 1e-3 * f * size, 1e-3 * 1e-3 * f * size);
    EXPECT_EQ(out.stats.segmentsOutsideView, 6u + 2u); // 3 + 3 off-screen pieces, 2 behind
}

/// Two wide ribbons crossing at right angles, strand 0 at z = zFirst, strand 1 at z = zSecond.
Groom crossingRibbons(float zFirst, float zSecond) {
    Groom g;
    addStraightStrand(g, Vec3f(-0.1f, 0.003f, zFirst), Vec3f(0.1f, 0.003f, zFirst), 3);
    addStraightStrand(g, Vec3f(0.002f, -0.1f, zSecond), Vec3f(0.002f, 0.1f, zSecond), 3);
    return g;
}

TEST(RasterCompositing, FrontToBackWithEarlyTermination) {
    const int size = 96;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    const RasterSettings settings = testSettings(0.05f); // 9 pixels in front, 6 behind
    const test::StrandColorShader shader;
    const int c = size / 2;
    for (const bool redInFront : {true, false}) {
        SCOPED_TRACE(redInFront);
        const Groom groom =
            redInFront ? crossingRibbons(0.0f, -0.5f) : crossingRibbons(-0.5f, 0.0f);
        const RasterOutput out = rasterize(groom, camera, shader, settings);
        const Rgb centre = out.film.beauty(out.film.index(c, c));
        EXPECT_NEAR(alpha(out.film)[out.film.index(c, c)], 1.0f, 1e-5f);
        EXPECT_NEAR(redInFront ? centre.r : centre.g, 1.0f, 1e-5f);
        EXPECT_EQ(redInFront ? centre.g : centre.r, 0.0f); // the back ribbon was never shaded here
        // Every fragment is either composited — and shaded once, or seen
        // through less than the tail transmittance (behind the front ribbon's
        // nearly covered edge pixels) and interpolated from its vertices — or
        // skipped.
        const RasterStats& st = out.stats;
        EXPECT_EQ(st.fragments, st.fragmentsComposited + st.fragmentsBehindOpaque);
        EXPECT_EQ(st.shadingPoints, st.fragmentsComposited - st.tailFragments + st.tailVertices);
        EXPECT_EQ(st.fragmentsInterpolated, st.tailFragments);
        // The back ribbon's fragments inside the front one: about 8 × 6 pixels.
        EXPECT_GE(st.fragmentsBehindOpaque, 35u);
        EXPECT_LE(st.fragmentsBehindOpaque, 70u);
    }
}

TEST(RasterCompositing, PartialCoverageCompositesOverTheBackground) {
    // Thin ribbons over a background B: per pixel, against each ribbon's
    // coverage rendered alone (a_f, a_b), the beauty must be
    //   a_f·red + (1 − a_f)·a_b·green + (1 − a_f)(1 − a_b)·B
    // — the compositing equation, computed here from the single-ribbon alphas,
    // not from the film's own layers.
    const int size = 64;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    RasterSettings settings = testSettings(1.5e-3f);
    settings.opaqueTransmittance = 0.0f;
    settings.background = Rgb(0.1f, 0.2f, 0.4f);
    const test::StrandColorShader shader;
    const Groom both = crossingRibbons(0.0f, -0.3f);
    Groom front, back;
    front.addStrand(both.strand(0));
    back.addStrand(both.strand(1));
    const Film fb = rasterize(both, camera, shader, settings).film;
    const Film ff = rasterize(front, camera, shader, settings).film;
    const Film fk = rasterize(back, camera, shader, settings).film;
    int overlapping = 0;
    for (std::size_t p = 0; p < fb.pixelCount(); ++p) {
        const float af = alpha(ff)[p], ab = alpha(fk)[p];
        overlapping += af > 0 && ab > 0 ? 1 : 0;
        const Rgb expected =
            Rgb(af, (1 - af) * ab, 0.0f) + (1 - af) * (1 - ab) * settings.background;
        const Rgb beauty = fb.beauty(p);
        for (int ch = 0; ch < 3; ++ch)
            ASSERT_NEAR(beauty[ch], expected[ch], 1e-6f) << "pixel " << p << " channel " << ch;
        EXPECT_NEAR(alpha(fb)[p], af + (1 - af) * ab, 1e-6f);
    }
    EXPECT_GE(overlapping, 1);
}

TEST(RasterCompositing, DensityMultiplierWidensTheRibbon) {
    // A strand standing for k hairs is the ribbon k·D wide that rays meet:
    // the same film as one hair of diameter k·D.
    const int size = 64;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    RasterSettings settings = testSettings(1e-3f); // 0.1 pixel: k = 3.5 stays below one
    Groom groom;
    addStraightStrand(groom, Vec3f(-0.1f, -0.0437f, 0.0f), Vec3f(0.1f, 0.0618f, 0.0f), 1);
    const test::ConstantShader shader;
    const Film one = rasterize(groom, camera, shader, settings).film;
    settings.fiberScale.densityMultiplier = 3.5f;
    const Film many = rasterize(groom, camera, shader, settings).film;
    settings.fiberScale.densityMultiplier = 1.0f;
    settings.fiberScale.diameter *= 3.5f;
    const Film thick = rasterize(groom, camera, shader, settings).film;
    double sumOne = 0, sumMany = 0;
    for (std::size_t p = 0; p < one.pixelCount(); ++p) {
        EXPECT_EQ(alpha(many)[p], alpha(thick)[p]) << "pixel " << p;
        EXPECT_EQ(rgb(many, "r0", p).r, rgb(thick, "r0", p).r) << "pixel " << p;
        sumOne += double(alpha(one)[p]);
        sumMany += double(alpha(many)[p]);
    }
    EXPECT_NEAR(sumMany / sumOne, 3.5, 0.01); // no pixel is covered twice
}

TEST(RasterCoverage, StrandsThroughTheNearPlaneAreClipped) {
    // The camera inside the hair: segments cross the near plane (1 mm here).
    const int size = 64;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    Groom groom;
    addStraightStrand(groom, Vec3f(0.001f, 0.0005f, 1.5f), Vec3f(0.05f, 0.02f, -0.5f), 4);
    addStraightStrand(groom, Vec3f(-0.02f, 0.01f, 0.9995f), Vec3f(0.02f, 0.01f, 0.9995f), 3);
    const test::ConstantShader shader;
    const RasterOutput out = rasterize(groom, camera, shader, testSettings(1e-4f));
    for (std::size_t p = 0; p < out.film.pixelCount(); ++p) {
        ASSERT_TRUE(out.film.beauty(p).isFinite());
        ASSERT_GE(depth(out.film)[p], 0.0f);
    }
    EXPECT_GT(out.stats.fragmentsComposited, 0u);
    EXPECT_GE(out.stats.segmentsOutsideView, 3u); // the second strand and the part behind
}

TEST(RasterCoverage, AbsurdCoordinatesAreSafe) {
    const int size = 32;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    Groom groom;
    addStraightStrand(groom, Vec3f(-3e38f, 0, 0), Vec3f(3e38f, 1e-3f, 0), 2); // overflows
    addStraightStrand(groom, Vec3f(-1e12f, 0, 0), Vec3f(1e12f, 0.01f, 0), 1); // vast but finite
    addStraightStrand(groom, Vec3f(0, 0, 0.5f), Vec3f(1e-7f, 0, 0.5f), 1);    // tiny
    const test::ConstantShader shader;
    const RasterOutput out = rasterize(groom, camera, shader, testSettings(7e-5f));
    for (std::size_t p = 0; p < out.film.pixelCount(); ++p)
        ASSERT_TRUE(out.film.beauty(p).isFinite() && std::isfinite(depth(out.film)[p]));
    EXPECT_GT(out.stats.fragmentsComposited, 0u); // the vast strand crosses the view
}

/// A surface layer: a disc of radius r pixels around the image centre at
/// `depthValue`, coverage 1 inside, radiance `radiance`.
SurfaceLayer discSurface(const Camera& camera, float r, float depthValue, const Rgb& radiance) {
    SurfaceLayer s;
    const std::size_t pixels = std::size_t(camera.width()) * std::size_t(camera.height());
    s.coverage.assign(pixels, 0.0f);
    s.depth.assign(pixels, 0.0f);
    s.radiance = LargeBuffer<Rgb>(pixels, Rgb(0.0f));
    for (int y = 0; y < camera.height(); ++y)
        for (int x = 0; x < camera.width(); ++x) {
            const float dx = float(x) + 0.5f - 0.5f * float(camera.width());
            const float dy = float(y) + 0.5f - 0.5f * float(camera.height());
            if (dx * dx + dy * dy < r * r) {
                const std::size_t p = std::size_t(y) * std::size_t(camera.width()) + std::size_t(x);
                s.coverage[p] = 1.0f;
                s.depth[p] = depthValue;
                s.radiance[p] = radiance;
            }
        }
    return s;
}

TEST(RasterSurfaces, HideHairBehindThemAndAreComposited) {
    const int size = 128;
    const Camera camera = testCamera(size, size, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    const RasterSettings settings = testSettings(2e-3f);
    const Rgb surfaceRadiance(0.3f, 0.2f, 0.1f);
    const SurfaceLayer disc = discSurface(camera, 50.0f, 0.9f, surfaceRadiance);
    const test::ConstantShader shader;
    // A short strand wholly behind the disc: culled before rasterization.
    Groom hidden;
    addStraightStrand(hidden, Vec3f(-0.02f, 0.01f, -0.3f), Vec3f(0.02f, 0.01f, -0.3f), 4);
    const RasterOutput h = rasterize(hidden, camera, shader, settings, disc);
    EXPECT_GE(h.stats.segmentTilesBehindSurfaces, 4u);
    EXPECT_EQ(h.stats.fragments, 0u);
    EXPECT_EQ(sum(hairAlpha(h.film)), 0.0);
    const std::size_t c = h.film.index(size / 2, size / 2);
    EXPECT_EQ(h.film.layer(kSurfaceLayer).rgb(c), surfaceRadiance);
    EXPECT_EQ(h.film.beauty(c), surfaceRadiance);
    EXPECT_EQ(alpha(h.film)[c], 1.0f);
    EXPECT_EQ(depth(h.film)[c], 0.9f);

    // A strand across the whole view behind the disc: visible only outside it.
    Groom across;
    addStraightStrand(across, Vec3f(-0.4f, 0.0f, -0.3f), Vec3f(0.4f, 0.0f, -0.3f), 40);
    const RasterOutput out = rasterize(across, camera, shader, settings, disc);
    const int y = size / 2;
    for (int x = 0; x < size; ++x) {
        const float r = std::abs(float(x) + 0.5f - float(size) / 2);
        const std::size_t p = out.film.index(x, y);
        if (r < 49.0f) {
            EXPECT_EQ(hairAlpha(out.film)[p], 0.0f) << x;
        } else if (r > 51.0f) {
            EXPECT_GT(hairAlpha(out.film)[p], 0.0f) << x;
        }
    }
    // The same strand in front of the disc covers it.
    Groom inFront;
    addStraightStrand(inFront, Vec3f(-0.4f, 0.0f, 0.5f), Vec3f(0.4f, 0.0f, 0.5f), 40);
    const RasterOutput front = rasterize(inFront, camera, shader, settings, disc);
    EXPECT_GT(hairAlpha(front.film)[front.film.index(size / 2, y)], 0.0f);
    EXPECT_EQ(front.stats.segmentTilesBehindSurfaces, 0u);
}

TEST(RasterSurfaces, WrongSizeIsAnInputError) {
    const Camera camera = testCamera(16, 16, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    SurfaceLayer bad;
    bad.coverage.assign(10, 1.0f);
    bad.depth.assign(10, 1.0f);
    bad.radiance = LargeBuffer<Rgb>(10, Rgb(1.0f));
    const test::ConstantShader shader;
    EXPECT_THROW(rasterize(Groom{}, camera, shader, testSettings(1e-3f), bad), InputError);
}

Camera groomCamera(std::uint32_t size) {
    return testCamera(size, size, Vec3f(0.45f, 0.05f, -0.6f), Vec3f(0.0f, -0.1f, -0.05f));
}

Groom smallGroom(std::uint32_t strands) {
    ProceduralGroomParams p;
    p.strands = strands;
    return generateGroom(p);
}

TEST(RasterDeterminism, SameBytesForAnyThreadCount) {
    const Groom groom = smallGroom(1500);
    const Camera camera = groomCamera(160);
    const test::SmoothShader shader(2);
    for (const ShadingRate rate :
         {ShadingRate::Fragment, ShadingRate::Vertex, ShadingRate::Adaptive}) {
        SCOPED_TRACE(toString(rate));
        RasterSettings settings = testSettings(7e-5f);
        settings.shadingRate = rate;
        settings.background = Rgb(0.05f);
        // A surface in the middle of the hair: its pixels close, hair behind is skipped.
        const SurfaceLayer surface = discSurface(camera, 40.0f, 0.75f, Rgb(0.2f));
        std::vector<unsigned char> reference;
        for (const int threads : {1, 2, 8}) {
            settings.threads = threads;
            const RasterOutput out = rasterize(groom, camera, shader, settings, surface);
            EXPECT_GT(out.stats.fragmentsComposited, 10000u);
            EXPECT_GT(out.stats.fragmentsBehindOpaque, 0u);
            if (reference.empty())
                reference = test::filmBytes(out.film);
            else
                EXPECT_TRUE(test::filmBytes(out.film) == reference) << threads << " threads";
        }
    }
}

/// Relative L1 distance of two films' beauty over the first's hair pixels.
double relativeBeautyL1(const Film& reference, const Film& estimate) {
    double diff = 0, total = 0;
    for (std::size_t p = 0; p < reference.pixelCount(); ++p) {
        if (hairAlpha(reference)[p] == 0)
            continue;
        const Rgb a = reference.beauty(p), b = estimate.beauty(p);
        for (int c = 0; c < 3; ++c) {
            diff += std::abs(double(a[c]) - double(b[c]));
            total += double(a[c]);
        }
    }
    return diff / total;
}

TEST(RasterShadingRate, VertexShadingApproximatesFragmentShading) {
    const Groom groom = smallGroom(2000);
    const Camera camera = groomCamera(200);
    const test::SmoothShader shader(2);
    RasterSettings settings = testSettings(7e-5f);
    const RasterOutput perFragment = rasterize(groom, camera, shader, settings);
    settings.shadingRate = ShadingRate::Vertex;
    const RasterOutput perVertex = rasterize(groom, camera, shader, settings);
    // Coverage does not depend on the shading rate.
    EXPECT_TRUE(alpha(perFragment.film) == alpha(perVertex.film));
    // Measured: 0.24% relative L1 with 5.3x fewer shader calls (segments are
    // ~1 cm, the shader varies over ~5 cm).
    EXPECT_LT(relativeBeautyL1(perFragment.film, perVertex.film), 0.01);
    EXPECT_LT(perVertex.stats.shadingPoints, perFragment.stats.shadingPoints);
}

TEST(RasterShadingRate, AdaptiveInterpolatesOnlyWhereTheProbeSaysItIsSmooth) {
    const Groom groom = smallGroom(2000);
    const Camera camera = groomCamera(200);
    const test::SmoothShader shader(2);
    RasterSettings settings = testSettings(7e-5f);
    const RasterOutput perFragment = rasterize(groom, camera, shader, settings);
    settings.shadingRate = ShadingRate::Adaptive;
    settings.shadingTolerance = 0.05f;
    const RasterOutput adaptive = rasterize(groom, camera, shader, settings);
    EXPECT_TRUE(alpha(perFragment.film) == alpha(adaptive.film));
    // This shader varies over ~5 cm and the segments are ~1 cm: most are
    // smooth. Measured: 99% of the probed segments smooth, 0.10% relative L1,
    // 2.2x fewer shader calls.
    EXPECT_GT(adaptive.stats.smoothSegments, adaptive.stats.probedSegments / 2);
    EXPECT_GT(adaptive.stats.fragmentsInterpolated, adaptive.stats.fragmentsComposited / 2);
    EXPECT_LT(2 * adaptive.stats.shadingPoints, perFragment.stats.shadingPoints);
    EXPECT_LT(relativeBeautyL1(perFragment.film, adaptive.film), 0.002);

    // τ = 0 accepts only a segment whose midpoint is exactly the ends' mean:
    // (almost) every fragment is shaded, and the image is fragment rate's.
    settings.shadingTolerance = 0.0f;
    const RasterOutput strict = rasterize(groom, camera, shader, settings);
    // Measured: none interpolated, the same image.
    EXPECT_LT(strict.stats.fragmentsInterpolated, strict.stats.fragmentsComposited / 100);
    EXPECT_LT(relativeBeautyL1(perFragment.film, strict.film), 1e-5);
}

/// Radiance r0 = r1 = 0.5 + 0.5·sin(k·y) (grey), varying along a segment far
/// faster than interpolating its vertices can follow: the worst case for
/// the tail. Average layers: none.
class StripeShader : public FragmentShader {
public:
    const ShaderLayout& layout() const override { return layout_; }
    void shade(std::span<const ShadingPoint> points, std::span<float> out) const override {
        for (std::size_t i = 0; i < points.size(); ++i) {
            const float v = 0.5f + 0.5f * std::sin(3000.0f * points[i].position.y);
            std::fill_n(out.data() + 6 * i, 6, v);
        }
    }

private:
    ShaderLayout layout_ = test::testLayout(2, 0);
};

// Hair seen through less than T_tail interpolates its segment's vertices:
// its weights sum to at most T_tail in each pixel, so no pixel's radiance
// moves by more than T_tail × the shader's range (here 1 per layer, two
// layers), even when interpolation is as wrong as it can be.
TEST(RasterShadingRate, TheTailMovesAPixelByAtMostItsShare) {
    const Groom groom = smallGroom(3000);
    const Camera camera = groomCamera(160);
    const StripeShader shader;
    RasterSettings settings = testSettings(1.5e-4f);
    settings.tailTransmittance = 0.0f;
    const RasterOutput full = rasterize(groom, camera, shader, settings);
    EXPECT_EQ(full.stats.tailFragments, 0u);
    EXPECT_EQ(full.stats.fragmentsInterpolated, 0u);
    for (const ShadingRate rate : {ShadingRate::Fragment, ShadingRate::Adaptive}) {
        for (const float tail : {1.0f / 16.0f, 0.25f}) {
            SCOPED_TRACE(testing::Message() << toString(rate) << ", T_tail " << tail);
            settings.shadingRate = rate;
            settings.shadingTolerance = 0.0f; // adaptive: (almost) nothing smooth
            settings.tailTransmittance = tail;
            const RasterOutput out = rasterize(groom, camera, shader, settings);
            EXPECT_TRUE(alpha(out.film) == alpha(full.film));
            EXPECT_GT(out.stats.tailFragments, full.stats.fragmentsComposited / 20);
            if (rate == ShadingRate::Fragment) { // (adaptive: plus its probes)
                EXPECT_LT(out.stats.shadingPoints, full.stats.shadingPoints);
            }
            double worst = 0;
            for (std::size_t p = 0; p < full.film.pixelCount(); ++p)
                worst = std::max(worst, double(std::abs(out.film.beauty(p).r -
                                                        full.film.beauty(p).r)));
            // Measured: the largest change is 0.36-0.67 of the bound; 10% (1/16)
            // and 30% (1/4) of the fragments in the tail.
            EXPECT_LE(worst, 2.0 * double(tail) * (1 + 1e-5));
            EXPECT_GT(worst, 0.1 * 2.0 * double(tail));
        }
    }
}

TEST(RasterShadingRate, AToleranceOrTailOutsideZeroToOneIsAnInputError) {
    const Camera camera = testCamera(16, 16, Vec3f(0, 0, 1), Vec3f(0, 0, 0));
    const test::ConstantShader shader;
    RasterSettings settings = testSettings(1e-3f);
    settings.shadingRate = ShadingRate::Adaptive;
    for (const float bad : {-0.1f, 1.5f, std::numeric_limits<float>::quiet_NaN()}) {
        settings.shadingTolerance = bad;
        EXPECT_THROW(rasterize(Groom{}, camera, shader, settings), InputError) << bad;
    }
    settings.shadingTolerance = 0.05f;
    for (const float bad : {-0.1f, 1.5f, std::numeric_limits<float>::quiet_NaN()}) {
        settings.tailTransmittance = bad;
        EXPECT_THROW(rasterize(Groom{}, camera, shader, settings), InputError) << bad;
    }
}

TEST(RasterFilm, RadianceIsPremultipliedAndAveragesAreNot) {
    const Groom groom = smallGroom(800);
    const Camera camera = groomCamera(96);
    RasterSettings settings = testSettings(7e-5f);
    settings.background = Rgb(0.05f);
    const test::ConstantShader shader(2);
    const Film film = rasterize(groom, camera, shader, settings).film;
    int hairPixels = 0;
    for (std::size_t p = 0; p < film.pixelCount(); ++p) {
        ASSERT_NEAR(film.layer(kBackgroundLayer).rgb(p).r, 0.05f * (1 - alpha(film)[p]), 1e-6f);
        if (hairAlpha(film)[p] < 1e-3f)
            continue;
        ++hairPixels;
        // Premultiplied hair radiance: the constant times the hair's coverage.
        ASSERT_NEAR(rgb(film, "r0", p).r, test::ConstantShader::kR0[0] * hairAlpha(film)[p], 1e-5f);
        // Averages: the constant itself, whatever the coverage.
        for (const char* light : {"light0", "light1"}) {
            ASSERT_NEAR(film.layer(std::string(light) + ".V").scalar(p),
                        test::ConstantShader::kLight[0], 1e-5f);
            ASSERT_NEAR(film.layer(std::string(light) + ".T_s").rgb(p).b,
                        test::ConstantShader::kLight[3], 1e-5f);
        }
    }
    EXPECT_GT(hairPixels, 500);
}

TEST(RasterFilm, RejectsNonFiniteShaderResultsAndReportsThePixel) {
    const Groom groom = smallGroom(300);
    const test::NaNShader shader;
    const RasterOutput out = rasterize(groom, groomCamera(64), shader, testSettings(7e-5f));
    EXPECT_GT(out.stats.invalidSamples, 0u);
    ASSERT_FALSE(out.warnings.empty());
    EXPECT_NE(out.warnings[0].find("at pixel ("), std::string::npos) << out.warnings[0];
    for (std::size_t p = 0; p < out.film.pixelCount(); ++p)
        ASSERT_TRUE(out.film.beauty(p).isFinite());
}

TEST(RasterFilm, AnEmptyGroomRendersTheSurfacesAndBackground) {
    const Camera camera = groomCamera(32);
    RasterSettings settings = testSettings(7e-5f);
    settings.background = Rgb(0.25f);
    const test::ConstantShader shader;
    const SurfaceLayer disc = discSurface(camera, 8.0f, 0.5f, Rgb(1.0f));
    const RasterOutput empty = rasterize(Groom{}, camera, shader, settings, disc);
    EXPECT_EQ(empty.stats.fragments, 0u);
    EXPECT_NEAR(sum(alpha(empty.film)), sum(disc.coverage), 1e-6);
    EXPECT_EQ(empty.film.beauty(0), Rgb(0.25f));
}

TEST(RasterInterrupt, StopsBetweenTiles) {
    const Groom groom = smallGroom(200);
    const Camera camera = groomCamera(64);
    const test::ConstantShader shader;
    requestInterrupt();
    EXPECT_THROW(rasterize(groom, camera, shader, testSettings(7e-5f)), Interrupted);
    clearInterrupt();
    EXPECT_NO_THROW(rasterize(groom, camera, shader, testSettings(7e-5f)));
}

} // namespace
} // namespace hairvox
