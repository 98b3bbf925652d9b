#include "dual_scattering_fragment_shader.h"

#include <hairvox/core/math.h>
#include <hairvox/strands/groom.h>

#include <chrono>

namespace hairvox::detail {

namespace {

std::int64_t nanosSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() -
                                                                start)
        .count();
}

/// Radiance layers: the ShadeResult components in order.
constexpr std::size_t kRadianceLayers = 5;
/// Floats per light among the averages: V, n, T_s (3), σ_f (3).
constexpr std::size_t kLightFloats = 8;

void put(float* out, const Rgb& c) {
    out[0] = c.r;
    out[1] = c.g;
    out[2] = c.b;
}

} // namespace

DualScatteringFragmentShader::DualScatteringFragmentShader(
    std::vector<DualScatteringShader> shaders, std::span<const std::uint8_t> fiberType,
    std::vector<Light> lights, std::vector<std::unique_ptr<LightGlobalTerm>> lightTerms)
    : shaders_(std::move(shaders))
    , fiberType_(fiberType)
    , lights_(std::move(lights))
    , terms_(std::move(lightTerms))
    , stats_(lights_.size()) {
    layout_.radiance = {"direct_R", "direct_TT", "direct_TRT", "back_direct", "scatter"};
    for (const Light& light : lights_) {
        layout_.averages.push_back({light.name + ".V", 1});
        layout_.averages.push_back({light.name + ".n", 1});
        layout_.averages.push_back({light.name + ".T_s", 3});
        layout_.averages.push_back({light.name + ".sigma_f", 3});
    }
}

void DualScatteringFragmentShader::shade(std::span<const ShadingPoint> points,
                                         std::span<float> out) const {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t lightCount = lights_.size();
    const std::size_t stride = layout_.stride();
    std::fill(out.begin(), out.end(), 0.0f);
    std::vector<GlobalTermQuery> queries(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
        queries[i] = {points[i].position, points[i].tangent, points[i].strand, true,
                      fiberTypeAt(fiberType_, points[i].segment)};
    std::vector<GlobalTerm> terms(points.size());
    std::vector<ShadeResult> radiance(points.size());
    std::int64_t globalTermNanos = 0;
    std::vector<GlobalTermStats> batchStats(lightCount);

    for (std::size_t l = 0; l < lightCount; ++l) {
        if (terms_[l]) {
            const auto evalStart = std::chrono::steady_clock::now();
            batchStats[l] = terms_[l]->evaluate(queries, terms);
            globalTermNanos += nanosSince(evalStart);
        } else {
            std::fill(terms.begin(), terms.end(), GlobalTerm::blocked());
        }
        const Light& light = lights_[l];
        for (std::size_t i = 0; i < points.size(); ++i) {
            const ShadingPoint& p = points[i];
            const GlobalTerm& g = terms[i];
            float* lightOut = out.data() + i * stride + 3 * kRadianceLayers + l * kLightFloats;
            lightOut[0] = g.V;
            lightOut[1] = g.n;
            put(lightOut + 2, g.T_s);
            put(lightOut + 5, safeSqrt(g.sigma2_f));
            if (!terms_[l] || (g.V == 0 && g.T_s.isBlack()))
                continue; // no light arrives: nothing to shade
            const Light::Path path = light.pathFrom(p.position);
            const ShadeResult r =
                shaders_[queries[i].fiberType].shade(path.omega, p.toCamera, p.tangent, g);
            const Rgb e = light.irradiance(path.distance);
            ShadeResult& sum = radiance[i];
            sum.directR += e * r.directR;
            sum.directTT += e * r.directTT;
            sum.directTRT += e * r.directTRT;
            sum.backDirect += e * r.backDirect;
            sum.scatter += e * r.scatter;
        }
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
        float* o = out.data() + i * stride;
        const ShadeResult& r = radiance[i];
        put(o, r.directR);
        put(o + 3, r.directTT);
        put(o + 6, r.directTRT);
        put(o + 9, r.backDirect);
        put(o + 12, r.scatter);
    }
    globalTermNanos_ += globalTermNanos;
    shadeNanos_ += nanosSince(start);
    const std::lock_guard lock(statsMutex_);
    for (std::size_t l = 0; l < lightCount; ++l)
        stats_[l] += batchStats[l];
}

std::vector<GlobalTermStats> DualScatteringFragmentShader::stats() const {
    const std::lock_guard lock(statsMutex_);
    return stats_;
}

} // namespace hairvox::detail
