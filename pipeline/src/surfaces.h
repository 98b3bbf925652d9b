// hairvox pipeline (private): the scene's opaque surfaces as the camera sees
// them — the SurfaceLayer the rasterizer composites the hair with
// (render/rasterizer.h).
//
// Visibility: one ray through every pixel corner. A pixel whose four corners
// meet the same surface at depths within 2% of each other (and whose centre
// does too) is wholly covered and shaded once, at its centre; any other pixel
// with a corner on a surface is a silhouette or a depth edge and takes 8×8
// samples for its coverage and mean depth, shaded at one sample per 4×4
// quadrant (weighted by the quadrant's hits). A surface narrower than a pixel
// between four corners that all miss it is not drawn. The rays go to Embree
// as streams (a row's corners, a row's centres, an edge pixel's samples),
// which find what the same rays alone find, bit for bit.
//
// Radiance is Lambertian, lit through the hair:
//     L = (ρ/π) Σ_l E_l · max(0, n·ω_l) · (V_l + T_s,l),
// with V and T_s the light's global term at the point (transmittance/: the
// hair's shadow — unscattered and forward-scattered light — and the other
// surfaces' shadow, withSurfaces()), queried a surfaceOffset() off the surface
// as a point on no fiber; and the environment's regions the same way, each
// with the share of its light above the surface (SurfaceEnvironment). With
// the volumetric integrator the scattered light is its solution's instead of
// dual scattering's T_s:
//     L = (ρ/π) [Σ_l E_l · max(0, n·ω_l) · V_l + E_s(x)],
// E_s the irradiance of the light the hair (and the surfaces) scattered onto
// the surface (volumetric/surface_irradiance.h).
#pragma once

#include "environment_lights.h"

#include <hairvox/core/rgb.h>
#include <hairvox/geometry/camera.h>
#include <hairvox/geometry/light.h>
#include <hairvox/geometry/surface_scene.h>
#include <hairvox/render/rasterizer.h>
#include <hairvox/transmittance/global_term_model.h>
#include <hairvox/volumetric/surface_irradiance.h>

#include <vector>

namespace hairvox::detail {

/// The environment's regions as surfaces see them (environment_lights.h):
/// region k's light over the normals, and its global term toward the
/// region's direction without the surfaces' shadow (null: skipped) — a
/// surface point is shadowed by the surfaces along D_k(n), one ray:
///     L += (ρ/π) Σ_k E_k(n) · (V_k + T_s,k) · [nothing along D_k(n)].
struct SurfaceEnvironment {
    const RegionIrradiance* irradiance = nullptr;
    std::vector<Light> lights; ///< per region: toward its direction
    std::vector<const LightGlobalTerm*> terms;
};

/// `terms[l]` is light l's global term, or null for a light that is skipped;
/// `albedo` has one entry per surface; `environment` (null: none) the
/// environment's regions; `scattered` the volumetric integrator's scattered
/// light on the surfaces (null: dual scattering's T_s).
SurfaceLayer surfaceLayer(const SurfaceScene& surfaces, const std::vector<Rgb>& albedo,
                          const Camera& camera, const std::vector<Light>& lights,
                          const std::vector<const LightGlobalTerm*>& terms,
                          const SurfaceEnvironment* environment = nullptr,
                          const SurfaceIrradiance* scattered = nullptr);

} // namespace hairvox::detail
