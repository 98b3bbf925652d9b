#include <hairvox/core/error.h>
#include <hairvox/transmittance/light_geometry.h>

namespace hairvox {

LightGeometry LightGeometry::directional(const Vec3f& towardLight) {
    const float len = glm::length(towardLight);
    if (!isFinite(towardLight) || !(len > 0))
        throw InputError(strCat("light direction ", towardLight,
                                " must be a finite, non-zero vector"));
    LightGeometry light;
    light.kind = Kind::Directional;
    light.direction = towardLight / len;
    return light;
}

LightGeometry LightGeometry::point(const Vec3f& position) {
    if (!isFinite(position))
        throw InputError(strCat("light position ", position, " must be finite"));
    LightGeometry light;
    light.kind = Kind::Point;
    light.position = position;
    return light;
}

std::ostream& operator<<(std::ostream& os, const LightGeometry& light) {
    if (light.kind == LightGeometry::Kind::Directional)
        return os << "LightGeometry(directional, toward " << light.direction << ")";
    return os << "LightGeometry(point at " << light.position << ")";
}

} // namespace hairvox
