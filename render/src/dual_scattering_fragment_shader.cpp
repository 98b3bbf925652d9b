#include "dual_scattering_fragment_shader.h"

#include <chrono>

namespace hairvox::detail {

namespace {

std::int64_t nanosSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() -
                                                                start)
        .count();
}

} // namespace

DualScatteringFragmentShader::DualScatteringFragmentShader(
    const DualScatteringShader& shader, std::vector<Light> lights,
    std::vector<std::unique_ptr<LightGlobalTerm>> lightTerms)
    : shader_(shader), lights_(std::move(lights)), terms_(std::move(lightTerms)),
      stats_(lights_.size()) {}

void DualScatteringFragmentShader::shade(std::span<const ShadingPoint> points,
                                         std::span<ShadeResult> radiance,
                                         std::span<GlobalTerm> globalTerms) const {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t lightCount = lights_.size();
    for (ShadeResult& r : radiance)
        r = {};
    std::vector<GlobalTermQuery> queries(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
        queries[i] = {points[i].position, points[i].tangent, points[i].strand};
    std::vector<GlobalTerm> terms(points.size());
    std::int64_t globalTermNanos = 0;
    std::vector<GlobalTermStats> batchStats(lightCount);

    for (std::size_t l = 0; l < lightCount; ++l) {
        if (!terms_[l]) {
            for (std::size_t i = 0; i < points.size(); ++i)
                globalTerms[i * lightCount + l] = GlobalTerm::blocked();
            continue;
        }
        const auto evalStart = std::chrono::steady_clock::now();
        batchStats[l] = terms_[l]->evaluate(queries, terms);
        globalTermNanos += nanosSince(evalStart);
        const Light& light = lights_[l];
        for (std::size_t i = 0; i < points.size(); ++i) {
            const ShadingPoint& p = points[i];
            globalTerms[i * lightCount + l] = terms[i];
            if (terms[i].V == 0 && terms[i].T_s.isBlack())
                continue; // no light arrives: nothing to shade
            const Light::Path path = light.pathFrom(p.position);
            const ShadeResult r = shader_.shade(path.omega, p.toCamera, p.tangent, terms[i]);
            addWeighted(radiance[i], r, light.irradiance(path.distance));
        }
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
