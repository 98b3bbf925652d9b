// The two integrators tied together (docs/DESIGN.md §8): path tracing to depth
// 1 — camera → fiber → light — is the rasterizer's single scattering with the
// exact global term's one shadow ray, V·f_s·cos θ_i. The same camera,
// coverage, lights, shadows and f_s, measured against the path tracer's own
// noise. The rasterizer is rendered finer than the path tracer: at the
// reference's resolution its one shading point per fragment and its
// compositing of a pixel's partly covering strands as if independent are what
// differ, not the light transport (docs/DESIGN.md §8).
#include "scene_test_util.h"
#include "test_util.h"

#include <hairvox/core/math.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/pipeline/scene.h>

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>
#include <string>

namespace hairvox {
namespace {

const std::vector<std::string> kDirect = {"direct_R", "direct_TT", "direct_TRT"};

struct Depth1 {
    double l1 = 0;             ///< rasterizer against the path tracer, over blocks
    double noiseL1 = 0;        ///< the L1 the path tracer's noise alone gives (its floor)
    double l1NoiseRemoved = 0; ///< l1 with that floor taken out (film/image_compare.h)
    double bias = 0;           ///< rasterizer against the path tracer, signed
    double coverageRatio = 0;  ///< Σ hair.A, rasterizer / path tracer
};

/// Path tracing to depth 1 at the scene's resolution against the rasterizer
/// rendered `super` times finer, as means over blocks of `block` × `block` of
/// the path tracer's pixels.
Depth1 compareDepth1(Scene scene, const test::TempDir& dir, std::uint32_t spp, int super = 8,
                     int block = 4) {
    PipelineOptions options;
    options.tableCacheDir = dir / "cache";
    scene.output = {};
    scene.integrator = Integrator::Path;
    scene.pathTrace.spp = spp;
    scene.pathTrace.maxDepth = 1; // camera → fiber → light
    const Film pt = renderScene(scene, options, false).film;
    // The rasterizer shades one point, with one shadow ray, per fragment, and
    // composites a pixel's fragments as if their coverages were independent:
    // it is rendered `super` times finer, and both are compared as means over
    // blocks of the path tracer's pixels, where what must agree is the mean,
    // not the pattern of point samples. (On the default scene over 4×4 blocks
    // at 4× its point sampling's own error, ~0.018 rel L1, was as large as the
    // path tracer's noise once that fell with stratified samples: 0.022
    // against a floor of 0.008, bias −0.4%; at 8× 0.017, bias −0.16%.)
    scene.integrator = Integrator::DualScattering;
    scene.globalTermMode = GlobalTermMode::Exact;
    scene.exact.rays = 1;
    scene.exact.radius = 0;
    scene.shadingRate = ShadingRate::Fragment;
    scene.camera.width *= static_cast<std::uint32_t>(super);
    scene.camera.height *= static_cast<std::uint32_t>(super);
    const Film ds = renderScene(scene, options, false).film;

    const ComparedImage reference =
        ComparedImage::fromFilm(pt, kDirect, "hair.A", "hair_half_a").boxFiltered(block);
    const ComparedImage estimate =
        ComparedImage::fromFilm(ds, kDirect, "hair.A").boxFiltered(super * block);
    const ImageError e = *compareImages(estimate, reference);
    Depth1 r;
    r.l1 = e.relL1;
    r.noiseL1 = e.noiseFloorL1;
    r.l1NoiseRemoved = e.relL1NoiseRemoved;
    r.bias = e.relBias;
    double covDs = 0, covPt = 0;
    for (std::size_t p = 0; p < reference.mask.size(); ++p) {
        covDs += double(estimate.mask[p]);
        covPt += double(reference.mask[p]);
    }
    r.coverageRatio = covDs / covPt;
    return r;
}

Scene smallDefault() {
    Scene scene = test::keyBackScene();
    scene.groom.procedural.strands = 1500; // k = 3: ribbons 3·D wide
    scene.camera.width = scene.camera.height = 96;
    return scene;
}

TEST(IntegratorsSlow, DepthOnePathTracingIsTheRasterizersSingleScattering) {
    test::TempDir dir;
    for (const auto& [name, scene] :
         {std::pair{"default", smallDefault()}, [] {
              Scene s = smallDefault();
              s.groom.procedural.style = GroomStyle::Curly;
              s.fiberScale.densityMultiplier = 1;
              s.groom.procedural.pointsPerStrand = 128;        // segments ~1/10 of a turn
              s.camera.position = Vec3f(-0.12f, 0.12f, -0.3f); // the curls over the crown
              s.camera.lookAt = Vec3f(0.02f, 0.06f, -0.04f);
              // Lit from the camera's side, as this bound was measured (the
              // default scene's lights now face its front view).
              s.lights[0].direction = glm::normalize(Vec3f(-0.6f, 0.65f, -0.45f));
              s.lights[1].direction = glm::normalize(Vec3f(0.45f, 0.3f, 0.85f));
              return std::pair{"curly close-up", s};
          }()}) {
        const Depth1 r = compareDepth1(scene, dir, 1024);
        RecordProperty(std::string(name) + " rel L1", std::to_string(r.l1));
        RecordProperty(std::string(name) + " noise", std::to_string(r.noiseL1));
        RecordProperty(std::string(name) + " bias", std::to_string(r.bias));
        RecordProperty(std::string(name) + " coverage ratio", std::to_string(r.coverageRatio));
        EXPECT_LT(r.l1, 1.15 * r.noiseL1 + 0.01) << name << ": noise " << r.noiseL1;
        EXPECT_LT(std::abs(r.bias), 0.02) << name;
        EXPECT_NEAR(r.coverageRatio, 1.0, 0.02) << name;
    }
}

/// A scene of data/scenes at 160² (density multiplier k unless 0).
Scene sceneAt160(const char* file, float k) {
    Scene scene = loadScene(test::dataDir() / "scenes" / file);
    if (k > 0)
        scene.fiberScale.densityMultiplier = k;
    scene.camera.width = scene.camera.height = 160;
    return scene;
}

/// Issue 36 §3: on real grooms at low resolution with a large density
/// multiplier (ribbons 0.04–0.14 pixel wide, several strands a pixel) depth-1
/// path tracing is the rasterizer's single scattering within 2% over 8×8
/// blocks — once the rasterizer is rendered fine enough that its estimate of
/// a pixel (a point per fragment, partial coverages composited) has converged
/// (Ratboy at 160²: 0.047 at the same resolution, 0.033, 0.021, 0.013 at 2×,
/// 4×, 8×; docs/DESIGN.md §8).
void expectDepth1Within2Percent(const char* name, const Scene& scene, int super) {
    test::TempDir dir;
    const Depth1 r = compareDepth1(scene, dir, 256, super, 8);
    testing::Test::RecordProperty("rel L1", std::to_string(r.l1));
    testing::Test::RecordProperty("noise", std::to_string(r.noiseL1));
    testing::Test::RecordProperty("rel L1 noise removed", std::to_string(r.l1NoiseRemoved));
    testing::Test::RecordProperty("bias", std::to_string(r.bias));
    testing::Test::RecordProperty("coverage ratio", std::to_string(r.coverageRatio));
    EXPECT_LT(r.l1NoiseRemoved, 0.02) << name << ": rel L1 " << r.l1 << ", noise " << r.noiseL1;
    EXPECT_LT(std::abs(r.bias), 0.01) << name;
    EXPECT_NEAR(r.coverageRatio, 1.0, 0.01) << name;
}

TEST(IntegratorsSlow, DepthOneOnRatboyAt160WithDensityMultiplier8) {
    expectDepth1Within2Percent("Ratboy", sceneAt160("ratboy_mohawk.json", 8), 8);
}

TEST(IntegratorsSlow, DepthOneOnTheBearAt160WithDensityMultiplier8) {
    expectDepth1Within2Percent("bear", sceneAt160("bear.json", 8), 4);
}

TEST(IntegratorsSlow, DepthOneOnTheDefaultSceneAt160) {
    Scene scene = test::keyBackScene();
    scene.camera.width = scene.camera.height = 160;
    expectDepth1Within2Percent("default scene", scene, 4);
}

/// Grid mode's visible direct term (V·f_s·cos θ_i summed over the hair) over
/// exact mode's, one shadow ray per point (unbiased for the mean V).
double gridOverExactDirect(Scene scene, const test::TempDir& dir,
                           GridEvaluation evaluation = GridEvaluation::Cache,
                           float startOffset = GridOptions{}.startOffset) {
    PipelineOptions options;
    options.tableCacheDir = dir / "cache";
    options.grid.evaluation = evaluation;
    options.grid.startOffset = startOffset;
    scene.output = {};
    scene.globalTermMode = GlobalTermMode::Exact;
    scene.exact.rays = 1;
    const Film exact = renderScene(scene, options, false).film;
    scene.globalTermMode = GlobalTermMode::Grid;
    const Film grid = renderScene(scene, options, false).film;
    return 1.0 + compareImages(ComparedImage::fromFilm(grid, kDirect, "hair.A"),
                               ComparedImage::fromFilm(exact, kDirect, "hair.A"))
                     ->relBias;
}

TEST(IntegratorsSlow, GridStartOffsetOnASparseGroom) {
    // With the own fiber's optical depth taken out, what the start offset
    // skips is the splat of the fibers under a visible point smeared out in
    // front of it — a dense layer's (docs/DESIGN.md §8). This groom (1,500
    // strands, k = 3) has none: from the point grid is exact's (measured
    // +0.03%), and each offset brightens it by what it skips (0.4, the
    // default: +1.3%; 1: +3.1%).
    test::TempDir dir;
    Scene scene = smallDefault();
    scene.camera.width = scene.camera.height = 128;
    std::map<float, double> error;
    for (const float offset : {0.0f, 0.4f, 1.0f}) {
        error[offset] = gridOverExactDirect(scene, dir, GridEvaluation::Cache, offset) - 1.0;
        RecordProperty("error at offset " + std::to_string(offset), std::to_string(error[offset]));
    }
    EXPECT_EQ(GridOptions{}.startOffset, 0.4f);
    EXPECT_LT(std::abs(error[0.0f]), 0.01);
    EXPECT_LT(error[0.0f], error[0.4f]);
    EXPECT_LT(error[0.4f], error[1.0f]);
    EXPECT_LT(std::abs(error[0.4f]), 0.02);
}

/// Issue 36 §2: the expected optical depth of a point's own fiber
/// (grid_global_term.cpp ownFiberCrossings()) is what the grid counts that
/// exact mode does not. Marched from the point itself (start offset 0) with
/// it taken out, the visible single scattering of the real grooms at large
/// density multipliers is exact's within 1% (measured 0.998–1.003; without
/// it 0.93–0.98).
TEST(IntegratorsSlow, GridWithoutTheOwnFiberIsExactOnRealGroomsMarchedFromThePoint) {
    test::TempDir dir;
    for (const auto& [name, scene] :
         {std::pair{"Ratboy k = 8", sceneAt160("ratboy_mohawk.json", 8)},
          std::pair{"bear k = 12", sceneAt160("bear.json", 0)},
          std::pair{"bear k = 8", sceneAt160("bear.json", 8)}}) {
        const double ratio = gridOverExactDirect(scene, dir, GridEvaluation::March, 0.0f);
        RecordProperty(name, std::to_string(ratio));
        EXPECT_NEAR(ratio, 1.0, 0.01) << name;
    }
}

/// Issue 36 §2: grid single scattering with the defaults (the cache, the own
/// fiber taken out, start offset 0.4) against exact mode at 160² on the
/// project's scenes at their density multipliers and at k = 8, and on the
/// clumped groom (data/scenes/locks.json: 7,500 strands pulled into locks of
/// 48, k = 8). Before: 0.992, 0.953, 0.969, 0.981, 1.011, 1.011.
TEST(IntegratorsSlow, GridSingleScatteringIsExactsOnTheProjectsGrooms) {
    test::TempDir dir;
    Scene defaultAt8 = sceneAt160("key_back.json", 8);
    struct Case {
        const char* name;
        Scene scene;
        double tolerance;
    };
    // The default scene at k = 8 (160,000 hairs on the head) is the densest
    // layer: the splat's smear of the fibers under a point out in front of it
    // leaves it 2.7% dark at the chosen offset (docs/DESIGN.md §8).
    for (const Case& c : {Case{"default k = 3", sceneAt160("key_back.json", 0), 0.02},
                          Case{"default k = 8", defaultAt8, 0.03},
                          Case{"locks k = 8", sceneAt160("locks.json", 0), 0.02},
                          Case{"Ratboy k = 8", sceneAt160("ratboy_mohawk.json", 8), 0.02},
                          Case{"Ratboy k = 4", sceneAt160("ratboy_mohawk.json", 0), 0.02},
                          Case{"bear k = 12", sceneAt160("bear.json", 0), 0.025},
                          Case{"bear k = 8", sceneAt160("bear.json", 8), 0.02}}) {
        const double ratio = gridOverExactDirect(c.scene, dir);
        RecordProperty(c.name, std::to_string(ratio));
        std::cout << c.name << ": grid / exact " << ratio << "\n";
        EXPECT_NEAR(ratio, 1.0, c.tolerance) << c.name;
    }
}

} // namespace
} // namespace hairvox
