// hairvox geometry: the scene as rays meet it (Embree 3) — the strands as
// ray-facing ribbons and the opaque surfaces, the one geometry that exact
// mode's shadow rays and the path tracer both intersect.
//
// Each strand segment is an Embree flat linear curve of width k·D_i at its
// points, linear between them (strands/groom.h ribbonWidthAt(): a modeled
// strand stands for k hairs of diameter D_i side by side, D_i the groom's
// per-point diameter or else the fiber scale's D, strands/fiber_scale.h), so a
// ray of direction ω that passes a fiber of tangent u hits it with
// probability proportional to k·D_i·|ω × u| — the cross-section the grid
// modes integrate (docs/DESIGN.md §5) — and each hit is one hair. A point of
// width 0 (a tapered tip) is never hit.
//
// A hit's tangent is the shading tangent the rasterizer uses too: the strand's
// point tangents interpolated along the segment (strands/groom.h). Embree's
// primitives are pieces of the segments (a few per segment: tighter boxes,
// faster rays), which the queries report as their segments.
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
//
// The own fiber: a ray leaving a point on a fiber must not meet that fiber
// again at its start. A crossing of the point's own strand is the fiber
// itself when the strand runs nearly straight between the point and the
// crossing — arc-length distance ≤ 1.5 × chord + slack — and is skipped; a
// curl looping back across the ray (arc length much longer than the chord) is
// another crossing and counts (isOwnFiber(); exact mode, and the path
// tracer's rays through intersect() and occluded()).
//
// Ribbons are butt-ended: Embree's flat linear curves have round end caps,
// whose hits are rejected, so that a ray meets exactly the cross-section
// k·D_i·|ω × u| per unit length — what the rasterizer covers and what the grid
// integrates (a fiber seen end-on blocks nothing).
//
// Surfaces: the scene's opaque spheres and meshes (geometry/surface_scene.h),
// met before any fiber behind them; they block light and end paths.
#pragma once

#include <hairvox/core/vecmath.h>
#include <hairvox/geometry/surface_scene.h>
#include <hairvox/strands/fiber_scale.h>
#include <hairvox/strands/groom.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

struct RTCFilterFunctionNArguments;

namespace hairvox {

inline constexpr std::uint32_t kUnknownStrand = std::numeric_limits<std::uint32_t>::max();

/// One fiber crossed by a ray.
struct FiberCrossing {
    float t; ///< distance along the ray
    std::uint32_t strand;
    std::uint32_t segment; ///< global segment index (Embree primitive)
    float arcLength;       ///< position of the crossing along its strand, from the root
    Vec3f tangent;         ///< unit shading tangent there (strands/groom.h shadingTangent)
};

/// A point on a strand's centreline.
struct FiberPoint {
    std::uint32_t strand;
    std::uint32_t segment;
    float arcLength; ///< from the root
};

/// The point a ray leaves from when it lies on a fiber, with the slack of the
/// own-fiber rule (see the file comment).
struct RayOrigin {
    FiberPoint fiber;
    float slack = 0;
};

/// What a ray meets first.
struct RayHit {
    enum class Kind { Fiber, Surface };
    Kind kind = Kind::Fiber;
    float t = 0;
    FiberPoint fiber{};       ///< Fiber: where, on which strand
    Vec3f tangent{0.0f};      ///< Fiber: unit shading tangent there, root → tip (shadingTangent)
    Vec3f normal{0.0f};          ///< Surface: unit shading normal, facing the ray's origin
    Vec3f geometricNormal{0.0f}; ///< Surface: unit, facing the ray's origin
    std::uint32_t surface = 0; ///< Surface: its index among the scene's surfaces
};

class RayScene {
public:
    /// The groom's strands as ribbons of width ribbonWidthAt(groom, scale, i)
    /// (locate() searches within max(D_i, k·D_i) of a centreline, at the
    /// widest point) and the opaque surfaces (null: none), which the RayScene
    /// shares.
    RayScene(const Groom& groom, const FiberScale& scale,
             std::shared_ptr<const SurfaceScene> surfaces = nullptr);
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

    /// The first fiber or surface on origin + t·dir, t ∈ (0, tMax), skipping
    /// the origin's own fiber when it lies on one. Thread-safe.
    std::optional<RayHit> intersect(const Vec3f& origin, const Vec3f& dir, float tMax,
                                    const RayOrigin* from = nullptr) const;
    /// Whether any fiber or surface lies on the segment (a binary shadow ray).
    bool occluded(const Vec3f& origin, const Vec3f& dir, float tMax,
                  const RayOrigin* from = nullptr) const;
    /// Whether an opaque surface lies on the segment (fibers ignored).
    bool surfaceOccluded(const Vec3f& origin, const Vec3f& dir, float tMax) const;

    /// The own-fiber rule: a crossing at arc length `arcLength` of the strand
    /// `own` lies on, seen `chord` away from `own`, is that fiber itself.
    static bool isOwnFiber(std::uint32_t strand, float arcLength, const FiberPoint& own, float chord,
                           float slack) {
        return strand == own.strand && std::abs(arcLength - own.arcLength) <= 1.5f * chord + slack;
    }

    /// The widest ribbon's width: max over the groom's points of k·D_i (k·D
    /// without per-point diameters; 0 for an empty groom).
    float ribbonWidth() const { return width_; }
    /// Null when the scene has no surfaces.
    const SurfaceScene* surfaces() const { return surfaces_.get(); }

private:
    struct Impl;
    /// Embree's filter for every query: rejects hits off the ribbons and the
    /// origin's own fiber, or collects every hit for crossings().
    static void filterHits(const RTCFilterFunctionNArguments* args);

    std::unique_ptr<Impl> impl_;
    float width_;
    float locateDistance_;
    std::shared_ptr<const SurfaceScene> surfaces_;
};

} // namespace hairvox
