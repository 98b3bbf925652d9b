// hairvox strands: procedural grooms on a head-sized sphere.
//
// Deterministic by seed (PCG32, no std:: distributions). Roots are spread
// evenly over a scalp region of the sphere (a jittered Fibonacci lattice
// masked by a hairline that is high at the forehead and low at the nape).
// Each strand grows along the scalp normal, is swept back from the face and
// bends under a gravity-like pull, sliding over the head (sphere collision)
// before it falls. Strands are grouped in clumps that share their wave/curl
// phase and draw together towards the tips, which is what makes the result
// read as hair rather than noise. Styles:
//  - straight: the gravity-shaped centreline only;
//  - wavy: a planar sine wave across the strand, growing from the root;
//  - curly: a helix around a shortened centreline (ringlets), with the
//    centreline shortened so that the fiber length stays near `length`.
// Units are metres; y is up and the face looks towards +z.
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/strands/groom.h>

#include <cstdint>
#include <optional>
#include <ostream>
#include <string_view>

namespace hairvox {

enum class GroomStyle { Straight, Wavy, Curly };

inline constexpr EnumNames<GroomStyle, 3> kGroomStyleNames{{{
    {GroomStyle::Straight, "straight"},
    {GroomStyle::Wavy, "wavy"},
    {GroomStyle::Curly, "curly"},
}}};
inline const char* toString(GroomStyle style) {
    return kGroomStyleNames.name(style);
}
inline std::ostream& operator<<(std::ostream& os, GroomStyle style) {
    return os << toString(style);
}

struct ProceduralGroomParams {
    GroomStyle style = GroomStyle::Wavy;
    std::uint32_t strands = 10000;
    /// 0 picks the style's default: 32 for straight and wavy, 64 for curly
    /// (about 8 points per curl turn).
    std::uint32_t pointsPerStrand = 0;
    std::uint64_t seed = 1;
    Vec3f headCenter{0.0f};
    float headRadius = 0.1f;       ///< m
    float length = 0.3f;           ///< mean fiber length, m
    float lengthVariation = 0.15f; ///< relative standard spread of the length, [0, 0.9]
    float waveAmplitude = 0.008f;  ///< wavy: half peak-to-peak, m
    float waveLength = 0.06f;      ///< wavy: m
    float curlRadius = 0.006f;     ///< curly: helix radius, m
    float curlPitch = 0.018f;      ///< curly: rise per turn along the centreline, m
    float clumpStrength = 0.35f;   ///< pull towards the clump centre at the tip, [0, 1]
    /// Optional per-point colours (Groom::color, linear RGB in [0, 1]): each
    /// clump of strands takes one of these at random — streaks of colour that
    /// follow the clumps. At most kMaxFiberTypes; empty: no colours. The
    /// geometry does not depend on them.
    std::vector<Rgb> colors;

    std::uint32_t resolvedPointsPerStrand() const;
    /// Throws InputError with the valid range of the first invalid parameter.
    void validate() const;
};

std::ostream& operator<<(std::ostream& os, const ProceduralGroomParams& p);

Groom generateGroom(const ProceduralGroomParams& params);

} // namespace hairvox
