// hairvox volumetric (internal): where a light's paths start — only toward the
// hair (multiple_scattering.h, "Emission").
//
// A light lights the hair through a plane ⟂ its axis through the hair's
// centre: parallel rays for a directional light, rays from the light's
// position for a point light. The hair's voxels, projected onto that plane
// (along the axis, or centrally from the point light), mark the texels of a
// grid in it (each voxel's texel and its 8 neighbours: a voxel's box projects
// within 0.87 voxels of its centre's projection); a path starts through a
// uniformly chosen marked texel, at a uniform point in it. A directional
// light's path then carries E·A/N (A the marked area), a point light's
// I/(N·p_ω) with p_ω = r²/(cos θ·A) the density of its direction in solid
// angle (r, θ: distance and angle to the axis of the plane point). A point
// light too close to the hair for the plane (a voxel centre more than ~78°
// off its axis) sends its paths uniformly over all directions instead.
// A path that misses the hair through a marked texel costs a walk of empty
// blocks; none is sent where no hair is.
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/geometry/light.h>

#include <cstdint>
#include <vector>

namespace hairvox {

struct FiberGrid;

class LightEmission {
public:
    /// The footprint of `grid` seen from `light`; `centre` and `radius` bound
    /// the hair (a sphere the paths start outside of).
    LightEmission(const Light& light, const FiberGrid& grid, const Vec3f& centre, float radius);

    struct Start {
        Vec3f origin, dir; ///< dir unit
        Rgb power;         ///< the path's power, for `paths` paths from this light
    };
    /// The path through the point (u1, u2) ∈ [0, 1)² of the footprint.
    Start start(float u1, float u2, std::uint64_t paths) const;

    /// The power the light sends toward the hair (what its paths carry in all,
    /// in expectation): the basis of its share of the paths.
    Rgb power() const { return power_; }
    /// Marked texels (0: the light sees no hair, or spreads uniformly).
    std::size_t texels() const { return marked_.size(); }

private:
    const Light* light_;
    Vec3f centre_, axis_, s_, t_; ///< axis: along the paths' travel
    float radius_ = 0, texel_ = 0;
    Vec2f gridMin_{0.0f};
    int gridWidth_ = 0;
    std::vector<std::uint32_t> marked_; ///< texel indices y·width + x, ascending
    bool uniform_ = false;              ///< a point light sending over the sphere
    Rgb power_{0.0f};
};

} // namespace hairvox
