#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/film/image_file.h>

#include <png.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace hairvox {

namespace {

/// Narkowicz 2015, "ACES Filmic Tone Mapping Curve": a fit of the ACES
/// reference rendering and output transforms, per channel.
float filmic(float x) {
    return std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
}

/// The sRGB transfer function (IEC 61966-2-1) of a value in [0, 1].
float srgbEncode(float v) {
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

} // namespace

std::vector<std::uint8_t> previewPixels(const Film& film, float exposure, ToneMap toneMap) {
    const float scale = std::exp2(exposure);
    std::vector<std::uint8_t> out(film.pixelCount() * 3);
    const FilmLayer& beauty = film.layer(Film::kBeauty);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, film.pixelCount(), 16384),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t p = range.begin(); p != range.end(); ++p) {
                              const Rgb c = beauty.rgb(p);
                              for (int ch = 0; ch < 3; ++ch) {
                                  const float x = std::max(c[ch] * scale, 0.0f);
                                  const float mapped =
                                      toneMap == ToneMap::Filmic ? filmic(x) : std::min(x, 1.0f);
                                  out[p * 3 + std::size_t(ch)] = static_cast<std::uint8_t>(
                                      std::lround(255.0f * srgbEncode(mapped)));
                              }
                          }
                      });
    return out;
}

std::vector<std::uint8_t> encodePng(int width, int height, const std::vector<std::uint8_t>& rgb) {
    if (width < 0 || height < 0 || rgb.size() != std::size_t(width) * std::size_t(height) * 3)
        throw std::logic_error(
            strCat("encodePng: ", rgb.size(), " bytes for ", width, " x ", height));
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    image.width = static_cast<png_uint_32>(width);
    image.height = static_cast<png_uint_32>(height);
    image.format = PNG_FORMAT_RGB;
    // One pass into a buffer of the largest size a PNG of this image can
    // have (asking libpng for the size first would encode it twice).
    png_alloc_size_t size = PNG_IMAGE_PNG_SIZE_MAX(image);
    std::vector<std::uint8_t> png(size);
    if (png_image_write_to_memory(&image, png.data(), &size, 0, rgb.data(), 0, nullptr)) {
        png.resize(size);
        return png;
    }
    const std::string message = image.message;
    png_image_free(&image);
    throw InputError(strCat("cannot encode PNG: ", message));
}

void writeEncodedPng(const std::filesystem::path& path, const std::vector<std::uint8_t>& png) {
    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
        out.close();
        if (!out)
            throw InputError(strCat(path.string(), ": cannot write PNG file"));
    });
}

void writePng(const std::filesystem::path& path, int width, int height,
              const std::vector<std::uint8_t>& rgb) {
    writeEncodedPng(path, encodePng(width, height, rgb));
}

} // namespace hairvox
