// hairvox tests: the analytic slab of parallel fibers (docs/DESIGN.md §5 and
// issue 5): straight fibers along x at uniform random (y, z) in a box, so the
// length density λ and every expected crossing count have closed forms.
#pragma once

#include <hairvox/core/rng.h>
#include <hairvox/strands/groom.h>
#include <hairvox/transmittance/crossing_table.h>
#include <hairvox/transmittance/global_term_model.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <cmath>

namespace hairvox::test {

struct Slab {
    float lengthX = 0.10f, thicknessY = 0.01f, depthZ = 0.20f; ///< metres
    int fibers = 8000;
    std::uint64_t seed = 11;

    /// Fiber length per unit volume.
    double lambda() const { return fibers / (double(thicknessY) * double(depthZ)); }

    /// Expected crossings from the bottom face (y = 0) up through the whole
    /// slab toward unit direction ω: λ·D·|ω × x̂|·(thickness / ω_y).
    double expectedN(const Vec3f& omega, float diameter) const {
        const double oy = omega.y, oz = omega.z;
        const double sinToFiber = std::sqrt(oy * oy + oz * oz);
        return lambda() * double(diameter) * sinToFiber * double(thicknessY) / oy;
    }

    Groom groom() const {
        Groom g;
        Pcg32 rng(seed);
        for (int i = 0; i < fibers; ++i) {
            const float y = thicknessY * rng.uniformFloat();
            const float z = depthZ * rng.uniformFloat() - 0.5f * depthZ;
            const Vec3f line[2] = {{-0.5f * lengthX, y, z}, {0.5f * lengthX, y, z}};
            g.addStrand(line);
        }
        return g;
    }
};

/// The fiber diameter of the slab tests: with the default slab, n = 2 straight up.
constexpr float kSlabDiameter = 5e-5f;

/// The slab's fiber grid at `voxelSize` (diameter kSlabDiameter).
inline FiberGrid splatSlab(const Slab& slab, double voxelSize) {
    SplatOptions options;
    options.voxelSize = voxelSize;
    options.fiberScale.diameter = kSlabDiameter;
    return splatStrands(slab.groom(), options);
}

/// Global-term settings of the slab tests (diameter kSlabDiameter, defaults otherwise).
inline GlobalTermSettings slabSettings() {
    GlobalTermSettings s;
    s.fiberScale.diameter = kSlabDiameter;
    return s;
}

/// A crossing table with the same ā_f and β̄_f² at every inclination, so the
/// closed forms depend on the crossing count only.
inline CrossingTable constantTable(float aBar, float beta2) {
    return CrossingTable::build([=](float) { return Rgb(aBar); },
                                [=](float) { return Rgb(beta2); });
}

} // namespace hairvox::test
