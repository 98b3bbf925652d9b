// The path tracer under an environment light (pathtrace/path_tracer.h): the
// identities (a uniform environment on a Lambertian sphere gives ρ·L; a patch
// at the zenith is a directional light from +y of the same irradiance), one
// fiber's single scattering against a quadrature of the map (light sampling
// and f_s sampling whose weights sum to one), a sun's noise against a nearly
// uniform sky's, determinism.
#include "film/film_bytes.h"
#include "scene_test_util.h"
#include "test_util.h"

#include <hairvox/core/distribution.h>
#include <hairvox/core/math.h>
#include <hairvox/core/rng.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/geometry/environment_map.h>
#include <hairvox/pathtrace/path_tracer.h>
#include <hairvox/shading/marschner.h>
#include <hairvox/strands/procedural.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

namespace hairvox {
namespace {

std::shared_ptr<const EnvironmentMap> shippedMap(const char* name) {
    return std::make_shared<const EnvironmentMap>(
        EnvironmentMap::readExr(test::dataDir() / "hdri" / name, Rgb(1.0f), 0, 1u << 30));
}

TEST(PathTracerEnvironment, PowerHeuristicWeightsSumToOne) {
    Pcg32 rng(3);
    for (int k = 0; k < 10000; ++k) {
        const float a = std::exp(rng.uniform(-30.0f, 30.0f)),
                    b = std::exp(rng.uniform(-30.0f, 30.0f));
        EXPECT_NEAR(powerHeuristic(a, b) + powerHeuristic(b, a), 1.0f, 1e-6f) << a << ", " << b;
        EXPECT_GE(powerHeuristic(a, b), 0.0f);
    }
    EXPECT_EQ(powerHeuristic(1.0f, 0.0f), 1.0f);
    EXPECT_EQ(powerHeuristic(0.0f, 1.0f), 0.0f);
    EXPECT_EQ(powerHeuristic(0.0f, 0.0f), 0.0f);
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(powerHeuristic(inf, 5.0f), 1.0f);
    EXPECT_EQ(powerHeuristic(5.0f, inf), 0.0f);
    EXPECT_EQ(powerHeuristic(3e38f, 3e38f), 0.5f); // no overflow
}

// One straight fiber under a map with a sun and a gradient, depth 1: each
// pixel's radiance per lobe is its coverage times ∫ L(ω) f_p(ω, ω_o) cos θ dω,
// summed here over the map's pixels (8 × 8 points each). The path tracer
// draws half of it from the map and half from f_s, weighted by the power
// heuristic: weights that did not sum to one would miss it by their excess.
TEST(PathTracerEnvironment, OneFiberSingleScatteringIsTheQuadratureOfTheMap) {
    Groom groom;
    const Vec3f a(-0.1f, 0.0f, 0.0f), b(0.1f, 0.0f, 0.0f);
    const Vec3f pts[2] = {a, b};
    groom.addStrand(pts);
    constexpr int width = 32, size = 33;
    std::vector<Rgb> pixels(std::size_t(width * width / 2));
    for (int j = 0; j < width / 2; ++j)
        for (int i = 0; i < width; ++i)
            pixels[std::size_t(j * width + i)] =
                Rgb(0.2f + 0.05f * float(i % 7), 0.3f, 0.1f + 0.04f * float(j));
    pixels[std::size_t(5 * width + 13)] = Rgb(400.0f, 300.0f, 200.0f); // a sun
    const auto map =
        std::make_shared<const EnvironmentMap>(width, pixels, "test", Rgb(1.0f), 20.0f);

    PathTraceScene scene;
    scene.groom = &groom;
    scene.fiberScale = FiberScale{2e-3f, 1.0f};
    scene.camera.position = Vec3f(0.0f, 0.05f, 1.0f);
    scene.camera.lookAt = Vec3f(0, 0, 0);
    scene.camera.fovY = 30.0f;
    scene.camera.width = scene.camera.height = size;
    scene.environment = map;
    PathTraceSettings settings;
    settings.spp = 16384;
    settings.maxDepth = 1; // camera → fiber → environment
    const Film film = pathTrace(scene, settings).film;

    const MarschnerBcsdf bcsdf(scene.fibers[0]);
    const Camera camera(scene.camera);
    const int row = size / 2;
    LobeValues expected;
    double got[3] = {0, 0, 0};
    for (int x = 0; x < size; ++x) {
        const Vec3f d =
            camera.toWorldDirection(camera.rayDirection(Vec2f(float(x) + 0.5f, float(row) + 0.5f)));
        const Vec3f p = camera.position() + (-camera.position().y / d.y) * d;
        if (std::abs(p.x) > 0.09f)
            continue;
        const std::size_t i = film.index(x, row);
        const float alpha = film.layer("hair.A").scalar(i);
        const Vec3f wo = glm::normalize(camera.position() - p);
        constexpr int kSub = 8;
        for (int j = 0; j < width / 2; ++j)
            for (int k = 0; k < width; ++k) {
                const Rgb L = map->scale() * map->pixel(k, j);
                for (int sj = 0; sj < kSub; ++sj) {
                    const double v0 = (j + double(sj) / kSub) / (width / 2),
                                 v1 = (j + double(sj + 1) / kSub) / (width / 2);
                    const double dOmega =
                        TwoPi / (width * kSub) * (std::cos(Pi * v0) - std::cos(Pi * v1));
                    for (int si = 0; si < kSub; ++si) {
                        const Vec3f omega =
                            map->direction((float(k) + (float(si) + 0.5f) / kSub) / float(width),
                                           float(0.5 * (v0 + v1)));
                        const FiberAngles fa =
                            FiberAngles::fromDirections(omega, wo, Vec3f(1, 0, 0));
                        const LobeValues f = bcsdf.eval(fa);
                        for (Lobe lobe : kLobes)
                            expected[lobe] += alpha * float(dOmega) * fa.cosTheta_i * (L * f[lobe]);
                    }
                }
            }
        got[0] += double(film.layer("direct_R").rgb(i).g);
        got[1] += double(film.layer("direct_TT").rgb(i).g);
        got[2] += double(film.layer("direct_TRT").rgb(i).g);
    }
    ASSERT_GT(double(expected.R.g), 0.0);
    // Measured over seeds 1-6 at this sample count (GCC): R within 1.0%, TT
    // 0.3%, TRT (1.5% of the light, drawn mostly by the others' samples)
    // 2.4%; Clang's rounding draws other samples (seeds 1 and 5: TRT +0.9%,
    // −2.1%). At 2048 samples TRT spread over −16%…+20%.
    EXPECT_NEAR(got[0], double(expected.R.g), 0.03 * double(expected.R.g));
    EXPECT_NEAR(got[1], double(expected.TT.g), 0.03 * double(expected.TT.g));
    EXPECT_NEAR(got[2], double(expected.TRT.g), 0.08 * double(expected.TRT.g));
}

using test::meanSurface;

TEST(PathTracerEnvironment, AUniformEnvironmentOnALambertianSphereIsAlbedoTimesRadiance) {
    const Groom none;
    PathTraceScene scene;
    scene.groom = &none;
    scene.fiberScale = FiberScale{1e-4f, 1.0f};
    scene.camera.position = Vec3f(0.0f, 0.1f, 0.6f);
    scene.camera.lookAt = Vec3f(0.0f);
    scene.camera.width = scene.camera.height = 48;
    scene.surfaces = std::make_shared<const SurfaceScene>(std::vector<Sphere>{{Vec3f(0.0f), 0.1f}},
                                                          std::vector<TriangleMesh>{});
    scene.surfaceAlbedo = {Rgb(0.5f, 0.4f, 0.3f)};
    const Rgb L(0.8f, 1.0f, 1.2f);
    scene.environment = std::make_shared<const EnvironmentMap>(EnvironmentMap::uniform(L));
    PathTraceSettings settings;
    settings.spp = 64;
    const Film film = pathTrace(scene, settings).film;
    const Rgb got = meanSurface(film), expected = scene.surfaceAlbedo[0] * L;
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(got[c], expected[c], 0.02f * expected[c]) << c;
    // The background is the environment seen, or not.
    EXPECT_EQ(film.layer("background").rgb(0), Rgb(0.0f));
    scene.environmentVisible = true;
    const Film seen = pathTrace(scene, settings).film;
    EXPECT_NEAR(seen.layer("background").rgb(0).g, L.g, 1e-5f);
}

/// A small wavy groom on a head, 64², lit by `map`.
struct SmallScene {
    Groom groom;
    PathTraceScene scene;

