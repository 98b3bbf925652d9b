// hairvox shading: the optical parameters of a hair fiber (Marschner et al.
// 2003, Table 1; conventions in docs/DESIGN.md §3).
//
// Angles are radians. α_R is signed as in Marschner (negative: the R lobe is
// shifted towards the root); the other lobes follow α_TT = −α_R/2,
// α_TRT = −3α_R/2, β_TT = β_R/2, β_TRT = 2β_R. σ_a is the RGB absorption
// coefficient per unit fiber *radius*.
#pragma once

#include <hairvox/core/hash.h>
#include <hairvox/core/math.h>
#include <hairvox/core/rgb.h>

#include <ostream>

namespace hairvox {

struct FiberParams {
    float eta = 1.55f;                    ///< index of refraction η, [1.1, 2.5]
    Rgb sigma_a{0.2f, 0.3f, 0.5f};        ///< absorption per unit radius, each in [0, 50]
    float alpha_R = radians(-7.5f);       ///< R-lobe longitudinal shift, [−20°, 20°]
    float beta_R = radians(7.5f);         ///< R-lobe longitudinal width, [0.5°, 45°]
    float eccentricity = 1.0f;            ///< a, [0.5, 1]
    float causticWidth = radians(15.0f);  ///< w_c, [1°, 45°]
    float causticGain = 0.5f;             ///< k_G, [0, 10]
    float causticFade = 0.3f;             ///< Δη', [0.01, 1]
    float causticMaxWidth = 0.5f;         ///< Δh_M, [0.01, 2]

    /// σ_a from melanin concentrations as in pbrt-v3/v4:
    /// c_eu·(0.419, 0.697, 1.37) + c_pheo·(0.187, 0.4, 1.05).
    static Rgb sigmaFromMelanin(float eumelanin, float pheomelanin);
    /// σ_a from the colour c a dense mass of these fibers should show: the
    /// inverse of the multiple-scattering albedo fitted by Chiang et al. 2016
    /// (Eq. 9), per channel σ_a = (ln c / f(β_n))² with
    /// f(β_n) = 5.969 − 0.215β_n + 2.532β_n² − 10.73β_n³ + 5.574β_n⁴ + 0.245β_n⁵
    /// at β_n = kColorRoughness (pbrt-v4's default azimuthal roughness: the
    /// Marschner fiber has no β_n; its smooth azimuthal lobes are closest to
    /// this). The fit is for σ_a per unit radius with path length 2cos γ_t /
    /// cos θ_t through the fiber, our convention. c = 1 gives σ_a = 0; each
    /// channel is clamped to [kMinColor, 1] first, so σ_a stays within the
    /// valid range (σ_a ≤ 22 at c = 1e-12).
    static Rgb sigmaFromColor(const Rgb& color);
    static constexpr float kColorRoughness = 0.3f;
    static constexpr float kMinColor = 1e-12f;

    /// Throws InputError naming the first parameter outside its range (given above).
    void validate() const;
    /// Folds every parameter into a content hash (table cache keys).
    void hashInto(Hasher& hasher) const;
};

std::ostream& operator<<(std::ostream& os, const FiberParams& p);

/// Zinke et al.'s density factors of the dual-scattering model. Zinke prints
/// 0.7; measured against the path tracer (docs/DESIGN.md §8), 1 with the
/// energy-conserving N^G is closer on every scene and melanin, so 1 is the default.
struct DualScatteringParams {
    float d_f = 1.0f; ///< forward scattering density factor, [0, 1]
    float d_b = 1.0f; ///< backward scattering density factor, [0, 1]

    void validate() const;
    void hashInto(Hasher& hasher) const;
};

std::ostream& operator<<(std::ostream& os, const DualScatteringParams& p);

} // namespace hairvox
