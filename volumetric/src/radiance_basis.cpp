#include <hairvox/volumetric/radiance_basis.h>

#include <hairvox/core/error.h>

#include <algorithm>
#include <cmath>

namespace hairvox {

int RadianceBasis::bin(float s) const {
    const int i = static_cast<int>((s + 1.0f) * 0.5f * float(thetaBins));
    return std::clamp(i, 0, thetaBins - 1);
}

void RadianceBasis::validate() const {
    if (thetaBins < 2 || thetaBins > 64)
        throw InputError(strCat("volumetric: theta_bins = ", thetaBins,
                                ": expected an integer in [2, 64]"));
    if (azimuthalOrder < 0 || azimuthalOrder > kMaxOrder)
        throw InputError(strCat("volumetric: azimuthal_order = ", azimuthalOrder,
                                ": expected an integer in [0, ", kMaxOrder, "]"));
}

std::ostream& operator<<(std::ostream& os, const RadianceBasis& b) {
    return os << "RadianceBasis(thetaBins=" << b.thetaBins << ", azimuthalOrder=" << b.azimuthalOrder
              << ")";
}

FiberFrame FiberFrame::about(const Vec3f& axis) {
    FiberFrame f;
    f.axis = axis;
    coordinateSystem(axis, f.e1, f.e2);
    return f;
}

FiberFrame FiberFrame::along(const Vec3f& tangent, const FiberFrame& reference) {
    FiberFrame f;
    f.axis = tangent;
    Vec3f e1 = reference.e1 - glm::dot(reference.e1, tangent) * tangent;
    if (glm::dot(e1, e1) < 1e-4f)
        e1 = reference.e2 - glm::dot(reference.e2, tangent) * tangent;
    f.e1 = glm::normalize(e1);
    f.e2 = glm::cross(tangent, f.e1);
    return f;
}

AzimuthalHarmonics AzimuthalHarmonics::of(const Vec3f& omega, const FiberFrame& frame, int order) {
    AzimuthalHarmonics h;
    h.s = std::clamp(glm::dot(omega, frame.axis), -1.0f, 1.0f);
    const float x = glm::dot(omega, frame.e1), y = glm::dot(omega, frame.e2);
    const float r = std::sqrt(x * x + y * y);
    // Along the axis the azimuth is undefined and every harmonic but the
    // constant has zero weight in the bin's solid angle: take φ = 0.
    const float c = r > 1e-7f ? x / r : 1.0f, sn = r > 1e-7f ? y / r : 0.0f;
    h.harmonic[0] = 1.0f;
    // cos kφ, sin kφ by the angle-addition recurrence (no trigonometric call).
    float ck = 1.0f, sk = 0.0f;
    for (int k = 1; k <= order; ++k) {
        const float cNext = ck * c - sk * sn, sNext = sk * c + ck * sn;
        ck = cNext;
        sk = sNext;
        h.harmonic[std::size_t(2 * k - 1)] = ck;
        h.harmonic[std::size_t(2 * k)] = sk;
    }
    return h;
}

} // namespace hairvox