    explicit SmallScene(int size = 64) {
        ProceduralGroomParams p;
        p.strands = 600;
        groom = generateGroom(p);
        scene.groom = &groom;
        scene.fiberScale = FiberScale{7e-5f, 3.0f};
        scene.camera.position = Vec3f(0.45f, 0.05f, -0.6f);
        scene.camera.lookAt = Vec3f(0.0f, -0.1f, -0.05f);
        scene.camera.width = scene.camera.height = std::uint32_t(size);
        scene.surfaces = std::make_shared<const SurfaceScene>(
            std::vector<Sphere>{{Vec3f(0.0f), 0.1f}}, std::vector<TriangleMesh>{});
        scene.surfaceAlbedo = {Rgb(0.55f, 0.4f, 0.33f)};
    }
};

ComparedImage hairOf(const Film& film) {
    return ComparedImage::fromFilm(film, {"direct_R", "direct_TT", "direct_TRT", "multiple"},
                                   "hair.A", "hair_half_a");
}

// A patch at the zenith (θ < 1.4°) lights the hair as a directional light from
// +y of the same irradiance ∫L dω: the two path traces agree within their
// noise.
TEST(PathTracerEnvironmentSlow, AZenithPatchIsADirectionalLightFromAbove) {
    std::vector<Rgb> pixels(512 * 256, Rgb(0.0f));
    std::fill(pixels.begin(), pixels.begin() + 2 * 512, Rgb(1000.0f));
    const auto patch = std::make_shared<const EnvironmentMap>(512, pixels, "patch");
    SmallScene withPatch, withLight;
    withPatch.scene.environment = patch;
    withLight.scene.lights = {Light::directional(Vec3f(0, 1, 0))};
    withLight.scene.lights[0].intensity = patch->integral().g;
    PathTraceSettings settings;
    settings.spp = 128;
    const Film a = pathTrace(withPatch.scene, settings).film;
    const Film b = pathTrace(withLight.scene, settings).film;
    const ImageError e = *compareImages(hairOf(a).boxFiltered(8), hairOf(b).boxFiltered(8));
    const ImageError floorA = *compareImages(hairOf(a).boxFiltered(8), hairOf(a).boxFiltered(8));
    // Two independent noisy images: their difference is about √2 floors.
    const double floor = std::hypot(e.noiseFloorL1, floorA.noiseFloorL1);
    EXPECT_LT(e.relL1, 1.5 * floor) << "floor " << floor;
    EXPECT_LT(std::abs(e.relBias), 0.03);
}

// A sun 22,000 times the sky, a few pixels wide, is found by light sampling:
// the hair's noise at equal samples stays within twice that under a nearly
// uniform overcast sky (without importance sampling it is tens of times).
TEST(PathTracerEnvironmentSlow, ASunsNoiseIsWithinTwiceAnOvercastSkys) {
    double floors[2];
    int k = 0;
    for (const char* name : {"city.exr", "sky.exr"}) {
        SmallScene s;
        s.scene.environment = shippedMap(name);
        PathTraceSettings settings;
        settings.spp = 32;
        const Film film = pathTrace(s.scene, settings).film;
        floors[k++] = compareImages(hairOf(film), hairOf(film))->noiseFloorL1;
    }
    EXPECT_LT(floors[1], 2.0 * floors[0]) << "city " << floors[0] << ", sky " << floors[1];
}

TEST(PathTracerEnvironment, SameBytesForAnyThreadCount) {
    SmallScene s(32);
    s.scene.environment = shippedMap("studio.exr");
    s.scene.environmentVisible = true;
    PathTraceSettings settings;
    settings.spp = 2;
    std::vector<unsigned char> reference;
    for (const int threads : {1, 2, 8}) {
        settings.threads = threads;
        const PathTraceOutput out = pathTrace(s.scene, settings);
        EXPECT_GT(out.stats.environmentShadowRays, 0u);
        EXPECT_GT(out.stats.escapedRays, 0u);
        if (reference.empty())
            reference = test::filmBytes(out.film);
        else
            EXPECT_TRUE(test::filmBytes(out.film) == reference) << threads << " threads";
    }
}

} // namespace
} // namespace hairvox
