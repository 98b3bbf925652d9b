// hairvox pipeline: what a comparison of two renders compares (film/image_compare.h)
// — the hair's radiance (hairRadianceOf), the beauty, or the sum of named RGB
// layers, over the pixels of a mask layer — for `hairvox compare` and the
// Python module's hairvox.compare.
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/film/film.h>
#include <hairvox/film/image_compare.h>

#include <string>
#include <vector>

namespace hairvox {

/// The value compared per pixel: the hair's radiance (direct + multiple
/// scattering, with a path tracer's half for its noise) or the beauty.
enum class ComparedValue { Hair, Beauty };

inline constexpr EnumNames<ComparedValue, 2> kComparedValueNames{{{
    {ComparedValue::Hair, "hair"},
    {ComparedValue::Beauty, "beauty"},
}}};

struct CompareSelection {
    ComparedValue what = ComparedValue::Hair;
    /// Non-empty: the sum of these RGB layers instead of `what` (no noise estimate).
    std::vector<std::string> layers;
    std::string mask = "hair.A"; ///< scalar layer selecting the compared pixels (> 0)
};

/// The image `selection` compares from `film`. InputError naming `source` and
/// the missing layer when the film lacks one (a render whose output.layers
/// kept only some).
ComparedImage comparedImage(const Film& film, const CompareSelection& selection,
                            const std::string& source);

} // namespace hairvox
