// The environment map (geometry/environment_map.h): its layout and rotation,
// its importance sampling against its own density (chi²), its integrals, the
// median cut, and every bad input an error naming the file.
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/core/rng.h>
#include <hairvox/film/image_file.h>
#include <hairvox/geometry/builtin_environment.h>
#include <hairvox/geometry/environment_map.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace hairvox {
namespace {

/// A W × W/2 map of random radiance in [0.1, 1.1) and, if `sun`, one pixel
/// 10⁴ times brighter.
std::vector<Rgb> randomPixels(int width, std::uint64_t seed, bool sun) {
    Pcg32 rng(seed);
    std::vector<Rgb> p(std::size_t(width) * std::size_t(width / 2));
    for (Rgb& c : p)
        c = Rgb(0.1f + rng.uniformFloat(), 0.1f + rng.uniformFloat(), 0.1f + rng.uniformFloat());
    if (sun)
        p[std::size_t(width / 8) * std::size_t(width) + std::size_t(width / 3)] = Rgb(1e4f);
    return p;
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

/// Writes `pixels` (row-major RGB, width × height) as an EXR, with an alpha
/// channel if asked.
void writeMap(const std::filesystem::path& path, int width, int height,
              const std::vector<Rgb>& pixels, bool alpha = false) {
    Film film(width, height);
    FilmLayer& rgb = film.layer(film.addLayer(std::string(Film::kBeauty), 3, true));
    for (std::size_t p = 0; p < pixels.size(); ++p)
        for (int c = 0; c < 3; ++c)
            rgb.at(p, c) = pixels[p][c];
    if (alpha) {
        FilmLayer& a = film.layer(film.addLayer(std::string(Film::kAlpha), 1, true));
        for (std::size_t p = 0; p < pixels.size(); ++p)
            a.at(p, 0) = 0.5f;
    }
    writeExr(path, film);
}

TEST(EnvironmentMap, LayoutPutsRowZeroUpAndTheMiddleColumnTowardMinusZ) {
    const EnvironmentMap map(64, randomPixels(64, 1, false), "test");
    const auto near = [](const Vec3f& a, const Vec3f& b) {
        return glm::distance(a, b) < 1e-5f;
    };
    EXPECT_TRUE(near(map.direction(0.5f, 0.5f), Vec3f(0, 0, -1)));
    EXPECT_TRUE(near(map.direction(0.75f, 0.5f), Vec3f(1, 0, 0)));
    EXPECT_TRUE(near(map.direction(0.25f, 0.5f), Vec3f(-1, 0, 0)));
    EXPECT_TRUE(near(map.direction(0.0f, 0.5f), Vec3f(0, 0, 1)));
    EXPECT_TRUE(near(map.direction(0.3f, 0.0f), Vec3f(0, 1, 0)));
    EXPECT_TRUE(near(map.direction(0.3f, 1.0f), Vec3f(0, -1, 0)));
    // The pixel a direction falls in, and back.
    EXPECT_EQ(map.radiance(Vec3f(0, 0, -1)), map.pixel(32, 16));
    EXPECT_EQ(map.radiance(Vec3f(0, 1, 0)),
              map.pixel(int(map.coordinates(Vec3f(0, 1, 0)).x * 64), 0));
    Pcg32 rng(7);
    for (int k = 0; k < 1000; ++k) {
        const float u = rng.uniformFloat(), v = 0.01f + 0.98f * rng.uniformFloat();
        const Vec2f uv = map.coordinates(map.direction(u, v));
        EXPECT_NEAR(uv.x, u, 1e-5f);
        EXPECT_NEAR(uv.y, v, 1e-5f);
    }
}

// Rotation ρ about +y: the world sees the map at u + ρ/360, so 90° is the map
// rolled left by a quarter of its width; its middle (−z) then faces −x.
TEST(EnvironmentMap, RotationByNinetyDegreesIsTheMapRolledByAQuarter) {
    const int width = 64, height = 32;
    const std::vector<Rgb> pixels = randomPixels(width, 3, true);
    std::vector<Rgb> rolled(pixels.size());
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i)
            rolled[std::size_t(j * width + i)] =
                pixels[std::size_t(j * width + (i + width / 4) % width)];
    const EnvironmentMap rotated(width, pixels, "rotated", Rgb(1.0f), 90.0f);
    const EnvironmentMap roll(width, rolled, "rolled", Rgb(1.0f), 0.0f);
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i) {
            const Vec3f omega =
                roll.direction((float(i) + 0.5f) / float(width), (float(j) + 0.5f) / float(height));
            ASSERT_EQ(rotated.radiance(omega), roll.radiance(omega)) << i << ", " << j;
        }
    Pcg32 rng(11);
    for (int k = 0; k < 2000; ++k) {
        const Vec3f omega = roll.direction(rng.uniformFloat(), rng.uniformFloat());
        const Rgb a = rotated.backdrop(omega), b = roll.backdrop(omega);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(a[c], b[c], 1e-3f * (1.0f + b[c]));
        EXPECT_NEAR(rotated.pdf(omega), roll.pdf(omega), 1e-4f * roll.pdf(omega));
    }
    EXPECT_EQ(rotated.radiance(Vec3f(-1, 0, 0)), pixels[std::size_t(16 * width + 32)]);
    // The same light, wherever it is turned.
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(rotated.integral()[c], roll.integral()[c], 1e-5f * roll.integral()[c]);
}

