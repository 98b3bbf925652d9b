// The path tracer (pathtrace/path_tracer.h): coverage and single scattering of
// simple fibers against closed forms, stratified pixel positions, the halves'
// noise estimate, continuation and determinism.
#include "film/film_bytes.h"
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/math.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/pathtrace/path_tracer.h>
#include <hairvox/shading/marschner.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

namespace hairvox {
namespace {

double layerSum(const Film& film, std::string_view name, int channel = 0) {
    const FilmLayer& l = film.layer(name);
    double s = 0;
    for (std::size_t p = 0; p < film.pixelCount(); ++p)
        s += double(l.value(p, channel));
    return s;
}

PathTraceScene fiberScene(const Groom& groom, float diameter, int size) {
    PathTraceScene s;
    s.groom = &groom;
    s.fiberScale = FiberScale{diameter, 1.0f};
    s.camera.position = Vec3f(0, 0, 1);
    s.camera.lookAt = Vec3f(0, 0, 0);
    s.camera.fovY = 30.0f;
    s.camera.width = s.camera.height = std::uint32_t(size);
    return s;
}

// Camera at z = 1 looking down −z: a fiber in the plane z = 0 covers D·f × L·f pixels.
TEST(PathTracer, ThinFiberCoversWidthTimesLength) {
    Groom groom;
    const Vec3f a(-0.1013f, -0.0571f, 0.0f), b(0.0877f, 0.0719f, 0.0f);
    const Vec3f pts[3] = {a, 0.5f * (a + b), b};
    groom.addStrand(pts);
    const int size = 128;
    const PathTraceScene scene = fiberScene(groom, 2e-3f, size);
    PathTraceSettings settings;
    settings.spp = 64;
    const Film film = pathTrace(scene, settings).film;
    const double f = 0.5 * size / std::tan(0.5 * radians(30.0));
    const double expected = 2e-3 * f * double(glm::distance(a, b)) * f;
    EXPECT_NEAR(layerSum(film, "hair.A"), expected, 0.01 * expected);
    EXPECT_NEAR(layerSum(film, "A"), expected, 0.01 * expected);
}

// The pixel positions are stratified (core/sobol.h): a half's 2^m samples put
// one point in each of 2^m columns of the pixel, so a vertical edge's coverage
// is within 1/2^m of exact in every pixel, where independent uniform
// positions would be off by ~0.065 on average at 32 spp (by more than 1/16 in
// ~45% of the edge pixels).
TEST(PathTracer, PixelPositionsAreStratified) {
    Groom groom;
    const Vec3f pts[2] = {Vec3f(0.0f, -0.2f, 0.0f), Vec3f(0.0f, 0.2f, 0.0f)};
    groom.addStrand(pts);
    const int size = 64;
    const double f = 0.5 * size / std::tan(0.5 * radians(30.0)); // pixels per unit at z = 0
    const double width = 3.4;                                    // pixels, edges at 32 ± 1.7
    const PathTraceScene scene = fiberScene(groom, float(width / f), size);
    PathTraceSettings settings;
    settings.spp = 32; // 16 in each half: one point in each sixteenth of a pixel's width
    const Film film = pathTrace(scene, settings).film;
    const FilmLayer& alpha = film.layer("hair.A");
    double worst = 0;
    int edgePixels = 0;
    for (int y = 12; y < size - 12; ++y) // inside the fiber's length, rows 8.1 to 55.9
        for (int x = 28; x < 36; ++x) {
            const double exact = std::clamp(
                std::min(x + 1.0, 32 + width / 2) - std::max(double(x), 32 - width / 2), 0.0, 1.0);
            worst = std::max(worst, std::abs(double(alpha.scalar(film.index(x, y))) - exact));
            edgePixels += exact > 0 && exact < 1;
        }
    EXPECT_EQ(edgePixels, 2 * (size - 24));
    EXPECT_LT(worst, 1.0 / 16 + 1e-3);
}

// One straight fiber, a light behind it and one in front: the single
// scattering per lobe (depth 1) is Σ_pixels coverage·E·f_p·cos θ_i, with f_p
// from shading/ at each pixel's point of the fiber.
TEST(PathTracer, OneFiberSingleScatteringIsMarschner) {
    Groom groom;
    const Vec3f a(-0.1f, 0.0f, 0.0f), b(0.1f, 0.0f, 0.0f);
    const Vec3f pts[2] = {a, b};
    groom.addStrand(pts);
    const int size = 65; // pixel centres on the fiber's row
    PathTraceScene scene = fiberScene(groom, 2e-3f, size);
    scene.camera.position = Vec3f(0.0f, 0.05f, 1.0f);
    scene.lights = {Light::directional(Vec3f(0.2f, 0.3f, -1.0f)),
                    Light::directional(Vec3f(-0.4f, 0.7f, 0.5f))};
    scene.lights[0].intensity = 2.0f;
    scene.lights[1].name = "front";
    PathTraceSettings settings;
    settings.spp = 256;
    const Film film = pathTrace(scene, settings).film;
    const MarschnerBcsdf bcsdf(scene.fibers[0]);
    const Camera camera(scene.camera);
    LobeValues expected;
    double coverage = 0;
    for (int x = 0; x < size; ++x) {
        // The pixel's point of the fiber: its centre's ray meets the line y = 0, z = 0.
        const Vec3f d = camera.toWorldDirection(camera.rayDirection(Vec2f(float(x) + 0.5f, 32.5f)));
        const Vec3f p = camera.position() + (-camera.position().y / d.y) * d;
        if (std::abs(p.x) > 0.09f)
            continue;
        const std::size_t i = film.index(x, 32);
        const float alpha = film.layer("hair.A").scalar(i);
        coverage += double(alpha);
        for (const Light& l : scene.lights) {
            const FiberAngles fa = FiberAngles::fromDirections(
                l.direction, glm::normalize(camera.position() - p), Vec3f(1, 0, 0));
            const LobeValues f = bcsdf.eval(fa);
            for (Lobe lobe : kLobes)
                expected[lobe] += alpha * l.intensity * fa.cosTheta_i * f[lobe];
        }
    }
    ASSERT_GT(coverage, 3.0);
    double got[3] = {0, 0, 0};
    for (int x = 0; x < size; ++x) {
        const std::size_t i = film.index(x, 32);
        const Vec3f d = camera.toWorldDirection(camera.rayDirection(Vec2f(float(x) + 0.5f, 32.5f)));
        const Vec3f p = camera.position() + (-camera.position().y / d.y) * d;
        if (std::abs(p.x) > 0.09f)
            continue;
        got[0] += double(film.layer("direct_R").rgb(i).g);
        got[1] += double(film.layer("direct_TT").rgb(i).g);
        got[2] += double(film.layer("direct_TRT").rgb(i).g);
    }
    EXPECT_NEAR(got[0], double(expected.R.g), 0.02 * double(expected.R.g));
    EXPECT_NEAR(got[1], double(expected.TT.g), 0.02 * double(expected.TT.g));
    EXPECT_NEAR(got[2], double(expected.TRT.g), 0.02 * double(expected.TRT.g));
}

/// A small wavy groom on a head, two lights, 64² (what the statistical tests run on).
struct SmallScene {
    Groom groom;
    PathTraceScene scene;

