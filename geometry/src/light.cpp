#include <hairvox/core/error.h>
#include <hairvox/geometry/light.h>

#include <algorithm>

namespace hairvox {

Light Light::directional(const Vec3f& towardLight) {
    const float len = glm::length(towardLight);
    if (!isFinite(towardLight) || !(len > 0))
        throw InputError(
            strCat("light direction ", towardLight, " must be a finite, non-zero vector"));
    Light light;
    light.kind = Kind::Directional;
    light.direction = towardLight / len;
    return light;
}

Light Light::point(const Vec3f& position) {
    if (!isFinite(position))
        throw InputError(strCat("light position ", position, " must be finite"));
    Light light;
    light.kind = Kind::Point;
    light.position = position;
    return light;
}

void Light::hashInto(Hasher& hasher) const {
    hasher.value(kind).value(direction).value(position).value(color).value(intensity);
}

Rgb Light::irradiance(float distance) const {
    const Rgb e = intensity * color;
    if (kind == Kind::Directional)
        return e;
    const float d = std::max(distance, 1e-6f);
    return e / (d * d);
}

std::ostream& operator<<(std::ostream& os, const Light& l) {
    os << "Light(" << l.name << ", ";
    if (l.kind == Light::Kind::Directional)
        os << "directional toward " << l.direction;
    else
        os << "point at " << l.position;
    return os << ", color=" << l.color << ", intensity=" << l.intensity << ")";
}

} // namespace hairvox
