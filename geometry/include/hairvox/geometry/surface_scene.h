// hairvox geometry: the opaque surfaces of a scene — analytic spheres and
// triangle meshes — as rays meet them. The one place where every stage asks
// what a surface hides or blocks: the camera's view of the surfaces
// (pipeline/), the global term's blocked shadow paths (transmittance/
// withSurfaces), the path tracer's and exact mode's rays (RayScene).
//
// Meshes live in an Embree 3 scene of their own (triangles, robust
// traversal); spheres are intersected analytically (Sphere::intersect).
// Surfaces are numbered spheres first, then meshes, in the order given.
//
// Surfaces are two-sided: a hit's normals face the ray's origin. The shading
// normal is the mesh's corner normals interpolated with the barycentric
// coordinates (flipped to the geometric normal's side), or the geometric
// normal. A ray leaving a surface point starts surfaceOffset() off the surface
// along the geometric normal, so that it does not meet its own triangle.
#pragma once

#include <hairvox/core/vecmath.h>
#include <hairvox/geometry/triangle_mesh.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace hairvox {

struct SurfaceHit {
    float t = 0;
    std::uint32_t surface = 0;   ///< spheres first, then meshes
    Vec3f normal{0.0f};          ///< unit shading normal, facing the ray's origin
    Vec3f geometricNormal{0.0f}; ///< unit, facing the ray's origin
};

/// How far off a surface point at x a ray leaving it starts: a small multiple
/// of the coordinates' magnitude (the float resolution there).
inline float surfaceOffset(const Vec3f& x) {
    return 1e-5f * (1.0f + std::max({std::abs(x.x), std::abs(x.y), std::abs(x.z)}));
}

class SurfaceScene {
public:
    /// Throws InputError for a sphere without a finite centre and positive
    /// radius, or a mesh with non-finite positions or out-of-range indices.
    SurfaceScene(std::vector<Sphere> spheres, std::vector<TriangleMesh> meshes);
    ~SurfaceScene();
    SurfaceScene(const SurfaceScene&) = delete;
    SurfaceScene& operator=(const SurfaceScene&) = delete;

    /// The nearest surface on origin + t·dir, t ∈ (0, tMax). Thread-safe.
    std::optional<SurfaceHit> intersect(const Vec3f& origin, const Vec3f& dir, float tMax) const;
    /// intersect() for many rays at once, the meshes traced as one stream of
    /// rays (Embree's coherent packets: a camera's rays through neighbouring
    /// pixels): hits[i] = intersect(origins[i], dirs[i], tMax). The three
    /// spans have the same size. Thread-safe.
    void intersect(std::span<const Vec3f> origins, std::span<const Vec3f> dirs, float tMax,
                   std::span<std::optional<SurfaceHit>> hits) const;
    /// Whether a surface lies on origin + t·dir, t ∈ (0, tMax) (a segment
    /// starting inside a sphere does). Thread-safe.
    bool occluded(const Vec3f& origin, const Vec3f& dir, float tMax) const;
    /// occluded() for many segments at once, the meshes tested as one stream
    /// of rays (Embree's coherent packets: a renderer's shadow rays toward a
    /// light): blocked[i] = occluded(origins[i], dirs[i], tMax[i]) (1 or 0).
    /// All four spans have the same size. Thread-safe.
    void occluded(std::span<const Vec3f> origins, std::span<const Vec3f> dirs,
                  std::span<const float> tMax, std::span<std::uint8_t> blocked) const {
        occluded(origins, dirs, tMax, blocked, RayCoherence::Coherent);
    }
    /// Whether Embree traces a stream as packets of neighbouring rays
    /// (Coherent: a camera's, a light's shadow rays from neighbouring
    /// fragments) or ray by ray (Incoherent). Each ray's answer is the
    /// intersection test of the mode chosen, which can differ between the
    /// two for a ray grazing a triangle's edge.
    enum class RayCoherence { Coherent, Incoherent };
    /// occluded() for a stream traced as `coherence` says. Ray by ray
    /// suits the environment's shadow rays (the hair's samples along many
    /// fibers toward a region, the surfaces' points toward their region
    /// light): Embree's packets of them cost 0.3 CPU-s more of the default
    /// scene's 5, for the same answers there (docs/environment.md).
    void occluded(std::span<const Vec3f> origins, std::span<const Vec3f> dirs,
                  std::span<const float> tMax, std::span<std::uint8_t> blocked,
                  RayCoherence coherence) const;
    /// Whether p is inside a sphere, or inside a closed mesh: the first surface
    /// met along most of three fixed directions is seen from behind.
    bool contains(const Vec3f& p) const;

    bool empty() const { return spheres_.empty() && meshes_.empty(); }
    std::size_t surfaceCount() const { return spheres_.size() + meshes_.size(); }
    std::size_t triangleCount() const;
    const std::vector<Sphere>& spheres() const { return spheres_; }
    const std::vector<TriangleMesh>& meshes() const { return meshes_; }
    Bounds3f bounds() const { return bounds_; }

private:
    struct Embree;
    std::vector<Sphere> spheres_;
    std::vector<TriangleMesh> meshes_;
    Bounds3f bounds_;
    std::unique_ptr<Embree> embree_; ///< null without meshes
};

} // namespace hairvox
