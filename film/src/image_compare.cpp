#include <hairvox/core/error.h>
#include <hairvox/film/image_compare.h>

#include <algorithm>
#include <cmath>

namespace hairvox {

ComparedImage ComparedImage::fromFilm(const Film& film, const std::vector<std::string>& layers,
                                      std::string_view maskLayer, std::string_view halfLayer) {
    ComparedImage image;
    image.width = film.width();
    image.height = film.height();
    image.value.assign(film.pixelCount(), Rgb(0.0f));
    for (const std::string& name : layers) {
        const FilmLayer& layer = film.layer(name);
        for (std::size_t p = 0; p < film.pixelCount(); ++p)
            image.value[p] += layer.rgb(p);
    }
    image.mask = film.layer(maskLayer).dense();
    if (!halfLayer.empty()) {
        const FilmLayer& h = film.layer(halfLayer);
        image.halfA.resize(film.pixelCount());
        for (std::size_t p = 0; p < film.pixelCount(); ++p)
            image.halfA[p] = h.rgb(p);
    }
    return image;
}

ComparedImage ComparedImage::beautyOf(const Film& film, std::string_view maskLayer) {
    return fromFilm(film, {std::string(Film::kBeauty)}, maskLayer,
                    film.find("half_a") ? "half_a" : std::string_view{});
}

ComparedImage ComparedImage::boxFiltered(int block) const {
    if (block < 1)
        throw InputError(strCat("box filter: block size ", block, " is not a positive integer"));
    ComparedImage out;
    out.width = (width + block - 1) / block;
    out.height = (height + block - 1) / block;
    const std::size_t n = std::size_t(out.width) * std::size_t(out.height);
    out.value.assign(n, Rgb(0.0f));
    out.mask.assign(n, 0.0f);
    if (!halfA.empty())
        out.halfA.assign(n, Rgb(0.0f));
    for (int by = 0; by < out.height; ++by)
        for (int bx = 0; bx < out.width; ++bx) {
            const std::size_t o = std::size_t(by) * std::size_t(out.width) + std::size_t(bx);
            const int x1 = std::min(width, (bx + 1) * block), y1 = std::min(height, (by + 1) * block);
            const float w = 1.0f / float((x1 - bx * block) * (y1 - by * block));
            for (int y = by * block; y < y1; ++y)
                for (int x = bx * block; x < x1; ++x) {
                    const std::size_t p = std::size_t(y) * std::size_t(width) + std::size_t(x);
                    out.value[o] += w * value[p];
                    out.mask[o] += w * mask[p];
                    if (!halfA.empty())
                        out.halfA[o] += w * halfA[p];
                }
        }
    return out;
}

std::optional<ImageError> compareImages(const ComparedImage& estimate,
                                        const ComparedImage& reference) {
    const std::size_t n = std::size_t(reference.width) * std::size_t(reference.height);
    if (estimate.width != reference.width || estimate.height != reference.height ||
        estimate.value.size() != n || reference.value.size() != n || reference.mask.size() != n ||
        (!reference.halfA.empty() && reference.halfA.size() != n))
        throw InputError(strCat("images differ in size: ", estimate.width, "x", estimate.height,
                                " against a ", reference.width, "x", reference.height,
                                " reference"));
    const bool noisy = !reference.halfA.empty();
    double sumAbs = 0, sumSquares = 0, sumSigned = 0, sumReference = 0, sumNoise = 0,
           sumNoiseSquares = 0;
    std::size_t pixels = 0;
    for (std::size_t p = 0; p < n; ++p) {
        if (!(reference.mask[p] > 0))
            continue;
        ++pixels;
        for (int c = 0; c < 3; ++c) {
            const double d = double(estimate.value[p][c]) - double(reference.value[p][c]);
            sumAbs += std::abs(d);
            sumSquares += d * d;
            sumSigned += d;
            sumReference += std::abs(double(reference.value[p][c]));
            if (noisy) {
                const double noise = double(reference.halfA[p][c]) - double(reference.value[p][c]);
                sumNoise += std::abs(noise);
                sumNoiseSquares += noise * noise;
            }
        }
    }
    if (pixels == 0 || !(sumReference > 0))
        return std::nullopt;
    const double values = 3.0 * double(pixels), mean = sumReference / values;
    ImageError e;
    e.pixels = pixels;
    e.relL1 = sumAbs / sumReference;
    e.relRmse = std::sqrt(sumSquares / values) / mean;
    e.relBias = sumSigned / sumReference;
    e.noiseFloorL1 = sumNoise / sumReference;
    e.relL1NoiseRemoved = std::sqrt(std::max(0.0, e.relL1 * e.relL1 - e.noiseFloorL1 * e.noiseFloorL1));
    e.relRmseNoiseRemoved =
        std::sqrt(std::max(0.0, (sumSquares - sumNoiseSquares) / values)) / mean;
    return e;
}

} // namespace hairvox
