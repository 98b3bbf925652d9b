// hairvox render: the lights of a scene.
//
// Directions follow docs/DESIGN.md §2: ω_i points away from the shaded point,
// toward the light; a directional light stores that unit vector. Radiometry:
//  - directional: the irradiance on a surface facing the light is
//    E = colour · intensity (intensity is an irradiance);
//  - point: E = colour · intensity / d² at distance d (intensity is a radiant
//    intensity), d clamped to ≥ 1e-6 scene units so that E stays finite.
// Reflected radiance is E ⊙ (the shader's result per unit incident radiance).
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>

#include <limits>
#include <ostream>
#include <string>

namespace hairvox {

struct Light {
    enum class Kind { Directional, Point };

    std::string name; ///< prefix of the light's AOV layers in the EXR ("key", "light1")
    Kind kind = Kind::Directional;
    Vec3f direction{0.0f, 1.0f, 0.0f}; ///< directional: unit ω_i, from the scene toward the light
    Vec3f position{0.0f};              ///< point light position
    Rgb color{1.0f};        ///< each channel in [0, 1000]
    float intensity = 1.0f; ///< [0, 1e6]

    struct Path {
        Vec3f omega;    ///< unit ω_i from the point toward the light
        float distance; ///< to the light; +∞ for a directional light
    };
    /// The shadow path from x (a point light at x itself: distance 0, ω = +y).
    Path pathFrom(const Vec3f& x) const {
        if (kind == Kind::Directional)
            return {direction, std::numeric_limits<float>::infinity()};
        const Vec3f d = position - x;
        const float len = glm::length(d);
        return len > 0 ? Path{d / len, len} : Path{Vec3f(0.0f, 1.0f, 0.0f), 0.0f};
    }

    /// Irradiance at a point `distance` away (pathFrom), facing the light.
    Rgb irradiance(float distance) const;
};

std::ostream& operator<<(std::ostream& os, const Light& light);

} // namespace hairvox
