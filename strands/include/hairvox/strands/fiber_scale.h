// hairvox strands: how thick a groom's fibers are and how many real hairs a
// modeled strand stands for — the scale controls artists expect (Sadeghi et
// al. 2010; Unreal's DensityScale), in the one form every stage reads.
//
// The density multiplier k has one meaning everywhere (DEVELOPERS.md): a
// modeled strand stands for k hairs of diameter D side by side. So the
// cross-section that a ray meets per unit length of strand is k·D
// (ribbonWidth()):
//  - voxelize records D and k; the global term's optical depth is λ·k·D·cos θ;
//  - exact mode, the path tracer and the rasterizer meet one ray-facing ribbon
//    k·D wide, one hair per crossing.
// (The rasterizer once drew D-wide ribbons composited as (1 − α)^k, k hairs at
// independent places in the pixel: O(α²) less coverage than the ribbon the
// rays meet, which put 2–5% between depth-1 path tracing and the rasterizer's
// single scattering at k = 3.)
#pragma once

#include <hairvox/core/hash.h>

#include <ostream>

namespace hairvox {

struct FiberScale {
    float diameter = 7e-5f;         ///< D, scene units (70 µm in metres), (0, 1000]
    float densityMultiplier = 1.0f; ///< k: real hairs per modeled strand, [0.01, 10000]

    /// k·D: the width of the ray-facing ribbon that stands for a strand's k hairs.
    float ribbonWidth() const { return diameter * densityMultiplier; }

    /// Throws InputError naming the field (fiber.diameter, fiber.density_multiplier)
    /// and its range.
    void validate() const;
    void hashInto(Hasher& hasher) const;
};

std::ostream& operator<<(std::ostream& os, const FiberScale& s);

} // namespace hairvox
