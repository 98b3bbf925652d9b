// Internal to hairvox render: the FragmentShader of a real render — the
// dual-scattering shader (shading/) fed with each light's global term
// (transmittance/), weighted by each light's irradiance.
#pragma once

#include <hairvox/render/fragment_shader.h>
#include <hairvox/render/light.h>
#include <hairvox/shading/dual_scattering_shader.h>
#include <hairvox/transmittance/global_term_model.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

namespace hairvox::detail {

class DualScatteringFragmentShader final : public FragmentShader {
public:
    /// `lightTerms[l]` is the global term toward lights[l], or null for a light
    /// that is skipped (contributes nothing; its AOVs read "blocked").
    DualScatteringFragmentShader(const DualScatteringShader& shader, std::vector<Light> lights,
                                 std::vector<std::unique_ptr<LightGlobalTerm>> lightTerms);

    void shade(std::span<const ShadingPoint> points, std::span<ShadeResult> radiance,
               std::span<GlobalTerm> globalTerms) const override;

    /// Thread-seconds spent evaluating the global term, and in shade() overall.
    double globalTermThreadSeconds() const { return 1e-9 * double(globalTermNanos_.load()); }
    double shadeThreadSeconds() const { return 1e-9 * double(shadeNanos_.load()); }
    /// Per light, summed over every batch.
    std::vector<GlobalTermStats> stats() const;

private:
    DualScatteringShader shader_;
    std::vector<Light> lights_;
    std::vector<std::unique_ptr<LightGlobalTerm>> terms_;
    mutable std::atomic<std::int64_t> globalTermNanos_{0}, shadeNanos_{0};
    mutable std::mutex statsMutex_;
    mutable std::vector<GlobalTermStats> stats_;
};

} // namespace hairvox::detail
