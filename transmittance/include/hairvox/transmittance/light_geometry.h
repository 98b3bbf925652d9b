// hairvox transmittance: where a light is, as seen from a shading point.
//
// Only geometry: colour and intensity belong to the scene. Directions follow
// docs/DESIGN.md §2: ω points away from the shading point, toward the light.
#pragma once

#include <hairvox/core/vecmath.h>

#include <limits>
#include <ostream>

namespace hairvox {

struct LightGeometry {
    enum class Kind { Directional, Point };

    Kind kind = Kind::Directional;
    Vec3f direction{0.0f, 1.0f, 0.0f}; ///< directional: unit vector from the scene toward the light
    Vec3f position{0.0f};              ///< point light position

    /// Throws InputError for a zero or non-finite direction.
    static LightGeometry directional(const Vec3f& towardLight);
    /// Throws InputError for a non-finite position.
    static LightGeometry point(const Vec3f& position);

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
};

std::ostream& operator<<(std::ostream& os, const LightGeometry& light);

} // namespace hairvox
