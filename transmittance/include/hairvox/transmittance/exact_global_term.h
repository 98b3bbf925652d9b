// hairvox transmittance: the exact global term by ray casting (docs/DESIGN.md §5).
//
// The strands become Embree 3 flat linear curves: ray-facing ribbons, so a ray
// crossing a fiber of tangent u registers one hit with probability
// proportional to the ribbon width times |ω × u| — the cross-section the grid
// modes integrate. The ribbon width is k·D, the fiber diameter D times the
// density multiplier k: a modeled strand stands for k real hairs lying side by
// side, so a ray crosses k times as many hairs on average and each crossing
// is one hair. This is the medium the grid (λ scaled by k) and the rasterizer
// (coverage 1 − (1 − α)^k) see; counting each hit of a D-wide ribbon k times
// instead would stack the k hairs on one spot and leave V unchanged by k.
// All hits along a shadow ray are collected (a context filter rejects every
// hit, so traversal continues), sorted, and deduplicated: Embree can report
// the same primitive twice, and a ray through the joint of two segments of one
// strand hits both ribbons. For one ray crossing fibers j = 1..m:
//   V = [m = 0],  P = ∏ ā_f(θ_j),  σ_f² = Σ β̄_f²(θ_j),  T_s = d_f (P − V).
// With K rays whose origins are spread over a disk of radius r perpendicular
// to the light, the global term is the mean over rays (σ_f² over the rays that
// crossed something, matching the grid's conditioning).
//
// Self-shadowing: the query point lies on its own fiber, which must not count.
// The own strand is the query's strand hint or else the strand whose
// centreline passes within max(D, k·D) of the point. A hit on that strand is
// the own fiber when the strand runs nearly straight between the point and
// the hit — arc length ≤ 1.5 × chord + 2(r + k·D) — and is dropped; a curl
// looping back across the ray (arc length much longer than the chord) is
// another crossing and counts.
#pragma once

#include <hairvox/strands/groom.h>
#include <hairvox/transmittance/global_term_model.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace hairvox {

struct ExactOptions {
    int rays = 1;     ///< K shadow rays per point, [1, 65536]
    float radius = 0; ///< r: ray origins spread over a disk of this radius, ⊥ to ω
    std::uint64_t seed = 1;

    void validate() const;
};

/// One fiber crossed by a shadow ray.
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

/// Embree scene of a groom's strands: every fiber crossing along a ray.
class StrandRayCaster {
public:
    /// Ribbons of width `ribbonWidth`; locate() searches within `locateDistance`
    /// (default: the ribbon width) of a centreline.
    StrandRayCaster(const Groom& groom, float ribbonWidth, float locateDistance = 0);
    ~StrandRayCaster();
    StrandRayCaster(const StrandRayCaster&) = delete;
    StrandRayCaster& operator=(const StrandRayCaster&) = delete;

    /// Crossings of the ray origin + t·dir, t ∈ (0, tMax), sorted by t and
    /// deduplicated (see the file comment). Thread-safe; `out` is overwritten.
    void crossings(const Vec3f& origin, const Vec3f& dir, float tMax,
                   std::vector<FiberCrossing>& out) const;

    /// The point of a strand centreline nearest to p, if one passes within
    /// the locate distance. With a strand hint only that strand is searched;
    /// otherwise a uniform grid of segments (built on first use).
    std::optional<FiberPoint> locate(const Vec3f& p,
                                     std::uint32_t strandHint = kUnknownStrand) const;

    float ribbonWidth() const { return width_; }

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    float width_;
    float locateDistance_;
};

/// The `exact` mode. Keeps a reference to nothing: the groom is copied into
/// the Embree scene.
std::unique_ptr<GlobalTermModel> makeExactModel(const Groom& groom, const CrossingTable& crossings,
                                                const GlobalTermSettings& settings,
                                                const ExactOptions& options);

} // namespace hairvox
