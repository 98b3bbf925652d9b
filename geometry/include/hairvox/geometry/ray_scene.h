// hairvox geometry: the scene as rays meet it (Embree 3) — the strands as
// ray-facing ribbons, the one geometry that exact mode's shadow rays and the
// path tracer both intersect.
//
// Each strand segment is an Embree flat linear curve of width k·D (the fiber
// scale's ribbonWidth(): a modeled strand stands for k hairs of diameter D
// side by side, strands/fiber_scale.h), so a ray of direction ω that passes a
// fiber of tangent u hits it with probability proportional to k·D·|ω × u| —
// the cross-section the grid modes integrate (docs/DESIGN.md §5) — and each
// hit is one hair.
//
// crossings(): every fiber along a ray. A context filter records and rejects
// every candidate, so traversal visits all of them; the hits are then sorted
// and deduplicated: Embree can report the same primitive twice, and a ray
// through the joint of two consecutive segments of one strand hits both
// ribbons within about a ribbon width (one crossing).
//
// locate(): the strand a point lies on (a shading point's own fiber, which
// its shadow rays must not count): the query's strand hint, else a uniform
// grid of segments built on first use (Embree 3 has no point queries on curves).
#pragma once

#include <hairvox/core/vecmath.h>
#include <hairvox/strands/fiber_scale.h>
#include <hairvox/strands/groom.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

namespace hairvox {

inline constexpr std::uint32_t kUnknownStrand = std::numeric_limits<std::uint32_t>::max();

/// One fiber crossed by a ray.
struct FiberCrossing {
    float t; ///< distance along the ray
    std::uint32_t strand;
    std::uint32_t segment; ///< global segment index (Embree primitive)
    float arcLength;       ///< position of the crossing along its strand, from the root
    Vec3f tangent;         ///< unit tangent of the crossed segment, root → tip
};

/// A point on a strand's centreline.
struct FiberPoint {
    std::uint32_t strand;
    std::uint32_t segment;
    float arcLength; ///< from the root
};

class RayScene {
public:
    /// The groom's strands as ribbons of width scale.ribbonWidth(); locate()
    /// searches within max(D, k·D) of a centreline.
    RayScene(const Groom& groom, const FiberScale& scale);
    ~RayScene();
    RayScene(const RayScene&) = delete;
    RayScene& operator=(const RayScene&) = delete;

    /// Fiber crossings of the ray origin + t·dir, t ∈ (0, tMax), sorted by t
    /// and deduplicated (see the file comment). Thread-safe; `out` is overwritten.
    void crossings(const Vec3f& origin, const Vec3f& dir, float tMax,
                   std::vector<FiberCrossing>& out) const;

    /// The point of a strand centreline nearest to p, if one passes within
    /// the locate distance. With a strand hint only that strand is searched.
    std::optional<FiberPoint> locate(const Vec3f& p,
                                     std::uint32_t strandHint = kUnknownStrand) const;

    float ribbonWidth() const { return width_; }

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    float width_;
    float locateDistance_;
};

} // namespace hairvox
