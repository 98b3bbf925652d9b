#include "render/test_shaders.h"
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/parallel.h>
#include <hairvox/render/output.h>
#include <hairvox/render/render.h>
#include <hairvox/strands/procedural.h>

#include <png.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace hairvox {
namespace {

struct Rendered {
    Scene scene;
    Film film;
};

Rendered renderSmall() {
    Scene scene = test::testScene(80, 60, Vec3f(0.45f, 0.05f, -0.6f), Vec3f(0.0f, -0.1f, -0.05f));
    scene.head = Head{};
    scene.lights.push_back(Light{LightGeometry::directional(glm::normalize(Vec3f(0.6f, 0.7f, 0.4f))), "key", Rgb(1.0f),
                                 3.0f});
    scene.lights.push_back(Light{LightGeometry::directional(Vec3f(0, 0, 1)), "back", Rgb(1.0f), 2.0f});
    scene.background = Rgb(0.02f, 0.03f, 0.04f);
    ProceduralGroomParams params;
    params.strands = 600;
    const test::SmoothShader shader(scene.lights.size());
    return {scene, renderImage(generateGroom(params), scene, shader).film};
}

TEST(Output, ExrHasEveryLayerAndBeautyIsTheirSum) {
    const Rendered r = renderSmall();
    test::TempDir dir;
    const auto path = dir / "image.exr";
    writeExr(path, r.film, Camera(r.scene.camera), {{"hairvox:note", "test"}});
    const ExrImage exr = readExr(path);
    EXPECT_EQ(exr.width, 80);
    EXPECT_EQ(exr.height, 60);
    EXPECT_EQ(exr.attributes.at("hairvox:note"), "test");
    EXPECT_EQ(exr.attributes.at("software"), "hairvox");
    const std::vector<std::string> layers = {"direct_R", "direct_TT", "direct_TRT", "back_direct",
                                             "scatter", "head", "background"};
    for (const char* name :
         {"R", "G", "B", "A", "hair.A", "Z", "key.V", "key.n", "key.T_s.R", "key.sigma_f.B",
          "back.V", "back.n", "back.T_s.G", "back.sigma_f.R"})
        EXPECT_TRUE(exr.channels.count(name)) << name;
    const char* rgb[3] = {"R", "G", "B"};
    int hairPixels = 0;
    for (std::size_t p = 0; p < r.film.pixelCount(); ++p) {
        for (int c = 0; c < 3; ++c) {
            const float beauty = exr.channels.at(rgb[c])[p];
            float components = 0;
            for (const std::string& layer : layers) {
                const float v = exr.channels.at(layer + "." + rgb[c])[p];
                ASSERT_TRUE(std::isfinite(v) && v >= 0) << layer << " " << p;
                components += v;
            }
            ASSERT_TRUE(std::isfinite(beauty) && beauty >= 0);
            // Half precision: 2^-11 relative per layer.
            ASSERT_NEAR(beauty, components, 4e-3f * components + 1e-5f) << p;
        }
        hairPixels += exr.channels.at("hair.A")[p] > 0 ? 1 : 0;
        ASSERT_NEAR(exr.channels.at("Z")[p], r.film.depth[p], 0.0f); // 32-bit float
    }
    EXPECT_GT(hairPixels, 200);
}

TEST(Output, ExrBytesDoNotDependOnTheThreadCount) {
    const Rendered r = renderSmall();
    test::TempDir dir;
    auto bytes = [&](int threads) {
        const ThreadLimit limit(threads);
        const auto path = dir / strCat("t", threads, ".exr");
        writeExr(path, r.film, Camera(r.scene.camera));
        std::ifstream in(path, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::string one = bytes(1);
    EXPECT_GT(one.size(), 1000u);
    EXPECT_EQ(bytes(2), one);
    EXPECT_EQ(bytes(4), one);
}

TEST(Output, ExrKeepsValuesBeyondHalfRange) {
    Film film(4, 2, {});
    film.directR[3] = Rgb(1e6f, 2.0f, 3.0f);
    CameraParams params;
    params.width = 4;
    params.height = 2;
    test::TempDir dir;
    writeExr(dir / "bright.exr", film, Camera(params));
    const ExrImage exr = readExr(dir / "bright.exr");
    EXPECT_EQ(exr.channels.at("direct_R.R")[3], 1e6f); // float, not Inf
    EXPECT_EQ(exr.channels.at("R")[3], 1e6f);
}

TEST(Output, PngIsTheTonemappedPreview) {
    const Rendered r = renderSmall();
    test::TempDir dir;
    writePng(dir / "preview.png", r.film, 0.5f, ToneMap::Filmic);
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    ASSERT_TRUE(png_image_begin_read_from_file(&image, (dir / "preview.png").c_str()));
    EXPECT_EQ(image.width, 80u);
    EXPECT_EQ(image.height, 60u);
    image.format = PNG_FORMAT_RGB;
    std::vector<std::uint8_t> pixels(PNG_IMAGE_SIZE(image));
    ASSERT_TRUE(png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr));
    EXPECT_EQ(pixels, previewPixels(r.film, 0.5f, ToneMap::Filmic));
}

TEST(Output, ToneMapsAreMonotoneAndDocumented) {
    Film film(5, 1, {});
    const float values[5] = {0.0f, 0.0031308f, 0.18f, 1.0f, 100.0f};
    for (int i = 0; i < 5; ++i)
        film.directTT[std::size_t(i)] = Rgb(values[i]);
    const std::vector<std::uint8_t> clamp = previewPixels(film, 0.0f, ToneMap::Clamp);
    EXPECT_EQ(clamp[0], 0);
    EXPECT_EQ(clamp[3], 10);   // 12.92 · 0.0031308 · 255 = 10.3
    EXPECT_EQ(clamp[6], 118);  // sRGB(0.18) = 0.461
    EXPECT_EQ(clamp[9], 255);
    const std::vector<std::uint8_t> filmic = previewPixels(film, 0.0f, ToneMap::Filmic);
    for (int i = 1; i < 5; ++i)
        EXPECT_GE(filmic[std::size_t(i) * 3], filmic[std::size_t(i - 1) * 3]);
    EXPECT_LT(filmic[9], 255); // highlights roll off instead of clipping at 1
    EXPECT_EQ(filmic[12], 255);
    const std::vector<std::uint8_t> brighter = previewPixels(film, 1.0f, ToneMap::Clamp);
    EXPECT_GT(brighter[6], clamp[6]);
}

TEST(Output, WriteOutputsWritesWhatTheSceneAsksFor) {
    Rendered r = renderSmall();
    test::TempDir dir;
    r.scene.output.exr = dir / "sub/a.exr";
    r.scene.output.png = dir / "sub/a.png";
    const auto written = writeOutputs(r.film, r.scene);
    ASSERT_EQ(written.size(), 2u);
    EXPECT_TRUE(std::filesystem::exists(dir / "sub/a.exr"));
    EXPECT_TRUE(std::filesystem::exists(dir / "sub/a.png"));
    EXPECT_EQ(readExr(dir / "sub/a.exr").attributes.at("hairvox:globalTermMode"), "grid");
    r.scene.output.png.clear();
    EXPECT_EQ(writeOutputs(r.film, r.scene).size(), 1u);
}

TEST(Output, FailedWritesLeaveNoFileAndKeepTheOldOne) {
    test::TempDir dir;
    const auto png = dir / "keep.png";
    test::writeText(png, "previous image");
    const Film empty(0, 0, {}); // libpng refuses a 0×0 image inside the writer
    EXPECT_THROW(writePng(png, empty, 0.0f, ToneMap::Clamp), InputError);
    std::ifstream in(png);
    std::string text;
    std::getline(in, text);
    EXPECT_EQ(text, "previous image");
    EXPECT_THROW(writePng(dir / "new.png", empty, 0.0f, ToneMap::Clamp), InputError);
    EXPECT_FALSE(std::filesystem::exists(dir / "new.png"));
    int files = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path()))
        ++files;
    EXPECT_EQ(files, 1); // no temporary left behind
    EXPECT_THROW(readExr(dir / "keep.png"), InputError);
}

// Regression (issue 8, Ctrl-C latency): the EXR writer polls for interruption
// between bands and lets Interrupted through (it used to become an InputError
// naming the file, and a 1024² image compressed for seconds after Ctrl-C).
TEST(Output, InterruptedExrWriteLeavesTheOldFile) {
    const Rendered r = renderSmall();
    test::TempDir dir;
    const auto path = dir / "keep.exr";
    test::writeText(path, "previous image");
    requestInterrupt();
    EXPECT_THROW(writeExr(path, r.film, Camera(r.scene.camera), {}), Interrupted);
    clearInterrupt();
    std::ifstream in(path);
    std::string text;
    std::getline(in, text);
    EXPECT_EQ(text, "previous image");
    int files = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path()))
        ++files;
    EXPECT_EQ(files, 1); // no temporary left behind
}

} // namespace
} // namespace hairvox
