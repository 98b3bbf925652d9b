// Tests' helper: a film as bytes, for "same bytes for any thread count".
#pragma once

#include <hairvox/film/film.h>

#include <vector>

namespace hairvox::test {

/// Every layer of the film, concatenated as bytes.
inline std::vector<unsigned char> filmBytes(const Film& film) {
    std::vector<unsigned char> bytes;
    for (const FilmLayer& layer : film.layers()) {
        const std::vector<float> values = layer.dense();
        const auto* p = reinterpret_cast<const unsigned char*>(values.data());
        bytes.insert(bytes.end(), p, p + values.size() * sizeof(float));
    }
    return bytes;
}

} // namespace hairvox::test
