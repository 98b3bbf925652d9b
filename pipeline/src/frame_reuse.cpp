#include "frame_reuse.h"

#include <hairvox/core/hash.h>

#include <span>

namespace hairvox {

FrameReuse::FrameReuse()
    : state_(std::make_unique<State>()) {}
FrameReuse::~FrameReuse() = default;

namespace detail {

std::uint64_t groomKey(const Groom& groom) {
    Hasher h;
    h.value(contentHash(groom));
    h.values(std::span<const float>(groom.thickness));
    h.values(std::span<const std::uint8_t>(groom.fiberType));
    return h.digest();
}

std::uint64_t gridKey(std::uint64_t groom, const SplatOptions& splat) {
    Hasher h;
    h.value(groom);
    h.value(splat.voxelSize).value(splat.storeOrientationTensor);
    splat.fiberScale.hashInto(h);
    h.string(splat.sourceFile); // recorded in the grid's metadata
    return h.digest();
}

std::uint64_t modelKey(std::uint64_t groom, std::uint64_t grid, const Scene& scene,
                       const PipelineOptions& options, const SceneGroom& sceneGroom,
                       const SceneSurfaces& surfaces, const EnvironmentMap* environment) {
    Hasher h;
    h.value(groom).value(grid);
    for (const FiberParams& fiber : sceneGroom.palette.fibers)
        fiber.hashInto(h);
    scene.dualScattering.hashInto(h);
    scene.fiberScale.hashInto(h);
    h.value(scene.globalTermMode);
    h.value(scene.exact.rays).value(scene.exact.radius).value(scene.exact.seed);
    options.grid.hashInto(h);
    h.value(scene.fiberSampleSpacing.has_value()).value(scene.fiberSampleSpacing.value_or(0.0f));
    h.string(scene.groom.file.string());
    if (surfaces.scene) {
        for (const Sphere& sphere : surfaces.scene->spheres())
            h.value(sphere.center).value(sphere.radius);
        for (const TriangleMesh& mesh : surfaces.scene->meshes())
            h.value(mesh.contentHash());
    }
    for (const Rgb& albedo : surfaces.albedo)
        h.value(albedo);
    for (const MeshSource& mesh : scene.meshes)
        h.string(mesh.file.string());
    h.value(environment != nullptr);
    if (environment) {
        environment->hashInto(h);
        h.string(scene.environment ? scene.environment->name : std::string());
        h.value(scene.environmentLights);
        options.environment.hashInto(h);
    }
    return h.digest();
}

std::uint64_t lightKey(std::uint64_t model, const Light& light) {
    Hasher h;
    h.value(model);
    light.hashInto(h);
    return h.digest();
}

} // namespace detail
} // namespace hairvox