    explicit SmallScene(int size = 64, std::uint32_t strands = 600) {
        ProceduralGroomParams p;
        p.strands = strands;
        groom = generateGroom(p);
        scene.groom = &groom;
        scene.fiberScale = FiberScale{7e-5f, 3.0f};
        scene.camera.position = Vec3f(0.45f, 0.05f, -0.6f);
        scene.camera.lookAt = Vec3f(0.0f, -0.1f, -0.05f);
        scene.camera.width = scene.camera.height = std::uint32_t(size);
        scene.lights = {Light::directional(Vec3f(0.6f, 0.7f, 0.4f)),
                        Light::directional(Vec3f(-0.45f, 0.3f, 0.85f))};
        scene.lights[1].name = "back";
        scene.lights[1].intensity = 2.0f;
        scene.surfaces = std::make_shared<const SurfaceScene>(
            std::vector<Sphere>{{Vec3f(0.0f), 0.1f}}, std::vector<TriangleMesh>{});
        scene.surfaceAlbedo = {Rgb(0.55f, 0.4f, 0.33f)};
        scene.background = Rgb(0.05f);
    }
};

TEST(PathTracer, SameBytesForAnyThreadCount) {
    const SmallScene s;
    PathTraceSettings settings;
    settings.spp = 4;
    std::vector<unsigned char> reference;
    for (const int threads : {1, 2, 8}) {
        settings.threads = threads;
        const PathTraceOutput out = pathTrace(s.scene, settings);
        EXPECT_EQ(out.stats.spp, 4u);
        EXPECT_GT(out.stats.scatteringEvents, out.stats.paths / 4);
        if (reference.empty())
            reference = test::filmBytes(out.film);
        else
            EXPECT_TRUE(test::filmBytes(out.film) == reference) << threads << " threads";
    }
    settings.seed = 2;
    EXPECT_FALSE(test::filmBytes(pathTrace(s.scene, settings).film) ==
                 reference); // the seed matters
}

// A run continued from its own output is the run that was never stopped (up
// to the float rounding of the stored means).
TEST(PathTracer, ContinuingARunGivesTheUninterruptedImage) {
    const SmallScene s;
    PathTraceSettings settings;
    settings.spp = 8;
    const Film whole = pathTrace(s.scene, settings).film;
    settings.spp = 4;
    const Film first = pathTrace(s.scene, settings).film;
    settings.spp = 8;
    const PathTraceOutput continued = pathTrace(s.scene, settings, &first, 4);
    EXPECT_EQ(continued.stats.spp, 8u);
    EXPECT_EQ(continued.stats.sppThisRun, 4u);
    for (const FilmLayer& layer : whole.layers()) {
        const std::vector<float> a = layer.dense(), b = continued.film.layer(layer.name).dense();
        ASSERT_EQ(a.size(), b.size()) << layer.name;
        for (std::size_t i = 0; i < a.size(); ++i)
            ASSERT_NEAR(b[i], a[i], 1e-5f * std::abs(a[i]) + 1e-7f) << layer.name << " " << i;
    }
    EXPECT_THROW(pathTrace(s.scene, settings, &first, 3), InputError); // an odd count is not ours
    const Film tooSmall(8, 8);
    EXPECT_THROW(pathTrace(s.scene, settings, &tooSmall, 4), InputError);
}

TEST(PathTracer, StopsAtTheTimeLimitAfterAWholePassAndOnInterrupt) {
    const SmallScene s;
    PathTraceSettings settings;
    settings.spp = 100000;
    settings.timeLimit = 1e-6;
    const PathTraceOutput limited = pathTrace(s.scene, settings);
    EXPECT_TRUE(limited.stats.timeLimited);
    EXPECT_EQ(limited.stats.spp, 2u); // one pass, never none
    settings.timeLimit = 0;
    requestInterrupt();
    const PathTraceOutput interrupted = pathTrace(s.scene, settings);
    clearInterrupt();
    EXPECT_TRUE(interrupted.stats.interrupted);
    EXPECT_EQ(interrupted.stats.spp, 0u);
}

/// Relative L1 between the hair's radiance of two films over the first one's hair pixels.
double hairL1(const Film& a, const Film& b, const std::vector<std::string>& layers) {
    const ComparedImage x = ComparedImage::fromFilm(a, layers, "hair.A");
    const ComparedImage y = ComparedImage::fromFilm(b, layers, "hair.A");
    return compareImages(y, x)->relL1;
}

// Russian roulette is unbiased: starting it at the first bounce or never (a
// depth it does not reach) gives the same image up to the noise.
TEST(PathTracer, RussianRouletteIsUnbiased) {
    const SmallScene s(48, 400);
    PathTraceSettings early, late;
    early.spp = late.spp = 256;
    early.rouletteDepth = 1;
    late.rouletteDepth = late.maxDepth = 1000;
    late.seed = 3;
    const PathTraceOutput a = pathTrace(s.scene, early), b = pathTrace(s.scene, late);
    EXPECT_EQ(b.stats.pathsAtDepthCap, 0u);
    const std::vector<std::string> all = {"direct_R", "direct_TT", "direct_TRT", "multiple"};
    const ComparedImage x = ComparedImage::fromFilm(a.film, all, "hair.A", "hair_half_a");
    const ComparedImage y = ComparedImage::fromFilm(b.film, all, "hair.A", "hair_half_a");
    const ImageError e = *compareImages(x, y);
    // Both are noisy: the bias of one against the other is zero within the
    // two images' noise (its standard error, from the halves, ≈ floor/√(π/2)·…).
    EXPECT_LT(std::abs(e.relBias), 0.03)
        << "relative bias " << e.relBias << ", floor " << e.noiseFloorL1;
    EXPECT_LT(e.relL1, 1.6 * std::sqrt(2.0) * e.noiseFloorL1) << "floor " << e.noiseFloorL1;
    // Roulette from the first bounce makes shorter paths on average.
    EXPECT_LT(a.stats.scatteringEvents, b.stats.scatteringEvents);
}

// The error against a long run falls as 1/√spp (the estimator's variance as 1/spp).
TEST(PathTracer, ErrorFallsAsOneOverRootSpp) {
    const SmallScene s(32, 300);
    PathTraceSettings settings;
    settings.spp = 2048;
    settings.seed = 99;
    const Film reference = pathTrace(s.scene, settings).film;
    const std::vector<std::string> all = {"direct_R", "direct_TT", "direct_TRT", "multiple"};
    std::vector<double> errors;
    for (const std::uint32_t spp : {16u, 64u, 256u}) {
        settings.spp = spp;
        settings.seed = 1;
        errors.push_back(hairL1(reference, pathTrace(s.scene, settings).film, all));
    }
    // Each 4× the samples halves the error (the reference's own noise, 1/√(2048/256) of the
    // last, flattens the last step a little).
    const double slope = std::log(errors[2] / errors[0]) / std::log(16.0);
    EXPECT_NEAR(slope, -0.5, 0.12) << errors[0] << " " << errors[1] << " " << errors[2];
}

} // namespace
} // namespace hairvox
