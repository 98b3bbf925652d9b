// Internal to hairvox pipeline: the fiber grid through the shared disk cache
// (PipelineOptions::diskCache, core/disk_cache.h) — the render tasks of a
// shot on a farm splat a groom once between them. The lights' prepared
// caches go through the same cache inside the grid model
// (GlobalTermSettings::diskCache).
#pragma once

#include <hairvox/core/disk_cache.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <cstdint>

namespace hairvox::detail {

/// The disk cache's kind of a fiber grid entry.
inline constexpr const char* kGridCacheKind = "grid";

/// The grid the cache holds under `key` (gridKey(): the groom's contents and
/// the splat's options), or splatStrands(groom, splat), stored there when
/// `store` (PipelineOptions::diskCacheStoresGrid). An entry
/// that is not a readable fiber grid is splatted again and replaced. The
/// grid is the same either way (fiberGridFromBytes(fiberGridBytes(g)) is g).
FiberGrid splatOrLoad(const Groom& groom, const SplatOptions& splat, const DiskCache& cache,
                      std::uint64_t key, bool store);

} // namespace hairvox::detail
