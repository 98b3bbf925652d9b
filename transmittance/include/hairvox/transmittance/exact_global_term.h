// hairvox transmittance: the exact global term by ray casting (docs/DESIGN.md §5).
//
// Shadow rays are cast through the groom's RayScene (geometry/ray_scene.h):
// ray-facing ribbons of width k·D, so a ray crossing a fiber of tangent u
// registers one hit with probability proportional to k·D·|ω × u| — the
// cross-section the grid modes integrate — and each hit is one hair. This is
// the medium the grid (λ scaled by k), the rasterizer and the path tracer
// (the same ribbons) see; counting each hit of a D-wide ribbon k times
// instead would stack the k hairs on one spot and leave V unchanged by k. Every
// crossing along a shadow ray is collected. For one ray crossing fibers j = 1..m:
//   V = [m = 0],  P = ∏ ā_f(θ_j),  σ_f² = Σ β̄_f²(θ_j),  T_s = d_f (P − V).
// With K rays whose origins are spread over a disk of radius r perpendicular
// to the light, the global term is the mean over rays (σ_f² over the rays that
// crossed something, matching the grid's conditioning). A crossing takes ā_f and
// β̄_f² of its own segment's fiber type (Groom::fiberType).
//
// Self-shadowing: the query point lies on its own fiber, which must not count.
// The own strand is the query's strand hint or else the strand whose
// centreline passes within max(D, k·D) of the point (RayScene::locate()); its
// crossings are dropped by RayScene::isOwnFiber() with a slack of
// 2(r + k·D), while a curl looping back across the ray counts. With per-point
// diameters D is the groom's widest (RayScene::ribbonWidth()).
#pragma once

#include <hairvox/strands/groom.h>
#include <hairvox/transmittance/global_term_model.h>

#include <cstdint>
#include <memory>

namespace hairvox {

struct ExactOptions {
    int rays = 1;     ///< K shadow rays per point, [1, 65536]
    float radius = 0; ///< r: ray origins spread over a disk of this radius, ⊥ to ω
    std::uint64_t seed = 1;

    void validate() const;
};

/// The `exact` mode, with one crossing table per fiber type of the groom.
/// Keeps a reference to nothing: the groom is copied into the Embree scene.
std::unique_ptr<GlobalTermModel> makeExactModel(const Groom& groom, CrossingTables crossings,
                                                const GlobalTermSettings& settings,
                                                const ExactOptions& options);

} // namespace hairvox
