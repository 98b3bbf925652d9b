// The whole render pipeline with the real dual-scattering shader and global
// term (pipeline/pipeline.h): layers, the radiance of a fiber against the
// shader evaluated directly, light and shadow cases, the head, determinism and
// the reference image.
#include "film/film_bytes.h"
#include "scene_test_util.h"
#include "test_util.h"

#include <hairvox/core/math.h>
#include <hairvox/film/image_file.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/shading/dual_scattering_shader.h>
#include <hairvox/strands/groom_io.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>

namespace hairvox {
namespace {

/// The default scene, small: 800 strands at 96², writing into `dir`.
Scene smallScene(const test::TempDir& dir, GlobalTermMode mode = GlobalTermMode::Grid) {
    Scene scene = test::keyBackScene();
    scene.name = "small";
    scene.groom.procedural.strands = 800;
    scene.camera.width = scene.camera.height = 96;
    scene.globalTermMode = mode;
    scene.exact.rays = 4;
    scene.exact.radius = 0.004f;
    scene.output.exr = dir / "small.exr";
    scene.output.png = dir / "small.png";
    return scene;
}

PipelineOptions options(const test::TempDir& dir, int threads = 0) {
    PipelineOptions o;
    o.threads = threads;
    o.tableCacheDir = dir / "cache";
    return o;
}

constexpr const char* kHairLayers[] = {"direct_R", "direct_TT", "direct_TRT", "back_direct",
                                       "scatter"};

double hairRadiance(const Film& film, std::size_t i) {
    double sum = 0;
    for (const char* layer : kHairLayers) {
        const Rgb r = film.layer(layer).rgb(i);
        sum += double(r.r) + double(r.g) + double(r.b);
    }
    return sum;
}

double hairAlpha(const Film& film, std::size_t i) {
    return double(film.layer(kHairAlphaLayer).scalar(i));
}

TEST(RenderPipeline, EveryModeWritesItsLayers) {
    test::TempDir dir;
    for (const GlobalTermMode mode :
         {GlobalTermMode::Grid, GlobalTermMode::Approx, GlobalTermMode::Exact}) {
        const Scene scene = smallScene(dir, mode);
        const SceneRender r = renderScene(scene, options(dir));
        ASSERT_EQ(r.written.size(), 2u) << toString(mode);
        EXPECT_EQ(r.raster->invalidSamples, 0u) << toString(mode);
        const ExrImage exr = readExr(scene.output.exr);
        for (const char* layer : {"R", "G", "B", "A", "direct_R.R", "direct_TT.G", "direct_TRT.B",
                                  "back_direct.R", "scatter.G", "surface.R", "background.B", "hair.A",
                                  "Z", "key.V", "key.n", "key.T_s.R", "key.sigma_f.G", "back.V"})
            EXPECT_TRUE(exr.channels.count(layer)) << toString(mode) << ": no layer " << layer;
        EXPECT_EQ(exr.attributes.at("hairvox:globalTermMode"), toString(mode));
        double scatter = 0;
        for (const auto& [name, values] : exr.channels)
            for (const float v : values)
                ASSERT_TRUE(std::isfinite(v) && v >= 0) << toString(mode) << " " << name;
        for (const float v : exr.channels.at("scatter.R"))
            scatter += double(v);
        EXPECT_GT(scatter, 0.0) << toString(mode) << ": no multiple scattering at all";
    }
}

// One straight fiber, nothing else, exact mode (its own fiber is not counted:
// V = 1, T_s = 0): where it crosses a pixel centre, the hair's radiance is the
// coverage times the light's irradiance times the dual-scattering shader's
// value, evaluated here directly from shading/. Ties the pipeline — camera,
// light, shading point, compositing — to the shader it feeds.
TEST(RenderPipeline, OneFiberIsTheShaderTimesCoverageAndIrradiance) {
    test::TempDir dir;
    Scene scene = smallScene(dir, GlobalTermMode::Exact);
    scene.groom.file = dir / "fiber.hair";
    Groom groom;
    const Vec3f line[3] = {{-0.05f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, {0.05f, 0.0f, 0.0f}};
    groom.addStrand(line);
    writeHairFile(scene.groom.file, groom);
    scene.head.reset();
    scene.meshes.clear();
    scene.background = Rgb(0.0f);
    scene.fiberScale = FiberScale{2e-3f, 1.0f}; // 0.3 pixel
    scene.camera.position = Vec3f(0.0f, 0.05f, 0.3f);
    scene.camera.lookAt = Vec3f(0.0f);
    scene.camera.width = scene.camera.height = 33; // pixel centres on the fiber's row
    scene.exact.rays = 1;
    scene.exact.radius = 0;
    scene.lights.resize(1);
    scene.lights[0] = Light::directional(Vec3f(0.3f, 0.8f, 0.4f));
    scene.lights[0].name = "key";
    scene.lights[0].intensity = 2.5f;
    const SceneRender r = renderScene(scene, options(dir), false);

    const DualScatteringTables tables =
        DualScatteringTables::loadOrBuild(scene.fiber, dir / "cache");
    const DualScatteringShader shader(MarschnerBcsdf(scene.fiber), tables, scene.dualScattering);
    const Camera camera(scene.camera);
    int checked = 0;
    for (int x = 10; x < 23; ++x) { // the fiber spans pixels 9 to 23
        // Where the pixel centre's ray meets the fiber's line (the plane z = 0 along y = 0).
        const Vec3f dir3 =
            camera.toWorldDirection(camera.rayDirection(Vec2f(float(x) + 0.5f, 16.5f)));
        const Vec3f o = camera.position();
        const float t = -o.z / dir3.z;
        const Vec3f p = o + t * dir3;
        if (std::abs(p.y) > 1e-4f)
            continue; // the centre ray passes beside the fiber
        const std::size_t i = r.film.index(x, 16);
        const double coverage = hairAlpha(r.film, i);
        ASSERT_GT(coverage, 0.05) << x;
        const Rgb f = shader
                          .shade(scene.lights[0].direction, glm::normalize(o - p), Vec3f(1, 0, 0),
                                 GlobalTerm::unoccluded())
                          .total();
        const Rgb expected = float(coverage) * 2.5f * f;
        const Rgb beauty = r.film.beauty(i);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(beauty[c], expected[c], 2e-3f * expected[c] + 1e-7f)
                << "x " << x << " c " << c;
        EXPECT_NEAR(r.film.layer("key.V").scalar(i), 1.0f, 1e-6f);
        ++checked;
    }
    EXPECT_GE(checked, 10);
}

TEST(RenderPipeline, NoLightGivesBlackHair) {
    test::TempDir dir;
    Scene scene = smallScene(dir);
    for (Light& light : scene.lights)
        light.intensity = 0;
    const SceneRender r = renderScene(scene, options(dir), false);
    for (const LightReport& l : r.lights)
        EXPECT_TRUE(l.skipped) << l.name;
    double alpha = 0;
    for (std::size_t i = 0; i < r.film.pixelCount(); ++i) {
        EXPECT_EQ(hairRadiance(r.film, i), 0.0);
        alpha += hairAlpha(r.film, i);
    }
    EXPECT_GT(alpha, 10.0); // the hair is there, and black
}

TEST(RenderPipeline, LightInsideTheHeadIsSkipped) {
    test::TempDir dir;
    Scene scene = smallScene(dir);
    scene.lights[1].kind = Light::Kind::Point;
    scene.lights[1].position = Vec3f(0.0f, 0.02f, 0.0f);
    const SceneRender r = renderScene(scene, options(dir), false);
    EXPECT_FALSE(r.lights[0].skipped);
    EXPECT_TRUE(r.lights[1].skipped);
    EXPECT_EQ(r.lights[1].stats.queries, 0u); // never evaluated
}

TEST(RenderPipeline, HeadShadowsTheHairBehindIt) {
    // Strands between the camera and the head, lit only from behind the head:
    // the head blocks every shadow ray, so the hair gets no light at all.
    test::TempDir dir;
    Scene scene = smallScene(dir);
    scene.groom.file = dir / "strands.hair";
    Groom groom;
    for (int i = 0; i < 40; ++i) {
        const float x = -0.03f + 0.0015f * float(i);
        const Vec3f line[5] = {{x, 0.03f, 0.13f},
                               {x, 0.01f, 0.13f},
                               {x, -0.01f, 0.13f},
                               {x, -0.03f, 0.13f},
                               {x, -0.05f, 0.13f}};
        groom.addStrand(line);
    }
    writeHairFile(scene.groom.file, groom);
    scene.camera.position = Vec3f(0, 0, 0.6f);
    scene.camera.lookAt = Vec3f(0, 0, 0);
    scene.lights.resize(1);
    scene.lights[0].direction = Vec3f(0, 0, -1);
    const SceneRender shadowed = renderScene(scene, options(dir), false);
    double alpha = 0;
    for (std::size_t i = 0; i < shadowed.film.pixelCount(); ++i) {
        EXPECT_EQ(hairRadiance(shadowed.film, i), 0.0) << "pixel " << i;
        alpha += hairAlpha(shadowed.film, i);
    }
    EXPECT_GT(alpha, 5.0);
    EXPECT_EQ(shadowed.lights[0].stats.blockedBySurface, shadowed.lights[0].stats.queries);
    // The same light in front of the head lights them.
    scene.lights[0].direction = Vec3f(0, 0, 1);
    const SceneRender lit = renderScene(scene, options(dir), false);
    double radiance = 0;
    for (std::size_t i = 0; i < lit.film.pixelCount(); ++i)
        radiance += hairRadiance(lit.film, i);
    EXPECT_GT(radiance, 0.1);
}

TEST(RenderPipeline, HeadIsLambertianAndHidesTheHairBehindIt) {
    test::TempDir dir;
    Scene scene = smallScene(dir);
    scene.meshes.clear(); // the analytic head sphere instead of the mannequin
    scene.head = Head{};
    scene.groom.procedural.strands = 50;
    scene.camera.position = Vec3f(0, 0, 0.5f);
    scene.camera.lookAt = Vec3f(0, 0, 0);
    scene.camera.width = scene.camera.height = 256; // the head is 142 pixels wide
    scene.lights.resize(1);
    scene.lights[0].direction = Vec3f(0, 0, 1);
    scene.lights[0].intensity = 2.0f;
    scene.lights[0].color = Rgb(1.0f);
    const SceneRender r = renderScene(scene, options(dir), false);
    // Lit head-on at the centre: albedo/π · E, wholly covering the pixel, at depth 0.4.
    const Film& film = r.film;
    const std::size_t c = film.index(128, 128);
    EXPECT_NEAR(film.layer(kSurfaceLayer).rgb(c).r, scene.head->albedo.r * 2.0f / float(Pi), 1e-3f);
    EXPECT_NEAR(film.layer(Film::kAlpha).scalar(c), 1.0f, 1e-6f);
    EXPECT_NEAR(film.layer(kDepthLayer).scalar(c), 0.4f, 0.01f);
    // The hair behind the head (its back half, from this camera) is culled by tiles.
    EXPECT_GT(r.raster->segmentTilesBehindSurfaces, 0u);
}

// output.layers: the layers left out are neither in the film nor in the
// EXR, the memory estimate counts only the kept ones, and the beauty and
// the kept layers are the same floats as in a render of every layer.
TEST(RenderPipeline, LayersLeftOutAreNotStoredAndChangeNothingElse) {
    test::TempDir dir;
    const Scene all = smallScene(dir);
    Scene some = all;
    some.output.exr = dir / "some.exr";
    some.output.png.clear();
    some.output.layers = std::vector<std::string>{"Z", "key.T_s"};
    some.validate();
    const SceneRender full = renderScene(all, options(dir), false);
    const SceneRender kept = renderScene(some, options(dir));
    std::vector<std::string> names;
    for (const FilmLayer& l : kept.film.layers())
        names.push_back(l.name);
    EXPECT_EQ(names, (std::vector<std::string>{"", "A", "Z", "key.T_s"}));
    for (const std::string& name : names) {
        const std::vector<float> a = full.film.layer(name).dense();
        const std::vector<float> b = kept.film.layer(name).dense();
        ASSERT_EQ(a.size(), b.size()) << name;
        EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0)
            << name << " differs";
    }
    const ExrImage exr = readExr(some.output.exr);
    EXPECT_EQ(exr.channels.size(), 4u + 1u + 3u); // R G B A, Z, key.T_s.{R,G,B}
    EXPECT_FALSE(exr.channels.count("hair.A"));
    EXPECT_TRUE(exr.channels.count("key.T_s.G"));
    int fullChannels = 0;
    for (const FilmLayer& l : full.film.layers())
        fullChannels += l.channels;
    EXPECT_EQ(estimateRenderMemory(all).filmChannels, fullChannels);
    EXPECT_EQ(estimateRenderMemory(some).filmChannels, 4 + 1 + 3);
    // None: the beauty and its alpha only; no hair alpha, yet the camera
    // still knows it sees hair (no "sees no hair" warning).
    some.output.layers = std::vector<std::string>{};
    const SceneRender none = renderScene(some, options(dir), false);
    EXPECT_EQ(none.film.layers().size(), 2u);
    for (const std::string& w : none.warnings)
        EXPECT_EQ(w.find("sees no hair"), std::string::npos) << w;
}

TEST(RenderPipeline, SameBytesForAnyThreadCount) {
    test::TempDir dir;
    const Scene scene = smallScene(dir);
    const std::vector<unsigned char> one =
        test::filmBytes(renderScene(scene, options(dir, 1), false).film);
    EXPECT_GT(one.size(), 96u * 96u * 4u);
    for (const int threads : {2, 8})
        EXPECT_TRUE(test::filmBytes(renderScene(scene, options(dir, threads), false).film) == one)
            << threads << " threads";
}

/// The reference image: the small default scene in grid mode, beauty only.
/// Regenerate with HAIRVOX_REGENERATE_REFERENCE=1 (then commit data/ref/).
TEST(RenderPipeline, MatchesReferenceImage) {
    test::TempDir dir;
    const Scene scene = smallScene(dir);
    const SceneRender r = renderScene(scene, options(dir));
    const auto reference = test::dataDir() / "ref" / "small_default.exr";
    if (const char* regenerate = std::getenv("HAIRVOX_REGENERATE_REFERENCE");
        regenerate && std::string(regenerate) == "1") {
        std::filesystem::copy_file(scene.output.exr, reference,
                                   std::filesystem::copy_options::overwrite_existing);
        GTEST_SKIP() << "regenerated " << reference;
    }
    const ExrImage ref = readExr(reference);
    const ExrImage now = readExr(scene.output.exr);
    ASSERT_EQ(ref.width, now.width);
    ASSERT_EQ(ref.height, now.height);
    double diff = 0, total = 0;
    for (const char* c : {"R", "G", "B"})
        for (std::size_t i = 0; i < ref.channels.at(c).size(); ++i) {
            diff += std::abs(double(now.channels.at(c)[i]) - double(ref.channels.at(c)[i]));
            total += std::abs(double(ref.channels.at(c)[i]));
        }
    // Relative L1 of the beauty: 0 on this machine; the threshold absorbs
    // last-bit differences of other compilers' maths libraries.
    EXPECT_LT(diff / total, 0.01) << "relative L1 " << diff / total
                                  << "; regenerate with HAIRVOX_REGENERATE_REFERENCE=1";
}

} // namespace
} // namespace hairvox
