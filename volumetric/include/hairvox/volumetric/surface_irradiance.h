// hairvox volumetric: the irradiance that scattered light brings to the opaque
// surfaces near the hair (docs/DESIGN.md §9: surfaces take part in the
// transport both ways) — skin lit by the light the hair scatters onto it.
//
// Per cell of the radiance cache's grid (cell_grid.h: m voxels a side)
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
#include <hairvox/volumetric/cell_grid.h>

#include <cstdint>
#include <vector>

namespace hairvox {

class SurfaceScene;

class SurfaceIrradiance {
public:
    /// The cells of `box` (its present cells ignored) that hold surface.
    SurfaceIrradiance(const SurfaceScene& surfaces, const CellGrid& box);

    std::size_t cellCount() const { return area_.size(); }
    std::uint64_t memoryBytes() const;

    /// The slot of the cell holding x, or -1 (no surface there, or outside).
    std::int64_t slotAt(const Vec3f& x) const { return grid_.slotAt(x); }
    /// Adds power Φ arriving on the surface in the cell. Not thread-safe for one slot.
    void deposit(std::uint32_t slot, const Rgb& power) { irradiance_[slot] += power / area_[slot]; }
    /// The mean irradiance on the surface around x; 0 away from the cells.
    Rgb irradiance(const Vec3f& x) const;

private:
    CellGrid grid_;
    std::vector<float> area_;         ///< per slot
    std::vector<Rgb> irradiance_;     ///< per slot
};

} // namespace hairvox
