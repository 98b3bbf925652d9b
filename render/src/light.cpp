#include <hairvox/render/light.h>

#include <algorithm>

namespace hairvox {

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
