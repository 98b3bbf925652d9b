#include <hairvox/core/error.h>
#include <hairvox/film/image_compare.h>

#include <cmath>

namespace hairvox {

BeautyImage BeautyImage::fromFilm(const Film& film, std::string_view maskLayer) {
    BeautyImage image;
    image.width = film.width();
    image.height = film.height();
    const FilmLayer& beauty = film.layer(Film::kBeauty);
    image.beauty.resize(film.pixelCount());
    for (std::size_t p = 0; p < film.pixelCount(); ++p)
        image.beauty[p] = beauty.rgb(p);
    image.mask = film.layer(maskLayer).data;
    return image;
}

BeautyImage BeautyImage::fromExr(const ExrImage& exr, std::string_view maskChannel) {
    const auto channel = [&](std::string_view name) -> const std::vector<float>& {
        const auto it = exr.channels.find(std::string(name));
        if (it == exr.channels.end())
            throw InputError(strCat("EXR image has no channel '", name, "'"));
        return it->second;
    };
    BeautyImage image;
    image.width = exr.width;
    image.height = exr.height;
    const std::vector<float>&r = channel("R"), &g = channel("G"), &b = channel("B");
    image.beauty.resize(r.size());
    for (std::size_t p = 0; p < r.size(); ++p)
        image.beauty[p] = Rgb(r[p], g[p], b[p]);
    image.mask = channel(maskChannel);
    return image;
}

std::optional<ImageError> compareImages(const BeautyImage& estimate, const BeautyImage& reference) {
    const std::size_t n = std::size_t(reference.width) * std::size_t(reference.height);
    if (estimate.width != reference.width || estimate.height != reference.height ||
        estimate.beauty.size() != n || reference.beauty.size() != n || reference.mask.size() != n)
        throw InputError(strCat("images differ in size: ", estimate.width, "x", estimate.height,
                                " against a ", reference.width, "x", reference.height,
                                " reference"));
    double sumAbs = 0, sumSquares = 0, sumReference = 0;
    std::size_t pixels = 0;
    for (std::size_t p = 0; p < n; ++p) {
        if (!(reference.mask[p] > 0))
            continue;
        ++pixels;
        for (int c = 0; c < 3; ++c) {
            const double d = double(estimate.beauty[p][c]) - double(reference.beauty[p][c]);
            sumAbs += std::abs(d);
            sumSquares += d * d;
            sumReference += std::abs(double(reference.beauty[p][c]));
        }
    }
    if (pixels == 0 || !(sumReference > 0))
        return std::nullopt;
    const double values = 3.0 * double(pixels);
    ImageError e;
    e.pixels = pixels;
    e.relL1 = sumAbs / sumReference;
    e.relRmse = std::sqrt(sumSquares / values) / (sumReference / values);
    return e;
}

} // namespace hairvox
