// hairvox film: an image as named layers of float channels (AOVs), the form
// every integrator fills and every image file is written from.
//
// A layer is RGB (3 channels) or scalar (1). Names follow OpenEXR's layer
// convention: the RGB layer "" is the beauty (channels R, G, B); "direct_R"
// has channels direct_R.R, direct_R.G, direct_R.B; a scalar layer's name is its
// channel's name ("A", "Z", "hair.A", "key.V"). What each layer means is the
// integrator's (render/ and pathtrace/ document theirs); the film only stores
// them. Storage is interleaved per layer (RGB RGB ...), row-major, row 0 at
// the top (geometry/camera.h).
#pragma once

#include <hairvox/core/large_array.h>
#include <hairvox/core/rgb.h>

#include <cstddef>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace hairvox {

struct FilmLayer {
    std::string name;
    int channels = 3; ///< 1 or 3
    /// Stored as 32-bit float in files even where half would hold the values
    /// (depth: half's 11-bit mantissa is too coarse).
    bool fullPrecision = false;
    LargeVector<float> data; ///< pixelCount() × channels

    Rgb rgb(std::size_t pixel) const {
        const float* p = &data[pixel * 3];
        return {p[0], p[1], p[2]};
    }
    float scalar(std::size_t pixel) const { return data[pixel]; }
};

class Film {
public:
    Film() = default;
    Film(int width, int height);

    int width() const { return width_; }
    int height() const { return height_; }
    std::size_t pixelCount() const { return std::size_t(width_) * std::size_t(height_); }
    std::size_t index(int x, int y) const {
        return std::size_t(y) * std::size_t(width_) + std::size_t(x);
    }

    /// What a new layer holds.
    enum class Init {
        Zero,
        /// Nothing yet: its producer writes every pixel before anything reads
        /// it, from the threads that render them (core/large_array.h: the
        /// pages are first touched there, not in a serial memset). Builds
        /// with HAIRVOX_POISON_UNINITIALIZED (the sanitizer builds) fill it
        /// with NaN, so that a pixel left unwritten shows in the tests.
        Uninitialized,
    };

    /// Adds a layer and returns its index. std::invalid_argument if the name
    /// is taken or channels is not 1 or 3.
    std::size_t addLayer(std::string name, int channels, bool fullPrecision = false,
                         Init init = Init::Zero);
    std::optional<std::size_t> find(std::string_view name) const;
    /// The named layer; std::out_of_range naming it if absent.
    const FilmLayer& layer(std::string_view name) const;
    FilmLayer& layer(std::string_view name);
    FilmLayer& layer(std::size_t index) { return layers_[index]; }
    const FilmLayer& layer(std::size_t index) const { return layers_[index]; }
    const std::vector<FilmLayer>& layers() const { return layers_; }

    /// The beauty layer "" (RGB).
    Rgb beauty(std::size_t pixel) const { return layer(kBeauty).rgb(pixel); }

    static constexpr std::string_view kBeauty = "";
    static constexpr std::string_view kAlpha = "A";

private:
    int width_ = 0, height_ = 0;
    std::vector<FilmLayer> layers_;
};

std::ostream& operator<<(std::ostream& os, const Film& film);

} // namespace hairvox
