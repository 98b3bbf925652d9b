// hairvox film: how far one image is from another, over the pixels that matter.
//
// Errors are measured on the beauty over the reference's masked pixels (the
// hair: a pixel whose mask coverage is > 0):
//   relative L1    Σ|I − I_ref| / Σ|I_ref|
//   relative RMSE  sqrt(mean (I − I_ref)²) / mean |I_ref|
// summed over pixels and RGB channels.
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/film/film.h>
#include <hairvox/film/image_file.h>

#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

namespace hairvox {

/// The beauty of an image and its mask: what image errors are computed from.
struct BeautyImage {
    int width = 0, height = 0;
    std::vector<Rgb> beauty;
    std::vector<float> mask; ///< coverage of what is measured (the hair), [0, 1]

    /// The film's beauty "" and its scalar layer `maskLayer` (std::out_of_range if absent).
    static BeautyImage fromFilm(const Film& film, std::string_view maskLayer);
    /// The same from an EXR read back (InputError naming the missing channel).
    static BeautyImage fromExr(const ExrImage& image, std::string_view maskChannel);
};

struct ImageError {
    double relL1 = 0;
    double relRmse = 0;
    std::size_t pixels = 0; ///< masked pixels compared
};

/// Error of `estimate` against `reference` over the reference's masked pixels;
/// nullopt when there are none or they are black. InputError if sizes differ.
std::optional<ImageError> compareImages(const BeautyImage& estimate, const BeautyImage& reference);

} // namespace hairvox
