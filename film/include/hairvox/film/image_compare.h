// hairvox film: how far one image is from another, over the pixels that
// matter, and how much of that is the reference's own noise.
//
// Errors are measured on an RGB value per pixel (the beauty, or the hair's
// radiance) over the reference's masked pixels (the hair: mask coverage > 0),
// summed over pixels and channels:
//   relative L1    Σ|I − I_ref| / Σ|I_ref|
//   relative RMSE  sqrt(mean (I − I_ref)²) / mean |I_ref|
//   relative bias  Σ(I − I_ref) / Σ|I_ref|     (signed: is I brighter?)
//
// A Monte Carlo reference (the path tracer) is the mean I_ref of two
// independent halves with equal sample counts, and carries half A's image
// I_A: then I_A − I_ref = (I_A − I_B)/2 has the distribution of I_ref − μ
// (for the halves' noise, whatever its correlation within a half), so its
// noise is removed from the errors without a model of it (docs/DESIGN.md §6):
//   - the bias is unbiased as it stands (E[I_ref] is the truth);
//   - RMSE exactly in expectation: E[(I − I_ref)²] = (I − μ)² + σ² and
//     E[(I_A − I_ref)²] = σ², so mean (I − I_ref)² − mean (I_A − I_ref)²
//     estimates the squared error against μ;
//   - L1 by its noise floor: a perfect estimate I = μ scores E|I − I_ref| =
//     E|I_A − I_ref| per value, so the floor is Σ|I_A − I_ref| / Σ|I_ref|, and
//     the error with the noise removed is taken in quadrature,
//     sqrt(relL1² − floor²) — exact where the error dwarfs the noise or is zero,
//     within ~10% (Gaussian noise) between.
// An error within 1.5× its floor is not resolved: the reference is too noisy
// to tell it from zero, and it is reported as such, never as agreement.
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/film/film.h>
#include <hairvox/film/image_file.h>

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hairvox {

/// An image to compare: a value per pixel, the mask of compared pixels, and
/// for a Monte Carlo image the value of its half A.
struct ComparedImage {
    int width = 0, height = 0;
    std::vector<Rgb> value;
    std::vector<float> mask;  ///< coverage of what is measured (the hair), [0, 1]
    std::vector<Rgb> halfA;   ///< the value of half the samples; empty: exact

    /// The sum of the film's RGB layers `layers` ("" is the beauty), its scalar
    /// layer `maskLayer`, and the RGB layer `halfLayer` when one is named
    /// (std::out_of_range naming a missing layer).
    static ComparedImage fromFilm(const Film& film, const std::vector<std::string>& layers,
                                  std::string_view maskLayer, std::string_view halfLayer = {});
    /// The beauty and its half layer "half_a" if the film has one.
    static ComparedImage beautyOf(const Film& film, std::string_view maskLayer);

    /// The mean over blocks of block × block pixels (the last row and column of
    /// blocks may be cut short): compares what two images say at a coarser
    /// scale, where a point-sampled estimate's aliasing and a path tracer's
    /// per-pixel noise average out but a bias does not. InputError if block < 1.
    ComparedImage boxFiltered(int block) const;
};

struct ImageError {
    double relL1 = 0;
    double relRmse = 0;
    double relBias = 0;
    std::size_t pixels = 0; ///< masked pixels compared
    /// With a noisy reference (else 0, and the errors below equal the raw ones):
    double noiseFloorL1 = 0;        ///< Σ|I_A − I_ref| / Σ|I_ref|
    double relL1NoiseRemoved = 0;   ///< sqrt(max(0, relL1² − floor²))
    /// sqrt(max(0, mean (I − I_ref)² − mean (I_A − I_ref)²)) / mean |I_ref|
    double relRmseNoiseRemoved = 0;

    /// Above the reference's noise: relL1 > 1.5 × its floor.
    bool resolved() const { return relL1 > 1.5 * noiseFloorL1; }
};

/// Error of `estimate` against `reference` over the reference's masked pixels;
/// nullopt when there are none or they are black. InputError if sizes differ.
std::optional<ImageError> compareImages(const ComparedImage& estimate,
                                        const ComparedImage& reference);

} // namespace hairvox
