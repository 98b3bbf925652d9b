// The whole render pipeline with the real dual-scattering shader and global
// term (render/pipeline.h): layers, energy bookkeeping, light and shadow
// cases, determinism and the reference image.
#include "test_util.h"

#include <hairvox/render/output.h>
#include <hairvox/render/pipeline.h>
#include <hairvox/strands/groom_io.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>

namespace hairvox {
namespace {

/// The default scene, small: 800 strands at 96², writing into `dir`.
Scene smallScene(const test::TempDir& dir, GlobalTermMode mode = GlobalTermMode::Grid) {
    Scene scene = defaultScene();
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

double hairRadiance(const Film& film, std::size_t i) {
    const Rgb r = film.directR[i] + film.directTT[i] + film.directTRT[i] + film.backDirect[i] +
                  film.scatter[i];
    return double(r.r) + double(r.g) + double(r.b);
}

TEST(RenderPipeline, EveryModeWritesConsistentLayers) {
    test::TempDir dir;
    for (const GlobalTermMode mode :
         {GlobalTermMode::Grid, GlobalTermMode::Approx, GlobalTermMode::Exact}) {
        const Scene scene = smallScene(dir, mode);
        const SceneRender r = renderScene(scene, options(dir));
        ASSERT_EQ(r.written.size(), 2u) << toString(mode);
        EXPECT_EQ(r.image.stats.invalidSamples, 0u) << toString(mode);
        const ExrImage exr = readExr(scene.output.exr);
        for (const char* layer : {"R", "G", "B", "A", "direct_R.R", "direct_TT.G", "direct_TRT.B",
                                  "back_direct.R", "scatter.G", "Z", "key.V", "key.n",
                                  "key.T_s.R", "key.sigma_f.G", "back.V"})
            EXPECT_TRUE(exr.channels.count(layer)) << toString(mode) << ": no layer " << layer;
        // Beauty is the sum of its component layers; nothing non-finite or negative.
        double hair = 0;
        const std::size_t pixels = std::size_t(exr.width) * std::size_t(exr.height);
        for (std::size_t i = 0; i < pixels; ++i) {
            float sum = 0;
            for (const char* layer : {"direct_R.R", "direct_TT.R", "direct_TRT.R", "back_direct.R",
                                      "scatter.R", "head.R", "background.R"})
                sum += exr.channels.at(layer)[i];
            const float beauty = exr.channels.at("R")[i];
            ASSERT_TRUE(std::isfinite(beauty));
            ASSERT_GE(beauty, 0.0f);
            EXPECT_NEAR(beauty, sum, 2e-3f * std::max(1.0f, beauty)) << "pixel " << i; // half floats
            hair += double(exr.channels.at("scatter.R")[i]);
        }
        EXPECT_GT(hair, 0.0) << toString(mode) << ": no multiple scattering at all";
        // The film, at full precision, adds up exactly.
        for (std::size_t i = 0; i < r.image.film.pixelCount(); ++i) {
            const Film& f = r.image.film;
            const Rgb sum = f.directR[i] + f.directTT[i] + f.directTRT[i] + f.backDirect[i] +
                            f.scatter[i] + f.head[i] + f.background[i];
            EXPECT_NEAR(f.beauty(i).g, sum.g, 1e-6f);
        }
    }
}

TEST(RenderPipeline, NoLightGivesBlackHair) {
    test::TempDir dir;
    Scene scene = smallScene(dir);
    for (Light& light : scene.lights)
        light.intensity = 0;
    const SceneRender r = renderScene(scene, options(dir), false);
    for (const LightReport& l : r.lights)
        EXPECT_TRUE(l.skipped) << l.name;
    double hairAlpha = 0;
    for (std::size_t i = 0; i < r.image.film.pixelCount(); ++i) {
        EXPECT_EQ(hairRadiance(r.image.film, i), 0.0);
        hairAlpha += double(r.image.film.hairAlpha[i]);
    }
    EXPECT_GT(hairAlpha, 10.0); // the hair is there, and black
}

TEST(RenderPipeline, LightInsideTheHeadIsSkipped) {
    test::TempDir dir;
    Scene scene = smallScene(dir);
    static_cast<LightGeometry&>(scene.lights[1]) = LightGeometry::point(Vec3f(0.0f, 0.02f, 0.0f));
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
        const Vec3f line[5] = {{x, 0.03f, 0.13f}, {x, 0.01f, 0.13f}, {x, -0.01f, 0.13f},
                               {x, -0.03f, 0.13f}, {x, -0.05f, 0.13f}};
        groom.addStrand(line);
    }
    writeHairFile(scene.groom.file, groom);
    scene.camera.position = Vec3f(0, 0, 0.6f);
    scene.camera.lookAt = Vec3f(0, 0, 0);
    scene.lights.resize(1);
    static_cast<LightGeometry&>(scene.lights[0]) = LightGeometry::directional(Vec3f(0, 0, -1));
    const SceneRender shadowed = renderScene(scene, options(dir), false);
    double hairAlpha = 0;
    for (std::size_t i = 0; i < shadowed.image.film.pixelCount(); ++i) {
        EXPECT_EQ(hairRadiance(shadowed.image.film, i), 0.0) << "pixel " << i;
        hairAlpha += double(shadowed.image.film.hairAlpha[i]);
    }
    EXPECT_GT(hairAlpha, 5.0);
    EXPECT_EQ(shadowed.lights[0].stats.blockedByOccluder, shadowed.lights[0].stats.queries);
    // The same light in front of the head lights them.
    static_cast<LightGeometry&>(scene.lights[0]) = LightGeometry::directional(Vec3f(0, 0, 1));
    const SceneRender lit = renderScene(scene, options(dir), false);
    double radiance = 0;
    for (std::size_t i = 0; i < lit.image.film.pixelCount(); ++i)
        radiance += hairRadiance(lit.image.film, i);
    EXPECT_GT(radiance, 0.1);
}

TEST(RenderPipeline, SameBytesForAnyThreadCount) {
    test::TempDir dir;
    const Scene scene = smallScene(dir);
    const SceneRender one = renderScene(scene, options(dir, 1), false);
    for (const int threads : {2, 8}) {
        const SceneRender many = renderScene(scene, options(dir, threads), false);
        const Film& a = one.image.film;
        const Film& b = many.image.film;
        ASSERT_EQ(a.pixelCount(), b.pixelCount());
        const auto same = [](const auto& x, const auto& y) {
            return x.size() == y.size() &&
                   std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
        };
        EXPECT_TRUE(same(a.directR, b.directR) && same(a.directTT, b.directTT) &&
                    same(a.directTRT, b.directTRT) && same(a.backDirect, b.backDirect) &&
                    same(a.scatter, b.scatter) && same(a.alpha, b.alpha) && same(a.V, b.V) &&
                    same(a.T_s, b.T_s) && same(a.n, b.n) && same(a.depth, b.depth))
            << threads << " threads";
    }
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
