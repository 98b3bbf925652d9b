// Triangle meshes in a render (scene "meshes", pipeline/): a mesh hides the
// hair behind it (rasterizer and path tracer), blocks light in every
// global-term mode, receives the hair's shadow, and the Ratboy scene renders
// its mohawk on its body.
#include "scene_test_util.h"
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/film/image_file.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/strands/groom_io.h>

#include <gtest/gtest.h>

#include <cmath>

namespace hairvox {
namespace {

/// 100 straight strands along x ∈ [−0.03, 0.03] in a slab around y = 0, in
/// five layers staggered in z (not in columns, which no density model fits).
Groom strandSlab(float xOffset = 0.0f) {
    Groom groom;
    for (int j = 0; j < 20; ++j)
        for (int k = 0; k < 5; ++k) {
            const float y = -0.004f + 0.002f * float(k);
            const float z = -0.02f + 0.002f * float(j) + 0.0008f * float((3 * k) % 5);
            Vec3f line[7];
            for (int i = 0; i < 7; ++i)
                line[i] = Vec3f(xOffset - 0.03f + 0.01f * float(i), y, z);
            groom.addStrand(line);
        }
    return groom;
}

/// An axis-aligned rectangle at height y over x ∈ [x0, x1], z ∈ [z0, z1], as OBJ text.
std::string rectangleObj(float y, float x0, float x1, float z0, float z1) {
    return strCat("v ", x0, " ", y, " ", z0, "\nv ", x1, " ", y, " ", z0, "\nv ", x1, " ", y, " ",
                  z1, "\nv ", x0, " ", y, " ", z1, "\nf 1 2 3 4\n");
}

/// The slab lit from above, seen from the front (+z), no head.
Scene slabScene(const test::TempDir& dir, GlobalTermMode mode) {
    Scene scene = test::keyBackScene();
    scene.name = "slab";
    scene.groom.file = dir / "slab.hair";
    writeHairFile(scene.groom.file, strandSlab());
    scene.meshes.clear();
    scene.head.reset();
    scene.globalTermMode = mode;
    scene.exact.rays = 16;
    scene.exact.radius = 0.002f;
    scene.voxelSize = 0.002f;
    scene.camera.position = Vec3f(0.0f, 0.01f, 0.3f);
    scene.camera.lookAt = Vec3f(0.0f);
    scene.camera.width = scene.camera.height = 64;
    scene.camera.fovY = 20.0f;
    scene.lights.resize(1);
    scene.lights[0] = Light::directional(Vec3f(0.0f, 1.0f, 0.0f));
    scene.lights[0].name = "key";
    scene.lights[0].intensity = 2.0f;
    scene.output.exr.clear();
    scene.output.png.clear();
    return scene;
}

MeshSource meshFile(const test::TempDir& dir, const std::string& name, const std::string& obj) {
    MeshSource m;
    m.file = dir / name;
    test::writeText(m.file, obj);
    return m;
}

PipelineOptions options(const test::TempDir& dir) {
    PipelineOptions o;
    o.tableCacheDir = dir / "cache";
    return o;
}

TEST(Meshes, HideTheHairBehindThemInTheRasterizerAndThePathTracer) {
    test::TempDir dir;
    for (const Integrator integrator : {Integrator::DualScattering, Integrator::Path}) {
        Scene scene = slabScene(dir, GlobalTermMode::Grid);
        scene.integrator = integrator;
        scene.pathTrace.spp = 4;
        // A wall between the camera and the hair over x < 0 (the left half of the image).
        scene.meshes.push_back(meshFile(dir, "wall.obj",
                                        "v -1 -1 0.1\nv 0 -1 0.1\nv 0 1 0.1\nv -1 1 0.1\nf 1 2 3 4\n"));
        const SceneRender r = renderScene(scene, options(dir), false);
        const Film& film = r.film;
        double hairLeft = 0, hairRight = 0, surfaceLeft = 0;
        for (int y = 0; y < film.height(); ++y)
            for (int x = 0; x < film.width(); ++x) {
                const std::size_t i = film.index(x, y);
                const double hair = double(film.layer(kHairAlphaLayer).scalar(i));
                if (x < film.width() / 2 - 1) {
                    hairLeft += hair;
                    surfaceLeft += double(film.layer(Film::kAlpha).scalar(i)) - hair;
                } else if (x > film.width() / 2) {
                    hairRight += hair;
                }
            }
        EXPECT_EQ(hairLeft, 0.0) << toString(integrator) << ": hair seen through the wall";
        EXPECT_GT(hairRight, 20.0) << toString(integrator);
        EXPECT_GT(surfaceLeft, 0.9 * 31 * 64) << toString(integrator) << ": the wall covers the left half";
    }
}

/// Mean light V over the hair in the image's left (x < 0) and right halves.
std::pair<double, double> meanVisibility(const Film& film) {
    double v[2] = {0, 0}, w[2] = {0, 0};
    const auto V = film.find("key.V");
    EXPECT_TRUE(V);
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            if (x >= film.width() / 2 - 1 && x <= film.width() / 2)
                continue; // the boundary column sees both halves
            const std::size_t i = film.index(x, y);
            const double a = double(film.layer(kHairAlphaLayer).scalar(i));
            const int side = x < film.width() / 2 ? 0 : 1;
            v[side] += a * double(film.layer(*V).scalar(i));
            w[side] += a;
        }
    return {v[0] / w[0], v[1] / w[1]};
}

TEST(Meshes, BlockTheLightInEveryGlobalTermModeAndAgreeWithExactMode) {
    test::TempDir dir;
    std::pair<double, double> exact{};
    for (const GlobalTermMode mode : {GlobalTermMode::Exact, GlobalTermMode::Grid, GlobalTermMode::Approx}) {
        Scene scene = slabScene(dir, mode);
        // A roof over the hair's x < 0 half, between it and the light above.
        scene.meshes.push_back(meshFile(dir, "roof.obj", rectangleObj(0.05f, -1.0f, 0.0f, -1.0f, 1.0f)));
        const SceneRender r = renderScene(scene, options(dir), false);
        const auto [left, right] = meanVisibility(r.film);
        EXPECT_EQ(left, 0.0) << toString(mode) << ": light through the roof";
        EXPECT_GT(right, 0.2) << toString(mode);
        EXPECT_GT(r.lights[0].stats.blockedBySurface, 0u) << toString(mode);
        if (mode == GlobalTermMode::Exact)
            exact = {left, right};
        else // the unroofed half differs only by the hair's own shadow: the grid's usual error
            EXPECT_NEAR(right, exact.second, 0.1 * exact.second) << toString(mode);
    }
    // The path tracer: no direct light reaches the roofed half either.
    Scene scene = slabScene(dir, GlobalTermMode::Grid);
    scene.integrator = Integrator::Path;
    scene.pathTrace.spp = 4;
    scene.meshes.push_back(meshFile(dir, "roof.obj", rectangleObj(0.05f, -1.0f, 0.0f, -1.0f, 1.0f)));
    const Film film = renderScene(scene, options(dir), false).film;
    double directLeft = 0, directRight = 0;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            const Rgb d = film.layer("direct_R").rgb(film.index(x, y)) +
                          film.layer("direct_TRT").rgb(film.index(x, y));
            (x < film.width() / 2 - 1 ? directLeft : directRight) += double(d.r + d.g + d.b);
        }
    EXPECT_EQ(directLeft, 0.0);
    EXPECT_GT(directRight, 0.0);
}

