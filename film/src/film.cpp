#include <hairvox/core/error.h>
#include <hairvox/film/film.h>

#include <stdexcept>

namespace hairvox {

Film::Film(int width, int height)
    : width_(width)
    , height_(height) {
    if (width < 0 || height < 0)
        throw std::invalid_argument(strCat("Film: size ", width, " x ", height));
}

std::size_t Film::addLayer(std::string name, int channels, bool fullPrecision, Init init) {
    if (channels != 1 && channels != 3)
        throw std::invalid_argument(
            strCat("Film: layer '", name, "' with ", channels, " channels"));
    if (find(name))
        throw std::invalid_argument(strCat("Film: layer '", name, "' added twice"));
    FilmLayer l;
    l.name = std::move(name);
    l.channels = channels;
    l.fullPrecision = fullPrecision;
    const std::size_t size = pixelCount() * std::size_t(channels);
    if (init == Init::Zero)
        l.data.assign(size, 0.0f);
    else
        l.data.resize(size); // NaN in the sanitizer builds (core/large_array.h)
    layers_.push_back(std::move(l));
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

std::ostream& operator<<(std::ostream& os, const Film& film) {
    os << "Film(" << film.width() << "x" << film.height() << ":";
    for (const FilmLayer& l : film.layers())
        os << " '" << l.name << "'" << (l.channels == 3 ? "rgb" : "");
    return os << ")";
}

} // namespace hairvox
