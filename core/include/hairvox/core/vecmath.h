// hairvox core: geometric vectors and bounding boxes.
//
// Points and directions are GLM vectors (world space, right-handed, y up in the
// procedural grooms and the default scene). Colours are a separate type (rgb.h).
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cmath>
#include <limits>
#include <ostream>

// Printing for test failures and error messages; in glm's namespace so that
// argument-dependent lookup finds it from any template.
namespace glm {
template <typename T, qualifier Q>
std::ostream& operator<<(std::ostream& os, const vec<3, T, Q>& v) {
    return os << "(" << v.x << ", " << v.y << ", " << v.z << ")";
}
} // namespace glm

namespace hairvox {

using Vec2f = glm::vec2;
using Vec3f = glm::vec3;
using Vec3d = glm::dvec3;

inline bool isFinite(const Vec3f& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// v / |v|, or `fallback` when v is too short to normalise reliably.
inline Vec3f normalizeOr(const Vec3f& v, const Vec3f& fallback) {
    const float len = glm::length(v);
    return len > 1e-12f ? v / len : fallback;
}

/// Two unit vectors perpendicular to unit n and to each other (Duff et al. 2017,
/// "Building an Orthonormal Basis, Revisited"): {s, t, n} is right-handed.
inline void coordinateSystem(const Vec3f& n, Vec3f& s, Vec3f& t) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    s = Vec3f(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    t = Vec3f(b, sign + n.y * n.y * a, -n.y);
}

/// Axis-aligned box; default-constructed empty (min > max).
struct Bounds3f {
    Vec3f min{std::numeric_limits<float>::infinity()};
    Vec3f max{-std::numeric_limits<float>::infinity()};

    bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    void extend(const Vec3f& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    void extend(const Bounds3f& b) {
        min = glm::min(min, b.min);
        max = glm::max(max, b.max);
    }
    Vec3f extent() const { return empty() ? Vec3f(0.0f) : max - min; }
    Vec3f center() const { return 0.5f * (min + max); }
};

inline std::ostream& operator<<(std::ostream& os, const Bounds3f& b) {
    if (b.empty())
        return os << "Bounds3f(empty)";
    return os << "Bounds3f(" << b.min << " .. " << b.max << ")";
}

/// A sphere (the opaque head of a scene: it hides hair and blocks light).
struct Sphere {
    Vec3f center{0.0f};
    float radius = 0;

    bool contains(const Vec3f& p) const {
        return glm::dot(p - center, p - center) < radius * radius;
    }

    /// The first t ∈ (0, tMax) at which the ray o + t·d (d unit) meets the
    /// sphere's surface, or a negative value if it does not. A ray starting
    /// inside meets it on the way out. The one ray–sphere intersection of the
    /// project (the head's occlusion, its primary visibility and the path
    /// tracer all call it).
    float intersect(const Vec3f& o, const Vec3f& d, float tMax) const {
        const Vec3f oc = o - center;
        const float b = glm::dot(oc, d);
        const float c = glm::dot(oc, oc) - radius * radius;
        const float disc = b * b - c;
        if (disc < 0)
            return -1.0f;
        const float root = std::sqrt(disc);
        // Of the two roots −b ∓ √disc, the nearer one in front of the origin;
        // c = (−b − √disc)(−b + √disc) gives the near root without cancellation.
        const float far = -b + root;
        const float near = far > 0 ? c / far : -b - root;
        const float t = near > 0 ? near : far;
        return t > 0 && t < tMax ? t : -1.0f;
    }
    /// Whether the segment o + t·d, t ∈ (0, tMax), meets the sphere (a segment
    /// starting inside does).
    bool intersects(const Vec3f& o, const Vec3f& d, float tMax) const {
        return contains(o) || intersect(o, d, tMax) > 0;
    }
};

} // namespace hairvox
