#include <hairvox/volumetric/surface_irradiance.h>

#include <hairvox/core/grid_traversal.h>
#include <hairvox/core/math.h>
#include <hairvox/geometry/surface_scene.h>

#include <algorithm>
#include <cmath>

namespace hairvox {

namespace {

/// Area samples per cell face area (H²) at least.
constexpr double kSamplesPerCellFace = 16.0;

} // namespace

SurfaceIrradiance::SurfaceIrradiance(const SurfaceScene& surfaces, float voxelSize,
                                     int cellVoxels, const glm::ivec3& cellMin,
                                     const glm::ivec3& dims)
    : h_(voxelSize)
    , cellVoxels_(cellVoxels)
    , cellMin_(cellMin)
    , dims_(dims) {
    const std::size_t boxCells = std::size_t(dims.x) * std::size_t(dims.y) * std::size_t(dims.z);
    std::vector<float> areaOf(boxCells, 0.0f);
    const auto add = [&](const Vec3f& x, double area) {
        const Vec3f q = cacheCoordinates(x);
        const glm::ivec3 r = glm::ivec3(floorToInt(q.x), floorToInt(q.y), floorToInt(q.z)) - cellMin_;
        if (r.x < 0 || r.y < 0 || r.z < 0 || r.x >= dims_.x || r.y >= dims_.y || r.z >= dims_.z)
            return;
        areaOf[(std::size_t(r.x) * std::size_t(dims_.y) + std::size_t(r.y)) * std::size_t(dims_.z) +
               std::size_t(r.z)] += float(area);
    };
    const double cellFace = double(h_) * cellVoxels * double(h_) * cellVoxels;
    const double sampleArea = cellFace / kSamplesPerCellFace;
    for (const TriangleMesh& mesh : surfaces.meshes())
        for (const auto& tri : mesh.triangles) {
            const Vec3f a = mesh.positions[tri[0]], b = mesh.positions[tri[1]],
                        c = mesh.positions[tri[2]];
            const double area = 0.5 * double(glm::length(glm::cross(b - a, c - a)));
            const auto n = std::max<std::size_t>(1, std::size_t(std::ceil(area / sampleArea)));
            for (std::size_t k = 0; k < n; ++k) {
                // R2 points folded into the triangle.
                float u = float(std::fmod(0.5 + 0.7548776662466927 * double(k + 1), 1.0));
                float v = float(std::fmod(0.5 + 0.5698402909980532 * double(k + 1), 1.0));
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
    index_.assign(boxCells, -1);
    for (std::size_t i = 0; i < boxCells; ++i)
        if (areaOf[i] > 0) {
            index_[i] = static_cast<std::int32_t>(area_.size());
            area_.push_back(areaOf[i]);
        }
    irradiance_.assign(area_.size(), Rgb(0.0f));
}

std::uint64_t SurfaceIrradiance::memoryBytes() const {
    return index_.capacity() * sizeof(std::int32_t) + area_.capacity() * sizeof(float) +
           irradiance_.capacity() * sizeof(Rgb);
}

std::int64_t SurfaceIrradiance::slotOfCell(const glm::ivec3& cell) const {
    const glm::ivec3 r = cell - cellMin_;
    if (r.x < 0 || r.y < 0 || r.z < 0 || r.x >= dims_.x || r.y >= dims_.y || r.z >= dims_.z)
        return -1;
    return index_[(std::size_t(r.x) * std::size_t(dims_.y) + std::size_t(r.y)) *
                      std::size_t(dims_.z) +
                  std::size_t(r.z)];
}

std::int64_t SurfaceIrradiance::slotAt(const Vec3f& x) const {
    const Vec3f q = cacheCoordinates(x);
    return slotOfCell(glm::ivec3(floorToInt(q.x), floorToInt(q.y), floorToInt(q.z)));
}

Rgb SurfaceIrradiance::irradiance(const Vec3f& x) const {
    if (area_.empty())
        return Rgb(0.0f);
    const Vec3f q = cacheCoordinates(x) - 0.5f;
    const glm::ivec3 base(floorToInt(q.x), floorToInt(q.y), floorToInt(q.z));
    const Vec3f f = q - Vec3f(base);
    Rgb sum(0.0f);
    float weights = 0;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::ivec3 o((corner >> 2) & 1, (corner >> 1) & 1, corner & 1);
        const std::int64_t slot = slotOfCell(base + o);
        if (slot < 0)
            continue;
        const float w = (o.x ? f.x : 1.0f - f.x) * (o.y ? f.y : 1.0f - f.y) * (o.z ? f.z : 1.0f - f.z);
        sum += w * irradiance_[std::size_t(slot)];
        weights += w;
    }
    return weights > 0 ? sum / weights : Rgb(0.0f);
}

} // namespace hairvox
