#include <hairvox/volumetric/surface_irradiance.h>

#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/math.h>
#include <hairvox/core/sampling.h>
#include <hairvox/geometry/surface_scene.h>

#include <algorithm>
#include <cmath>

namespace hairvox {

namespace {

/// Area samples per cell face area (H²) at least.
constexpr double kSamplesPerCellFace = 16.0;

} // namespace

SurfaceIrradiance::SurfaceIrradiance(const SurfaceScene& surfaces, const CellGrid& box)
    : grid_(box.voxelSize(), box.cellVoxels(), box.boxMin(), box.boxDims()) {
    std::vector<float> areaOf(grid_.boxCells(), 0.0f);
    const auto add = [&](const Vec3f& x, double area) {
        const std::int64_t i = grid_.boxIndex(grid_.cellAt(x));
        if (i >= 0)
            areaOf[std::size_t(i)] += float(area);
    };
    const double cellFace = double(grid_.cellSize()) * double(grid_.cellSize());
    const double sampleArea = cellFace / kSamplesPerCellFace;
    for (const TriangleMesh& mesh : surfaces.meshes())
        for (const auto& tri : mesh.triangles) {
            const Vec3f a = mesh.positions[tri[0]], b = mesh.positions[tri[1]],
                        c = mesh.positions[tri[2]];
            const double area = 0.5 * double(glm::length(glm::cross(b - a, c - a)));
            const auto n = std::max<std::size_t>(1, std::size_t(std::ceil(area / sampleArea)));
            for (std::size_t k = 0; k < n; ++k) {
                // R2 points (shifted by ½) folded into the triangle.
                const Vec2f r2 = r2Point(double(k + 1), 0x8000'0000'8000'0000ull);
                float u = r2.x, v = r2.y;
                if (u + v > 1.0f) {
                    u = 1.0f - u;
                    v = 1.0f - v;
                }
                add(a + u * (b - a) + v * (c - a), area / double(n));
            }
        }
    for (const Sphere& sphere : surfaces.spheres()) {
        const double area = 4.0 * Pi * double(sphere.radius) * double(sphere.radius);
        const auto n = std::max<std::size_t>(1, std::size_t(std::ceil(area / sampleArea)));
        // A Fibonacci lattice: equal-area points.
        constexpr double golden = 2.399963229728653; // π(3 − √5)
        for (std::size_t k = 0; k < n; ++k) {
            const double z = 1.0 - (2.0 * double(k) + 1.0) / double(n);
            const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
            const double phi = golden * double(k);
            add(sphere.center + sphere.radius * Vec3f(float(r * std::cos(phi)),
                                                      float(r * std::sin(phi)), float(z)),
                area / double(n));
        }
    }
    std::vector<std::uint8_t> marked(areaOf.size());
    for (std::size_t i = 0; i < areaOf.size(); ++i)
        marked[i] = areaOf[i] > 0;
    for (const std::size_t i : grid_.makePresent(marked))
        area_.push_back(areaOf[i]);
    irradiance_.assign(area_.size(), Rgb(0.0f));
}

std::uint64_t SurfaceIrradiance::memoryBytes() const {
    return grid_.memoryBytes() + area_.capacity() * sizeof(float) +
           irradiance_.capacity() * sizeof(Rgb);
}

Rgb SurfaceIrradiance::irradiance(const Vec3f& x) const {
    Rgb sum(0.0f);
    const float weights =
        grid_.forEachAround(x, [&](std::size_t slot, float w) { sum += w * irradiance_[slot]; });
    return weights > 0 ? sum / weights : Rgb(0.0f);
}

} // namespace hairvox
