// Internal to hairvox pipeline: what the frames of a sequence carry from one
// to the next (FrameReuse, pipeline.h) and the keys that say when they can:
// each key is what a stage's result is made of — contents as loaded, and
// every setting the stage reads — never a file's time (a name only where a
// message quotes it).
#pragma once

#include <hairvox/pipeline/pipeline.h>

#include <cstdint>
#include <map>
#include <memory>

namespace hairvox {

struct FrameReuse::State {
    /// The last frame's assets (its grid, model and groom), and the keys
    /// they were built under; null before the first frame.
    std::shared_ptr<const SceneAssets> assets;
    std::uint64_t gridKey = 0, modelKey = 0;
    /// Its lights' prepared terms (of assets->globalTerm), by lightKey().
    std::map<std::uint64_t, std::shared_ptr<const LightGlobalTerm>> lights;
    /// The volumetric integrator's solution, and the key it was solved under
    /// (the model's key, every light's, the integrator's settings).
    std::shared_ptr<const MultipleScatteringSolution> multiple;
    std::uint64_t multipleKey = 0;

    /// Forgets the frame before (its memory is freed unless this frame shares it).
    void release() {
        lights.clear();
        multiple.reset();
        assets.reset();
    }
};

namespace detail {

/// The groom as every stage reads it: its points, diameters and fiber types.
std::uint64_t groomKey(const Groom& groom);

/// What splatStrands() makes the fiber grid from: the groom (groomKey()),
/// and the options that change the grid (not the memory budget, threads or
/// progress).
std::uint64_t gridKey(std::uint64_t groom, const SplatOptions& splat);

/// What the rest of a frame's assets are made from besides the groom and
/// the grid (gridKey(), 0 in exact mode): the tables and crossing tables
/// (each fiber type's optics, d_b), the model's settings (fiber scale, d_f,
/// the surfaces' contents and colours), the global-term mode with its
/// options, the environment light (its map, colour, rotation, name and the
/// options of its regions), and the names the groom's and meshes' messages quote.
std::uint64_t modelKey(std::uint64_t groom, std::uint64_t grid, const Scene& scene,
                       const PipelineOptions& options, const SceneGroom& sceneGroom,
                       const SceneSurfaces& surfaces, const EnvironmentMap* environment);

/// A light's prepared term under a model (modelKey()): the light, all but its name.
std::uint64_t lightKey(std::uint64_t model, const Light& light);

} // namespace detail
} // namespace hairvox
