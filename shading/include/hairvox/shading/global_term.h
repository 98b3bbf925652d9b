// hairvox shading: the dual-scattering global term at a shading point for one
// light (docs/DESIGN.md §5), the contract between the transmittance stage that
// computes it and the shader that consumes it.
#pragma once

#include <hairvox/core/rgb.h>

#include <ostream>

namespace hairvox {

struct GlobalTerm {
    float n = 0;       ///< expected number of fibers crossed toward the light
    float V = 1;       ///< direct visibility: probability that no fiber is crossed
    Rgb P{1.0f};       ///< mean product of forward attenuations ∏ā_f(θ_k) (1 when nothing is crossed)
    Rgb T_s{0.0f};     ///< forward-scattered transmittance d_f·(P − V), ≥ 0
    Rgb sigma2_f{0.0f}; ///< accumulated forward variance Σβ̄_f²(θ_k) (rad²), conditioned on a crossing

    /// Nothing between the point and the light.
    static GlobalTerm unoccluded() { return {}; }
    /// The light is blocked by an opaque occluder (the head): no light at all.
    static GlobalTerm blocked() { return {0.0f, 0.0f, Rgb(0.0f), Rgb(0.0f), Rgb(0.0f)}; }
};

inline std::ostream& operator<<(std::ostream& os, const GlobalTerm& g) {
    return os << "GlobalTerm(n=" << g.n << ", V=" << g.V << ", P=" << g.P << ", T_s=" << g.T_s
              << ", sigma2_f=" << g.sigma2_f << ")";
}

/// The dual-scattering shader's output for one light (RenderMan report §2.3),
/// every component already multiplied by cos θ_i and by its visibility weight,
/// so that total() is the reflected radiance per unit incident radiance and the
/// renderer's AOVs add up to its beauty image.
struct ShadeResult {
    Rgb directR, directTT, directTRT; ///< V·f_p^direct·cos θ_i per lobe (single scattering)
    Rgb backDirect;                   ///< V·d_b·f_back^direct·cos θ_i (local multiple scattering)
    Rgb scatter;                      ///< F_scatter·cos θ_i (global multiple scattering)

    Rgb total() const { return directR + directTT + directTRT + backDirect + scatter; }
};

inline std::ostream& operator<<(std::ostream& os, const ShadeResult& s) {
    return os << "ShadeResult(R=" << s.directR << ", TT=" << s.directTT << ", TRT=" << s.directTRT
              << ", backDirect=" << s.backDirect << ", scatter=" << s.scatter << ")";
}

} // namespace hairvox