/// The Wilson–Hilferty approximation of P(χ²_k ≥ x).
double chi2Tail(double x, double k) {
    const double z = (std::cbrt(x / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
    return 0.5 * std::erfc(z / std::sqrt(2.0));
}

// Samples land in each pixel as often as their density says (pdf() in solid
// angle times the pixel's solid angle, ∫ per pixel exactly), and every
// sample's radiance and density are those of its direction.
TEST(EnvironmentMap, SamplingPassesAChiSquareTestAgainstItsDensity) {
    const int width = 32, height = 16;
    const EnvironmentMap map(width, randomPixels(width, 5, true), "chi2", Rgb(1.0f, 0.5f, 2.0f),
                             33.0f);
    // A pixel's probability: its density in (u, v) over W·H, from pdf() at
    // its centre times the Jacobian 2π² sin θ.
    std::vector<double> expected(std::size_t(width * height));
    double total = 0;
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i) {
            const float u = (float(i) + 0.5f) / float(width), v = (float(j) + 0.5f) / float(height);
            const double sinTheta = std::sin(Pi * double(v));
            expected[std::size_t(j * width + i)] = double(map.pdf(map.direction(u, v))) * 2.0 * Pi *
                                                   Pi * sinTheta / double(width * height);
            total += expected[std::size_t(j * width + i)];
        }
    EXPECT_NEAR(total, 1.0, 1e-4); // the density integrates to one

    constexpr int kSamples = 400'000;
    std::vector<double> observed(expected.size(), 0.0);
    Pcg32 rng(17);
    Rgbd estimate(0.0);
    for (int k = 0; k < kSamples; ++k) {
        const EnvironmentSample s = map.sample(rng.uniformFloat(), rng.uniformFloat());
        ASSERT_GT(s.pdf, 0.0f);
        ASSERT_EQ(s.pdf, map.pdf(s.omega));
        ASSERT_EQ(s.radiance, map.radiance(s.omega));
        const Vec2f uv = map.coordinates(s.omega);
        observed[std::size_t(std::min(int(uv.y * float(height)), height - 1) * width +
                             std::min(int(uv.x * float(width)), width - 1))] += 1;
        estimate += Rgbd(s.radiance) / double(s.pdf);
    }
    // Cells expected fewer than 5 times pooled into one.
    double chi2 = 0, pooledExpected = 0, pooledObserved = 0;
    int cells = 0;
    for (std::size_t p = 0; p < expected.size(); ++p) {
        const double e = expected[p] * kSamples;
        if (e < 5) {
            pooledExpected += e;
            pooledObserved += observed[p];
            continue;
        }
        chi2 += (observed[p] - e) * (observed[p] - e) / e;
        ++cells;
    }
    if (pooledExpected > 0) {
        chi2 +=
            (pooledObserved - pooledExpected) * (pooledObserved - pooledExpected) / pooledExpected;
        ++cells;
    }
    ASSERT_GT(cells, 300);
    EXPECT_GT(chi2Tail(chi2, cells - 1), 1e-3) << "chi2 " << chi2 << " over " << cells << " cells";
    // L/pdf estimates ∫L dω without bias.
    const Rgb integral = map.integral();
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(estimate[c] / kSamples, double(integral[c]), 0.01 * double(integral[c]));

    // A test that can fail: the same counts against a density off by the
    // sin θ Jacobian (uniform in v instead) fail it.
    std::vector<double> withoutJacobian(expected.size());
    double norm = 0;
    for (std::size_t p = 0; p < expected.size(); ++p) {
        withoutJacobian[p] = expected[p] / std::sin(Pi * (double(p / width) + 0.5) / height);
        norm += withoutJacobian[p];
    }
    double wrong = 0;
    for (std::size_t p = 0; p < expected.size(); ++p) {
        const double e = withoutJacobian[p] / norm * kSamples;
        if (e >= 5)
            wrong += (observed[p] - e) * (observed[p] - e) / e;
    }
    EXPECT_LT(chi2Tail(wrong, cells - 1), 1e-6);
}

TEST(EnvironmentMap, AUniformMapHasItsClosedFormIntegrals) {
    const Rgb L(0.5f, 1.0f, 2.0f);
    const EnvironmentMap map = EnvironmentMap::uniform(L);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(map.integral()[c], 4.0 * Pi * double(L[c]), 1e-4 * 4.0 * Pi * double(L[c]));
    for (const Vec3f& n :
         {Vec3f(0, 1, 0), Vec3f(1, 0, 0), glm::normalize(Vec3f(0.3f, -0.5f, 0.8f))}) {
        const Rgb e = map.irradiance(n);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(e[c], Pi * double(L[c]), 2e-3 * Pi * double(L[c])) << n;
    }
    EXPECT_EQ(map.radiance(Vec3f(0, 0, 1)), L);
    EXPECT_EQ(map.backdrop(glm::normalize(Vec3f(0.2f, 0.7f, 0.1f))), L);
}

// Median cut: the regions partition the map; their irradiances sum to the
// map's integral; the energy cut isolates a sun and points at it; the
// solid-angle cut of a uniform map makes regions of nearly equal area.
TEST(EnvironmentMap, MedianCutPartitionsTheMapAndFindsTheSun) {
    const int width = 128;
    const EnvironmentMap map(width, randomPixels(width, 9, true), "split");
    for (const EnvironmentSplit by : {EnvironmentSplit::Energy, EnvironmentSplit::SolidAngle}) {
        const std::vector<EnvironmentRegion> regions = map.split(24, by);
        ASSERT_EQ(regions.size(), 24u);
        std::vector<int> covered(std::size_t(width * width / 2), 0);
        Rgbd sum(0.0);
        for (const EnvironmentRegion& r : regions) {
            for (int j = r.y0; j < r.y1; ++j)
                for (int i = r.x0; i < r.x1; ++i)
                    ++covered[std::size_t(j * width + i)];
            sum += Rgbd(r.irradiance);
            EXPECT_NEAR(glm::length(r.direction), 1.0f, 1e-5f);
            EXPECT_GE(r.spread2, 0.0f);
        }
        for (int c : covered)
            ASSERT_EQ(c, 1);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(sum[c], double(map.integral()[c]), 1e-4 * double(map.integral()[c]));
    }
    // The sun (pixel (42, 16), 70% of the energy): the region holding it
    // points at it, and the cuts still reach the whole sky — of 8 regions
    // none spans a quarter of the sphere (cutting by weight alone spent six
    // on the sun's rectangle and left a region of half the sky).
    const Vec3f sun = map.direction((42 + 0.5f) / 128.0f, (16 + 0.5f) / 64.0f);
    int holders = 0;
    for (const EnvironmentRegion& r : map.split(8, EnvironmentSplit::Energy)) {
        EXPECT_LT(r.solidAngle, Pi) << r;
        if (r.x0 <= 42 && 42 < r.x1 && r.y0 <= 16 && 16 < r.y1) {
            ++holders;
            EXPECT_GT(glm::dot(r.direction, sun), std::cos(radians(1.0f))) << r;
            EXPECT_LT(r.spread2, 1e-2f) << r; // the sky around it, 4-5°
        }
    }
    EXPECT_EQ(holders, 1);
    const EnvironmentMap uniform = EnvironmentMap::uniform(Rgb(1.0f));
    for (const EnvironmentRegion& r : uniform.split(16, EnvironmentSplit::SolidAngle))
        EXPECT_NEAR(r.solidAngle, 4.0 * Pi / 16.0, 0.2 * 4.0 * Pi / 16.0);
}

// A lossy codec's ringing: negative values beside a bright pixel are folded
// into it with every channel's energy kept; a negative value with no light
// around it to absorb it is an error that says how many and where.
TEST(EnvironmentMap, NegativeRingingIsFoldedWithItsEnergyKept) {
    const int width = 32;
    std::vector<Rgb> p(std::size_t(width * width / 2), Rgb(0.0f));
    const auto at = [&](int i, int j) -> Rgb& {
        return p[std::size_t(j * width + i)];
    };
    at(10, 8) = Rgb(100.0f, 50.0f, 10.0f);
    at(9, 8) = Rgb(-8.0f, -1.0f, 0.0f);
    at(11, 9) = Rgb(-5.0f, 0.0f, -2.0f);
    at(20, 3) = Rgb(1.0f);
    // Energy of each channel, negatives included: what the fold keeps.
    const auto energy = [&](const std::vector<Rgb>& px) {
        Rgbd e(0.0);
        for (int j = 0; j < width / 2; ++j) {
            const double dOmega =
                TwoPi / width *
                (std::cos(Pi * j / (width / 2)) - std::cos(Pi * (j + 1) / (width / 2)));
            for (int i = 0; i < width; ++i)
                e += Rgbd(px[std::size_t(j * width + i)]) * dOmega;
        }
        return e;
    };
    const Rgbd before = energy(p);
    const EnvironmentMap map(width, p, "ringing");
    EXPECT_EQ(map.negativeFolds().values, 4u);
    EXPECT_EQ(map.negativeFolds().lowest, -8.0f);
    EXPECT_EQ(map.negativeFolds().radius, 1);
    std::vector<Rgb> after(p.size());
    for (int j = 0; j < width / 2; ++j)
        for (int i = 0; i < width; ++i) {
            after[std::size_t(j * width + i)] = map.pixel(i, j);
            ASSERT_GE(map.pixel(i, j).minComponent(), 0.0f);
        }
    const Rgbd kept = energy(after);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(kept[c], before[c], 1e-6 * before[c]);
    EXPECT_EQ(map.pixel(20, 3), Rgb(1.0f)); // far from the ringing: untouched

    at(25, 12) = Rgb(0.0f, -0.5f, 0.0f); // nothing within 8 pixels to absorb it
    const std::string e = errorOf([&] { EnvironmentMap(width, p, "negative.exr"); });
    EXPECT_TRUE(test::contains(e, "negative.exr: 1 negative pixel values")) << e;
    EXPECT_TRUE(test::contains(e, "column 25, row 12, G = -0.5")) << e;
}

TEST(EnvironmentMap, BadInputIsAnErrorNamingTheFile) {
    test::TempDir dir;
    // Missing, not an EXR, truncated.
    EXPECT_TRUE(test::contains(
        errorOf([&] { EnvironmentMap::readExr(dir / "none.exr", Rgb(1.0f), 0, 1u << 30); }),
        "none.exr: cannot read OpenEXR file"));
    test::writeText(dir / "text.exr", "not an image\n");
    EXPECT_TRUE(test::contains(
        errorOf([&] { EnvironmentMap::readExr(dir / "text.exr", Rgb(1.0f), 0, 1u << 30); }),
        "text.exr: cannot read OpenEXR file"));
    writeMap(dir / "good.exr", 64, 32, randomPixels(64, 2, false));
    {
        const std::string bytes = test::readBytes(dir / "good.exr");
        std::ofstream(dir / "truncated.exr", std::ios::binary)
            .write(bytes.data(), std::streamsize(bytes.size() / 2));
    }
    EXPECT_TRUE(test::contains(
        errorOf([&] { EnvironmentMap::readExr(dir / "truncated.exr", Rgb(1.0f), 0, 1u << 30); }),
        "truncated.exr: cannot read OpenEXR file"));
    // Not 2:1 (from the header and from pixels).
    writeMap(dir / "square.exr", 32, 32, std::vector<Rgb>(32 * 32, Rgb(1.0f)));
    EXPECT_TRUE(test::contains(
        errorOf([&] { EnvironmentMap::readExr(dir / "square.exr", Rgb(1.0f), 0, 1u << 30); }),
        "square.exr: 32 x 32 pixels: expected a latitude-longitude map twice as wide as high"));
    EXPECT_TRUE(test::contains(errorOf([] { EnvironmentMap(10, std::vector<Rgb>(30), "odd"); }),
                               "odd: 10 x 3 pixels: expected a latitude-longitude map"));
    // No R, G, B: a luminance-only image.
    {
        Film film(16, 8);
        film.addLayer("Y", 1, true);
        writeExr(dir / "luminance.exr", film);
    }
    EXPECT_TRUE(test::contains(
        errorOf([&] { EnvironmentMap::readExr(dir / "luminance.exr", Rgb(1.0f), 0, 1u << 30); }),
        "luminance.exr: no channel R (an RGB or RGBA image is needed; the file has Y)"));
    // Over the budget: refused from the header.
    EXPECT_TRUE(test::contains(
        errorOf([&] { EnvironmentMap::readExr(dir / "good.exr", Rgb(1.0f), 0, 40'000); }),
        "good.exr: 64 x 32 pixels would need"));
    // Non-finite pixels: how many and where.
    std::vector<Rgb> nan = randomPixels(16, 4, false);
    nan[3] = Rgb(std::nanf(""), 0.0f, 0.0f);
    nan[40].b = std::numeric_limits<float>::infinity();
    const std::string e = errorOf([&] { EnvironmentMap(16, nan, "nan.exr"); });
    EXPECT_TRUE(test::contains(e, "nan.exr: 2 of 128 pixels are not finite")) << e;
    EXPECT_TRUE(test::contains(e, "column 3, row 0")) << e;
    EXPECT_TRUE(test::contains(e, "column 8, row 2")) << e;
    // An RGBA map reads, its alpha ignored.
    writeMap(dir / "rgba.exr", 64, 32, randomPixels(64, 2, false), true);
    const EnvironmentMap rgba = EnvironmentMap::readExr(dir / "rgba.exr", Rgb(2.0f), 0, 1u << 30);
    EXPECT_EQ(rgba.width(), 64);
    EXPECT_NEAR(rgba.pixel(5, 5).r, randomPixels(64, 2, false)[5 * 64 + 5].r, 1e-3f);
    EXPECT_EQ(rgba.scale(), Rgb(2.0f));
}

// The shipped maps (half floats, DWA compression) read, with their ringing folded.
TEST(EnvironmentMap, ReadsTheShippedDwaMaps) {
    for (const char* name : {"studio.exr", "sky.exr", "city.exr"}) {
        const EnvironmentMap map =
            EnvironmentMap::readExr(test::dataDir() / "hdri" / name, Rgb(1.0f), 0, 1u << 30);
        EXPECT_EQ(map.width(), 512) << name;
        EXPECT_EQ(map.height(), 256) << name;
        EXPECT_GT(map.negativeFolds().values, 0u) << name;
        EXPECT_LT(map.negativeFolds().energy, 0.15) << name;
    }
    const EnvironmentMap sky =
        EnvironmentMap::readExr(test::dataDir() / "hdri" / "sky.exr", Rgb(1.0f), 0, 1u << 30);
    EXPECT_GT(sky.maxLuminance(), 5000.0f);
}

// The maps built into the program are the shipped files, byte for byte, and
// read from memory as from disk; bad bytes in memory are an error naming the map.
TEST(EnvironmentMap, BuiltInMapsAreTheShippedFilesReadFromMemory) {
    ASSERT_EQ(builtinEnvironmentNames(), "studio, sky, city");
    for (const BuiltinEnvironment& builtin : builtinEnvironments()) {
        const std::filesystem::path file =
            test::dataDir() / "hdri" / (std::string(builtin.name) + ".exr");
        const std::string bytes = test::readBytes(file);
        ASSERT_EQ(builtin.exr.size(), bytes.size()) << builtin.name;
        EXPECT_EQ(std::memcmp(builtin.exr.data(), bytes.data(), bytes.size()), 0) << builtin.name;
        const EnvironmentMap fromMemory =
            EnvironmentMap::readExr(builtin.source(), Rgb(1.0f), 30.0f, 1u << 30);
        const EnvironmentMap fromFile = EnvironmentMap::readExr(file, Rgb(1.0f), 30.0f, 1u << 30);
        EXPECT_EQ(fromMemory.source(), "built-in map " + std::string(builtin.name));
        EXPECT_EQ(fromMemory.width(), fromFile.width());
        EXPECT_EQ(fromMemory.integral(), fromFile.integral()) << builtin.name;
        EXPECT_EQ(fromMemory.pixel(300, 100), fromFile.pixel(300, 100)) << builtin.name;
    }
    EXPECT_TRUE(test::contains(errorOf([] { builtinEnvironment("lobby"); }),
                               "no built-in environment map \"lobby\": expected one of studio, "
                               "sky, city"));
    // Cut short in memory: OpenEXR's error, named by the source, not a crash.
    const std::span<const unsigned char> studio = builtinEnvironment("studio").exr;
    const ExrSource cut = ExrSource::memory("half a map", studio.first(studio.size() / 2));
    EXPECT_TRUE(
        test::contains(errorOf([&] { EnvironmentMap::readExr(cut, Rgb(1.0f), 0, 1u << 30); }),
                       "half a map: cannot read OpenEXR file"));
    const ExrSource header = ExrSource::memory("a header", studio.first(40));
    EXPECT_TRUE(test::contains(errorOf([&] { readExrInfo(header); }),
                               "a header: cannot read OpenEXR file"));
}

} // namespace
} // namespace hairvox
