#include <hairvox/core/large_array.h>

#include <sys/mman.h>

#include <algorithm>

namespace hairvox {

namespace {

std::size_t roundUpToHugePages(std::size_t bytes) {
    return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
}

} // namespace

void* allocateLarge(std::size_t bytes, std::size_t alignment) {
    if (bytes < kHugePageBytes)
        return ::operator new(std::max<std::size_t>(bytes, 1), std::align_val_t(alignment));
    if (bytes > std::size_t(-1) - kHugePageBytes)
        throw std::bad_alloc();
    const std::size_t rounded = roundUpToHugePages(bytes);
    void* p = ::operator new(rounded, std::align_val_t(std::max(alignment, kHugePageBytes)));
    // Advice only: where the kernel has no transparent huge pages it fails
    // or is ignored, and the block is ordinary pages.
    ::madvise(p, rounded, MADV_HUGEPAGE);
    return p;
}

void deallocateLarge(void* p, std::size_t bytes, std::size_t alignment) noexcept {
    if (bytes < kHugePageBytes)
        ::operator delete(p, std::align_val_t(alignment));
    else
        ::operator delete(p, std::align_val_t(std::max(alignment, kHugePageBytes)));
}

} // namespace hairvox
