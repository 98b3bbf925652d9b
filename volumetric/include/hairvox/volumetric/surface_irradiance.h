// hairvox volumetric: the irradiance that scattered light brings to the opaque
// surfaces near the hair (docs/DESIGN.md §9: surfaces take part in the
// transport both ways) — skin lit by the light the hair scatters onto it.
//
// Per cell of the radiance cache's grid (radiance_cache.h: m voxels a side)
// within one cell of the hair: the surfaces' area A in the cell, and the
// power Φ that light paths bring onto it after their first scattering. A
// path that meets a surface there deposits its power, and
//     E = Σ Φ / A
// estimates the cell's mean irradiance on its surface (photon mapping's
// density estimate, with the cell as the kernel). A surface point reads the
// trilinear mean of the cells around it that hold surface (weights
// renormalised); the Lambertian surface then reflects ρ/π · E. Light that
// reaches a surface unscattered is direct lighting, which the renderer
// computes with each light's visibility; surfaces farther than a cell from
// the hair receive none of this (their interreflection is not modelled).
//
// A is measured by sampling the surfaces uniformly by area (a mesh's
// triangles with points of the R2 sequence, the spheres with Fibonacci
// lattices), 16 points per cell face area at least.
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>

#include <cstdint>
#include <vector>

namespace hairvox {

class SurfaceScene;

class SurfaceIrradiance {
public:
    /// Cells of side m·h (world box of cell C: [(m·C − ½)·h, (m·C + m − ½)·h))
    /// holding surface within the cells [cellMin, cellMin + dims).
    SurfaceIrradiance(const SurfaceScene& surfaces, float voxelSize, int cellVoxels,
                      const glm::ivec3& cellMin, const glm::ivec3& dims);

    std::size_t cellCount() const { return area_.size(); }
    std::uint64_t memoryBytes() const;

    /// The slot of the cell holding x, or -1 (no surface there, or outside).
    std::int64_t slotAt(const Vec3f& x) const;
    /// Adds power Φ arriving on the surface in the cell. Not thread-safe for one slot.
    void deposit(std::uint32_t slot, const Rgb& power) { irradiance_[slot] += power / area_[slot]; }
    /// The mean irradiance on the surface around x; 0 away from the cells.
    Rgb irradiance(const Vec3f& x) const;

private:
    std::int64_t slotOfCell(const glm::ivec3& cell) const;
    Vec3f cacheCoordinates(const Vec3f& x) const {
        return (x / h_ + 0.5f) / float(cellVoxels_);
    }

    float h_ = 1;
    int cellVoxels_ = 1;
    glm::ivec3 cellMin_{0}, dims_{0};
    std::vector<std::int32_t> index_; ///< dense over the box: slot or -1
    std::vector<float> area_;         ///< per slot
    std::vector<Rgb> irradiance_;     ///< per slot
};

} // namespace hairvox
