#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/shading/dual_scattering_shader.h>
#include <hairvox/shading/longitudinal.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hairvox {

namespace {

std::uint64_t paramsDigest(const FiberParams& p) {
    Hasher h;
    p.hashInto(h);
    return h.digest();
}

DualScatteringTables tablesFor(const DualScatteringTables& tables, float d_b) {
    return tables.options().d_b == d_b ? tables : tables.withBackwardDensity(d_b);
}

} // namespace

DualScatteringShader::DualScatteringShader(const MarschnerBcsdf& bcsdf,
                                           const DualScatteringTables& tables,
                                           const DualScatteringParams& params)
    : bcsdf_(bcsdf)
    , tables_(tablesFor(tables, params.d_b))
    , params_(params) {
    params_.validate();
    if (paramsDigest(bcsdf.params()) != paramsDigest(tables.params()))
        throw std::invalid_argument(strCat("DualScatteringShader: tables built for ",
                                           tables.params(), " used with ", bcsdf.params()));
}

DualScatteringShader::Backscatter DualScatteringShader::backscatter(float theta_i) const {
    using S = DualScatteringTables::Sample;
    const auto [ABar_b, DeltaBar_b, sigma2Bar_b] =
        tables_.interpolate(theta_i, &S::ABar_b, &S::DeltaBar_b, &S::sigma2Bar_b);
    return {ABar_b, DeltaBar_b, sigma2Bar_b};
}

Rgb DualScatteringShader::fBack(const FiberAngles& a, const Backscatter& b,
                                const Rgb& sigma2) const {
    const float azimuthal = 0.5f * std::max(a.cosPhi, 0.0f);
    if (azimuthal == 0)
        return Rgb(0.0f);
    const Rgb longitudinal =
        longitudinalLobe(Rgb(a.theta_h) - b.DeltaBar_b, b.sigma2Bar_b + sigma2);
    return b.ABar_b * longitudinal * (azimuthal / a.cos2Theta_d);
}

Rgb DualScatteringShader::fBack(const FiberAngles& a, const Rgb& sigma2) const {
    return fBack(a, backscatter(a.theta_i), sigma2);
}

Rgb DualScatteringShader::fsScatter(const FiberAngles& a, const Rgb& sigma2_f) const {
    const LobeValues ng = tables_.NG(a.theta_d, a.phi);
    Rgb sum(0.0f);
    for (Lobe p : kLobes) {
        const float beta = bcsdf_.beta(p);
        sum +=
            ng[p] * longitudinalLobe(Rgb(a.theta_h - bcsdf_.alpha(p)), Rgb(beta * beta) + sigma2_f);
    }
    return sum * (1.0f / a.cos2Theta_d);
}

ShadeResult DualScatteringShader::shade(const FiberAngles& a, const GlobalTerm& g) const {
    ShadeResult r;
    // Components whose weight is zero are not computed (DESIGN.md §7).
    const bool direct = g.V > 0, scatter = !g.T_s.isBlack();
    if (a.cosTheta_i <= 0 || !(direct || scatter))
        return r;
    const Backscatter b = backscatter(a.theta_i);
    if (direct) {
        const float w = g.V * a.cosTheta_i;
        const LobeValues f = bcsdf_.eval(a);
        r.directR = f.R * w;
        r.directTT = f.TT * w;
        r.directTRT = f.TRT * w;
        r.backDirect = fBack(a, b, Rgb(0.0f)) * (params_.d_b * w);
    }
    if (scatter) {
        const Rgb sigma2_f = max(g.sigma2_f, Rgb(0.0f));
        r.scatter = g.T_s *
                    (fsScatter(a, sigma2_f) +
                     static_cast<float>(Pi) * params_.d_b * fBack(a, b, sigma2_f)) *
                    a.cosTheta_i;
    }
    return r;
}

} // namespace hairvox
