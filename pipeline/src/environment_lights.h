// hairvox pipeline (private): the environment light in the dual-scattering
// integrator (docs/environment.md has the design and its measurements).
//
// Hair. The map is cut into K regions (EnvironmentMap::split: median cut of
// luminance × solid angle, Debevec 2005), each a directional light of the
// region's irradiance ∫L dω from its energy-weighted mean direction, prepared
// like any light (its global term in the scene's mode: V, T_s, σ_f² toward
// that direction) and shaded with the fiber's longitudinal lobes widened by
// the region's angular spread (DualScatteringShader::shade's spread2), so
// that a region's R highlight is as wide as the region rather than a copy of
// the lobe per light. The surfaces' shadow on the hair is the share of the
// region's light they leave, from EnvironmentOptions::hairShadowRays rays per
// point along the region cut again by energy (RegionSurfaceShadow).
//
// Surfaces (Lambertian). A region's light reaches a surface point with normal
// n as E_k(n) = ∫_region L(ω) max(0, n·ω) dω — part of a region may lie below
// the surface — from the mean direction D_k(n) of that light. Both are
// tabulated over a latitude–longitude grid of normals (bilinear), from the
// region cut again into sub-regions (their irradiances and directions), so
// that Σ_k E_k(n) is the map's irradiance (a uniform map on a sphere gives
// albedo × L). The point is lit through the hair by the region's global term
// (V + T_s toward its direction) and shadowed by the surfaces along D_k(n)
// (one ray): the skin under the hair gets the light that crosses it, and a
// chin's shadow on the neck is a region's soft edge at a time.
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/geometry/camera.h>
#include <hairvox/geometry/environment_map.h>
#include <hairvox/geometry/light.h>
#include <hairvox/geometry/surface_scene.h>
#include <hairvox/render/rasterizer.h>
#include <hairvox/transmittance/global_term_model.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace hairvox::detail {

/// E_k(n) and D_k(n) of each region over the normals n (see above).
class RegionIrradiance {
public:
    /// Normals tabulated: kNormalsX azimuths × kNormalsY inclinations from +y
    /// to −y (both poles included), 5.7° apart.
    static constexpr int kNormalsX = 64, kNormalsY = 33;

    RegionIrradiance() = default;
    /// `subdivisions` sub-regions per region (EnvironmentMap::split within it).
    RegionIrradiance(const EnvironmentMap& map, std::span<const EnvironmentRegion> regions,
                     std::size_t subdivisions);

    struct Value {
        Rgb irradiance{0.0f};              ///< E_k(n)
        Vec3f direction{0.0f, 1.0f, 0.0f}; ///< D_k(n), unit (meaningless where E_k is 0)
    };
    /// Region k's light on a surface of unit normal n.
    Value at(std::size_t region, const Vec3f& n) const;
    std::size_t regionCount() const { return regions_; }
    std::size_t memoryBytes() const { return table_.capacity() * sizeof(Node); }

private:
    struct Node {
        Rgb irradiance;
        Vec3f direction; ///< Σ luminance(E_j)·max(0, n·d_j)·d_j over the sub-regions j
    };
    std::size_t regions_ = 0;
    std::vector<Node> table_; ///< [region][y][x]
};

/// The environment as the dual-scattering integrator lights with it.
struct EnvironmentLighting {
    std::vector<EnvironmentRegion> regions;
    /// One directional light per region (named "<environment>.<k>"), in
    /// the regions' order, and its EnvironmentRegion::spread2.
    std::vector<Light> lights;
    std::vector<float> spread2;
    RegionIrradiance surfaces;
    /// Per region: its sub-regions by energy, the directions the hair's
    /// surface shadow is cast along (RegionSurfaceShadow).
    std::vector<std::vector<EnvironmentRegion>> shadowDirections;
};

/// Cuts the map into `count` regions weighed `by`, tabulates what surfaces
/// see of each (`subdivisions` sub-regions a region), and cuts each into
/// `shadowRays` directions for the hair's surface shadow.
EnvironmentLighting environmentLighting(const EnvironmentMap& map, const std::string& name,
                                        std::size_t count, EnvironmentSplit by,
                                        std::size_t subdivisions, std::size_t shadowRays);

/// What the hair sees of a region through the surfaces: the share of its
/// light that no surface blocks, from one ray along each of `directions` (the
/// region cut again by energy, EnvironmentLighting::shadowDirections), each
/// weighing its share of the region's luminance. A region of the sky half
/// behind a body lights hair lying on the body by half, where one ray along
/// its mean direction gives all or nothing (Ratboy's mohawk on its body under
/// sky.exr, 8 regions: 4 rays took the error against the path tracer from
/// 0.431 to 0.404, at 1.5x the CPU time; docs/environment.md). The result is the
/// mixture of `inner`'s term (the share) and GlobalTerm::blocked() (the
/// rest): V, P and T_s scaled by the share, σ_f² (conditioned on a
/// crossing) kept; a point no ray leaves is blocked without being evaluated.
/// Without surfaces it is `inner`.
class RegionSurfaceShadow final : public LightGlobalTerm {
public:
    RegionSurfaceShadow(std::shared_ptr<const LightGlobalTerm> inner,
                        std::shared_ptr<const SurfaceScene> surfaces,
                        std::span<const EnvironmentRegion> directions);
    GlobalTermStats evaluate(std::span<const GlobalTermQuery> queries,
                             std::span<GlobalTerm> out) const override;
    bool blocksEverything() const override { return inner_->blocksEverything(); }
    std::size_t memoryBytes() const override { return inner_->memoryBytes(); }

private:
    std::shared_ptr<const LightGlobalTerm> inner_;
    std::shared_ptr<const SurfaceScene> surfaces_; ///< null: none
    std::vector<Vec3f> directions_;
    std::vector<float> weights_; ///< each direction's share of the region's luminance
};

/// The map's backdrop as the camera sees it: per pixel the mean of
/// EnvironmentMap::backdrop() over 2 × 2 points of the pixel, evaluated when
/// the rasterizer asks for the pixel. `map` and `camera` must outlive it.
BackgroundLayer backgroundLayer(const EnvironmentMap& map, const Camera& camera);

} // namespace hairvox::detail
