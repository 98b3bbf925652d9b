#include <hairvox/core/error.h>
#include <hairvox/shading/fiber_params.h>

#include <algorithm>
#include <cmath>

namespace hairvox {

namespace {

void requireRange(const char* name, float value, float lo, float hi, const char* unit = "") {
    if (!(value >= lo && value <= hi))
        throw InputError(strCat(name, " = ", value, unit, " should be in the range [", lo, ", ",
                                hi, "]", unit));
}

void requireDegrees(const char* name, float radiansValue, float loDeg, float hiDeg) {
    requireRange(name, degrees(radiansValue), loDeg, hiDeg, " deg");
}

} // namespace

Rgb FiberParams::sigmaFromMelanin(float eumelanin, float pheomelanin) {
    requireRange("eumelanin", eumelanin, 0.0f, 20.0f);
    requireRange("pheomelanin", pheomelanin, 0.0f, 20.0f);
    return eumelanin * Rgb(0.419f, 0.697f, 1.37f) + pheomelanin * Rgb(0.187f, 0.4f, 1.05f);
}

Rgb FiberParams::sigmaFromColor(const Rgb& color) {
    const float b = kColorRoughness;
    const float f = 5.969f - 0.215f * b + 2.532f * b * b - 10.73f * b * b * b +
                    5.574f * b * b * b * b + 0.245f * b * b * b * b * b;
    Rgb sigma;
    for (int c = 0; c < 3; ++c) {
        const float lnC = std::log(std::clamp(color[c], kMinColor, 1.0f)) / f;
        sigma[c] = lnC * lnC;
    }
    return sigma;
}

void FiberParams::validate() const {
    requireRange("eta", eta, 1.1f, 2.5f);
    for (int c = 0; c < 3; ++c)
        requireRange("sigma_a", sigma_a[c], 0.0f, 50.0f);
    requireDegrees("alpha_R", alpha_R, -20.0f, 20.0f);
    requireDegrees("beta_R", beta_R, 0.5f, 45.0f);
    requireRange("eccentricity", eccentricity, 0.5f, 1.0f);
    requireDegrees("caustic_width", causticWidth, 1.0f, 45.0f);
    requireRange("caustic_gain", causticGain, 0.0f, 10.0f);
    requireRange("caustic_fade", causticFade, 0.01f, 1.0f);
    requireRange("caustic_max_width", causticMaxWidth, 0.01f, 2.0f);
}

void FiberParams::hashInto(Hasher& hasher) const {
    hasher.value(eta).value(sigma_a).value(alpha_R).value(beta_R).value(eccentricity);
    hasher.value(causticWidth).value(causticGain).value(causticFade).value(causticMaxWidth);
}

void DualScatteringParams::hashInto(Hasher& hasher) const {
    hasher.value(d_f).value(d_b);
}

std::ostream& operator<<(std::ostream& os, const FiberParams& p) {
    return os << "FiberParams(eta=" << p.eta << ", sigma_a=" << p.sigma_a
              << ", alpha_R=" << degrees(p.alpha_R) << "deg, beta_R=" << degrees(p.beta_R)
              << "deg, eccentricity=" << p.eccentricity << ", w_c=" << degrees(p.causticWidth)
              << "deg, k_G=" << p.causticGain << ", dEta'=" << p.causticFade
              << ", dh_M=" << p.causticMaxWidth << ")";
}

void DualScatteringParams::validate() const {
    requireRange("d_f", d_f, 0.0f, 1.0f);
    requireRange("d_b", d_b, 0.0f, 1.0f);
}

std::ostream& operator<<(std::ostream& os, const DualScatteringParams& p) {
    return os << "DualScatteringParams(d_f=" << p.d_f << ", d_b=" << p.d_b << ")";
}

} // namespace hairvox
