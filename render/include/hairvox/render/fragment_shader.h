// hairvox render: the interface between the rasterizer and whatever shades
// the hair it finds.
//
// Shading is deferred: the rasterizer finds which points of which strands are
// visible in which pixels, then hands them to a FragmentShader in batches (so
// that an expensive per-point term — the dual-scattering global term — can be
// evaluated for many points at once) and composites the answers. A shader
// returns, per point, a fixed number of floats whose meaning its ShaderLayout
// declares:
//  - radiance layers (RGB): radiance toward the camera, composited with the
//    fragment's weight (premultiplied by coverage) and added to the beauty;
//  - average layers (1 or 3 channels): any per-point quantity (visibility,
//    optical depth, ...) that the film keeps as the weighted mean over the
//    visible hair in the pixel (not premultiplied; 0 where there is no hair).
//
// Shading rate:
//  - fragment: every visible fragment is shaded at the point of its segment
//    nearest to the pixel centre (in screen space, perspective-correct);
//  - vertex:   the strand vertices of every segment with a visible fragment in
//    a tile are shaded once per tile, and each fragment interpolates its
//    segment's two vertex results linearly in the segment parameter;
//  - adaptive: the rate is chosen per segment by the error interpolation
//    would make there, measured before the fragments are shaded. A segment
//    with more than three visible fragments in a tile is shaded at t = 0, ½, 1;
//    if the midpoint's radiance is within a tolerance τ of the ends' linear
//    interpolation (relative to the segment's mean radiance, summed over every
//    radiance layer), its fragments interpolate the three results piecewise
//    linearly — where the global term, the shadows and the highlights vary
//    slowly along the fiber — and otherwise each fragment is shaded.
// In every mode the shading tangent is the vertex tangents interpolated along
// the segment, so the modes differ only in where the shader is evaluated.
//
// The tail: at the fragment and adaptive rates, hair seen through less than
// the tail transmittance T_tail — the fragments composited once a pixel's
// transmittance in front of them has fallen below T_tail — interpolates its
// segment's two vertex results, as at the vertex rate, instead of being
// shaded. Those fragments' weights sum to at most T_tail in every pixel, so
// the change to a pixel is at most T_tail times the interpolation's error
// there; in dense hair they are a third of the visible fragments.
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/core/vecmath.h>

#include <cstdint>
#include <ostream>
#include <span>
#include <string>
#include <vector>

namespace hairvox {

enum class ShadingRate { Fragment, Vertex, Adaptive };

inline constexpr EnumNames<ShadingRate, 3> kShadingRateNames{{{
    {ShadingRate::Fragment, "fragment"},
    {ShadingRate::Vertex, "vertex"},
    {ShadingRate::Adaptive, "adaptive"},
}}};

/// The adaptive rate's τ by default (docs/scene.md: image error and savings).
inline constexpr float kDefaultShadingTolerance = 0.05f;
/// T_tail by default (docs/scene.md: image error and savings).
inline constexpr float kDefaultTailTransmittance = 1.0f / 16.0f;
inline const char* toString(ShadingRate rate) {
    return kShadingRateNames.name(rate);
}
inline std::ostream& operator<<(std::ostream& os, ShadingRate r) {
    return os << toString(r);
}

/// A visible point on a fiber's centreline, in world space.
struct ShadingPoint {
    Vec3f position;
    Vec3f tangent;         ///< unit fiber tangent u, root → tip
    Vec3f toCamera;        ///< unit ω_o, from the point toward the camera
    std::uint32_t strand;  ///< index of the strand in the groom
    std::uint32_t segment; ///< point index of the root-side vertex of the segment holding the point
};

std::ostream& operator<<(std::ostream& os, const ShadingPoint& p);

/// What a shader returns per point: radiance layers first (3 floats each),
/// then average layers (AverageLayer::channels floats each).
struct ShaderLayout {
    struct AverageLayer {
        std::string name;
        int channels = 1; ///< 1 or 3
    };
    std::vector<std::string> radiance; ///< RGB layer names, e.g. "direct_R"
    std::vector<AverageLayer> averages;

    std::size_t radianceFloats() const { return 3 * radiance.size(); }
    /// Floats per shaded point.
    std::size_t stride() const;
};

class FragmentShader {
public:
    virtual ~FragmentShader() = default;

    virtual const ShaderLayout& layout() const = 0;

    /// Shades a batch: out[i·stride .. (i + 1)·stride) for points[i], laid out
    /// as layout() says. Results must depend only on the point (not on the
    /// batch); radiance must be finite and non-negative, averages finite — the
    /// rasterizer rejects anything else and reports it. Called concurrently
    /// from several threads, each call in its own TBB work isolation: a
    /// shader may run parallel loops, and a thread waiting in them runs only
    /// their tasks, so thread-local state survives them.
    virtual void shade(std::span<const ShadingPoint> points, std::span<float> out) const = 0;
};

} // namespace hairvox
