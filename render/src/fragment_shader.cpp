#include <hairvox/render/fragment_shader.h>

namespace hairvox {

const char* toString(ShadingRate rate) {
    return rate == ShadingRate::Vertex ? "vertex" : "fragment";
}

std::optional<ShadingRate> parseShadingRate(std::string_view name) {
    if (name == "fragment")
        return ShadingRate::Fragment;
    if (name == "vertex")
        return ShadingRate::Vertex;
    return std::nullopt;
}

std::ostream& operator<<(std::ostream& os, const ShadingPoint& p) {
    return os << "ShadingPoint(position=" << p.position << ", tangent=" << p.tangent
              << ", toCamera=" << p.toCamera << ", strand=" << p.strand
              << ", segment=" << p.segment << ")";
}

void addWeighted(ShadeResult& sum, const ShadeResult& s, const Rgb& w) {
    sum.directR += w * s.directR;
    sum.directTT += w * s.directTT;
    sum.directTRT += w * s.directTRT;
    sum.backDirect += w * s.backDirect;
    sum.scatter += w * s.scatter;
}

void addWeighted(ShadeResult& sum, const ShadeResult& s, float w) { addWeighted(sum, s, Rgb(w)); }

} // namespace hairvox
