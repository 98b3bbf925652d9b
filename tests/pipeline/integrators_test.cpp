// The two integrators tied together (docs/DESIGN.md §8): path tracing to depth
// 1 — camera → fiber → light — is the rasterizer's single scattering with the
// exact global term's one shadow ray, V·f_s·cos θ_i. The same camera,
// coverage, lights, shadows and f_s, measured against the path tracer's own
// noise.
#include "test_util.h"

#include <hairvox/core/math.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/pipeline/pipeline.h>

#include <gtest/gtest.h>

#include <cmath>

namespace hairvox {
namespace {

const std::vector<std::string> kDirect = {"direct_R", "direct_TT", "direct_TRT"};

struct Depth1 {
    double l1 = 0;          ///< rasterizer against the mean of two path traces, 4×4 block means
    double noiseL1 = 0;     ///< what the path traces' noise alone gives: L1(PT₁, PT₂)/2
    double bias = 0;        ///< rasterizer against the path traces, signed
    double coverageRatio = 0; ///< Σ hair.A, rasterizer / path tracer
};

Depth1 compareDepth1(Scene scene, const test::TempDir& dir, std::uint32_t spp) {
    scene.globalTermMode = GlobalTermMode::Exact;
    scene.exact.rays = 1;
    scene.exact.radius = 0;
    scene.output = {};
    PipelineOptions options;
    options.tableCacheDir = dir / "cache";
    const Film ds = renderScene(scene, options, false).film;
    scene.integrator = Integrator::Path;
    scene.pathTrace.spp = spp;
    scene.pathTrace.maxDepth = 1; // camera → fiber → light
    std::vector<Film> pt;
    for (const std::uint64_t seed : {1u, 2u}) {
        scene.pathTrace.seed = seed;
        pt.push_back(renderScene(scene, options, false).film);
    }
    // Over 4×4 blocks: the rasterizer shades one point (one shadow ray) per
    // fragment and aliases where the path tracer integrates each pixel; what
    // must agree is the mean, not that pattern.
    constexpr int kBlock = 4;
    const ComparedImage a = ComparedImage::fromFilm(pt[0], kDirect, "hair.A").boxFiltered(kBlock);
    const ComparedImage b = ComparedImage::fromFilm(pt[1], kDirect, "hair.A").boxFiltered(kBlock);
    ComparedImage mean = a;
    for (std::size_t p = 0; p < mean.value.size(); ++p) {
        mean.value[p] = 0.5f * (a.value[p] + b.value[p]);
        mean.mask[p] = 0.5f * (a.mask[p] + b.mask[p]);
    }
    Depth1 r;
    const ComparedImage dsImage =
        ComparedImage::fromFilm(ds, kDirect, "hair.A").boxFiltered(kBlock);
    const ImageError e = *compareImages(dsImage, mean);
    r.l1 = e.relL1;
    r.bias = e.relBias;
    r.noiseL1 = 0.5 * compareImages(a, b)->relL1;
    double covDs = 0, covPt = 0;
    for (std::size_t p = 0; p < mean.mask.size(); ++p) {
        covDs += double(dsImage.mask[p]);
        covPt += double(mean.mask[p]);
    }
    r.coverageRatio = covDs / covPt;
    return r;
}

Scene smallDefault() {
    Scene scene = defaultScene();
    scene.groom.procedural.strands = 1500;
    scene.camera.width = scene.camera.height = 96;
    return scene;
}

// The default scene's groom (k = 3: the rasterizer composites a strand's
// coverage α as 1 − (1 − α)³, the path tracer meets ribbons 3D wide — the same
// to first order in α, a little less where thin strands cross a pixel alone).
TEST(IntegratorsSlow, DepthOnePathTracingIsTheRasterizersSingleScattering) {
    test::TempDir dir;
    for (const auto& [name, scene] : {std::pair{"default, k = 3", smallDefault()}, [] {
             Scene s = smallDefault();
             s.groom.procedural.style = GroomStyle::Curly;
             s.fiberScale.densityMultiplier = 1;
             s.camera.position = Vec3f(-0.28f, -0.1f, -0.35f); // a close-up of the curls
             s.camera.lookAt = Vec3f(-0.05f, -0.2f, -0.1f);
             return std::pair{"curly close-up, k = 1", s};
         }()}) {
        const Depth1 r = compareDepth1(scene, dir, 512);
        RecordProperty(std::string(name) + " rel L1", std::to_string(r.l1));
        RecordProperty(std::string(name) + " noise", std::to_string(r.noiseL1));
        RecordProperty(std::string(name) + " bias", std::to_string(r.bias));
        EXPECT_LT(r.l1, 1.15 * r.noiseL1 + 0.01) << name << ": noise " << r.noiseL1;
        EXPECT_LT(std::abs(r.bias), 0.02) << name;
        EXPECT_NEAR(r.coverageRatio, 1.0, 0.02) << name;
    }
}

} // namespace
} // namespace hairvox
