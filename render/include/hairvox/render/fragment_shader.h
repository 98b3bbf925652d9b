// hairvox render: the interface between the rasterizer and the shading.
//
// Shading is deferred: the rasterizer finds which points of which strands are
// visible in which pixels, then hands them to a FragmentShader in batches (so
// that the per-light global term can be evaluated for many points at once) and
// composites the answers. The shader returns, per point, the reflected
// radiance summed over the scene's lights as the components of the dual-
// scattering model (shading/global_term.h ShadeResult: single scattering per
// lobe, f_back^direct, F_scatter — each already multiplied by cos θ_i, its
// visibility weight and the light's irradiance), plus the global term toward
// each light, which the film keeps as AOVs.
//
// Shading rate:
//  - fragment: every visible fragment is shaded at the point of its segment
//    nearest to the pixel centre (in screen space, perspective-correct);
//  - vertex:   the strand vertices of every segment with a visible fragment in
//    a tile are shaded once per tile, and each fragment interpolates its
//    segment's two vertex results linearly in the segment parameter.
// In both modes the shading tangent is the vertex tangents interpolated along
// the segment, so the two differ only in where the shader is evaluated.
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/shading/global_term.h>

#include <cstdint>
#include <optional>
#include <ostream>
#include <span>
#include <string_view>

namespace hairvox {

enum class ShadingRate { Fragment, Vertex };

const char* toString(ShadingRate rate);
std::optional<ShadingRate> parseShadingRate(std::string_view name);
inline std::ostream& operator<<(std::ostream& os, ShadingRate r) { return os << toString(r); }

/// A visible point on a fiber's centreline, in world space.
struct ShadingPoint {
    Vec3f position;
    Vec3f tangent;          ///< unit fiber tangent u, root → tip
    Vec3f toCamera;         ///< unit ω_o, from the point toward the camera
    std::uint32_t strand;   ///< index of the strand in the groom
    std::uint32_t segment;  ///< point index of the root-side vertex of the segment holding the point
};

std::ostream& operator<<(std::ostream& os, const ShadingPoint& p);

class FragmentShader {
public:
    virtual ~FragmentShader() = default;

    /// Shades a batch. `radiance[i]` receives the radiance reflected toward
    /// the camera at points[i], summed over the lights; `globalTerms` holds
    /// points.size() × L entries (L = the scene's light count), the global
    /// term at points[i] toward light l at index i·L + l (L = 0: empty).
    /// Results must depend only on the point (not on the batch), be finite
    /// and non-negative; the film rejects anything else and reports it.
    /// Called concurrently from several threads.
    virtual void shade(std::span<const ShadingPoint> points, std::span<ShadeResult> radiance,
                       std::span<GlobalTerm> globalTerms) const = 0;
};

/// sum += weight ⊙ s, component by component (a light's irradiance, a pixel weight).
void addWeighted(ShadeResult& sum, const ShadeResult& s, const Rgb& weight);
void addWeighted(ShadeResult& sum, const ShadeResult& s, float weight);

} // namespace hairvox
