#include <hairvox/core/error.h>
#include <hairvox/film/film.h>

#include <algorithm>
#include <new>
#include <stdexcept>

namespace hairvox {

FilmLayer::FilmLayer(std::string name_, int channels_, bool fullPrecision_, int width, int height,
                     Rgb fill)
    : name(std::move(name_))
    , channels(channels_)
    , fullPrecision(fullPrecision_)
    , width_(width)
    , height_(height)
    , tilesX_((width + kTileSize - 1) / kTileSize)
    , tilesY_((height + kTileSize - 1) / kTileSize)
    , tiles_(std::size_t(tilesX_) * std::size_t(tilesY_)) {
    for (int c = 0; c < std::min(channels, 3); ++c)
        fill_[std::size_t(c)] = fill[c];
}

void FilmLayer::fillPixels(float* out, std::size_t pixels) const {
    if (channels == 1) {
        std::fill_n(out, pixels, fill_[0]);
        return;
    }
    for (std::size_t p = 0; p < pixels; ++p, out += 3) {
        out[0] = fill_[0];
        out[1] = fill_[1];
        out[2] = fill_[2];
    }
}

bool FilmLayer::zeroFill() const {
    return std::all_of(fill_.begin(), fill_.end(), [](float v) { return isPositiveZero(v); });
}

float* FilmLayer::tile(int tx, int ty) {
    auto& t = tiles_[std::size_t(ty) * std::size_t(tilesX_) + std::size_t(tx)];
    if (!t) {
        if (zeroFill()) {
            // calloc: zeros without a pass of our own where the allocator
            // hands out fresh pages.
            t.reset(static_cast<float*>(std::calloc(tileFloats(), sizeof(float))));
            if (!t)
                throw std::bad_alloc();
        } else {
            t.reset(static_cast<float*>(std::malloc(tileFloats() * sizeof(float))));
            if (!t)
                throw std::bad_alloc();
            fillPixels(t.get(), kTilePixels);
        }
    }
    return t.get();
}

std::size_t FilmLayer::tilesHeld() const {
    return std::size_t(
        std::count_if(tiles_.begin(), tiles_.end(), [](const auto& t) { return t != nullptr; }));
}

bool FilmLayer::copyRow(int y, float* out) const {
    const int ty = y / kTileSize;
    bool any = false;
    for (int tx = 0; tx < tilesX_ && !any; ++tx)
        any = tileOrNull(tx, ty) != nullptr;
    if (!any)
        return false;
    const auto c = std::size_t(channels);
    for (int tx = 0; tx < tilesX_; ++tx) {
        const int x0 = tx * kTileSize;
        const std::size_t n = std::size_t(std::min(kTileSize, width_ - x0)) * c;
        float* dst = out + std::size_t(x0) * c;
        if (const float* t = tileOrNull(tx, ty))
            std::copy_n(t + offset(x0, y), n, dst);
        else
            fillPixels(dst, n / c);
    }
    return true;
}

std::vector<float> FilmLayer::dense() const {
    const auto c = std::size_t(channels);
    const std::size_t row = std::size_t(width_) * c;
    std::vector<float> out(row * std::size_t(height_), 0.0f);
    for (int y = 0; y < height_; ++y) {
        float* dst = out.data() + std::size_t(y) * row;
        if (!copyRow(y, dst))
            fillPixels(dst, std::size_t(width_));
    }
    return out;
}

void FilmLayer::assign(std::span<const float> values) {
    const auto c = std::size_t(channels);
    if (values.size() != std::size_t(width_) * std::size_t(height_) * c)
        throw std::invalid_argument(strCat("FilmLayer '", name, "': ", values.size(),
                                           " values for ", width_, " x ", height_, " x ", c));
    for (int y = 0; y < height_; ++y)
        for (int tx = 0; tx < tilesX_; ++tx) {
            const int x0 = tx * kTileSize, n = std::min(kTileSize, width_ - x0);
            const auto row = values.subspan(
                (std::size_t(y) * std::size_t(width_) + std::size_t(x0)) * c, std::size_t(n) * c);
            // A tile only for what is not the fill: what a tile left out reads as.
            bool fillOnly = !tileOrNull(tx, y / kTileSize);
            for (std::size_t i = 0; fillOnly && i < row.size(); ++i)
                fillOnly = isFill(i % c, row[i]);
            if (fillOnly)
                continue;
            std::copy(row.begin(), row.end(), tile(tx, y / kTileSize) + offset(x0, y));
        }
}

Film::Film(int width, int height)
    : width_(width)
    , height_(height) {
    if (width < 0 || height < 0)
        throw std::invalid_argument(strCat("Film: size ", width, " x ", height));
}

std::size_t Film::addLayer(std::string name, int channels, bool fullPrecision, Rgb fill) {
    if (channels != 1 && channels != 3)
        throw std::invalid_argument(
            strCat("Film: layer '", name, "' with ", channels, " channels"));
    if (find(name))
        throw std::invalid_argument(strCat("Film: layer '", name, "' added twice"));
    layers_.emplace_back(std::move(name), channels, fullPrecision, width_, height_, fill);
    return layers_.size() - 1;
}

std::optional<std::size_t> Film::find(std::string_view name) const {
    for (std::size_t i = 0; i < layers_.size(); ++i)
        if (layers_[i].name == name)
            return i;
    return std::nullopt;
}

const FilmLayer& Film::layer(std::string_view name) const {
    const std::optional<std::size_t> i = find(name);
    if (!i)
        throw std::out_of_range(strCat("Film: no layer '", name, "'"));
    return layers_[*i];
}

FilmLayer& Film::layer(std::string_view name) {
    return const_cast<FilmLayer&>(static_cast<const Film&>(*this).layer(name));
}

std::size_t Film::bytesHeld() const {
    std::size_t bytes = 0;
    for (const FilmLayer& l : layers_)
        bytes += l.bytesHeld();
    return bytes;
}

std::size_t Film::denseBytes() const {
    std::size_t bytes = 0;
    for (const FilmLayer& l : layers_)
        bytes += pixelCount() * std::size_t(l.channels) * sizeof(float);
    return bytes;
}

std::ostream& operator<<(std::ostream& os, const Film& film) {
    os << "Film(" << film.width() << "x" << film.height() << ":";
    for (const FilmLayer& l : film.layers())
        os << " '" << l.name << "'" << (l.channels == 3 ? "rgb" : "");
    return os << ")";
}

} // namespace hairvox
