#include <hairvox/render/fragment_shader.h>

namespace hairvox {

std::ostream& operator<<(std::ostream& os, const ShadingPoint& p) {
    return os << "ShadingPoint(position=" << p.position << ", tangent=" << p.tangent
              << ", toCamera=" << p.toCamera << ", strand=" << p.strand << ", segment=" << p.segment
              << ")";
}

std::size_t ShaderLayout::stride() const {
    std::size_t n = radianceFloats();
    for (const AverageLayer& a : averages)
        n += std::size_t(a.channels);
    return n;
}

} // namespace hairvox
