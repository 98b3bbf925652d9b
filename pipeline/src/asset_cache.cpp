#include "asset_cache.h"

#include <hairvox/core/error.h>

#include <iostream>
#include <string>

namespace hairvox::detail {

FiberGrid splatOrLoad(const Groom& groom, const SplatOptions& splat, const DiskCache& cache,
                      std::uint64_t key, bool store) {
    if (const auto bytes = cache.load(kGridCacheKind, key)) {
        const std::string name = cache.entryPath(kGridCacheKind, key).string();
        try {
            return fiberGridFromBytes(*bytes, name);
        } catch (const InputError& e) {
            std::cerr << "hairvox: warning: cache entry " << e.what() << "; splatted again\n";
            cache.discard(kGridCacheKind, key);
        }
    }
    FiberGrid grid = splatStrands(groom, splat);
    if (store)
        cache.store(kGridCacheKind, key, fiberGridBytes(grid));
    return grid;
}

} // namespace hairvox::detail
