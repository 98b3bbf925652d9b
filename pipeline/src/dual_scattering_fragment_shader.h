// hairvox pipeline (private): the FragmentShader of the rasterized integrators
// — the dual-scattering shader (shading/) fed with each light's global term
// (transmittance/), weighted by each light's irradiance; for the volumetric
// integrator, its single scattering with the multiple scattering read from
// the radiance cache (volumetric/radiance_cache.h) instead of dual
// scattering's.
//
// Layout (render/fragment_shader.h), the EXR layers of a render:
//   radiance  direct_R, direct_TT, direct_TRT   V·f_p·cos θ_i per lobe (single scattering)
//   dual scattering:
//             back_direct                      V·d_b·f_back^direct·cos θ_i (local multiple
//                                              scattering)
//             scatter                          F_scatter·cos θ_i (global multiple scattering)
//   volumetric:
//             multiple                         ∫ f_s L cos θ_i dω_i over the cached light that
//                                              has scattered at least once (the path
//                                              tracer's layer of the same name)
//   averages  per light l: l.V, l.n (scalars); dual scattering also l.T_s, l.sigma_f
//             (RGB, σ_f = √σ_f²)
// A point is shaded with the shader of its segment's fiber type (Groom::fiberType).
// The environment's lights add to the radiance layers like the others.
#pragma once

#include <hairvox/geometry/light.h>
#include <hairvox/render/fragment_shader.h>
#include <hairvox/shading/dual_scattering_shader.h>
#include <hairvox/transmittance/global_term_model.h>
#include <hairvox/volumetric/radiance_cache.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

namespace hairvox::detail {

/// The layout above for these lights: dual scattering's, or with
/// `multipleScattering` the volumetric integrator's.
ShaderLayout hairShaderLayout(std::span<const Light> lights, bool multipleScattering);

/// The environment's regions as lights (environment_lights.h): each shaded
/// with its angular spread, into the radiance layers only (no per-light AOVs).
/// With a groom and a spacing, their terms are evaluated at samples along the
/// fibers planned once for all of them (FiberSamplePlan) and interpolated.
struct ShadedEnvironment {
    std::vector<Light> lights;
    std::vector<float> spread2; ///< per light (DualScatteringShader::shade)
    std::vector<std::shared_ptr<const LightGlobalTerm>> terms; ///< null: skipped
    const Groom* groom = nullptr;                              ///< must outlive the shader
    float spacing = 0; ///< world units between samples along a fiber; 0: none
};

/// The volumetric integrator's multiple scattering (radiance_cache.h). With
/// a groom and a spacing, the cells' light is read at samples along the
/// fibers (FiberSamplePlan), each in the frame of the fiber's shading tangent
/// there (strands/groom.h shadingTangent: a blend of 8 cells and a rotation
/// per sample), and a point's radiance toward its own ω_o is interpolated
/// between the two samples around it, each contracted with the fiber's kernel
/// (a rotation is ~6× a contraction; the cache varies over its cells, a
/// fragment every pixel). Without, or where a batch of points would need
/// more samples than it has points: at every point, about its own tangent.
struct ShadedMultiple {
    const RadianceCache* cache = nullptr; ///< null: dual scattering
    const Groom* groom = nullptr;         ///< must outlive the shader
    float spacing = 0;                    ///< world units between samples along a fiber; 0: none
};

class DualScatteringFragmentShader final : public FragmentShader {
public:
    /// `shaders[t]` shades fiber type t; `fiberType` is the groom's
    /// (Groom::fiberType, empty for an untyped groom; it must outlive the
    /// shader). `lightTerms[l]` is the global term toward lights[l], or null
    /// for a light that is skipped (contributes nothing; its AOVs read "blocked").
    /// `environment`: the environment's regions (ShadedEnvironment, above).
    /// With `multiple`.cache (the volumetric integrator; must outlive the
    /// shader) the multiple scattering comes from it (ShadedMultiple, above),
    /// and the shaders give single scattering only (their back_direct and
    /// scatter are not read).
    DualScatteringFragmentShader(std::vector<DualScatteringShader> shaders,
                                 std::span<const std::uint8_t> fiberType, std::vector<Light> lights,
                                 std::vector<std::shared_ptr<const LightGlobalTerm>> lightTerms,
                                 ShadedEnvironment environment = {}, ShadedMultiple multiple = {});

    const ShaderLayout& layout() const override { return layout_; }
    void shade(std::span<const ShadingPoint> points, std::span<float> out) const override;

    /// Thread-seconds spent evaluating the global term, and in shade() overall.
    double globalTermThreadSeconds() const { return 1e-9 * double(globalTermNanos_.load()); }
    double shadeThreadSeconds() const { return 1e-9 * double(shadeNanos_.load()); }
    /// Per light, summed over every batch.
    std::vector<GlobalTermStats> stats() const;
    /// Over the environment's lights, summed over every batch.
    GlobalTermStats environmentStats() const;

private:
    std::vector<DualScatteringShader> shaders_; ///< per fiber type
    std::span<const std::uint8_t> fiberType_;
    std::vector<Light> lights_;
    std::vector<std::shared_ptr<const LightGlobalTerm>> terms_;
    ShadedEnvironment environment_;
    /// The multiple scattering of `points` into out's `multiple` layer
    /// (ShadedMultiple); `queries` are the points'.
    void shadeMultiple(std::span<const ShadingPoint> points,
                       std::span<const GlobalTermQuery> queries, std::span<float> out) const;

    ShadedMultiple multiple_;
    /// With multiple_.groom: strandTangents() of its points.
    std::vector<Vec3f> pointTangents_;
    ShaderLayout layout_;
    mutable std::atomic<std::int64_t> globalTermNanos_{0}, shadeNanos_{0};
    mutable std::mutex statsMutex_;
    mutable std::vector<GlobalTermStats> stats_;
    mutable GlobalTermStats environmentStats_;
};

} // namespace hairvox::detail
