// The film and its files (film/): layers round-trip through EXR at the
// precision each is stored with, the PNG is the tone-mapped preview, and a
// failed or interrupted write leaves nothing behind.
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/parallel.h>
#include <hairvox/core/rng.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/film/image_file.h>

#include <gtest/gtest.h>
#include <half.h>
#include <png.h>

#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <thread>

namespace hairvox {
namespace {

/// A film of pseudo-random layers: a beauty, an RGB layer, a scalar and a
/// full-precision scalar (depth-like).
/// `sparse` and `dense` written to EXR at every compression: the same
/// bytes. Leaves the last pair in `dir` (sparse.exr, dense.exr).
void expectTheSameFiles(const Film& sparse, const Film& dense, const std::filesystem::path& dir) {
    const auto bytes = [](const std::filesystem::path& path) {
        std::ifstream in(path, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    for (const auto& [compression, name] : kExrCompressionNames.entries) {
        ExrHeader header;
        header.compression = compression;
        writeExr(dir / "sparse.exr", sparse, header);
        writeExr(dir / "dense.exr", dense, header);
        EXPECT_EQ(bytes(dir / "sparse.exr"), bytes(dir / "dense.exr")) << name;
    }
}

Film randomFilm(int width, int height, std::uint64_t seed) {
    Film film(width, height);
    Pcg32 rng(seed);
    for (const auto& [name, channels, full] :
         {std::tuple{std::string(Film::kBeauty), 3, false}, std::tuple{std::string("A"), 1, false},
          std::tuple{std::string("direct_R"), 3, false}, std::tuple{std::string("key.V"), 1, false},
          std::tuple{std::string("Z"), 1, true}}) {
        FilmLayer& layer = film.layer(film.addLayer(name, channels, full));
        std::vector<float> values(film.pixelCount() * std::size_t(channels));
        for (float& x : values)
            x = full ? 1.0f + rng.uniformFloat() : rng.uniformFloat();
        layer.assign(values);
    }
    return film;
}

TEST(Film, LayersAreNamedOnce) {
    Film film(4, 3);
    EXPECT_EQ(film.addLayer("x", 3), 0u);
    EXPECT_EQ(film.addLayer("y", 1), 1u);
    EXPECT_EQ(film.layer("x").dense().size(), 36u);
    EXPECT_EQ(film.layer("y").dense().size(), 12u);
    EXPECT_THROW(film.addLayer("x", 1), std::invalid_argument);
    EXPECT_THROW(film.addLayer("z", 2), std::invalid_argument);
    EXPECT_THROW(static_cast<void>(film.layer("missing")), std::out_of_range);
    EXPECT_FALSE(film.find("missing"));
}

TEST(Film, HoldsOnlyTheTilesWrittenAndReadsZeroElsewhere) {
    // 70 × 40 pixels: 3 × 2 tiles, the last column and row partial.
    Film film(70, 40);
    FilmLayer& layer = film.layer(film.addLayer("x", 3));
    EXPECT_EQ(layer.tilesX(), 3);
    EXPECT_EQ(layer.tilesY(), 2);
    EXPECT_EQ(layer.tilesHeld(), 0u);
    EXPECT_EQ(film.bytesHeld(), 0u);
    EXPECT_EQ(film.denseBytes(), 70u * 40u * 3u * sizeof(float));
    EXPECT_EQ(layer.value(69, 39, 2), 0.0f);
    EXPECT_EQ(layer.rgb(film.index(69, 39)), Rgb(0.0f));
    EXPECT_EQ(layer.dense(), std::vector<float>(70 * 40 * 3, 0.0f));

    layer.at(69, 39, 2) = 5.0f;
    EXPECT_EQ(layer.tilesHeld(), 1u);
    EXPECT_NE(layer.tileOrNull(2, 1), nullptr);
    EXPECT_EQ(layer.tileOrNull(0, 0), nullptr);
    EXPECT_EQ(layer.value(69, 39, 2), 5.0f);
    EXPECT_EQ(layer.value(film.index(69, 39), 2), 5.0f);
    EXPECT_EQ(layer.value(68, 39, 2), 0.0f);
    EXPECT_EQ(layer.dense()[film.index(69, 39) * 3 + 2], 5.0f);
    EXPECT_EQ(film.bytesHeld(), FilmLayer::kTilePixels * 3 * sizeof(float));
    // A row: false, and nothing written, where its tiles are all not held;
    // else zeros where a tile is not held.
    std::vector<float> row(70 * 3, -1.0f);
    EXPECT_FALSE(layer.copyRow(5, row.data()));
    EXPECT_EQ(row, std::vector<float>(70 * 3, -1.0f));
    ASSERT_TRUE(layer.copyRow(39, row.data()));
    for (std::size_t i = 0; i < row.size(); ++i)
        EXPECT_EQ(row[i], i == 69 * 3 + 2 ? 5.0f : 0.0f) << i;

    // assign() holds the tiles with anything but +0 (−0 is kept), and
    // dense() gives back what it was given.
    std::vector<float> values(70 * 40 * 3, 0.0f);
    values[film.index(40, 5) * 3] = 1.0f;      // tile (1, 0)
    values[film.index(3, 35) * 3 + 1] = -0.0f; // tile (0, 1)
    Film other(70, 40);
    FilmLayer& assigned = other.layer(other.addLayer("y", 3));
    assigned.assign(values);
    EXPECT_EQ(assigned.tilesHeld(), 2u);
    EXPECT_NE(assigned.tileOrNull(1, 0), nullptr);
    EXPECT_NE(assigned.tileOrNull(0, 1), nullptr);
    const std::vector<float> back = assigned.dense();
    ASSERT_EQ(back.size(), values.size());
    for (std::size_t i = 0; i < values.size(); ++i)
        ASSERT_EQ(std::bit_cast<std::uint32_t>(back[i]), std::bit_cast<std::uint32_t>(values[i]))
            << i;
    EXPECT_THROW(assigned.assign(std::vector<float>(5)), std::invalid_argument);
}

TEST(ExrFile, TilesNotHeldWriteAsZeros) {
    // The same image, once with its zero tiles left out and once with every
    // tile held: the same file, byte for byte, at every compression.
    Film sparse(70, 40), dense(70, 40);
    for (Film* film : {&sparse, &dense}) {
        film->addLayer(std::string(Film::kBeauty), 3);
        film->addLayer("Z", 1, true);
        FilmLayer& beauty = film->layer(Film::kBeauty);
        beauty.at(40, 5, 0) = 0.5f;
        beauty.at(3, 35, 1) = -0.0f;
        // Z fills tile (0, 0), whose rows the chunks before rows 32–39
        // packed: those rows, none of whose Z tiles is held, must still be zeros.
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x)
                film->layer("Z").at(x, y) = 2.0f;
    }
    for (FilmLayer* l : {&dense.layer(Film::kBeauty), &dense.layer("Z")})
        for (int ty = 0; ty < l->tilesY(); ++ty)
            for (int tx = 0; tx < l->tilesX(); ++tx)
                l->tile(tx, ty);
    EXPECT_EQ(sparse.layer(Film::kBeauty).tilesHeld(), 2u);
    EXPECT_EQ(sparse.layer("Z").tilesHeld(), 1u);
    EXPECT_EQ(dense.layer(Film::kBeauty).tilesHeld(), 6u);
    test::TempDir dir;
    expectTheSameFiles(sparse, dense, dir.path());
    const ExrImage exr = readExr(dir / "sparse.exr");
    EXPECT_EQ(exr.channels.at("R")[sparse.index(40, 5)], 0.5f);
    EXPECT_TRUE(std::signbit(exr.channels.at("G")[sparse.index(3, 35)]));
    EXPECT_EQ(exr.channels.at("Z")[sparse.index(0, 0)], 2.0f);
    EXPECT_EQ(exr.channels.at("Z")[sparse.index(5, 35)], 0.0f);
}

TEST(Film, ALayersTilesNotHeldReadAsItsFill) {
    // A background-like layer: its fill is what it reads, allocates and
    // writes where it holds no tile.
    const Rgb background(0.05f, 0.06f, 0.07f);
    Film film(70, 40);
    // (Both added before either is referenced: adding a layer moves the others.)
    film.addLayer("bg", 3, false, background);
    film.addLayer("s", 1, false, Rgb(2.0f, 9.0f, 9.0f));
    FilmLayer& layer = film.layer("bg");
    const FilmLayer& scalar = film.layer("s");
    EXPECT_FALSE(layer.zeroFill());
    EXPECT_EQ(layer.rgb(film.index(69, 39)), background);
    EXPECT_EQ(layer.value(3, 4, 1), 0.06f);
    EXPECT_EQ(scalar.value(3, 4), 2.0f);
    EXPECT_TRUE(layer.isFill(2, 0.07f));
    EXPECT_FALSE(layer.isFill(2, 0.0f));
    EXPECT_EQ(layer.tilesHeld(), 0u);
    // A tile is allocated as the fill, its pixels outside the image too.
    layer.at(69, 39, 0) = 1.0f;
    const float* t = layer.tileOrNull(2, 1);
    ASSERT_NE(t, nullptr);
    for (std::size_t i = 0; i < FilmLayer::kTilePixels * 3; ++i)
        EXPECT_EQ(t[i], i == (7 * 32 + 5) * 3 ? 1.0f : background[int(i % 3)]) << i;
    // Rows and dense(): the fill where no tile is held.
    std::vector<float> row(70 * 3, -1.0f);
    EXPECT_FALSE(layer.copyRow(5, row.data()));
    ASSERT_TRUE(layer.copyRow(39, row.data()));
    for (std::size_t i = 0; i < row.size(); ++i)
        EXPECT_EQ(row[i], i == 69 * 3 ? 1.0f : background[int(i % 3)]) << i;
    const std::vector<float> values = layer.dense();
    for (std::size_t i = 0; i < values.size(); ++i)
        ASSERT_EQ(values[i], i == film.index(69, 39) * 3 ? 1.0f : background[int(i % 3)]) << i;
    // assign() holds only the tiles with a value other than the fill (a +0
    // is such a value here).
    Film other(70, 40);
    FilmLayer& assigned = other.layer(other.addLayer("bg", 3, false, background));
    std::vector<float> given = values;
    given[other.index(40, 5) * 3 + 1] = 0.0f; // tile (1, 0)
    assigned.assign(given);
    EXPECT_EQ(assigned.tilesHeld(), 2u);
    EXPECT_NE(assigned.tileOrNull(1, 0), nullptr);
    EXPECT_NE(assigned.tileOrNull(2, 1), nullptr);
    EXPECT_EQ(assigned.dense(), given);
}

TEST(ExrFile, TilesNotHeldWriteAsTheirLayersFill) {
    // A layer whose fill is a colour, with one tile held, and the same values
    // in a zero-fill layer holding every tile: the same file, byte for byte,
    // at every compression; and the fill in half where it fits.
    const Rgb background(0.05f, 0.06f, 0.07f);
    Film sparse(70, 40), dense(70, 40);
    sparse.addLayer(std::string(Film::kBeauty), 3, false, background);
    dense.addLayer(std::string(Film::kBeauty), 3);
    sparse.layer(Film::kBeauty).at(40, 5, 0) = 0.5f;
    FilmLayer& all = dense.layer(Film::kBeauty);
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 70; ++x)
            for (int c = 0; c < 3; ++c)
                all.at(x, y, c) = x == 40 && y == 5 && c == 0 ? 0.5f : background[c];
    EXPECT_EQ(sparse.layer(Film::kBeauty).tilesHeld(), 1u);
    test::TempDir dir;
    expectTheSameFiles(sparse, dense, dir.path());
    const ExrImage exr = readExr(dir / "sparse.exr");
    EXPECT_EQ(exr.channels.at("R")[sparse.index(40, 5)], 0.5f);
    EXPECT_NEAR(exr.channels.at("B")[sparse.index(69, 39)], 0.07f, 1e-4f);
}

TEST(ExrFile, EveryLayerRoundTripsAtItsPrecision) {
    const Film film = randomFilm(37, 23, 5);
    test::TempDir dir;
    ExrHeader header;
    header.attributes = {{"hairvox:note", "test"}};
    header.worldToCamera = Matrix44{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {2, 3, 4, 1}}};
    writeExr(dir / "image.exr", film, header);
    const ExrImage exr = readExr(dir / "image.exr");
    EXPECT_EQ(exr.width, 37);
    EXPECT_EQ(exr.height, 23);
    EXPECT_EQ(exr.attributes.at("hairvox:note"), "test");
    EXPECT_EQ(exr.attributes.at("software"), "hairvox");
    const char* rgb[3] = {"R", "G", "B"};
    EXPECT_EQ(exr.channels.size(), 3u + 1u + 3u + 1u + 1u);
    for (std::size_t p = 0; p < film.pixelCount(); ++p) {
        for (int c = 0; c < 3; ++c) {
            // Half: 11-bit mantissa, relative error ≤ 2^-11 in [0.5, 1), absolute below.
            ASSERT_NEAR(exr.channels.at(rgb[c])[p], film.beauty(p)[c], 5e-4f);
            ASSERT_NEAR(exr.channels.at(std::string("direct_R.") + rgb[c])[p],
                        film.layer("direct_R").rgb(p)[c], 5e-4f);
        }
        ASSERT_NEAR(exr.channels.at("key.V")[p], film.layer("key.V").scalar(p), 5e-4f);
        ASSERT_EQ(exr.channels.at("Z")[p], film.layer("Z").scalar(p)); // 32-bit float, exact
    }
}

TEST(ExrFile, BytesDoNotDependOnTheThreadCount) {
    const Film film = randomFilm(80, 60, 7);
    test::TempDir dir;
    auto bytes = [&](int threads) {
        const ThreadLimit limit(threads);
        const auto path = dir / strCat("t", threads, ".exr");
        writeExr(path, film);
        std::ifstream in(path, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::string one = bytes(1);
    EXPECT_GT(one.size(), 1000u);
    EXPECT_EQ(bytes(2), one);
    EXPECT_EQ(bytes(4), one);
}

TEST(ExrFile, ZipLevelTradesSizeAndIsChecked) {
    // A smooth image (as renders are), taller than one band of rows.
    Film film(300, 600);
    FilmLayer& beauty = film.layer(film.addLayer(std::string(Film::kBeauty), 3));
    std::vector<float> values(3 * film.pixelCount());
    for (std::size_t i = 0; i < values.size(); ++i)
        values[i] = 0.5f + 0.4f * std::sin(0.001f * float(i));
    beauty.assign(values);
    test::TempDir dir;
    std::uintmax_t size[10] = {};
    for (const int level : {1, 9}) {
        ExrHeader header;
        header.zipLevel = level;
        const auto path = dir / strCat("level", level, ".exr");
        writeExr(path, film, header);
        size[level] = std::filesystem::file_size(path);
        const std::vector<float> g = readExr(path).channels.at("G");
        ASSERT_EQ(g.size(), film.pixelCount());
        float worst = 0; // lossless up to half's rounding, at any level
        for (std::size_t p = 0; p < g.size(); ++p)
            worst = std::max(worst, std::abs(g[p] - values[3 * p + 1]));
        EXPECT_LT(worst, 1e-3f) << level;
    }
    EXPECT_LE(size[9], size[1]);
    ExrHeader bad;
    bad.zipLevel = 0;
    EXPECT_THROW(writeExr(dir / "bad.exr", film, bad), InputError);
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.exr"));
}

TEST(ExrFile, EveryCompressionIsLosslessAndTradesSize) {
    // A render-like image: smooth hair over a flat background.
    Film film(300, 600);
    std::vector<float> values(3 * film.pixelCount());
    for (std::size_t i = 0; i < values.size(); ++i)
        values[i] = (i / 3) % 300 < 150 ? 0.02f : 0.5f + 0.4f * std::sin(0.001f * float(i));
    film.layer(film.addLayer(std::string(Film::kBeauty), 3)).assign(values);
    test::TempDir dir;
    std::map<ExrCompression, std::uintmax_t> size;
    std::vector<float> first;
    for (const auto& [compression, name] : kExrCompressionNames.entries) {
        ExrHeader header;
        header.compression = compression;
        const auto path = dir / strCat(name, ".exr");
        writeExr(path, film, header);
        size[compression] = std::filesystem::file_size(path);
        const std::vector<float> g = readExr(path).channels.at("G");
        ASSERT_EQ(g.size(), film.pixelCount());
        if (first.empty())
            first = g;
        EXPECT_EQ(g, first) << name << ": the same half values as every other compression";
    }
    EXPECT_LT(size[ExrCompression::Zips], size[ExrCompression::Rle]);
    EXPECT_LT(size[ExrCompression::Rle], size[ExrCompression::None]);
}

TEST(ExrFile, NamesLongerThan31CharactersRoundTrip) {
    // A light's AOVs carry its name: OpenEXR needs the file's long-names
    // flag past 31 characters.
    Film film(5, 4);
    const std::string name = "a_rim_light_named_at_some_length.T_s";
    FilmLayer& layer = film.layer(film.addLayer(name, 3));
    std::vector<float> values(3 * film.pixelCount());
    for (std::size_t i = 0; i < values.size(); ++i)
        values[i] = 0.25f * float(i % 7);
    layer.assign(values);
    test::TempDir dir;
    ExrHeader header;
    header.attributes = {{"hairvox:an_attribute_named_past_31_chars", "x"}};
    writeExr(dir / "long.exr", film, header);
    const ExrImage exr = readExr(dir / "long.exr");
    EXPECT_EQ(exr.attributes.at("hairvox:an_attribute_named_past_31_chars"), "x");
    for (std::size_t p = 0; p < film.pixelCount(); ++p)
        ASSERT_EQ(exr.channels.at(name + ".G")[p], layer.rgb(p)[1]); // quarters: exact in half
}

TEST(ExrFile, KeepsValuesBeyondHalfRange) {
    Film film(4, 2);
    film.addLayer(std::string(Film::kBeauty), 3);
    film.layer(Film::kBeauty).at(3, 0) = 1e6f;
    test::TempDir dir;
    writeExr(dir / "bright.exr", film);
    const ExrImage exr = readExr(dir / "bright.exr");
    EXPECT_EQ(exr.channels.at("R")[3], 1e6f); // float, not Inf
}

TEST(ExrFile, HalvesRoundAsImathDoesOnEveryCpu) {
    // The writer converts to half with F16C where the CPU has it (SIMD) and
    // with Imath elsewhere: both must give Imath's bits (round to nearest,
    // ties to even), over the whole half range — denormals, ties, the top —
    // in scalar and RGB layers (3 floats apart) and in the vector tails.
    test::forEachSimdTarget([] {
        constexpr int width = 259, height = 7;
        Film film(width, height);
        const std::size_t rgbLayer = film.addLayer("direct_R", 3);
        const std::size_t scalarLayer = film.addLayer("key.V", 1);
        FilmLayer& rgb = film.layer(rgbLayer);
        FilmLayer& scalar = film.layer(scalarLayer);
        Pcg32 rng(17);
        std::vector<float> special{0.0f, -0.0f, 65504.0f, -65504.0f, 6.1035156e-5f, 5.9604645e-8f,
                                   2.9802322e-8f, 2.9802326e-8f, 8.940697e-8f, 1.0f + 1.0f / 2048.0f,
                                   1.0f + 3.0f / 2048.0f, 2049.0f, 2051.0f, 1e-30f};
        const auto value = [&](std::size_t i) {
            if (i < special.size())
                return special[i];
            // Exponents from 2^-30 (below every half) to 2^15, either sign.
            const float x = std::ldexp(1.0f + rng.uniformFloat(), int(rng.uniformFloat() * 46.0f) - 30);
            return rng.uniformFloat() < 0.5f ? -x : x;
        };
        std::vector<float> rgbValues(3 * film.pixelCount()), scalarValues(film.pixelCount());
        for (std::size_t i = 0; i < rgbValues.size(); ++i)
            rgbValues[i] = value(i);
        for (std::size_t i = 0; i < scalarValues.size(); ++i)
            scalarValues[i] = value(i);
        rgb.assign(rgbValues);
        scalar.assign(scalarValues);
        test::TempDir dir;
        writeExr(dir / "halves.exr", film);
        const ExrImage exr = readExr(dir / "halves.exr");
        const char* names[3] = {"direct_R.R", "direct_R.G", "direct_R.B"};
        for (std::size_t p = 0; p < film.pixelCount(); ++p) {
            for (std::size_t c = 0; c < 3; ++c) {
                const float x = rgbValues[3 * p + c];
                ASSERT_EQ(std::bit_cast<std::uint32_t>(exr.channels.at(names[c])[p]),
                          std::bit_cast<std::uint32_t>(float(Imath::half(x))))
                    << "pixel " << p << " channel " << c << " value " << x;
            }
            const float x = scalarValues[p];
            ASSERT_EQ(std::bit_cast<std::uint32_t>(exr.channels.at("key.V")[p]),
                      std::bit_cast<std::uint32_t>(float(Imath::half(x))))
                << "pixel " << p << " value " << x;
        }
    });
}

TEST(PngFile, IsTheTonemappedPreview) {
    const Film film = randomFilm(80, 60, 9);
    test::TempDir dir;
    const std::vector<std::uint8_t> preview = previewPixels(film, 0.5f, ToneMap::Filmic);
    writePng(dir / "preview.png", film.width(), film.height(), preview);
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    ASSERT_TRUE(png_image_begin_read_from_file(&image, (dir / "preview.png").c_str()));
    EXPECT_EQ(image.width, 80u);
    EXPECT_EQ(image.height, 60u);
    image.format = PNG_FORMAT_RGB;
    std::vector<std::uint8_t> pixels(PNG_IMAGE_SIZE(image));
    ASSERT_TRUE(png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr));
    EXPECT_EQ(pixels, preview);
}

TEST(PngFile, ToneMapsAreMonotoneAndDocumented) {
    Film film(5, 1);
    film.addLayer(std::string(Film::kBeauty), 3);
    const float values[5] = {0.0f, 0.0031308f, 0.18f, 1.0f, 100.0f};
    for (std::size_t i = 0; i < 5; ++i)
        for (std::size_t c = 0; c < 3; ++c)
            film.layer(Film::kBeauty).at(i, int(c)) = values[i];
    const std::vector<std::uint8_t> clamp = previewPixels(film, 0.0f, ToneMap::Clamp);
    EXPECT_EQ(clamp[0], 0);
    EXPECT_EQ(clamp[3], 10);  // 12.92 · 0.0031308 · 255 = 10.3
    EXPECT_EQ(clamp[6], 118); // sRGB(0.18) = 0.461
    EXPECT_EQ(clamp[9], 255);
    const std::vector<std::uint8_t> filmic = previewPixels(film, 0.0f, ToneMap::Filmic);
    for (int i = 1; i < 5; ++i)
        EXPECT_GE(filmic[std::size_t(i) * 3], filmic[std::size_t(i - 1) * 3]);
    EXPECT_LT(filmic[9], 255); // highlights roll off instead of clipping at 1
    EXPECT_EQ(filmic[12], 255);
    const std::vector<std::uint8_t> brighter = previewPixels(film, 1.0f, ToneMap::Clamp);
    EXPECT_GT(brighter[6], clamp[6]);
}

int filesIn(const std::filesystem::path& dir) {
    int files = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir))
        ++files;
    return files;
}

