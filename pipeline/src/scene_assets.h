// Internal to hairvox pipeline: a scene's assets prepared for the
// rasterized integrators (dual scattering, volumetric) — the groom, the
// surfaces, the environment map, the fiber grid, the dual-scattering tables
// and the global-term model — built, taken from the frame before (FrameReuse)
// or from the disk cache (asset_cache.h) where their keys match.
#pragma once

#include "frame_reuse.h"

#include <hairvox/pipeline/pipeline.h>

#include <cstdint>

namespace hairvox::detail {

/// What prepareAssets() did: built the assets, or found them all in the
/// frame before (then `reused` says which), and the keys it built them under.
struct FrameAssets {
    const SceneAssets* reused = nullptr;
    bool gridReused = false;
    std::uint64_t gridKey = 0, modelKey = 0; ///< when reuse was asked for
};

/// loadSceneAssets() into `assets` (empty, where they will stay: the model
/// refers to their grid and groom), taking from `reuse` (when given) the
/// grid, or every asset of the frame before, where their keys match, and
/// dropping the rest of the frame before before allocating anew.
/// Where the tables derived from the fibers' optics (dual-scattering
/// tables, the volumetric integrator's scattering kernels) are kept between
/// processes: PipelineOptions::tableCacheDir, or beside the shared grids and
/// lights of PipelineOptions::diskCache, or defaultTableCacheDir().
std::filesystem::path tableCacheDirOf(const PipelineOptions& options);

FrameAssets prepareAssets(const Scene& scene, const PipelineOptions& options, SceneAssets* assets,
                          FrameReuse::State* reuse);

} // namespace hairvox::detail