TEST(Meshes, ReceiveTheHairsShadow) {
    // A floor under the hair, lit from above and a little from the front:
    // where the hair's shadow falls, the floor is darker than with the hair
    // moved away — never brighter — in every mode.
    test::TempDir dir;
    for (const GlobalTermMode mode : {GlobalTermMode::Grid, GlobalTermMode::Exact, GlobalTermMode::Approx}) {
        Scene scene = slabScene(dir, mode);
        scene.lights[0] = Light::directional(Vec3f(0.0f, 1.0f, 0.5f));
        scene.lights[0].name = "key";
        scene.camera.position = Vec3f(0.0f, 0.25f, -0.2f); // from behind and above: the shadow is in view
        scene.camera.lookAt = Vec3f(0.0f, -0.02f, -0.02f);
        scene.meshes.push_back(meshFile(dir, "floor.obj", rectangleObj(-0.02f, -0.2f, 0.2f, -0.2f, 0.2f)));
        const Film with = renderScene(scene, options(dir), false).film;
        writeHairFile(scene.groom.file, strandSlab(5.0f)); // the same hair far away
        const Film without = renderScene(scene, options(dir), false).film;
        writeHairFile(scene.groom.file, strandSlab());
        int shadowed = 0, floorPixels = 0;
        for (std::size_t i = 0; i < with.pixelCount(); ++i) {
            if (with.layer(kHairAlphaLayer).scalar(i) > 0)
                continue; // the floor seen through hair: not comparable
            const float a = with.layer(kSurfaceLayer).rgb(i).g, b = without.layer(kSurfaceLayer).rgb(i).g;
            if (!(b > 0))
                continue;
            ++floorPixels;
            EXPECT_LE(a, b * 1.0001f) << toString(mode) << " pixel " << i;
            shadowed += a < 0.9f * b ? 1 : 0;
        }
        EXPECT_GT(floorPixels, 1000) << toString(mode);
        EXPECT_GT(shadowed, 50) << toString(mode) << ": no shadow of the hair on the floor";
    }
}

TEST(Meshes, RatboyRendersItsMohawkOnItsBody) {
    test::TempDir dir;
    Scene scene = loadScene(test::dataDir() / "scenes" / "ratboy_mohawk.json");
    ASSERT_EQ(scene.meshes.size(), 1u);
    scene.camera.width = scene.camera.height = 96;
    scene.output.exr.clear();
    scene.output.png.clear();
    const SceneRender r = renderScene(scene, options(dir), false);
    EXPECT_EQ(r.raster->invalidSamples, 0u);
    const Film& film = r.film;
    double hair = 0, body = 0, keyBlocked = 0;
    for (std::size_t i = 0; i < film.pixelCount(); ++i) {
        const double h = double(film.layer(kHairAlphaLayer).scalar(i));
        hair += h;
        body += double(film.layer(Film::kAlpha).scalar(i)) - h;
    }
    for (const LightReport& l : r.lights)
        keyBlocked += double(l.stats.blockedBySurface);
    EXPECT_GT(hair, 200.0);
    EXPECT_GT(body, 0.15 * 96 * 96); // the body is in view
    EXPECT_GT(keyBlocked, 0.0);      // and shadows some hair
    EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
}

TEST(Meshes, BadMeshesAreErrorsNamingTheSceneEntryAndTheFile) {
    test::TempDir dir;
    Scene scene = slabScene(dir, GlobalTermMode::Grid);
    scene.meshes.push_back(meshFile(dir, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"));
    try {
        renderScene(scene, options(dir), false);
        FAIL() << "no error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("meshes[0]"), std::string::npos) << what;
        EXPECT_NE(what.find("bad.obj: line 4: vertex index 9 is out of range"), std::string::npos) << what;
    }
    scene.meshes.back().file = dir / "missing.obj";
    EXPECT_THROW(renderScene(scene, options(dir), false), InputError);
}

} // namespace
} // namespace hairvox
