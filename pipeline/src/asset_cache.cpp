#include "asset_cache.h"

#include <hairvox/core/error.h>

#include <iostream>
#include <sstream>
#include <string>

namespace hairvox::detail {

FiberGrid splatOrLoad(const Groom& groom, const SplatOptions& splat, const DiskCache& cache,
                      std::uint64_t key) {
    if (const auto bytes = cache.load(kGridCacheKind, key)) {
        std::istringstream in(
            std::string(reinterpret_cast<const char*>(bytes->data()), bytes->size()),
            std::ios::binary);
        const std::string name = cache.entryPath(kGridCacheKind, key).string();
        try {
            return readFiberGrid(in, name);
        } catch (const InputError& e) {
            std::cerr << "hairvox: warning: cache entry " << e.what() << "; splatted again\n";
        }
    }
    FiberGrid grid = splatStrands(groom, splat);
    const std::string bytes = fiberGridVdbBytes(grid);
    cache.store(kGridCacheKind, key,
                std::span(reinterpret_cast<const std::byte*>(bytes.data()), bytes.size()));
    return grid;
}

} // namespace hairvox::detail
