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
};

std::ostream& operator<<(std::ostream& os, const DualScatteringParams& p);

} // namespace hairvox
