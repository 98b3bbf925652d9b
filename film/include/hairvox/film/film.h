// hairvox film: an image as named layers of float channels (AOVs), the form
// every integrator fills and every image file is written from.
//
// A layer is RGB (3 channels) or scalar (1). Names follow OpenEXR's layer
// convention: the RGB layer "" is the beauty (channels R, G, B); "direct_R"
// has channels direct_R.R, direct_R.G, direct_R.B; a scalar layer's name is its
// channel's name ("A", "Z", "hair.A", "key.V"). What each layer means is the
// integrator's (render/ and pathtrace/ document theirs); the film only stores
// them. Row 0 is at the top (geometry/camera.h).
//
// Storage is sparse, in tiles of kTileSize² pixels (the rasterizer's tiles):
// a layer holds a tile only once something is written into it, and a tile it
// does not hold reads as the layer's fill — zeros, or a value per channel
// given when the layer is added (the rasterizer's background and beauty
// layers: the background colour, what every pixel shows where nothing is
// seen). Most AOVs are zero wherever no hair is seen — on the 1080p head, 80%
// of the tiles of every hair layer — and a film of dense layers was most of a
// render's memory (357 of the head's 679 MiB), every byte of it paid at its
// first touch (docs/DESIGN.md §7, "A sparse film"). Within a tile, pixels are
// row-major and a pixel's channels interleaved (RGB RGB ...); a tile at the
// image's right or bottom edge has the full size, its pixels outside the
// image the fill.
#pragma once

