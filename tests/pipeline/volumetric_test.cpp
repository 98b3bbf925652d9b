// The volumetric integrator through the pipeline (docs/DESIGN.md §9): its
// scene keys, its layers, its determinism, and its multiple scattering
// against the path tracer's on block means of the hair's radiance.
#include "scene_test_util.h"
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/pipeline/pipeline.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <iostream>

namespace hairvox {
namespace {

Scene smallVolumetric(std::uint32_t strands = 1500, std::uint32_t size = 64) {
    Scene scene = test::keyBackScene();
    scene.groom.procedural.strands = strands;
    scene.camera.width = scene.camera.height = size;
    scene.integrator = Integrator::Volumetric;
    scene.output = {};
    return scene;
}

SceneRender render(const Scene& scene, const test::TempDir& dir, int threads = 0,
                   float multipleSampleSpacing = PipelineOptions{}.multipleSampleSpacing) {
    PipelineOptions options;
    options.tableCacheDir = dir / "cache";
    options.threads = threads;
    options.multipleSampleSpacing = multipleSampleSpacing;
    return renderScene(scene, options, false);
}

double layerSum(const Film& film, const std::string& name) {
    const FilmLayer& layer = film.layer(name);
    double sum = 0;
    for (std::size_t p = 0; p < film.pixelCount(); ++p) {
        const Rgb v = layer.rgb(p);
        sum += double(v.r) + double(v.g) + double(v.b);
    }
    return sum;
}

/// The error of the default scene with this integrator object.
std::string errorOf(const nlohmann::json& integrator) {
    nlohmann::json j = nlohmann::json::parse(defaultSceneJson());
    j["integrator"] = integrator;
    return test::sceneErrorOf(j);
}

TEST(Volumetric, SceneKeysAreReadAndCheckedPerIntegrator) {
    nlohmann::json j = nlohmann::json::parse(defaultSceneJson());
    j["integrator"] = {
        {"type", "volumetric"}, {"paths", 1000},       {"cell_voxels", 3}, {"sh_order", 4},
        {"max_depth", 40},      {"roulette_depth", 5}, {"seed", 9},        {"transport", "fibers"},
        {"denoise", false},     {"gradients", false}};
    const Scene s = parseScene(j, "scene.json", "/");
    EXPECT_EQ(s.integrator, Integrator::Volumetric);
    EXPECT_EQ(s.volumetric.paths, 1000u);
    EXPECT_EQ(s.volumetric.cache.cellVoxels, 3);
    EXPECT_EQ(s.volumetric.cache.shOrder, 4);
    EXPECT_EQ(s.volumetric.maxDepth, 40u);
    EXPECT_EQ(s.volumetric.rouletteDepth, 5u);
    EXPECT_EQ(s.volumetric.seed, 9u);
    EXPECT_EQ(s.volumetric.transport, VolumetricTransport::Fibers);
    EXPECT_FALSE(s.volumetric.cache.denoise);
    EXPECT_FALSE(s.volumetric.cache.gradients);
    const Scene defaults = parseScene(nlohmann::json::parse(defaultSceneJson()), "scene.json", "/");
    EXPECT_TRUE(defaults.volumetric.cache.denoise);
    EXPECT_TRUE(defaults.volumetric.cache.gradients);

    EXPECT_NE(errorOf({{"type", "volumetric"}, {"sh_order", 0}})
                  .find("/integrator/sh_order: expected an integer in [1, 8], got 0"),
              std::string::npos);
    EXPECT_NE(errorOf({{"type", "volumetric"}, {"cell_voxels", 17}}).find("/integrator/cell_voxels"),
              std::string::npos);
    EXPECT_NE(errorOf({{"type", "volumetric"}, {"sh_order", 9}}).find("/integrator/sh_order"),
              std::string::npos);
    EXPECT_NE(errorOf({{"type", "volumetric"}, {"paths_per_cell", -1}})
                  .find("/integrator/paths_per_cell"),
              std::string::npos);
    EXPECT_NE(errorOf({{"type", "volumetric"}, {"paths", "many"}}).find("/integrator/paths"),
              std::string::npos);
    EXPECT_NE(errorOf({{"type", "volumetric"}, {"denoise", 1}}).find("/integrator/denoise"),
              std::string::npos);
    EXPECT_NE(errorOf({{"type", "volumetric"}, {"gradients", "yes"}}).find("/integrator/gradients"),
              std::string::npos);
    EXPECT_NE(errorOf({{"type", "volumetric"}, {"transport", "photons"}})
                  .find("/integrator/transport"),
              std::string::npos);
    // A key of another integrator names the one it belongs to.
    EXPECT_NE(errorOf({{"type", "volumetric"}, {"spp", 4}})
                  .find("/integrator/spp: applies to the \"path\" integrator only"),
              std::string::npos);
    EXPECT_NE(errorOf({{"type", "path"}, {"sh_order", 8}})
                  .find("applies to the \"volumetric\" integrator only"),
              std::string::npos);
}

TEST(Volumetric, RendersSingleAndMultipleScatteringLayers) {
    test::TempDir dir;
    Scene scene = smallVolumetric();
    scene.volumetric.paths = 40000;
    const SceneRender r = render(scene, dir);
    ASSERT_TRUE(r.volumetric.has_value());
    EXPECT_EQ(r.volumetric->paths, 40000u);
    EXPECT_GT(r.volumetric->cells, 0u);
    EXPECT_GT(r.volumetric->crossings, r.volumetric->paths);
    double direct = 0;
    for (const char* name : {"direct_R", "direct_TT", "direct_TRT"})
        direct += layerSum(r.film, name);
    const double multiple = layerSum(r.film, "multiple");
    EXPECT_TRUE(std::isfinite(multiple));
    // The default scene's light hair: multiple scattering is a large share of
    // the hair's radiance (the path tracer: 69% of the key-lit hair's).
    EXPECT_GT(multiple, 0.2 * direct);
    EXPECT_LT(multiple, 5.0 * direct);
}

TEST(Volumetric, DarkHairScattersLessThanLightHair) {
    test::TempDir dir;
    const auto ratio = [&](float eumelanin) {
        Scene scene = smallVolumetric();
        scene.volumetric.paths = 20000;
        scene.fiber.sigma_a = FiberParams::sigmaFromMelanin(eumelanin, 0.0f);
        const SceneRender r = render(scene, dir);
        double direct = 0;
        for (const char* name : {"direct_R", "direct_TT", "direct_TRT"})
            direct += layerSum(r.film, name);
        return layerSum(r.film, "multiple") / direct;
    };
    const double light = ratio(0.12f), dark = ratio(4.0f);
    EXPECT_GT(light, 0.2);
    // Through a dark fiber little but R's few percent survives a scattering:
    // multiple scattering falls to a small fraction of single (measured 0.66
    // and 0.081).
    EXPECT_LT(dark, 0.2 * light) << "light " << light << ", dark " << dark;
}

TEST(Volumetric, AnEnvironmentLightsTheSolveThroughItsRegions) {
    test::TempDir dir;
    Scene scene = smallVolumetric();
    scene.volumetric.paths = 20000;
    scene.lights.clear();
    scene.environment = EnvironmentLight{}; // uniform white
    scene.environment->visible = false;
    const SceneRender r = render(scene, dir);
    ASSERT_TRUE(r.volumetric.has_value());
    // Every region lights the solve: the paths are shared among them.
    EXPECT_EQ(r.volumetric->pathsPerLight.size(), std::size_t(scene.environmentLights));
    for (const std::uint64_t n : r.volumetric->pathsPerLight)
        EXPECT_GT(n, 0u);
    double direct = 0;
    for (const char* name : {"direct_R", "direct_TT", "direct_TRT"})
        direct += layerSum(r.film, name);
    const double multiple = layerSum(r.film, "multiple");
    EXPECT_GT(direct, 0.0);
    EXPECT_GT(multiple, 0.2 * direct); // light hair under light from everywhere
    EXPECT_TRUE(std::isfinite(multiple));
}

TEST(Volumetric, SameBytesForAnyThreadCount) {
    test::TempDir dir;
    Scene scene = smallVolumetric(800, 48);
    scene.volumetric.paths = 20000;
    const SceneRender one = render(scene, dir, 1), two = render(scene, dir, 2);
    for (const std::string_view name : {std::string_view("multiple"), Film::kBeauty}) {
        const std::vector<float> a = one.film.layer(name).dense(), b = two.film.layer(name).dense();
        ASSERT_EQ(a.size(), b.size());
        EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0) << name;
    }
}

TEST(Volumetric, ReadingTheCellsAlongTheFibersKeepsTheMultipleLayer) {
    // The cache read at samples along the fibers (half a cell apart, the
    // default) against every fragment read where it is, the same solve:
    // the interpolation between samples, in the frames of the shading
    // tangents there, must keep the layer (measured at 256²: rel L1 0.0117,
    // bias +0.0001). Read in the segments' frames instead it moved by 6%,
    // with a +1.7% bias.
    test::TempDir dir;
    Scene scene = smallVolumetric(1500, 256);
    scene.volumetric.paths = 40000;
    const std::vector<float> sampled = render(scene, dir).film.layer("multiple").dense();
    const std::vector<float> each = render(scene, dir, 0, 0.0f).film.layer("multiple").dense();
    ASSERT_EQ(sampled.size(), each.size());
    double diff = 0, signedDiff = 0, sum = 0;
    for (std::size_t i = 0; i < each.size(); ++i) {
        diff += std::abs(double(sampled[i]) - double(each[i]));
        signedDiff += double(sampled[i]) - double(each[i]);
        sum += double(each[i]);
    }
    ASSERT_GT(sum, 0.0);
    std::cout << "multiple, sampled against every fragment: rel L1 " << diff / sum << ", bias "
              << signedDiff / sum << "\n";
    EXPECT_GT(diff, 0.0); // the samples are used
    EXPECT_LT(diff / sum, 0.03);
    EXPECT_LT(std::abs(signedDiff / sum), 0.003);
    PipelineOptions bad;
    bad.multipleSampleSpacing = 3.0f;
    try {
        (void)renderScene(scene, bad, false);
        ADD_FAILURE() << "a spacing of 3 cells was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("multiple sample spacing"), std::string::npos);
    }
}

/// The hair's radiance of the volumetric integrator and of dual scattering
/// against the path tracer's (256 spp), block means over 4×4 pixels (the
/// issue's measure), printed under `label`.
struct AgainstPathTracer {
    ImageError volumetric, dualScattering;
};
AgainstPathTracer againstPathTracer(Scene scene, const test::TempDir& dir, const char* label) {
    scene.integrator = Integrator::Volumetric;
    const Film volumetric = render(scene, dir).film;
    scene.integrator = Integrator::DualScattering;
    const Film ds = render(scene, dir).film;
    scene.integrator = Integrator::Path;
    scene.pathTrace.spp = 256;
    const Film pt = render(scene, dir).film;
    constexpr int kBlock = 4;
    const ComparedImage reference = hairRadianceOf(pt).boxFiltered(kBlock);
    const AgainstPathTracer r{
        *compareImages(hairRadianceOf(volumetric).boxFiltered(kBlock), reference),
        *compareImages(hairRadianceOf(ds).boxFiltered(kBlock), reference)};
    std::cout << label << ", against the path tracer (4x4 blocks, its noise "
              << r.volumetric.noiseFloorL1 << "): volumetric rel L1 " << r.volumetric.relL1
              << ", bias " << r.volumetric.relBias << "; dual scattering "
              << r.dualScattering.relL1 << ", bias " << r.dualScattering.relBias << "\n";
    return r;
}

// The default groom, thinned, at 96², full depth; dual scattering beside it.
TEST(VolumetricSlow, HairRadianceMatchesThePathTracerOnBlockMeans) {
    test::TempDir dir;
    const auto [e, d] = againstPathTracer(smallVolumetric(1500, 96), dir, "default, 96²");
    // Measured: volumetric 0.054 (bias −0.0%; 0.055, −0.8% without the
    // cells' gradients; 0.053, −1.1% reading the cache as traced; 0.051,
    // −0.9% before the flights left their own fiber), dual scattering 0.20,
    // the path tracer's own noise 0.032.
    EXPECT_LT(std::abs(e.relBias), 0.04);
    EXPECT_LT(e.relL1, 0.08);
    EXPECT_LT(e.relL1, 0.5 * d.relL1);
}

// The curly close-up (data/scenes/curly_closeup.json), blond: a helix puts
// fibers of every azimuth in a cell — the scene that measured the reading in
// each fiber's own frame and the flights leaving their own fiber
// (docs/DESIGN.md §9); at 80×60.
TEST(VolumetricSlow, CurlyHairMatchesThePathTracerOnBlockMeans) {
    test::TempDir dir;
    Scene scene = loadScene(test::dataDir() / "scenes" / "curly_closeup.json");
    scene.output = {};
    scene.fiber.sigma_a = FiberParams::sigmaFromMelanin(0.3f, 0.0f);
    scene.camera.width = 80;
    scene.camera.height = 60;
    scene.globalTermMode = GlobalTermMode::Grid;
    const auto [e, d] = againstPathTracer(scene, dir, "curly, 80x60");
    // Measured: volumetric 0.083 against a floor of 0.057, bias +0.1% (0.083,
    // −1.3% without the cells' gradients; 0.086, −1.9% reading the cache as
    // traced; 0.093, +4.6% before the flights left their own fiber); dual
    // scattering 0.175.
    EXPECT_LT(std::abs(e.relBias), 0.025);
    EXPECT_LT(e.relL1, 0.1);
    EXPECT_LT(e.relL1, 0.6 * d.relL1);
}

// Thin hair: depth 2 — light scattered once by one fiber and once more by
// the fiber seen — against the path tracer capped at the same depth, on the
// thinned default groom; and multiple scattering vanishing with the density
// (depth 2 grows as the square of the optical depth, single scattering as it).
TEST(VolumetricSlow, DepthTwoMatchesThePathTracersOnThinHair) {
    test::TempDir dir;
    Scene scene = smallVolumetric(1500, 64);
    scene.volumetric.maxDepth = 2;
    const SceneRender volumetric = render(scene, dir);
    scene.integrator = Integrator::Path;
    scene.pathTrace.spp = 256;
    scene.pathTrace.maxDepth = 2;
    const Film pt = render(scene, dir).film;
    constexpr int kBlock = 4;
    const auto multiple = [&](const Film& film) {
        return ComparedImage::fromFilm(film, {"multiple"}, "hair.A").boxFiltered(kBlock);
    };
    const ImageError e = *compareImages(multiple(volumetric.film), multiple(pt));
    std::cout << "depth 2 against the path tracer's (64², 4x4 blocks): rel L1 " << e.relL1
              << ", bias " << e.relBias << "\n";
    // Measured: rel L1 0.131 (the path tracer's noise in it), bias −2.8%;
    // −5.4% without the cells' gradients — the deficit at depth 2 that
    // docs/DESIGN.md §9 measures on the default look, most of it the cells'
    // resolution at the layer's surface.
    EXPECT_LT(std::abs(e.relBias), 0.05);
    EXPECT_LT(e.relL1, 0.2);

    const auto multipleOverDirect = [&](float k) {
        Scene thin = smallVolumetric(1500, 64);
        thin.volumetric.maxDepth = 2;
        thin.volumetric.paths = 200000;
        thin.fiberScale.densityMultiplier = k;
        for (MeshSource& mesh : thin.meshes)
            mesh.albedo = Rgb(0.0f); // light the skin sends does not thin out with the hair
        const Film film = render(thin, dir).film;
        double direct = 0;
        for (const char* name : {"direct_R", "direct_TT", "direct_TRT"})
            direct += layerSum(film, name);
        return layerSum(film, "multiple") / direct;
    };
    const float k = scene.fiberScale.densityMultiplier;
    const double dense = multipleOverDirect(k), thin = multipleOverDirect(k / 8);
    std::cout << "multiple / direct at k = " << k << ": " << dense << ", at k/8: " << thin << "\n";
    // Measured: 0.34 and 0.073 (linear in k would be 0.042).
    EXPECT_GT(dense, 0.0);
    EXPECT_LT(thin, 0.3 * dense);
}

} // namespace
} // namespace hairvox
