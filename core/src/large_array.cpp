#include <hairvox/core/large_array.h>

#include <sys/mman.h>

#include <algorithm>
#include <cstring>

namespace hairvox {

namespace {

std::size_t roundUpToHugePages(std::size_t bytes) {
    return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
}

/// Filled into every new block where the build poisons what it has not
/// written (HAIRVOX_POISON_UNINITIALIZED): 0xFF bytes are NaN as floats and
/// out of range as indices, so that a read before the first write shows.
void poison([[maybe_unused]] void* p, [[maybe_unused]] std::size_t bytes) {
#ifdef HAIRVOX_POISON_UNINITIALIZED
    std::memset(p, 0xFF, bytes);
#endif
}

} // namespace

void* allocateLarge(std::size_t bytes, std::size_t alignment) {
    if (bytes < kHugePageBytes) {
        void* p = ::operator new(std::max<std::size_t>(bytes, 1), std::align_val_t(alignment));
        poison(p, bytes);
        return p;
    }
    if (bytes > std::size_t(-1) - kHugePageBytes)
        throw std::bad_alloc();
    const std::size_t rounded = roundUpToHugePages(bytes);
    void* p = ::operator new(rounded, std::align_val_t(std::max(alignment, kHugePageBytes)));
    // Advice only: where the kernel has no transparent huge pages it fails
    // or is ignored, and the block is ordinary pages.
    ::madvise(p, rounded, MADV_HUGEPAGE);
    poison(p, bytes);
    return p;
}

void deallocateLarge(void* p, std::size_t bytes, std::size_t alignment) noexcept {
    if (bytes < kHugePageBytes)
        ::operator delete(p, std::align_val_t(alignment));
    else
        ::operator delete(p, std::align_val_t(std::max(alignment, kHugePageBytes)));
}

} // namespace hairvox