#include <hairvox/core/rgb.h>

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hairvox {

/// Whether v is +0, bit for bit (−0 and NaN are values of their own).
inline bool isPositiveZero(float v) {
    return std::bit_cast<std::uint32_t>(v) == 0;
}

class FilmLayer {
public:
    /// Pixels on a side of a tile.
    static constexpr int kTileSize = 32;
    static constexpr std::size_t kTilePixels = std::size_t(kTileSize) * kTileSize;

    /// `fill`: what each channel reads where no tile is held (the first
    /// `channels` values; zeros by default).
    FilmLayer(std::string name, int channels, bool fullPrecision, int width, int height,
              Rgb fill = Rgb(0.0f));

    std::string name;
    int channels = 3; ///< 1 or 3
    /// Stored as 32-bit float in files even where half would hold the values
    /// (depth: half's 11-bit mantissa is too coarse).
    bool fullPrecision = false;

    int width() const { return width_; }
    int height() const { return height_; }
    int tilesX() const { return tilesX_; }
    int tilesY() const { return tilesY_; }

    /// What channel c reads where no tile is held.
    float fill(int c = 0) const { return fill_[std::size_t(c)]; }
    /// Whether v is channel c's fill, bit for bit: what a tile not held
    /// already reads as (a value written needs no tile).
    bool isFill(std::size_t c, float v) const {
        return std::bit_cast<std::uint32_t>(v) == std::bit_cast<std::uint32_t>(fill_[c]);
    }
    /// Whether every channel's fill is +0.
    bool zeroFill() const;

    /// Channel c of pixel (x, y); the fill where the tile is not held.
    float value(int x, int y, int c = 0) const {
        const float* t = tileOrNull(x / kTileSize, y / kTileSize);
        return t ? t[offset(x, y) + std::size_t(c)] : fill(c);
    }
    /// Channel c of pixel (x, y), its tile allocated (the fill) if not held.
    float& at(int x, int y, int c = 0) {
        return tile(x / kTileSize, y / kTileSize)[offset(x, y) + std::size_t(c)];
    }

    /// The same by pixel index y · width + x.
    float value(std::size_t pixel, int c = 0) const { return value(xOf(pixel), yOf(pixel), c); }
    float& at(std::size_t pixel, int c = 0) { return at(xOf(pixel), yOf(pixel), c); }
    Rgb rgb(std::size_t pixel) const {
        const int x = xOf(pixel), y = yOf(pixel);
        const float* t = tileOrNull(x / kTileSize, y / kTileSize);
        if (!t)
            return {fill(0), fill(1), fill(2)};
        const float* p = t + offset(x, y);
        return {p[0], p[1], p[2]};
    }
    float scalar(std::size_t pixel) const { return value(pixel); }

    /// Tile (tx, ty)'s kTilePixels × channels values, or null if not held.
    const float* tileOrNull(int tx, int ty) const {
        return tiles_[std::size_t(ty) * std::size_t(tilesX_) + std::size_t(tx)].get();
    }
    /// Tile (tx, ty)'s values, allocated as the fill on the first call. Calls
    /// for different tiles may run concurrently; calls for one tile may not.
    float* tile(int tx, int ty);
    /// Tiles held, of tilesX() · tilesY().
    std::size_t tilesHeld() const;
    /// Bytes the held tiles take.
    std::size_t bytesHeld() const { return tilesHeld() * tileFloats() * sizeof(float); }

    /// Row y's width · channels values into `out`, the fill where no tile is
    /// held; false, and `out` untouched, where the row's tiles are all not
    /// held (the row is the fill).
    bool copyRow(int y, float* out) const;
    /// Every pixel's channels, row-major: width · height · channels values.
    std::vector<float> dense() const;
    /// Sets every pixel from `values` (dense()'s order; size checked).
    void assign(std::span<const float> values);

private:
    struct Free {
        void operator()(float* p) const noexcept { std::free(p); }
    };

    std::size_t tileFloats() const { return kTilePixels * std::size_t(channels); }
    /// `pixels` pixels' channels, each the fill, into `out`.
    void fillPixels(float* out, std::size_t pixels) const;
    int xOf(std::size_t pixel) const { return int(pixel % std::size_t(width_)); }
    int yOf(std::size_t pixel) const { return int(pixel / std::size_t(width_)); }
    /// Channel 0 of pixel (x, y) within its tile.
    std::size_t offset(int x, int y) const {
        return (std::size_t(y % kTileSize) * kTileSize + std::size_t(x % kTileSize)) *
               std::size_t(channels);
    }

    int width_ = 0, height_ = 0, tilesX_ = 0, tilesY_ = 0;
    std::array<float, 3> fill_{}; ///< per channel (the first `channels`), the rest 0
    std::vector<std::unique_ptr<float[], Free>> tiles_; ///< row-major, null: the fill
};

class Film {
public:
    static constexpr int kTileSize = FilmLayer::kTileSize;

    Film() = default;
    Film(int width, int height);

    int width() const { return width_; }
    int height() const { return height_; }
    std::size_t pixelCount() const { return std::size_t(width_) * std::size_t(height_); }
    std::size_t index(int x, int y) const {
        return std::size_t(y) * std::size_t(width_) + std::size_t(x);
    }

    /// Adds a layer, `fill` everywhere (zeros by default; a scalar layer
    /// takes fill.r) and holding no tile, and returns its index.
    /// std::invalid_argument if the name is taken or channels is not 1 or 3.
    std::size_t addLayer(std::string name, int channels, bool fullPrecision = false,
                         Rgb fill = Rgb(0.0f));
    std::optional<std::size_t> find(std::string_view name) const;
    /// The named layer; std::out_of_range naming it if absent.
    const FilmLayer& layer(std::string_view name) const;
    FilmLayer& layer(std::string_view name);
    FilmLayer& layer(std::size_t index) { return layers_[index]; }
    const FilmLayer& layer(std::size_t index) const { return layers_[index]; }
    const std::vector<FilmLayer>& layers() const { return layers_; }

    /// The beauty layer "" (RGB).
    Rgb beauty(std::size_t pixel) const { return layer(kBeauty).rgb(pixel); }
    /// Bytes the layers' held tiles take, and what dense layers would.
    std::size_t bytesHeld() const;
    std::size_t denseBytes() const;

    static constexpr std::string_view kBeauty = "";
    static constexpr std::string_view kAlpha = "A";

private:
    int width_ = 0, height_ = 0;
    std::vector<FilmLayer> layers_;
};

std::ostream& operator<<(std::ostream& os, const Film& film);

} // namespace hairvox