std::string firstLine(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::string text;
    std::getline(in, text);
    return text;
}

TEST(PngFile, FailedWritesLeaveNoFileAndKeepTheOldOne) {
    test::TempDir dir;
    const auto png = dir / "keep.png";
    test::writeText(png, "previous image");
    // libpng refuses a 0×0 image inside the writer.
    EXPECT_THROW(writePng(png, 0, 0, {}), InputError);
    EXPECT_EQ(firstLine(png), "previous image");
    EXPECT_THROW(writePng(dir / "new.png", 0, 0, {}), InputError);
    EXPECT_FALSE(std::filesystem::exists(dir / "new.png"));
    EXPECT_EQ(filesIn(dir.path()), 1); // no temporary left behind
    EXPECT_THROW(readExr(dir / "keep.png"), InputError);
}

// Regression (issue 8, Ctrl-C latency): the EXR writer polls for interruption
// between bands and lets Interrupted through. The interrupt arrives while the
// file is being written — the temporary exists — so the test fails if the
// writer does not stop, or stops without cleaning up, or never started.
TEST(ExrFile, InterruptedWriteLeavesTheOldFile) {
    const Film film = randomFilm(1024, 2048, 11); // seconds of compression on one thread
    test::TempDir dir;
    const auto path = dir / "keep.exr";
    test::writeText(path, "previous image");
    std::atomic<bool> done{false}, sawTemporary{false};
    std::thread interrupter([&] {
        while (!done) {
            if (filesIn(dir.path()) > 1) { // the writer's temporary is there
                sawTemporary = true;
                requestInterrupt();
                return;
            }
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
    });
    const ThreadLimit oneThread(1);
    bool interrupted = false;
    try {
        writeExr(path, film);
    } catch (const Interrupted&) {
        interrupted = true;
    }
    done = true;
    interrupter.join();
    clearInterrupt();
    ASSERT_TRUE(sawTemporary) << "the write finished before the interrupt could arrive";
    EXPECT_TRUE(interrupted);
    EXPECT_EQ(firstLine(path), "previous image");
    EXPECT_EQ(filesIn(dir.path()), 1); // no temporary left behind
}

} // namespace
} // namespace hairvox
