// hairvox pipeline (private): the scene's opaque surfaces as the camera sees
// them — the SurfaceLayer the rasterizer composites the hair with
// (render/rasterizer.h).
//
// The head sphere: a pixel centre farther than one pixel's angle from the
// silhouette cone is wholly inside or outside it; the pixels on the
// silhouette take 8×8 samples for their coverage, mean depth and mean
// radiance. Radiance is Lambertian, (albedo/π)·Σ E_l·cos θ_l, lit by the
// scene's lights without shadows.
#pragma once

#include <hairvox/geometry/camera.h>
#include <hairvox/geometry/light.h>
#include <hairvox/pipeline/scene.h>
#include <hairvox/render/rasterizer.h>

#include <vector>

namespace hairvox::detail {

SurfaceLayer headSurfaceLayer(const Head& head, const Camera& camera,
                              const std::vector<Light>& lights);

} // namespace hairvox::detail
