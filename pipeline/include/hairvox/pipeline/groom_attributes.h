// hairvox pipeline: a groom file's per-point attributes turned into what every
// stage reads (strands/groom.h) — thickness into per-point diameters D_i in
// scene units, colours into a palette of fiber types.
//
// Thickness (scene key groom.thickness):
//   diameter  the file's value is D_i in scene units (.hair files);
//   scale     the file's value multiplies fiber.diameter (TressFX's per-strand
//             thickness is a ratio of the asset's fiber radius);
//   auto      scale for .tfx, diameter otherwise (the default);
//   ignore    every fiber is fiber.diameter wide.
// D_i is then read through ribbonWidthAt(): the splat weighs each segment by
// its mean D_i/D (λ·k·D stays the optical depth), the exact ribbons and the
// rasterizer's ribbons are k·D_i wide at each point.
//
// Colour (scene key groom.color: "use", the default, or "ignore"):
// a segment's colour is the mean of its two points' colours (linear RGB, the
// appearance of a dense mass of such fibers), mapped to σ_a by
// FiberParams::sigmaFromColor() (Chiang et al. 2016, Eq. 9); the other optical
// parameters are the scene's fiber. At most kMaxFiberTypes distinct colours
// are kept exactly; more are quantised by cutting the widest box of colours at
// its middle (linear RGB, where the error is judged) into kMaxFiberTypes
// types of mean colour, and the largest channel error is reported. Every
// stage reads a segment's type through fiberTypeAt(): the shader and the path
// tracer scatter with that type's fiber, exact mode attenuates each crossing
// by its type's ā_f, the grid mixes the types' rates by the fractions splatted
// per voxel, and approx assumes the fibers in front are of the query's type.
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/core/rgb.h>
#include <hairvox/shading/fiber_params.h>
#include <hairvox/strands/groom.h>

#include <string>
#include <vector>

namespace hairvox {

enum class GroomThickness { Auto, Diameter, Scale, Ignore };

inline constexpr EnumNames<GroomThickness, 4> kGroomThicknessNames{{{
    {GroomThickness::Auto, "auto"},
    {GroomThickness::Diameter, "diameter"},
    {GroomThickness::Scale, "scale"},
    {GroomThickness::Ignore, "ignore"},
}}};
inline const char* toString(GroomThickness t) {
    return kGroomThicknessNames.name(t);
}

enum class GroomColor { Use, Ignore };

inline constexpr EnumNames<GroomColor, 2> kGroomColorNames{{{
    {GroomColor::Use, "use"},
    {GroomColor::Ignore, "ignore"},
}}};
inline const char* toString(GroomColor c) {
    return kGroomColorNames.name(c);
}

/// Applies `rule` to groom.thickness (see the file comment); `source` names
/// the file in messages. Throws InputError naming the strand and point of a
/// negative or non-finite thickness, and when every fiber would have zero
/// width. Appends a warning when D_i / fiber.diameter leaves [0.01, 100]
/// (likely a units mistake). Returns a note for the load report ("" if none).
std::string resolveThickness(Groom& groom, GroomThickness rule, const FiberScale& scale,
                             const std::string& source, std::vector<std::string>& warnings);

/// The fiber types of a groom: the fiber of each type, indexed by Groom::fiberType.
struct FiberPalette {
    std::vector<FiberParams> fibers; ///< at least one; one when the groom has no colours
    std::vector<Rgb> colors;         ///< each type's colour; empty when not from colours
    float maxColorError = 0;         ///< largest |segment colour − its type's colour| per channel

    std::size_t size() const { return fibers.size(); }
};

/// Sets groom.fiberType from groom.color (under GroomColor::Use, when the
/// groom has colours; otherwise clears it) and returns the palette built from
/// `base`.
/// Throws InputError naming the strand and point of a negative or non-finite
/// colour. Warns when quantisation moved a colour by more than 0.02.
FiberPalette resolveColors(Groom& groom, GroomColor rule, const FiberParams& base,
                           const std::string& source, std::vector<std::string>& warnings);

} // namespace hairvox
