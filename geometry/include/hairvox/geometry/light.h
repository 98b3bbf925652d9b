// hairvox geometry: a light of the scene — where it is, as seen from a
// shading point, and what it emits.
//
// Directions follow docs/DESIGN.md §2: ω_i points away from the shaded point,
// toward the light; a directional light stores that unit vector. Radiometry:
//  - directional: the irradiance on a surface facing the light is
//    E = colour · intensity (intensity is an irradiance);
//  - point: E = colour · intensity / d² at distance d (intensity is a radiant
//    intensity), d clamped to ≥ 1e-6 scene units so that E stays finite.
// Reflected radiance is E ⊙ (a BSDF's value times the cosine). The global term
// (transmittance/) reads only the geometry; integrators read both.
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>

#include <limits>
#include <ostream>
#include <string>

namespace hairvox {

struct Light {
    enum class Kind { Directional, Point };

    Kind kind = Kind::Directional;
    Vec3f direction{0.0f, 1.0f, 0.0f}; ///< directional: unit vector from the scene toward the light
    Vec3f position{0.0f};              ///< point light position
    std::string name = "light";        ///< prefix of the light's AOV layers ("key", "light1")
    Rgb color{1.0f};                   ///< each channel in [0, 1000]
    float intensity = 1.0f;            ///< [0, 1e6]

    /// Throws InputError for a zero or non-finite direction.
    static Light directional(const Vec3f& towardLight);
    /// Throws InputError for a non-finite position.
    static Light point(const Vec3f& position);

    struct Path {
        Vec3f omega;    ///< unit direction from the point toward the light
        float distance; ///< to the light; +∞ for a directional light
    };
    /// The shadow path from x. A point light at x itself gives distance 0.
    Path pathFrom(const Vec3f& x) const {
        if (kind == Kind::Directional)
            return {direction, std::numeric_limits<float>::infinity()};
        const Vec3f d = position - x;
        const float len = glm::length(d);
        return len > 0 ? Path{d / len, len} : Path{Vec3f(0.0f, 1.0f, 0.0f), 0.0f};
    }

    /// Irradiance at a point `distance` away (pathFrom), facing the light.
    Rgb irradiance(float distance) const;
    /// Emits nothing (black or zero intensity): integrators skip it.
    bool isDark() const { return !(intensity > 0) || color.isBlack(); }
    /// What it lights with: every field but the name (which only names its AOVs).
    void hashInto(Hasher& hasher) const;
};

inline constexpr EnumNames<Light::Kind, 2> kLightKindNames{{{
    {Light::Kind::Directional, "directional"},
    {Light::Kind::Point, "point"},
}}};

std::ostream& operator<<(std::ostream& os, const Light& light);

} // namespace hairvox
